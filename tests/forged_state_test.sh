#!/usr/bin/env bash
# Malformed or foreign swarm samples are ignored and counted by the
# agent; its drone keeps holding its altitude on the real server's samples,
# also after another participant republishes the server's scene or publishes
# one that cannot be flown.
source "$(dirname "$0")/lib.sh"
scenario="$SRC/tests/scenarios/one_drone.yaml"
start sim "$BIN/ddswarm-sim" --scenario "$scenario" --domain "$DOMAIN"
start agent "$BIN/ddswarm-agent" --id 0 --config "$scenario" --domain "$DOMAIN"
timeout 60 "$BIN/ddswarm-gs" --config "$scenario" --domain "$DOMAIN" wait-agents --count 1 || fail "agent not online"
timeout 60 "$BIN/ddswarm-gs" --config "$scenario" --domain "$DOMAIN" takeoff --wait || fail "takeoff"
timeout 60 "$BIN/forged_swarm_state" --domain "$DOMAIN" --attack 3 --z 2.0 || fail "the agent applied forged samples or did not count them"
# A copy of the server's own scene from another participant does not make
# that participant the server: its plausible states are refused too.
timeout 60 "$BIN/forged_swarm_state" --domain "$DOMAIN" --attack 3 --z 2.0 --copy-scene ||
  fail "after a copied scene the agent applied forged samples, or the server lost it"
grep -q "refused a copy of the server's scene" "$WORK/agent.log" || fail "the agent did not say it refused the copied scene"
# A scene that cannot be flown (a broken or hostile server's) is refused
# before any of it applies: the agent once died of it in a Fast DDS thread.
timeout 60 "$BIN/forged_swarm_state" --domain "$DOMAIN" --attack 3 --z 2.0 --bad-scene ||
  fail "after a scene that cannot be flown the agent applied forged samples, or the server lost it"
grep -q "refused a scene (instance [0-9a-f]*) that cannot be flown: scene.bounds_max" "$WORK/agent.log" ||
  fail "the agent did not say it refused the scene"
kill -0 "$PID_agent" || fail "the agent died"
echo PASS
