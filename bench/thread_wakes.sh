#!/usr/bin/env bash
# Where the wake-ups go. Launches N agent processes (lockstep by
# default), takes off, holds, then counts each thread's context switches (voluntary =
# it slept and was woken; involuntary = preempted) and CPU over a few seconds
# of ticking, for the server and agent 1, per tick; then every agent's CPU and
# runs per second, main thread apart. With --stacks, also saves
# every thread's stack (gdb) so a thread id can be told apart: Fast DDS's
# threads are all named after the process.
# Usage: bench/thread_wakes.sh [--bin DIR] [--mode lockstep|realtime] [--time S] [--out DIR] [--stacks] N
set -u
SRC="$(cd "$(dirname "$0")/.." && pwd)"
source "$SRC/bench/bench_lib.sh"
bench_swarm_options 5 "$@"
STACKS=0
N=""
for a in "${BENCH_REST[@]}"; do
  case "$a" in
    --stacks) STACKS=1 ;;
    -h|--help) sed -n '2,8p' "$0"; exit 0 ;;
    *) N="$a" ;;
  esac
done
[ -n "$N" ] || { echo "thread_wakes: give N, the number of agent processes" >&2; exit 2; }
[ -n "$OUT" ] || OUT="$(mktemp -d /tmp/ddswarm-wakes.XXXXXX)"
mkdir -p "$OUT"
SCENARIO="$OUT/scenario.yaml"
bench_scenario "$SCENARIO"
trap bench_stop_launch EXIT
trap 'exit 130' INT TERM
bench_hold_swarm "$MODE" "$N" "$OUT" "$SCENARIO" >&2 || exit 1
bench_swarm_pids || { echo "thread_wakes: server or agent 1 not found" >&2; exit 1; }
sim=$SIM_PID agent=$AGENT_PID

snap() {  # snap PID -> "tid voluntary involuntary cpu_ns" per thread (schedstat: ns, not jiffies)
  for t in /proc/"$1"/task/*; do
    echo "$(basename "$t") $(awk '/^voluntary_ctxt/{v=$2} /^nonvoluntary/{n=$2} END{print v, n}' "$t/status")" \
         "$(cut -d' ' -f1 "$t/schedstat")"
  done 2>/dev/null | sort
}
agents=$(pgrep -P "$LAUNCH_PID" -x ddswarm-agent | tr '\n' ' ')
all_snap() {  # every agent's threads: "pid tid cpu_ns runs" (bash builtins only: forks would stretch the window)
  local p t a b c
  for p in $agents; do
    for t in /proc/"$p"/task/*; do
      read -r a b c <"$t/schedstat" && echo "$p ${t##*/} $a $c"
    done
  done 2>/dev/null
}
sim_tick() { timeout 30 "${GS[@]}" status 2>/dev/null | grep -o 'sim [0-9.]*' | head -1 | cut -d' ' -f2; }
t0=$(sim_tick); w0=$(date +%s.%N); snap "$sim" >"$OUT/sim0"; snap "$agent" >"$OUT/agent0"
a0=$(date +%s.%N); all_snap >"$OUT/all0"
sleep "$SECS"
a1=$(date +%s.%N); all_snap >"$OUT/all1"
t1=$(sim_tick); w1=$(date +%s.%N); snap "$sim" >"$OUT/sim1"; snap "$agent" >"$OUT/agent1"
if [ "$STACKS" = 1 ]; then
  gdb -p "$agent" -batch -ex "thread apply all bt 8" >"$OUT/agent_stacks.txt" 2>&1
  gdb -p "$sim" -batch -ex "thread apply all bt 8" >"$OUT/sim_stacks.txt" 2>&1
fi
ticks=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%d", (b - a) * 50 }')  # 50 Hz control
[ "$ticks" -gt 0 ] || { echo "thread_wakes: the swarm did not tick" >&2; exit 1; }
echo "== $MODE, N=$N: $ticks ticks in $(awk -v a="$w0" -v b="$w1" 'BEGIN { printf "%.1f", b - a }') s;" \
  "per tick, the threads that woke at least once in 100 ticks =="
for who in sim agent; do
  echo "-- $who (pid $([ $who = sim ] && echo "$sim" || echo "$agent")) --"
  echo "| thread | woken | preempted | CPU (µs) |"
  echo "|---|---|---|---|"
  join "$OUT/${who}0" "$OUT/${who}1" | awk -v T="$ticks" '{
    v = ($5 - $2) / T; n = ($6 - $3) / T; c = ($7 - $4) / 1e3 / T
    if (v + n >= 0.01) printf "| %s | %.2f | %.2f | %.1f |\n", $1, v, n, c }'
done
# Every agent, not one: the mean CPU and runs (wake-ups plus preemptions,
# schedstat) per second of its main thread and of all its other threads.
awk -v T="$(echo "$a1 - $a0" | bc)" 'NR == FNR { c0[$1 " " $2] = $3; r0[$1 " " $2] = $4; next }
  ($1 " " $2) in c0 { k = $1 " " $2; w = ($1 == $2) ? "main" : "other"
    c[w] += $3 - c0[k]; r[w] += $4 - r0[k]; if (!($1 in seen)) { seen[$1] = 1; n++ } }
  END { if (n) printf "all %d agents, per agent and second of wall time: %.2f ms of CPU; main thread %.2f ms in %.1f runs, other threads %.2f ms in %.1f runs\n",
    n, (c["main"] + c["other"]) / 1e6 / n / T, c["main"] / 1e6 / n / T, r["main"] / n / T, c["other"] / 1e6 / n / T, r["other"] / n / T }' \
  "$OUT/all0" "$OUT/all1"
[ "$STACKS" = 1 ] && echo "stacks: $OUT/agent_stacks.txt, $OUT/sim_stacks.txt"
exit 0
