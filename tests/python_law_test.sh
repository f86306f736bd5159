#!/usr/bin/env bash
# Swarm laws in Python (agent.law.type: python, examples/python_law), in lockstep:
# 1. the whole swarm flies examples/python_law/boids.py through the thesis task;
# 2. a Python law that raises mid-task (drone 1) lands its own drone: its
#    traceback is in its agent's log, the fault in `ddswarm-gs status`, and the
#    five others complete the task;
# 3. a missing module or class, or a parameter the class does not declare, is
#    refused before anything flies: one line naming file, line and field, exit 2.
source "$(dirname "$0")/lib.sh"
scenario="$SRC/config/thesis_course.yaml"
examples="$SRC/examples/python_law"

launch_lockstep boids --set agent.law.type=python --set agent.law.module="$examples/boids.py" \
  --set agent.law.class=Boids --gs 'takeoff --wait; status; task --speed 0.8' || fail "the Python swarm's launch failed"
grep -q "task complete:" "$WORK/boids.log" || fail "the Python swarm did not complete the task"
grep -q "| law python Boids" "$WORK/boids.log" || fail "the status line does not name the Python law"

launch_lockstep broken \
  --set "agent.overrides=[{ids: 1, law: {type: python, module: \"$examples/broken.py\", class: RaisesLater, params: {after_s: 12}}}]" \
  --gs 'takeoff --wait; task --speed 0.8; status' || fail "the launch with a failing Python law failed"
grep -q "task complete:" "$WORK/broken.log" || fail "the five sound drones did not complete the task"
grep -q "lost drones (agent lost, failsafe): 1" "$WORK/broken.log" || fail "drone 1 is not reported lost"
grep -q "law fault: drone 1 (python RaisesLater): threw: Python ZeroDivisionError: division by zero" "$WORK/broken.log" ||
  fail "ddswarm-gs status does not show drone 1's Python fault"
grep -q "ddswarm python law: RaisesLater.step: ZeroDivisionError: division by zero" "$WORK/broken/agent_1.log" ||
  fail "agent 1's log lacks the exception"
grep -q 'broken.py([0-9]*): divide' "$WORK/broken/agent_1.log" || fail "agent 1's log lacks the traceback"

refused_law "{type: python, module: $WORK/nope.py, class: X}" "refused.yaml:64: agent.law.module = $WORK/nope.py: no such file"
refused_law "{type: python, module: $examples/boids.py, class: Nope}" "agent.law.class = Nope: no such class in $examples/boids.py"
refused_law "{type: python, module: $examples/boids.py, class: Boids, params: {cohesion_gian: 1}}" \
  "refused.yaml:64: agent.law.params.cohesion_gian = 1: unknown parameter (this law takes"
refused_law "{type: python, module: $examples/boids.py, class: Boids, params: {radius_m: -1}}" \
  "agent.law.class = Boids: Python ValueError: radius_m must be > 0, not -1.0"
echo PASS
