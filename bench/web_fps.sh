#!/usr/bin/env bash
# Frame rate of the web view with many drones in headless Chromium
# (SwiftShader WebGL, no GPU), at each quality level. By default the drones
# come from the mock bridge (no DDS: the page's cost alone); with --real, from
# a real realtime swarm behind ddswarm-gs --web.
# Usage: bench/web_fps.sh [BIN_DIR] [DRONES] [SECONDS] [--real]
set -u
SRC="$(cd "$(dirname "$0")/.." && pwd)"
BIN="${1:-$SRC/build/default/bin}"; N="${2:-128}"; T="${3:-10}"; MODE="${4:-mock}"
source "$SRC/bench/bench_lib.sh"
WORK="$(mktemp -d)"; DOMAIN=$(bench_domain)
PIDS=()
trap 'for p in "${PIDS[@]}"; do kill $p 2>/dev/null; done; wait 2>/dev/null; rm -rf "$WORK"' EXIT
if [ "$MODE" = "--real" ]; then
  "$BIN/ddswarm-launch" "$SRC/config/thesis_course.yaml" --drones "$N" --mode realtime --domain "$DOMAIN" \
    --log-dir "$WORK/logs" --gs "wait-agents --count $N; takeoff --wait; task --speed 0.8" >"$WORK/launch.log" 2>&1 & PIDS+=($!)
  "$BIN/ddswarm-gs" --config "$SRC/config/thesis_course.yaml" --domain "$DOMAIN" --web 127.0.0.1:0 >"$WORK/web.log" 2>&1 & PIDS+=($!)
  what="real swarm (ddswarm-gs --web)"
else
  node "$SRC/ground_station/web/www/dev/mock_bridge.mjs" --port 0 --drones "$N" --start task >"$WORK/web.log" 2>&1 & PIDS+=($!)
  what="mock bridge"
fi
url=""
for _ in $(seq 1 100); do
  url=$(grep -o 'http://127.0.0.1:[0-9]*/' "$WORK/web.log" | head -1)
  [ -n "$url" ] && break; sleep 0.2
done
[ -n "$url" ] || { echo "web view did not start"; cat "$WORK/web.log"; exit 1; }
if [ "$MODE" = "--real" ]; then
  for _ in $(seq 1 240); do grep -q "task .*acknowledged" "$WORK/launch.log" && break; sleep 0.5; done
fi
echo "== web view fps: $N drones, $what, $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg) =="
node "$SRC/tests/web/fps.mjs" --url "$url" --seconds "$T" --quality all --shot "${DDSWARM_FPS_SHOTS:-$WORK/shots}"
