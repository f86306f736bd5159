#!/usr/bin/env bash
# The mesh world in the web view (docs/worlds.md): a lockstep server of
# config/mesh_world.yaml with wind, and `ddswarm-gs --web` beside it.
# tests/web/mesh_world_test.mjs checks that the bridge serves each mesh file
# the Scene names, byte for byte, and nothing else under /mesh/; that the
# page draws each mesh with as many triangles as the server loaded; and that
# the wind the server flies reaches the page (arrows, particles, the panel).
# A screenshot goes to the test's artifacts. No agents: the Scene is
# published as the server joins.
source "$(dirname "$0")/lib.sh"
ARTIFACTS="${DDSWARM_ARTIFACTS:-$BIN/../test-artifacts}/mp_web_mesh_world"
mkdir -p "$ARTIFACTS"
[ -x /usr/bin/chromium ] || fail "/usr/bin/chromium is missing: run scripts/setup"
[ -d "$SRC/tests/node_modules/playwright-core" ] || fail "playwright-core is missing: run scripts/setup"
[ -d "$SRC/ground_station/web/www/node_modules/three" ] || fail "three.js is missing: run scripts/setup"

# The mesh world with a wind, written beside its mesh files' folder so its
# relative file names still name them.
CONFIG="$WORK/mesh_world_windy.yaml"
mkdir -p "$WORK/meshes"
cp "$SRC/config/meshes/bridge.stl" "$SRC/config/meshes/town.obj" "$WORK/meshes/"
{ cat "$SRC/config/mesh_world.yaml"
  printf 'wind:\n  steady_mps: [3, 0, 0]\n  turbulence: true\n  gusts_per_minute: 2\n'; } >"$CONFIG"

start sim "$BIN/ddswarm-sim" --scenario "$CONFIG" --drones 2 --mode lockstep --domain "$DOMAIN"
start web "$BIN/ddswarm-gs" --config "$CONFIG" --domain "$DOMAIN" --web 127.0.0.1:0
url=$(web_url) || fail "no web bridge address"
for _ in $(seq 1 100); do
  grep -q "mesh obstacle" "$WORK/sim.log" && break
  sleep 0.1
done
grep -q "ddswarm-sim: 2 mesh obstacle(s), 268 triangles" "$WORK/sim.log" ||
  fail "the server does not say it loaded the meshes: $(cat "$WORK/sim.log")"

timeout 120 node "$SRC/tests/web/mesh_world_test.mjs" --url "$url" --out "$ARTIFACTS" \
  --files "$WORK/meshes/bridge.stl,$WORK/meshes/town.obj" --triangles 76,192 || fail "browser test failed"
kill -0 "$PID_web" 2>/dev/null || fail "the bridge died"
echo PASS
