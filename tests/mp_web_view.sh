#!/usr/bin/env bash
# The web view in a real browser (Debian's chromium, headless, SwiftShader WebGL,
# driven by playwright-core): a lockstep swarm, its agents and
# `ddswarm-gs --web`; tests/web/view_test.mjs checks the page draws as many
# drones as fly, at their DDS positions within 0.1 m, that its Take off button
# gets the swarm airborne by the DDS state, that the bridge survives a
# browser leaving mid-stream and malformed messages, and saves screenshots
# (paths printed); tests/web/replay_test.mjs plays the run's recording in the
# page. The page's frame rate is a benchmark: bench/web_fps.sh.
source "$(dirname "$0")/lib.sh"
N=4
CONFIG="$SRC/config/thesis_course.yaml"
ARTIFACTS="${DDSWARM_ARTIFACTS:-$BIN/../test-artifacts}/mp_web_view"
mkdir -p "$ARTIFACTS"
[ -x /usr/bin/chromium ] || fail "/usr/bin/chromium is missing: run scripts/setup"
[ -d "$SRC/tests/node_modules/playwright-core" ] || fail "playwright-core is missing: run scripts/setup"
[ -d "$SRC/ground_station/web/www/node_modules/three" ] || fail "three.js is missing: run scripts/setup"

start sim "$BIN/ddswarm-sim" --scenario "$CONFIG" --drones "$N" --mode lockstep --domain "$DOMAIN"
for i in $(seq 0 $((N - 1))); do
  start "agent$i" "$BIN/ddswarm-agent" --id "$i" --config "$CONFIG" --drones "$N" --domain "$DOMAIN"
done
start web "$BIN/ddswarm-gs" --config "$CONFIG" --domain "$DOMAIN" --web 127.0.0.1:0
url=$(web_url) || fail "no web bridge address"
echo "bridge at $url"
timeout 60 "$BIN/ddswarm-gs" --config "$CONFIG" --domain "$DOMAIN" wait-agents --count "$N" || fail "agents did not come online"
# The run is recorded, for the page's recording player afterwards.
start rec "$BIN/ddswarm-record" -o "$WORK/run.mcap" --domain "$DOMAIN" \
  --topics ddswarm/swarm_state,ddswarm/scene,ddswarm/task,ddswarm/collision
sleep 1

timeout 300 node "$SRC/tests/web/view_test.mjs" --url "$url" --drones "$N" --out "$ARTIFACTS" \
  --gs "$BIN/ddswarm-gs" --domain "$DOMAIN" --config "$CONFIG" || fail "browser test failed"
kill -0 "$PID_web" 2>/dev/null || fail "the bridge died"
kill -INT "$PID_rec"; wait_pid "$PID_rec" 20 || fail "the recorder did not stop"
ls -l "$WORK/run.mcap"
timeout 180 node "$SRC/tests/web/replay_test.mjs" --url "$url" --recording "$WORK/run.mcap" --drones "$N" --out "$ARTIFACTS" \
  || fail "recording player test failed"

echo "load average: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) cores"
echo PASS
