#!/usr/bin/env bash
# An agent whose server went silent, and to which a new server announced
# itself but nothing the new one sends arrives, joins again as a new
# participant (docs/faults.md, "An agent deaf to a new server"). A server
# SIGKILLed while it held the lock of an agent's shared-memory port leaves
# that agent so. Here a participant that only takes the server's name
# (tests/announce_peer, no scene) plays the new server nothing comes from.
# While the real server lives, the same participant changes nothing.
source "$(dirname "$0")/lib.sh"
fly_six_own_server
start impostor "$BIN/announce_peer" --domain "$DOMAIN" --name ddswarm-sim --time 120
rule='a new server announced itself'
deaf() { grep -l "$rule" "$WORK"/agent_*.log 2>/dev/null | wc -l; }
# An agent that met the killed server's lock starts its process again as a
# new participant instead, and then waits for a scene (docs/faults.md): it too
# has left the dead server's participant.
left() { grep -lE "$rule|starting this process again as a new participant" "$WORK"/agent_*.log 2>/dev/null | wc -l; }
sleep 8  # longer than the twice the lease (2 x 3 s) the rule waits
[ "$(deaf)" -eq 0 ] || fail "an agent left its live server for a participant that only took its name"
gs status | tee "$WORK/status1.txt"
grep -q "6 airborne" "$WORK/status1.txt" || fail "the swarm did not stay airborne beside the impostor"

kill -KILL "$PID_sim1"; wait "$PID_sim1" 2>/dev/null
killed=$(date +%s.%N)
for _ in $(seq 200); do [ "$(left)" -eq 6 ] && break; sleep 0.1; done
[ "$(left)" -eq 6 ] || fail "$(left) of 6 agents joined again while the new server's scene never came"
[ "$(deaf)" -ge 1 ] || fail "no agent applied the rule ('$rule'): each started again instead"
echo "every agent joined again $(echo "$(date +%s.%N) - $killed" | bc) s after the kill at most"
grep -h "$rule" "$WORK/agent_0.log"

kill -TERM "$PID_impostor"
start sim2 "$BIN/ddswarm-sim" --scenario "$scenario" --mode realtime --domain "$DOMAIN"
gs wait-agents --count 6 --timeout 60 || fail "the agents did not come online with a real new server"
gs takeoff --wait || fail "takeoff with the new server"
gs status | tee "$WORK/status2.txt"
grep -q "6 airborne" "$WORK/status2.txt" || fail "the swarm did not take off with the new server"
echo PASS
