#!/usr/bin/env bash
# An agent that hears its server's scene but none of its swarm states (here:
# its swarm-state reader asks for an ownership the server's writer does not
# offer; in the field, a reader that lost or never matched the server's
# writer among 128 participants) must not hold its drone for ever while the
# server waits for it. The server's scene writer stays matched, so the server
# is alive: after twice its DDS lease the agent says so and joins again as a
# new participant. A normal agent beside it stays.
source "$(dirname "$0")/lib.sh"
scenario="$SRC/config/thesis_course.yaml"
# The shipped profiles, with EXCLUSIVE ownership on the swarm-state reader
# only (the server's writer is SHARED: no match).
unmatched_profiles "$WORK/deaf_profiles.xml" data_reader:state || fail "profiles"
start sim "$BIN/ddswarm-sim" --scenario "$scenario" --drones 2 --mode realtime --domain "$DOMAIN"
start agent0 "$BIN/ddswarm-agent" --id 0 --drones 2 --config "$scenario" --domain "$DOMAIN" \
  --dds-profiles "$WORK/deaf_profiles.xml"
start agent1 "$BIN/ddswarm-agent" --id 1 --drones 2 --config "$scenario" --domain "$DOMAIN"
# The scene, 6 s (twice the 3 s lease) without a swarm state, then the scene again.
for _ in $(seq 250); do
  [ "$(grep -c "scene .* received" "$WORK/agent0.log")" -ge 2 ] && break
  sleep 0.1
done
cat "$WORK/agent0.log"
grep -q "no swarm state from the server for [0-9.]* s while its scene writer is still matched: this participant does not hear the server; leaving DDS and joining again" \
  "$WORK/agent0.log" || fail "agent 0 held its drone without hearing the server and did not say so"
[ "$(grep -c "scene .* received" "$WORK/agent0.log")" -ge 2 ] ||
  fail "agent 0 did not join again and get the scene as a new participant"
grep -q "drone 1: agent .* online" "$WORK/sim.log" || fail "the server did not hear the normal agent 1"
grep -q "does not hear the server" "$WORK/agent1.log" && fail "agent 1, hearing the server, gave up its participant"
echo "agent 0 joined again after $(sed -n 's/.*no swarm state from the server for \([0-9.]*\) s.*/\1/p' \
  "$WORK/agent0.log" | head -1) s without a swarm state; agent 1 stayed"
echo PASS
