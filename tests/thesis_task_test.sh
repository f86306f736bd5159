#!/usr/bin/env bash
# The full thesis task with six agent processes completes in
# lockstep through the pillar course at the given speed with zero collisions,
# in bounded wall time; the result is appended to a CSV.
source "$(dirname "$0")/lib.sh"
speed="${1:-0.8}"
started=$SECONDS
timeout 240 "$BIN/ddswarm-launch" "$SRC/config/thesis_course.yaml" --mode lockstep --domain "$DOMAIN" \
  --set sim.agent_timeout_s=5 --log-dir "$WORK/logs" --gs "takeoff --wait; task --speed $speed --csv $WORK/result.csv" >"$WORK/launch.log" 2>&1
rc=$?
cat "$WORK/launch.log"
cp "$WORK"/logs/*.log "$WORK/" 2>/dev/null
[ $rc -eq 0 ] || fail "launch exited $rc"
grep -q "task complete:" "$WORK/launch.log" || fail "no task result line"
grep -q "collisions: obstacle 0, drone 0, ground 0" "$WORK/launch.log" || fail "collisions during the task"
rows=$(($(wc -l <"$WORK/result.csv") - 1))
[ "$rows" -eq 1 ] || fail "expected one CSV row, got $rows"
head -1 "$WORK/result.csv" | grep -q "seed" || fail "CSV lacks the seed column"
sed -n 2p "$WORK/result.csv" | grep -q "^thesis_course,0,1," || fail "CSV row lacks scenario name and seed: $(sed -n 2p "$WORK/result.csv")"
echo "wall time $((SECONDS - started)) s"
echo PASS
