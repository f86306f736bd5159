#!/usr/bin/env bash
# Swarm laws per drone (docs/laws.md), through the launcher in lockstep:
# 1. a mixed swarm (drones 3-5 fly Reynolds, the rest the thesis's law)
#    completes the thesis task, and the ground station names both laws;
# 2. a law that throws mid-task (fault injection, drone 2) takes down its own
#    drone only: it hovers, lands and is reported; its agent keeps running and
#    says why; the five others complete the task.
source "$(dirname "$0")/lib.sh"
scenario="$SRC/config/thesis_course.yaml"

launch_lockstep mixed --set 'agent.overrides=[{ids: "3-5", law: {type: reynolds}}]' \
  --gs 'takeoff --wait; status; task --speed 0.8' || fail "the mixed swarm's launch failed"
grep -q "law 3 reynolds, 3 thesis\|laws 3 reynolds, 3 thesis" "$WORK/mixed.log" ||
  fail "the status line does not name the swarm's two laws"
grep -q "task complete:" "$WORK/mixed.log" || fail "the mixed swarm did not complete the task"
grep -q "flying the reynolds law" "$WORK/mixed/agent_3.log" || fail "agent 3 does not fly Reynolds"
grep -q "flying the" "$WORK/mixed/agent_0.log" && fail "agent 0 flies another law than the thesis's"

launch_lockstep fault --set 'agent.overrides=[{ids: 2, law: {type: thesis, fault: throw, fault_after_s: 12}}]' \
  --gs 'takeoff --wait; task --speed 0.8; status; status --drones' || fail "the faulted swarm's launch failed"
grep -q "task complete:" "$WORK/fault.log" || fail "the five sound drones did not complete the task"
grep -q "lost drones (agent lost, failsafe): 2" "$WORK/fault.log" || fail "drone 2 is not reported lost"
grep -q "law fault: drone 2 (thesis): threw: injected fault (agent.law.fault: throw)" "$WORK/fault.log" ||
  fail "ddswarm-gs status does not show drone 2's law fault"
grep -q "drone 2: the thesis law faulted at sim time 12.* then lands" "$WORK/fault/agent_2.log" ||
  fail "agent 2's log does not say its law faulted"
grep -qi "error\|terminate\|segmentation" "$WORK/fault/agent_1.log" && fail "a sound agent logged an error"
row=$(awk '$1 == 2 && NF >= 8' "$WORK/fault.log" | tail -1)
echo "drone 2 at the end: $row"
echo "$row" | grep -q "failsafe" || fail "drone 2 is not in failsafe at the end"
z=$(echo "$row" | awk '{ print $4 }')
awk -v z="$z" 'BEGIN { exit !(z < 0.3) }' || fail "drone 2 did not land (z = $z m)"
echo PASS
