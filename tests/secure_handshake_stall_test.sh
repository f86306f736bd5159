#!/usr/bin/env bash
# DDS Security: a secure agent whose participant never completes its
# authentication handshakes (tests/stall_handshake.cpp loses every handshake
# message its first participant sends, as Fast DDS 2.9 sometimes leaves a
# server-agent pair pending for good) joins again as a new participant once
# the server has announced itself agent.handshake_timeout_s (10-15 s) ago
# with that handshake still pending, and the swarm, that agent included,
# takes off. The other agents never leave DDS.
source "$(dirname "$0")/lib.sh"
secure_swarm_setup 3
common=(--config "$scenario" --drones 3 --domain "$DOMAIN" --secure "$C")
# The sanitizer builds' runtime must load first; the fault library goes after it.
export ASAN_OPTIONS="${ASAN_OPTIONS:-}:verify_asan_link_order=0"

start sim "$BIN/ddswarm-sim" --scenario "$scenario" --domain "$DOMAIN" --secure "$C"
start agent0 "$BIN/ddswarm-agent" --id 0 "${common[@]}"
start agent1 "$BIN/ddswarm-agent" --id 1 "${common[@]}"
start agent2 env LD_PRELOAD="$BIN/stall_handshake.so" "$BIN/ddswarm-agent" --id 2 "${common[@]}"
t0=$SECONDS
gs wait-agents --count 3 --timeout "$(slow 40)" || fail "the stalled agent did not come online"
echo "3 of 3 secure agents online after $((SECONDS - t0)) s"
grep -q "stall_handshake: this participant's handshake messages are lost" "$WORK/agent2.log" ||
  fail "the fault did not act on agent 2 (no handshake message of it was lost)"
stalled=$(grep "handshake with this participant has not ended" "$WORK/agent2.log")
echo "$stalled" | grep -q "joining again as a new participant" ||
  fail "agent 2 came online without joining again: the fault did not stall it"
echo "$stalled"
for a in agent0 agent1; do
  ! grep -q "joining again" "$WORK/$a.log" || fail "$a, which nothing stalled, joined again"
done
gs takeoff --wait || fail "the swarm did not take off with the agent that joined again"
echo PASS
