#!/usr/bin/env bash
# An agent that hears no scene within agent.rejoin_after_s leaves DDS
# and joins again as a new participant (Fast DDS 2.9 sometimes never matches
# one of 128 processes started at once). Once a server is there, the re-joined
# agent gets the scene, stops re-joining, and flies its drone.
source "$(dirname "$0")/lib.sh"
scenario="$WORK/rejoin.yaml"
sed 's/^agent:$/agent:\n  rejoin_after_s: 2.0/' "$SRC/config/thesis_course.yaml" >"$scenario"
grep -q "rejoin_after_s: 2.0" "$scenario" || fail "could not write the test scenario"
start agent "$BIN/ddswarm-agent" --id 0 --config "$scenario" --domain "$DOMAIN"
# No server: it re-joins after ~3 s (2 s without a scene + its 1 s duplicate
# probe), then after twice as long (rejoin_patience_s).
for _ in $(seq "$(slow 150)"); do [ "$(grep -c "joining again" "$WORK/agent.log")" -ge 2 ] && break; sleep 0.1; done
[ "$(grep -c "joining again" "$WORK/agent.log")" -ge 2 ] || fail "the agent did not re-join twice without a server"
instances=$(sed -n 's/.*agent \([0-9a-f]*\) flying.*/\1/p' "$WORK/agent.log" | sort -u | wc -l)
[ "$instances" -ge 2 ] || fail "a re-join should be a new participant with a new agent instance (saw $instances)"
# A server comes: the agent gets the scene and stays.
start sim "$BIN/ddswarm-sim" --scenario "$scenario" --domain "$DOMAIN"
for _ in $(seq "$(slow 200)"); do grep -q "scene 'thesis_course' received" "$WORK/agent.log" && break; sleep 0.1; done
grep -q "scene 'thesis_course' received" "$WORK/agent.log" || fail "the re-joined agent never received the scene"
n=$(grep -c "joining again" "$WORK/agent.log")
# SIGUSR1 to the server before any mission (what ddswarm-launch sends when its
# discovery server dropped the server's endpoints): it starts again as a new
# server, and the agent follows it.
kill -USR1 "$PID_sim"
for _ in $(seq "$(slow 100)"); do grep -q "starting again as a new server" "$WORK/sim.log" && break; sleep 0.1; done
grep -q "starting again as a new server" "$WORK/sim.log" || fail "SIGUSR1 did not make the server start again"
for _ in $(seq "$(slow 200)"); do grep -q "new server instance" "$WORK/agent.log" && break; sleep 0.1; done
grep -q "new server instance" "$WORK/agent.log" || fail "the agent never heard the new server"
timeout 60 "$BIN/ddswarm-gs" --config "$scenario" --domain "$DOMAIN" wait-agents --count 1 --timeout 30 || fail "the re-joined agent is not online"
timeout 60 "$BIN/ddswarm-gs" --config "$scenario" --domain "$DOMAIN" takeoff --wait || fail "the re-joined agent's drone did not take off"
[ "$(grep -c "joining again" "$WORK/agent.log")" -eq "$n" ] || fail "the agent kept re-joining after it had the scene"
grep -q "drone 0: agent .* online" "$WORK/sim.log" || fail "the server never saw the agent"
echo "re-joined $n times before the server came; then flew"
# SIGUSR1 (what ddswarm-launch sends when its discovery server dropped the
# agent's endpoints): the agent joins again at once, as a new participant the
# server adopts, and its drone, in the air, keeps flying under it.
kill -USR1 "$PID_agent"
for _ in $(seq "$(slow 100)"); do grep -q "asked to join again" "$WORK/agent.log" && break; sleep 0.1; done
grep -q "asked to join again" "$WORK/agent.log" || fail "SIGUSR1 did not make the agent join again"
kill -0 "$PID_agent" 2>/dev/null || fail "SIGUSR1 ended the agent"
for _ in $(seq "$(slow 200)"); do [ "$(grep -c "scene 'thesis_course' received" "$WORK/agent.log")" -ge 2 ] && break; sleep 0.1; done
[ "$(grep -c "scene 'thesis_course' received" "$WORK/agent.log")" -ge 2 ] || fail "the agent did not get the scene after joining again"
timeout 60 "$BIN/ddswarm-gs" --config "$scenario" --domain "$DOMAIN" land --wait || fail "the drone did not land after its agent joined again"
echo "joined again on SIGUSR1, then landed"
# Once a mission has begun, a new server would be a new world: it stays.
kill -USR1 "$PID_sim"
for _ in $(seq "$(slow 100)"); do grep -q "a mission has begun: staying" "$WORK/sim.log" && break; sleep 0.1; done
grep -q "a mission has begun: staying" "$WORK/sim.log" || fail "the server did not refuse to start again mid-mission"
[ "$(grep -c "starting again as a new server" "$WORK/sim.log")" -eq 1 ] || fail "the server started again mid-mission"

# A ground station that hears no server through a discovery server within
# 20 s joins again as a new participant, and keeps trying (40 s, ...) until
# its discovery timeout (the discovery server may have dropped its endpoints).
ds_scenario="$WORK/rejoin_ds.yaml"
sed 's/^ground_station:$/ground_station:\n  discovery_timeout_s: 40.0/' "$scenario" >"$ds_scenario"
grep -q "discovery_timeout_s: 40.0" "$ds_scenario" || fail "could not write the discovery-server scenario"
ds_domain=$(( DOMAIN + 1 ))  # in the test's block (lib.sh)
port=$(( 20000 + RANDOM % 20000 ))
start ds fast-discovery-server -i 0 -l 127.0.0.1 -p "$port" -x "$SRC/config/discovery_server.xml"
start gs_early timeout 60 "$BIN/ddswarm-gs" --config "$ds_scenario" --domain "$ds_domain" \
  --discovery-server "127.0.0.1:$port" wait-agents --count 1 --timeout 30
for _ in $(seq "$(slow 250)"); do grep -q "joining again as a new participant" "$WORK/gs_early.log" && break; sleep 0.1; done
grep -q "joining again as a new participant" "$WORK/gs_early.log" || fail "the ground station did not join again after 20 s without a server"
start sim_ds "$BIN/ddswarm-sim" --scenario "$ds_scenario" --domain "$ds_domain" --discovery-server "127.0.0.1:$port"
start agent_ds "$BIN/ddswarm-agent" --id 0 --config "$ds_scenario" --domain "$ds_domain" --discovery-server "127.0.0.1:$port"
wait_pid "$PID_gs_early" 60; rc=$?
cat "$WORK/gs_early.log"
[ $rc -eq 0 ] || fail "the re-joined ground station exited $rc"
grep -q "1/6 agents online" "$WORK/gs_early.log" || fail "the re-joined ground station did not see the agent"
echo PASS
