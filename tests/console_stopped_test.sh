#!/usr/bin/env bash
# The ground-station console left at its prompt, stopped (Ctrl-Z) for longer
# than its DDS lease, then resumed (fg): its peers dropped it meanwhile, and
# Fast DDS 2.9 does not always match the two sides again. It must say so and
# join again as a new participant, and its next command must reach every
# agent (ground_station/rejoining_commander.hpp).
source "$(dirname "$0")/lib.sh"
scenario="$SRC/tests/scenarios/slow_liveness.yaml"
start launch "$BIN/ddswarm-launch" "$scenario" --domain "$DOMAIN" --log-dir "$WORK"
gs wait-agents --count 3 --timeout "$(slow 40)" || fail "agents not online"

mkfifo "$WORK/menu.in"
exec 3<>"$WORK/menu.in"  # held open here: the console reads what the test writes
start menu bash -c "exec '$BIN/ddswarm-gs' --config '$scenario' --domain $DOMAIN menu < '$WORK/menu.in'"
prompted() { [ "$(tail -c 2 "$WORK/menu.log")" = "> " ]; }  # waiting for a line
acks() { grep -c "distance 3/3 acknowledged" "$WORK/menu.log"; }
wait_acks() {  # N SECONDS: until the console has printed N acknowledged distance changes
  local end=$((SECONDS + $2))
  while [ "$(acks)" -lt "$1" ] && [ $SECONDS -lt "$end" ]; do sleep 0.2; done
  [ "$(acks)" -ge "$1" ]
}
for _ in $(seq "$(slow 300)"); do prompted && break; sleep 0.1; done
prompted || fail "the console did not prompt"
printf '3\n2.5\n' >&3
wait_acks 1 "$(slow 30)" || fail "the first distance change was not acknowledged by all"

for _ in $(seq 50); do prompted && break; sleep 0.1; done
kill -STOP "$PID_menu"
sleep 6  # twice the console's 3 s lease
kill -CONT "$PID_menu"
sleep 1
printf '3\n3.5\n' >&3
wait_acks 2 "$(slow 60)" || fail "after the stop, the distance change was not acknowledged by all"
grep -q "longer than its DDS lease (3.0 s" "$WORK/menu.log" ||
  fail "the console did not say it was stopped longer than its lease"
grep "longer than its DDS lease" "$WORK/menu.log"

printf '0\n' >&3
wait_pid "$PID_menu" "$(slow 15)"; rc=$?
[ $rc -eq 0 ] || fail "the console exited $rc on 0 (quit)"
echo PASS
