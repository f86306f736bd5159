#!/usr/bin/env bash
# DDS Security: a swarm launched with --secure takes off and moves under
# the authenticated ground station, and the recorder's identity records it.
# A participant without credentials sees no topic and cannot move a drone;
# the recorder's identity is refused a writer.
source "$(dirname "$0")/lib.sh"
secure_swarm_setup 3

start record "$BIN/ddswarm-record" --domain "$DOMAIN" --secure "$C" -o "$WORK/run.mcap" --duration 60
start launch "$BIN/ddswarm-launch" "$scenario" --domain "$DOMAIN" --secure "$C"
gs wait-agents --count 3 --timeout 30 || fail "the secure agents did not come online"
gs takeoff --wait || fail "the secure swarm did not take off"
p0=$(xy 0); [ -n "$p0" ] || fail "the ground station sees no swarm state"
gs move --north 1 --time 2 --wait || fail "move not acknowledged"
gs hold || fail "hold not acknowledged"
p1=$(xy 0)
d=$(moved "$p0" "$p1"); echo "drone 0 moved $d m north under the authenticated ground station"
awk -v d="$d" 'BEGIN { exit !(d > 1.0) }' || fail "drone 0 did not move ($p0 -> $p1)"

# No credentials: the ground station finds no server ...
out=$(timeout 30 "$BIN/ddswarm-gs" --domain "$DOMAIN" status 2>&1); rc=$?
echo "$out"
[ $rc -eq 1 ] && echo "$out" | grep -q "no simulation server" ||
  fail "a ground station without credentials saw the server (exit $rc)"
# ... and a plain participant hears nothing, matches nothing, and moves nothing.
sleep 2  # let the hold settle
p1=$(xy 0)
out=$("$BIN/secure_probe" --domain "$DOMAIN" --publish velocity --drone 0 --spoof --east 2 --for 4); echo "$out"
echo "$out" | grep -q "writer created matched=0 sent=[1-9][0-9]* heard_state=0 heard_status=0 heard_heartbeats=0" ||
  fail "a participant without credentials matched or heard the secure swarm"
p2=$(xy 0)
d=$(moved "$p1" "$p2"); echo "drone 0 moved $d m while commanded 2 m/s east for 4 s without credentials"
awk -v d="$d" 'BEGIN { exit !(d < 0.3) }' || fail "drone 0 moved under an unauthenticated command ($p1 -> $p2)"

# The recorder's identity reads but may not write.
out=$("$BIN/secure_probe" --domain "$DOMAIN" --secure "$C" --security-role recorder --publish swarm_state --wait-match 20 --for 1)
echo "$out"
echo "$out" | grep -q "writer refused matched=0 sent=0 heard_state=[1-9]" ||
  fail "the recorder's identity was allowed a SwarmState writer, or heard nothing"

# The recorder's file holds the swarm's state and the agents' commands.
kill -INT "$PID_record"
wait_pid "$PID_record" 15 || fail "the recorder did not finish cleanly"
info=$("$BIN/ddswarm-record" info "$WORK/run.mcap") || fail "cannot read the recording"
echo "$info"
echo "$info" | awk '$1 == "ddswarm/swarm_state" && $2 > 100 { ok = 1 } END { exit !ok }' ||
  fail "the secure recording has no SwarmState messages"
echo "$info" | awk '$1 == "ddswarm/velocity_cmd" && $2 > 100 { ok = 1 } END { exit !ok }' ||
  fail "the secure recording has no velocity commands (drone partitions not read)"
echo PASS
