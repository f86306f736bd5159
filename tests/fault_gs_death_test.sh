#!/usr/bin/env bash
# The ground station dies (SIGKILL) mid-task. The swarm completes the
# task it was given, and a new ground station sees the current state and the
# task's result.
source "$(dirname "$0")/lib.sh"
scenario="$SRC/config/thesis_course.yaml"
gs() { timeout 60 "$BIN/ddswarm-gs" --config "$scenario" --domain "$DOMAIN" "$@"; }
start launch "$BIN/ddswarm-launch" "$scenario" --mode realtime --domain "$DOMAIN" --log-dir "$WORK"
gs wait-agents --count 6 --timeout 60 || fail "agents not online"
gs takeoff --wait || fail "takeoff"
start gstask "$BIN/ddswarm-gs" --config "$scenario" --domain "$DOMAIN" task --speed 2
for _ in $(seq 100); do grep -q "acknowledged" "$WORK/gstask.log" && break; sleep 0.1; done
grep -q "task 6/6 acknowledged" "$WORK/gstask.log" || fail "task not accepted"
sleep 2
kill -KILL "$PID_gstask"; wait "$PID_gstask" 2>/dev/null
for _ in 1 2 3; do  # the latched task status follows the reader's match
  gs status | tee "$WORK/status.txt"
  grep -q "task running" "$WORK/status.txt" && break
done
grep -q "task running" "$WORK/status.txt" || fail "a new ground station does not see the running task"
grep -q "6/6 online" "$WORK/status.txt" || fail "a new ground station does not see the swarm"
timeout 150 "$BIN/ddswarm-gs" --config "$scenario" --domain "$DOMAIN" task --attach >"$WORK/result.log" 2>&1; rc=$?
cat "$WORK/result.log"
[ $rc -eq 0 ] || fail "the task did not complete after the ground station died (exit $rc)"
grep -q "task complete:" "$WORK/result.log" || fail "no result line"
grep -q "lost drones" "$WORK/result.log" && fail "no drone should be lost"
gs status | tee "$WORK/status2.txt"
grep -q "task complete in" "$WORK/status2.txt" || fail "a new ground station does not see the result"
echo PASS
