#!/usr/bin/env bash
# SIGTERM to a stopped process (Ctrl-Z then kill, or a harness cleaning up)
# is taken by whichever thread runs first after SIGCONT. Handled on one of
# Fast DDS's threads, it interrupts an interprocess wait and the process
# dies in std::terminate ("Interrupted system call"), 4 times in 30 for a
# lone agent. Every process must stop cleanly instead: exit 0, nothing thrown.
# So the signals are taken on one thread of each process (common/process.hpp).
source "$(dirname "$0")/lib.sh"
scenario="$SRC/config/thesis_course.yaml"
start sim "$BIN/ddswarm-sim" --scenario "$scenario" --mode realtime --domain "$DOMAIN"

stop_while_stopped() {  # NAME: SIGSTOP, SIGTERM, SIGCONT; it must exit 0
  local name="$1" pid
  pid=$(eval echo "\$PID_$name")
  kill -STOP "$pid"
  sleep 0.3
  kill -TERM "$pid"
  kill -CONT "$pid"
  wait_pid "$pid" 15; local rc=$?
  echo "$name: exit $rc"
  [ $rc -eq 0 ] || fail "$name exited $rc after SIGTERM while stopped"
  if grep -q "terminate called" "$WORK/$name.log"; then fail "$name: $(grep -A1 'terminate called' "$WORK/$name.log")"; fi
}

# The ground-station console reading a pipe: its main thread waits for a
# line while the signal thread takes Ctrl-C; the wait must see the stop.
mkfifo "$WORK/menu.in"
start menu_input bash -c "exec sleep 60 > '$WORK/menu.in'"
start menu bash -c "exec '$BIN/ddswarm-gs' --config '$scenario' --domain $DOMAIN menu < '$WORK/menu.in'"
prompted() { [ "$(tail -c 2 "$WORK/menu.log")" = "> " ]; }  # waiting for a line
for _ in $(seq 300); do prompted && break; sleep 0.1; done
prompted || fail "the console did not prompt"
sleep 0.5
kill -INT "$PID_menu"
wait_pid "$PID_menu" 3; rc=$?
echo "menu: exit $rc after Ctrl-C"
[ $rc -eq 0 ] && grep -q "Interrupted" "$WORK/menu.log" || fail "the console did not leave on Ctrl-C: exit $rc"

# Agents that have joined the swarm and read its state.
for i in $(seq 8); do
  start "agent$i" "$BIN/ddswarm-agent" --id $((i % 6)) --config "$scenario" --domain "$DOMAIN"
  for _ in $(seq 50); do grep -q "flying" "$WORK/agent$i.log" && break; sleep 0.1; done
  grep -q "flying" "$WORK/agent$i.log" || fail "agent$i did not join"
  sleep 0.5
  stop_while_stopped "agent$i"
done
stop_while_stopped sim
# And a server publishing to an agent, twice more.
for i in 2 3; do
  start "sim$i" "$BIN/ddswarm-sim" --scenario "$scenario" --mode realtime --domain "$DOMAIN"
  start "agent_for_sim$i" "$BIN/ddswarm-agent" --id 0 --config "$scenario" --domain "$DOMAIN"
  for _ in $(seq 50); do grep -q "online" "$WORK/sim$i.log" && break; sleep 0.1; done
  grep -q "online" "$WORK/sim$i.log" || fail "sim$i: no agent came online"
  stop_while_stopped "sim$i"
  kill -TERM "$(eval echo "\$PID_agent_for_sim$i")"
done
echo PASS
