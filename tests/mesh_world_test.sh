#!/usr/bin/env bash
# The mesh world through the launcher in lockstep (docs/worlds.md): the
# thesis law flies the thesis task under the bridge and down the town's
# street of config/mesh_world.yaml; the server says what it loaded; the
# referee measures the clearance to the meshes' triangles (finite, so it
# sees them). The launcher's --set writes the scenario elsewhere: the mesh
# files, named relative to config/, are still found.
source "$(dirname "$0")/lib.sh"
scenario="$SRC/config/mesh_world.yaml"

launch_lockstep mesh --gs 'takeoff --wait; task --speed 0.8' || fail "the mesh world launch failed"
grep -q "ddswarm-sim: 2 mesh obstacle(s), 268 triangles" "$WORK/mesh/sim.log" ||
  fail "the server does not say it loaded the meshes"
line=$(grep "task complete:" "$WORK/mesh.log") || fail "the swarm did not complete the task in the mesh world"
clearance=$(echo "$line" | sed -n 's/.*min obstacle clearance \([0-9.]*\) m.*/\1/p')
[ -n "$clearance" ] || fail "no finite obstacle clearance in: $line"
awk -v c="$clearance" 'BEGIN { exit !(c > 0 && c < 6) }' ||
  fail "the clearance to the meshes is $clearance m: the referee does not see them"
echo "mesh world: $line"
echo PASS
