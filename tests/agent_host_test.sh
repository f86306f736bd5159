#!/usr/bin/env bash
# An agent host (ddswarm-agent --ids) flies many drones' brains in
# one process. The thesis task with all six drones in one host gives exactly
# the lockstep result of six agent processes (each brain independent, seeing
# only what its drone receives); a second host cannot claim a drone the
# first flies (exit 3); bad --ids are one-line errors with exit 2.
source "$(dirname "$0")/lib.sh"
scenario="$SRC/config/thesis_course.yaml"
out=$("$BIN/ddswarm-agent" --ids 0-9 --config "$scenario" --domain "$DOMAIN" 2>&1); rc=$?
echo "$out"
[ $rc -eq 2 ] && echo "$out" | grep -q "ids must be in \[0, 5\]" || fail "out-of-range --ids: rc $rc"
out=$("$BIN/ddswarm-agent" --ids 1,1 --config "$scenario" --domain "$DOMAIN" 2>&1); rc=$?
[ $rc -eq 2 ] && echo "$out" | grep -q "id 1 given twice" || fail "duplicate --ids: rc $rc: $out"

run_task() {  # run_task NAME AGENT-ARGS...: prints the result line
  local name=$1; shift
  start "sim_$name" "$BIN/ddswarm-sim" --scenario "$scenario" --mode lockstep --domain "$DOMAIN"
  local sim_pid=$!
  "$@"
  timeout 120 "$BIN/ddswarm-gs" --config "$scenario" --domain "$DOMAIN" task --takeoff >"$WORK/$name.result" 2>&1 \
    || { cat "$WORK/$name.result"; fail "$name: task failed"; }
  kill -TERM $sim_pid
  wait_pid $sim_pid 10 >/dev/null
}
host_agents() {
  start host "$BIN/ddswarm-agent" --ids 0-5 --config "$scenario" --domain "$DOMAIN"
  for _ in $(seq 50); do grep -q "flying drones 0..5" "$WORK/host.log" && break; sleep 0.1; done
  # A second process cannot take a drone the host flies.
  timeout 20 "$BIN/ddswarm-agent" --ids 5 --config "$scenario" --domain "$DOMAIN" >"$WORK/rival.log" 2>&1
  local rc=$?
  [ $rc -eq 3 ] || { cat "$WORK/rival.log"; fail "a rival for drone 5 should exit 3, got $rc"; }
}
process_agents() {
  for i in 0 1 2 3 4 5; do start "p$i" "$BIN/ddswarm-agent" --id $i --config "$scenario" --domain "$DOMAIN"; done
}
run_task host host_agents
kill -TERM "$PID_host"; wait_pid "$PID_host" 10 || fail "the host did not stop on SIGTERM"
run_task procs process_agents
grep "task complete" "$WORK/host.result" || fail "host: no result"
grep "task complete" "$WORK/procs.result" || fail "processes: no result"
strip() { grep "task complete" "$1" | sed 's/(wall [0-9.]* s)//'; }
[ "$(strip "$WORK/host.result")" = "$(strip "$WORK/procs.result")" ] || fail "the agent host and six processes disagree"
# The launcher splits the swarm into agent hosts (the six processes go first).
for i in 0 1 2 3 4 5; do pid_var="PID_p$i"; kill -TERM "${!pid_var}"; done
for i in 0 1 2 3 4 5; do pid_var="PID_p$i"; wait_pid "${!pid_var}" 10 >/dev/null; done
timeout 120 "$BIN/ddswarm-launch" "$scenario" --mode lockstep --agent-hosts 2 --domain "$DOMAIN" --log-dir "$WORK/hosts" \
  --gs "takeoff --wait; task" >"$WORK/hosts.result" 2>&1 || { cat "$WORK/hosts.result"; fail "launch --agent-hosts 2"; }
grep -q "started 3 process(es)" "$WORK/hosts.result" || fail "expected the server and two agent hosts"
[ "$(strip "$WORK/hosts.result")" = "$(strip "$WORK/procs.result")" ] || fail "two agent hosts and six processes disagree"
echo PASS
