#!/usr/bin/env bash
# Samples malformed on the wire never bring a process down: while a
# legitimate plain-DDS agent (scripted_commander) hovers drone 0 at 2 m,
# malformed_publisher sends VelocityCommands and AgentStatus heartbeats whose
# bool byte is 2, which Fast CDR refuses by throwing. The server must stay up,
# the drone must keep hovering within 0.1 m, and the refused samples must be
# counted in the server's status (`ddswarm-gs status`: malformed N > 0).
source "$(dirname "$0")/lib.sh"
start sim "$BIN/ddswarm-sim" --scenario "$SRC/tests/scenarios/one_drone.yaml" --mode realtime \
  --domain "$DOMAIN" --duration 50
start commander "$BIN/scripted_commander" --domain "$DOMAIN" --z 2.0 --hold 8 --tolerance 0.1 --timeout 40
sleep 3  # the commander is climbing or hovering by now; its hold check covers the attack
kill -0 "$PID_sim" 2>/dev/null || fail "the server exited before the attack"
start malformed "$BIN/malformed_publisher" --domain "$DOMAIN" --id 0 --attack 3
wait_pid "$PID_malformed" 20 || fail "malformed_publisher failed (exit $?)"
cat "$WORK/malformed.log"
kill -0 "$PID_sim" 2>/dev/null || fail "the server died from malformed samples"
status=$(timeout 20 "$BIN/ddswarm-gs" --domain "$DOMAIN" status 2>&1) || fail "status failed: $status"
echo "$status"
kill -0 "$PID_sim" 2>/dev/null || fail "the server died from malformed samples"
n=$(echo "$status" | sed -n 's/.*malformed \([0-9]*\).*/\1/p')
[ -n "$n" ] && [ "$n" -gt 0 ] || fail "status does not count the malformed samples: $status"
wait_pid "$PID_commander" 40
rc=$?
cat "$WORK/commander.log"
[ $rc -eq 0 ] || fail "the legitimate commander did not hold 2 m within 0.1 m through the attack (exit $rc)"
echo PASS
