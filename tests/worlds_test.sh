#!/usr/bin/env bash
# Worlds and weather through the launcher in lockstep (docs/worlds.md): the
# thesis law flies the thesis task through a generated forest added to the
# course, past a generated wall with two gaps, and in wind with turbulence
# and gusts; the server says what it made; a windy run flown twice with the
# same seed gives the same result to the last digit.
source "$(dirname "$0")/lib.sh"
scenario="$SRC/config/thesis_course.yaml"
result() { grep "task complete:" "$WORK/$1.log" | sed 's/ (wall [0-9.]* s)//'; }

launch_lockstep forest --set scene.generate.forest.density_per_100m2=0.5 \
  --gs 'takeoff --wait; task --speed 0.8' || fail "the forest launch failed"
grep -q "task complete:" "$WORK/forest.log" || fail "the swarm did not complete the task in the forest"
grep -q "generated world: a forest of 18 pillars (of 18 wanted)" "$WORK/forest/sim.log" ||
  fail "the server does not say it generated the forest"

launch_lockstep wall --set scene.generate.walls.count=1 --set scene.generate.walls.openings=2 \
  --set scene.generate.walls.opening_width_m=8 --set scene.generate.walls.first_at_m=62 \
  --gs 'takeoff --wait; task --speed 0.8' || fail "the wall launch failed"
grep -q "task complete:" "$WORK/wall.log" || fail "the swarm did not complete the task past the wall"
grep -q "generated world: walls of 3 boxes" "$WORK/wall/sim.log" || fail "the server does not say it built the wall"

windy=(--set 'wind.steady_mps=[3, 0, 0]' --set wind.turbulence=true --set wind.gusts_per_minute=2)
launch_lockstep windy "${windy[@]}" --gs 'takeoff --wait; task --speed 0.8' || fail "the windy launch failed"
grep -q "ddswarm-sim: wind 3.0 m/s, Dryden turbulence, gusts" "$WORK/windy/sim.log" || fail "the server does not say it blows"
launch_lockstep windy_again "${windy[@]}" --gs 'takeoff --wait; task --speed 0.8' || fail "the second windy launch failed"
[ -n "$(result windy)" ] || fail "the swarm did not complete the task in the wind"
[ "$(result windy)" = "$(result windy_again)" ] ||
  fail "two lockstep runs in the same seeded wind differ: '$(result windy)' / '$(result windy_again)'"
# Calm, the same course gives another result: the wind acts.
launch_lockstep calm --gs 'takeoff --wait; task --speed 0.8' || fail "the calm launch failed"
[ "$(result windy)" != "$(result calm)" ] || fail "the wind changed nothing"
echo PASS
