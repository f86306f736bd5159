#!/usr/bin/env bash
# DDS Security: an agent with credentials for drone 2 cannot command
# drone 3. In a secure 4-drone swarm, agent-2's identity
#  - is refused a writer in drone 3's partition;
#  - sends, on its own drone 2 channel, plausible commands for drone 3 that
#    carry drone 3's live agent instance and the current tick: the server
#    counts every one as an impostor's and drone 3 does not move;
# and the real agent binary started for drone 3 with agent-2's identity
# cannot fly it.
source "$(dirname "$0")/lib.sh"
secure_swarm_setup 4
impostors() { gs status | sed -n 's/.*impostor \([0-9]*\).*/\1/p'; }

start launch "$BIN/ddswarm-launch" "$scenario" --drones 4 --domain "$DOMAIN" --secure "$C"
gs wait-agents --count 4 --timeout 30 || fail "the secure agents did not come online"
gs takeoff --wait || fail "the secure swarm did not take off"
sleep 2  # let the swarm settle into its hover

# A writer in drone 3's partition with agent-2's identity: refused.
out=$("$BIN/secure_probe" --domain "$DOMAIN" --secure "$C" --security-role agent-2 --publish velocity \
  --drone 3 --partition drone/3 --for 1); echo "$out"
echo "$out" | grep -q "writer refused" || fail "agent-2's identity got a writer in drone 3's partition"

# Spoofed commands for drone 3 on agent-2's own channel: rejected, counted.
n0=$(impostors); p0=$(xy 3)
[ -n "$n0" ] && [ -n "$p0" ] || fail "no status from the server"
out=$("$BIN/secure_probe" --domain "$DOMAIN" --secure "$C" --security-role agent-2 --publish velocity \
  --drone 3 --partition drone/2 --spoof --east 2 --wait-match 20 --for 4); echo "$out"
echo "$out" | grep -q "writer created matched=[1-9].* heard_heartbeats=[1-9]" ||
  fail "agent-2's identity did not reach the server on its own channel (the attack was not tried)"
n1=$(impostors); p1=$(xy 3)
d=$(moved "$p0" "$p1")
echo "impostor commands counted: $n0 -> $n1; drone 3 moved $d m while agent-2 commanded it 2 m/s east for 4 s"
[ $((n1 - n0)) -ge 50 ] || fail "the server did not count agent-2's commands for drone 3 as an impostor's"
awk -v d="$d" 'BEGIN { exit !(d < 0.3) }' || fail "drone 3 moved under agent-2's commands ($p0 -> $p1)"

# The agent binary for drone 3 with agent-2's identity stops with a clear error.
# (Its own participant id: drone 3's is the real agent's, and an agent refuses a taken one.)
out=$(timeout 30 "$BIN/ddswarm-agent" --id 3 --config "$scenario" --drones 4 --domain "$DOMAIN" \
  --secure "$C" --security-role agent-2 --participant-id 31 --duration 5 2>&1); rc=$?
echo "$out" | tail -2
[ $rc -ne 0 ] && echo "$out" | grep -q "cannot create writer for ddswarm/velocity_cmd.*agent-2.*drone/3" ||
  fail "an agent with agent-2's identity was allowed to fly drone 3 (exit $rc)"
# Missing credentials: one line naming them, exit 2.
out=$(timeout 30 "$BIN/ddswarm-agent" --id 5 --config "$scenario" --drones 6 --domain "$DOMAIN" \
  --secure "$C" --duration 1 2>&1); rc=$?
echo "$out"
[ $rc -eq 2 ] && [ "$(echo "$out" | wc -l)" -eq 1 ] && echo "$out" | grep -q "agent-5.cert.pem, agent-5.key.pem" ||
  fail "missing credentials were not one clear line with exit 2 (exit $rc)"
echo PASS
