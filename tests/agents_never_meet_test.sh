#!/usr/bin/env bash
# Under DDS Security an agent announces itself only to the participant ids of
# the server and tools (0-31) and takes id 32 + its drone, so agents never
# discover, and so never authenticate with, one another, while a tool, which
# announces to every id, still finds each agent (DdsConfig::
# announce_to_tools_only; docs/security.md). Checked without security over
# UDP on 127.0.0.1, as secure participants use it, with tests/announce_peer
# processes: two as agents and one as a tool. As a control, the same two
# agents announcing to every id meet.
source "$(dirname "$0")/lib.sh"
peer() { "$BIN/announce_peer" --domain "$DOMAIN" "$@"; }
# The most readers and writers a peer matched at once, its own included.
result() { sed -n 's/^matched //p' "$WORK/$1.log"; }

start c1 peer --participant-id 33 --time 5
start c2 peer --participant-id 34 --time 5
wait_pid "$PID_c1" 30 && wait_pid "$PID_c2" 30 || fail "a control peer failed"
echo "control, announcing to every id: agent 1 $(result c1), agent 2 $(result c2)"
[ "$(result c1)" = "readers=2 writers=2" ] && [ "$(result c2)" = "readers=2 writers=2" ] ||
  fail "the control's two agents did not meet: the check below would prove nothing"

# A ground station under DDS Security meets no agent (DdsConfig::meets_agents):
# it takes an id above every agent's and announces to the tools only, so it
# matches the tool alone, and the tool all four.
start a1 peer --participant-id 33 --tools-only --time 7
start a2 peer --participant-id 34 --tools-only --time 7
start gs peer --meets-no-agent --time 7
sleep 1
start tool peer --time 5
wait_pid "$PID_a1" 30 && wait_pid "$PID_a2" 30 && wait_pid "$PID_gs" 30 &&
  wait_pid "$PID_tool" 30 || fail "a peer failed"
echo "announcing to the tools only: agent 1 $(result a1), agent 2 $(result a2)," \
  "ground station $(result gs), tool $(result tool)"
[ "$(result tool)" = "readers=4 writers=4" ] || fail "the tool did not find both agents and the ground station"
[ "$(result a1)" = "readers=2 writers=2" ] && [ "$(result a2)" = "readers=2 writers=2" ] ||
  fail "an agent matched more than the tool: the agents, or an agent and the ground station, met"
[ "$(result gs)" = "readers=2 writers=2" ] || fail "the ground station matched more than the tool"
echo PASS
