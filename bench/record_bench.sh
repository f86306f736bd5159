#!/usr/bin/env bash
# Issue 6: the recorder keeps up with a 64-drone real-time run (state and
# scans at 50 Hz) with zero dropped samples, in bounded memory.
# Usage: bench/record_bench.sh BIN_DIR [DRONES] [SECONDS]
set -u
BIN="$1"; N="${2:-64}"; T="${3:-20}"
SRC="$(cd "$(dirname "$0")/.." && pwd)"
source "$SRC/bench/bench_lib.sh"
WORK="$(mktemp -d)"; DOMAIN=$(bench_domain)
trap 'kill $SIM $REC 2>/dev/null; wait 2>/dev/null; rm -rf "$WORK"' EXIT
"$BIN/ddswarm-sim" --scenario "$SRC/config/thesis_course.yaml" --drones "$N" --domain "$DOMAIN" \
  --duration $((T + 6)) >"$WORK/sim.log" 2>&1 & SIM=$!
sleep 1
"$BIN/ddswarm-record" -o "$WORK/bench.mcap" --domain "$DOMAIN" --duration "$T" >"$WORK/rec.log" 2>&1 & REC=$!
peak=0
while kill -0 $REC 2>/dev/null; do
  rss=$(awk '/VmRSS/ { print $2 }' /proc/$REC/status 2>/dev/null || echo 0)
  [ "${rss:-0}" -gt "$peak" ] && peak=$rss
  sleep 0.5
done
wait $REC; rc=$?
echo "== recorder: $N drones, real time, ${T} s; peak RSS $((peak / 1024)) MB; exit $rc =="
tail -1 "$WORK/rec.log"
"$BIN/record_check" "$WORK/bench.mcap"
