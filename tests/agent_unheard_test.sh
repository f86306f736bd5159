#!/usr/bin/env bash
# An agent that hears the server but is not heard by it (here: its command
# and heartbeat writers offer an ownership the server's readers do not
# accept; in the field, a one-sided loss of its participant) must not fly on
# silently. The server's samples mark its drone agent-less; after twice its
# DDS lease the agent says so and joins again as a new participant. Heard
# agents stay, in real time and in a lockstep swarm paused before its mission.
source "$(dirname "$0")/lib.sh"
scenario="$SRC/config/thesis_course.yaml"
# The shipped profiles, with EXCLUSIVE ownership on the agent's command and
# heartbeat writers only (the server's readers are SHARED: no match).
unmatched_profiles "$WORK/deaf_profiles.xml" data_writer:command data_writer:heartbeat || fail "profiles"
start sim "$BIN/ddswarm-sim" --scenario "$scenario" --drones 2 --mode realtime --domain "$DOMAIN"
start agent0 "$BIN/ddswarm-agent" --id 0 --drones 2 --config "$scenario" --domain "$DOMAIN" \
  --dds-profiles "$WORK/deaf_profiles.xml"
start agent1 "$BIN/ddswarm-agent" --id 1 --drones 2 --config "$scenario" --domain "$DOMAIN"
for _ in $(seq 200); do grep -q "does not hear this agent" "$WORK/agent0.log" && break; sleep 0.1; done
cat "$WORK/agent0.log"
grep -q "marked drone 0 agent-less .* the server does not hear this agent" "$WORK/agent0.log" ||
  fail "agent 0 flew on unheard without saying so"
grep -q "agent .* flying" "$WORK/agent0.log" || fail "agent 0 never flew"
grep -q "drone 0: agent .* online" "$WORK/sim.log" && fail "the server heard agent 0 after all: the test's premise is broken"
grep -q "drone 1: agent .* online" "$WORK/sim.log" || fail "the server did not hear the normal agent 1"
grep -q "does not hear this agent" "$WORK/agent1.log" && fail "agent 1, heard, gave up its participant"

# Heard agents of a lockstep swarm paused at tick 0 (no mission yet) read
# that tick again and again; it must say they are live (the server refreshes
# the flags of a tick it publishes again), or they all leave after 6 s.
kill -TERM "$PID_sim" "$PID_agent0" "$PID_agent1"
wait_pid "$PID_sim" 10; wait_pid "$PID_agent0" 10; wait_pid "$PID_agent1" 10
start sim2 "$BIN/ddswarm-sim" --scenario "$scenario" --drones 2 --mode lockstep --domain "$DOMAIN"
start agent0b "$BIN/ddswarm-agent" --id 0 --drones 2 --config "$scenario" --domain "$DOMAIN"
start agent1b "$BIN/ddswarm-agent" --id 1 --drones 2 --config "$scenario" --domain "$DOMAIN"
for _ in $(seq 100); do [ "$(grep -c "online" "$WORK/sim2.log")" -ge 2 ] && break; sleep 0.1; done
[ "$(grep -c "online" "$WORK/sim2.log")" -ge 2 ] || fail "the lockstep swarm did not come up"
sleep 9
if grep -h "does not hear this agent" "$WORK/agent0b.log" "$WORK/agent1b.log"; then
  fail "an agent of the paused lockstep swarm took itself for unheard"
fi
# Nor for deaf: a paused lockstep server publishes its tick again every 0.25 s.
if grep -h "does not hear the server" "$WORK/agent0b.log" "$WORK/agent1b.log"; then
  fail "an agent of the paused lockstep swarm took itself for deaf"
fi
echo "paused lockstep swarm: both agents stayed for 9 s"
echo PASS
