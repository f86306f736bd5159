#!/usr/bin/env bash
# The window wall through the launcher in lockstep (docs/worlds.md, "3D
# sensors"): the thesis law flies the thesis task through two generated walls
# with windows, with 5 rows x 8 rays of distance sensors over 40 deg
# (config/window_wall.yaml). The server says what it generated and what its
# sensors are; the swarm completes the task without touching a wall, and the
# referee's clearance to the walls is finite (it sees them).
source "$(dirname "$0")/lib.sh"
scenario="$SRC/config/window_wall.yaml"

launch_lockstep window --gs 'takeoff --wait; task --speed 0.8' || fail "the window wall launch failed"
grep -q "ddswarm-sim: generated world: .*walls of 8 boxes" "$WORK/window/sim.log" ||
  fail "the server does not say it generated the two walls with their windows"
grep -q "ddswarm-sim: sensors: 5 rows of 8 rays over 40 deg of elevation (40 a scan)" \
  "$WORK/window/sim.log" || fail "the server does not say it casts 5 rows of 8 rays"
line=$(grep "task complete:" "$WORK/window.log") || fail "the swarm did not complete the task through the windows"
echo "$line" | grep -q "collisions: obstacle 0," || fail "a drone touched a wall: $line"
clearance=$(echo "$line" | sed -n 's/.*min obstacle clearance \([0-9.]*\) m.*/\1/p')
[ -n "$clearance" ] || fail "no finite obstacle clearance in: $line"
echo "window wall: $line"
echo PASS
