#!/usr/bin/env bash
# Issue 8: dds.best_effort_streams (real time only) sends the swarm state and
# the velocity commands best-effort. Six agent processes fly with it: every
# command is acknowledged, every drone gets airborne, and a ground station
# reading the scenario's dds section sees the drones' states. In lockstep the
# server refuses it with one line naming the field.
source "$(dirname "$0")/lib.sh"
timeout 120 "$BIN/ddswarm-launch" "$SRC/config/thesis_course.yaml" --mode realtime --domain "$DOMAIN" \
  --log-dir "$WORK/logs" --set dds.best_effort_streams=true \
  --gs "takeoff --wait; hold --time 3 --wait; status --drones; land --wait" >"$WORK/launch.log" 2>&1
rc=$?
cat "$WORK/launch.log"
[ $rc -eq 0 ] || { tail -n 20 "$WORK"/logs/*.log; fail "launch exited $rc"; }
grep -q "takeoff 6/6 acknowledged" "$WORK/launch.log" || fail "not every drone acknowledged the take-off"
grep -q "| 6 airborne |" "$WORK/launch.log" || fail "not all 6 drones were airborne"
[ "$(grep -c "airborne" "$WORK/launch.log")" -ge 6 ] || fail "the drones' states did not reach the ground station"
sed 's/^  domain_id: 0$/  domain_id: 0\n  best_effort_streams: true/' "$SRC/config/thesis_course.yaml" >"$WORK/lockstep_be.yaml"
timeout 20 "$BIN/ddswarm-sim" --scenario "$WORK/lockstep_be.yaml" --mode lockstep --domain "$DOMAIN" >"$WORK/refused.log" 2>&1
rc=$?
cat "$WORK/refused.log"
[ $rc -ne 0 ] || fail "the server accepted best-effort streams in lockstep"
grep -q "dds.best_effort_streams = true: needs scenario.mode: realtime" "$WORK/refused.log" || fail "no one-line error naming the field"
echo PASS
