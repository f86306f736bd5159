#!/usr/bin/env bash
# Pipelined lockstep (sim.lockstep_pipeline) flies the thesis task
# with six agent processes, collision-free, and stays deterministic: two runs
# with the same seed give the same result to the last digit.
source "$(dirname "$0")/lib.sh"
run() {  # run TAG: one pipelined lockstep swarm through the task; result line in $WORK/TAG.result
  local tag="$1"
  timeout "$(slow 240)" "$BIN/ddswarm-launch" "$SRC/config/thesis_course.yaml" --mode lockstep --domain "$DOMAIN" \
    --set sim.lockstep_pipeline=true --set sim.agent_timeout_s=5 --log-dir "$WORK/$tag" \
    --gs "takeoff --wait; task --csv $WORK/$tag.csv" >"$WORK/$tag.log" 2>&1
  local rc=$?
  cat "$WORK/$tag.log"
  [ $rc -eq 0 ] || fail "$tag: launch exited $rc"
  grep -q "lockstep mode (pipelined" "$WORK/$tag/sim.log" || fail "$tag: the server did not run pipelined"
  grep "task complete:" "$WORK/$tag.log" | sed 's/ (wall [^)]*)//' >"$WORK/$tag.result"
  [ -s "$WORK/$tag.result" ] || fail "$tag: no task result line"
  grep -q "collisions: obstacle 0, drone 0, ground 0" "$WORK/$tag.result" || fail "$tag: collisions during the task"
}
run first
run second
a=$(cat "$WORK/first.result"); b=$(cat "$WORK/second.result")
[ "$a" = "$b" ] || fail "pipelined lockstep reruns differ: '$a' vs '$b'"
echo "pipelined lockstep reruns identical: $a"
echo PASS
