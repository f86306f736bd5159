#!/usr/bin/env bash
# The recorder keeps up with a 64-drone real-time run (state and
# scans at 50 Hz) with zero dropped samples, in bounded memory.
# Usage: bench/record_bench.sh BIN_DIR [DRONES] [SECONDS] [SCENARIO]
set -u
BIN="$1"; N="${2:-64}"; T="${3:-20}"
SRC="$(cd "$(dirname "$0")/.." && pwd)"
source "$SRC/bench/bench_lib.sh"
# The thesis course holds up to about 340 drones at its start; larger swarms
# start in the open field of the 512-drone bench (config/swarm_field.yaml).
SCENARIO="${4:-$SRC/config/thesis_course.yaml}"
if [ $# -lt 4 ] && ! "$BIN/ddswarm-sim" --check --scenario "$SCENARIO" --drones "$N" >/dev/null 2>&1; then
  SCENARIO="$SRC/config/swarm_field.yaml"
fi
"$BIN/ddswarm-sim" --check --scenario "$SCENARIO" --drones "$N" >/dev/null ||
  { echo "record_bench: $N drones do not fit $SCENARIO" >&2; exit 2; }
WORK="$(mktemp -d)"; DOMAIN=$(bench_domain)
trap 'kill $SIM $REC 2>/dev/null; wait 2>/dev/null; rm -rf "$WORK"' EXIT
"$BIN/ddswarm-sim" --scenario "$SCENARIO" --drones "$N" --domain "$DOMAIN" \
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
echo "== recorder: $N drones in $(basename "$SCENARIO"), real time, ${T} s; peak RSS $((peak / 1024)) MB; exit $rc =="
tail -1 "$WORK/rec.log"
if ! kill -0 $SIM 2>/dev/null; then
  echo "record_bench: the server ended before the recording did; its log:" >&2
  tail -5 "$WORK/sim.log" >&2
  exit 1
fi
"$BIN/record_check" "$WORK/bench.mcap"
