#!/usr/bin/env bash
# Hostile and broken samples never move a drone: while a legitimate plain-DDS
# agent (scripted_commander) hovers drone 0 at 2 m, hostile_publisher sends
# NaN/inf/absurd/unknown-id/stale/future/impostor velocity commands and
# malformed mission commands. Every matching SimStatus rejected_* counter must
# grow and the drone must keep hovering within 0.1 m of 2 m: the commander
# checks its whole hold, the attacker watches the attack window (height,
# drift, speed, failsafe, the legitimate agent's liveness). Afterwards
# `ddswarm-gs status` must show every reason's count above zero.
source "$(dirname "$0")/lib.sh"
start sim "$BIN/ddswarm-sim" --scenario "$SRC/tests/scenarios/one_drone.yaml" --mode realtime \
  --domain "$DOMAIN" --duration 50
start commander "$BIN/scripted_commander" --domain "$DOMAIN" --z 2.0 --hold 10 --tolerance 0.1 --timeout 40
start hostile "$BIN/hostile_publisher" --domain "$DOMAIN" --id 0 --z 2.0 --tolerance 0.1 --attack 3 --timeout 30
wait_pid "$PID_hostile" 45
hostile_rc=$?
cat "$WORK/hostile.log"
wait_pid "$PID_commander" 30
commander_rc=$?
cat "$WORK/commander.log"
[ $hostile_rc -eq 0 ] || fail "hostile samples were not all rejected, or they disturbed the drone (exit $hostile_rc)"
[ $commander_rc -eq 0 ] || fail "the legitimate commander did not hold 2 m within 0.1 m through the attack (exit $commander_rc)"
grep -q 'agent .* online' "$WORK/sim.log" || fail "the server never saw the legitimate agent"
# The operator sees every rejection, by reason, in the ground station's status.
status=$(timeout 20 "$BIN/ddswarm-gs" --domain "$DOMAIN" status 2>&1) || fail "status failed: $status"
echo "$status"
for reason in non-finite absurd 'unknown id' 'stale tick' 'future tick' impostor mission; do
  n=$(echo "$status" | sed -n "s/.*[(, ]$reason \([0-9]*\)[,)].*/\1/p")
  [ -n "$n" ] && [ "$n" -gt 0 ] || fail "status does not show the rejected '$reason' samples: $status"
done
echo PASS
