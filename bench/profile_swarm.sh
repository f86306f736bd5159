#!/usr/bin/env bash
# Where the time goes in a flying swarm. Launches N agent processes
# (lockstep or real time), takes off, holds, then samples the server and one
# agent with perf (cpu-clock, user space) for a few seconds and prints the
# share of each library and the hottest symbols, plus user/system CPU split.
# Usage: bench/profile_swarm.sh [--bin DIR] [--mode lockstep|realtime] [--time S] [--out DIR] N...
set -u
SRC="$(cd "$(dirname "$0")/.." && pwd)"
source "$SRC/bench/bench_lib.sh"
bench_swarm_options 8 "$@"
SIZES=()
for a in "${BENCH_REST[@]}"; do
  case "$a" in
    -h|--help) sed -n '2,7p' "$0"; exit 0 ;;
    *) SIZES+=("$a") ;;
  esac
done
[ ${#SIZES[@]} -gt 0 ] || SIZES=(6 64 128)
command -v perf >/dev/null || { echo "profile_swarm: perf not installed (Debian linux-perf)" >&2; exit 2; }
[ -n "$OUT" ] || OUT="$(mktemp -d /tmp/ddswarm-profile.XXXXXX)"
mkdir -p "$OUT"
SCENARIO="$OUT/profile_scenario.yaml"
bench_scenario "$SCENARIO"
trap bench_stop_launch EXIT
trap 'exit 130' INT TERM

cpu_split() {  # cpu_split PID -> "user_s sys_s"
  awk '{ sub(/.*\) /, ""); print $12 / 100, $13 / 100 }' "/proc/$1/stat" 2>/dev/null
}

report() {  # report NAME DATA
  echo "-- $1: share by library --"
  perf report -i "$2" --no-children --sort dso --stdio 2>/dev/null | grep -E '^ +[0-9]' | head -8
  echo "-- $1: hottest symbols --"
  perf report -i "$2" --no-children --sort dso,sym --stdio 2>/dev/null | grep -E '^ +[0-9]' | head -25 |
    cut -c1-160
}

for n in "${SIZES[@]}"; do
  log="$OUT/$MODE-$n"
  mkdir -p "$log"
  bench_hold_swarm "$MODE" "$n" "$log" "$SCENARIO" || { bench_stop_launch; continue; }
  bench_swarm_pids || { echo "N=$n: server or agent 1 not found"; bench_stop_launch; continue; }
  sim=$SIM_PID agent=$AGENT_PID
  read -r su0 ss0 < <(cpu_split "$sim"); read -r au0 as0 < <(cpu_split "$agent")
  perf record -q -e cpu-clock -F 999 -p "$sim" -o "$log/sim.perf" -- sleep "$SECS" >/dev/null 2>&1 &
  p1=$!
  perf record -q -e cpu-clock -F 999 -p "$agent" -o "$log/agent.perf" -- sleep "$SECS" >/dev/null 2>&1 &
  p2=$!
  wait $p1 $p2
  read -r su1 ss1 < <(cpu_split "$sim"); read -r au1 as1 < <(cpu_split "$agent")
  threads_sim=$(ls /proc/"$sim"/task | wc -l); threads_agent=$(ls /proc/"$agent"/task | wc -l)
  bench_stop_launch
  echo
  echo "==== $MODE, N=$n: ${SECS} s; load $(cut -d' ' -f1 /proc/loadavg) ===="
  awk -v su="$(echo "$su1 - $su0" | bc)" -v ss="$(echo "$ss1 - $ss0" | bc)" -v au="$(echo "$au1 - $au0" | bc)" \
      -v as="$(echo "$as1 - $as0" | bc)" -v t="$SECS" -v ts="$threads_sim" -v ta="$threads_agent" 'BEGIN {
    printf "server: %.2f cores user + %.2f system (%d threads); agent 1: %.3f user + %.3f system (%d threads)\n",
           su / t, ss / t, ts, au / t, as / t, ta }'
  report "server (ddswarm-sim)" "$log/sim.perf"
  report "agent 1" "$log/agent.perf"
done
echo "perf data in $OUT"
