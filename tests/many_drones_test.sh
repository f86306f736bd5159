#!/usr/bin/env bash
# More than ten drones (Fast DDS keeps 10 instances per keyed topic unless
# told otherwise): 16 agent processes take off and land, all acknowledged.
source "$(dirname "$0")/lib.sh"
timeout 200 "$BIN/ddswarm-launch" "$SRC/config/thesis_course.yaml" --drones 16 --mode lockstep \
  --domain "$DOMAIN" --log-dir "$WORK/logs" --gs "takeoff --wait; status --drones; land --wait" >"$WORK/launch.log" 2>&1
rc=$?
cat "$WORK/launch.log"
[ $rc -eq 0 ] || { cp "$WORK"/logs/*.log "$WORK/" 2>/dev/null; fail "launch exited $rc"; }
grep -q "takeoff 16/16 acknowledged" "$WORK/launch.log" || fail "not every drone acknowledged"
[ "$(grep -c "airborne" "$WORK/launch.log")" -ge 16 ] || fail "not all 16 drones were airborne"
echo PASS
