#!/usr/bin/env bash
# The scale benches run and print their tables (bench/swarm_bench.sh
# --quick at tiny N, lockstep at two physics rates). No timed assertion:
# figures are printed, never judged.
# Run by scripts/bench --quick (not by the test suite: a benchmark, ~2 min).
# Usage: DDSWARM_BIN=build/release/bin DDSWARM_SRC=. bench/smoke_check.sh
source "$(dirname "$0")/../tests/lib.sh"
start bench bash "$SRC/bench/swarm_bench.sh" --bin "$BIN" --quick --sizes 3 --physics "1000 250" --out "$WORK/out"
wait_pid "$PID_bench" 400; rc=$?
out="$WORK/bench.log"
# On failure, the logs of every swarm run that failed (swarm_bench keeps them).
fail() { cat "$WORK/out/failed_runs.log" 2>/dev/null; echo "FAIL: $*"; exit 1; }
[ $rc -eq 0 ] || fail "swarm_bench exit $rc"
for title in "bare Fast DDS lockstep floor" "== lockstep:" "== real time:" "== Table 1:"; do
  grep -q -- "$title" "$out" || fail "no '$title' table"
done
# Each table has a row for N = 3 with a figure in it, and Table 1 its split.
grep -Eq '^\| 3 \| simple \| [0-9]+ \|' "$out" || fail "floor row for N=3 missing or empty"
# The ceiling of lockstep (the floor with the server's physics between ticks,
# and with the physics hidden), at each physics rate flown, every cell a figure.
grep -q "== the ceiling of lockstep" "$out" || fail "no ceiling table"
for hz in 1000 250; do
  grep -Eq "^\\| 3 \\| $hz( \\| [0-9.]+){9} \\|$" "$out" || fail "ceiling row at $hz Hz for N=3 missing or empty"
done
for v in plain pipelined hosts; do
  for hz in 1000 250; do
    grep -Eq "^\\| 3 \\| $v \\| $hz \\| [0-9.]+ \\| [0-9.]+ \\|" "$out" ||
      fail "lockstep $v row at $hz Hz physics for N=3 missing or empty"
  done
done
grep -Eq '^\| 3 \| [0-9.]+ \| [0-9]+ / [0-9]+ / [0-9]+ \|' "$out" || fail "real-time row for N=3 missing or empty"
# ... with the share of misses in swarm-wide stalls and the kernel threads' CPU.
grep -Eq '^\| 3 \| [0-9.]+ \| [0-9]+ / [0-9]+ / [0-9]+ \| [0-9.]+ % \([0-9]+ of [0-9]+\) \| [0-9]+ % \| [0-9.]+ \| [0-9.]+ \([0-9.]+\) \| [0-9.]+ \| [0-9.]+ \| [0-9.]+ \([^ ]+ [0-9.]+\) \|' "$out" ||
  fail "real-time row for N=3 lacks the stall share or the kernel threads' CPU"
grep -Eq '^\| task flight \| [0-9.]+ \|' "$out" || fail "Table 1 split missing"
grep -q "4 runs, 0 failed" "$out" || fail "Table 1 quick runs failed"
# Where the wake-ups go: each process's threads, woken and CPU per tick.
start wakes bash "$SRC/bench/thread_wakes.sh" --bin "$BIN" --time 2 --out "$WORK/wakes" 3
wait_pid "$PID_wakes" 150; rc=$?
[ $rc -eq 0 ] || fail "thread_wakes exit $rc"
grep -Eq '^== lockstep, N=3: [1-9][0-9]* ticks' "$WORK/wakes.log" || fail "thread_wakes counted no ticks"
for who in sim agent; do
  sed -n "/^-- $who /,/^--/p" "$WORK/wakes.log" | grep -Eq '^\| [0-9]+ \| [0-9.]+ \| [0-9.]+ \| [0-9.]+ \|' ||
    fail "thread_wakes: no thread row for the $who"
done
grep -Eq '^all 3 agents, per agent and second of wall time: [0-9.]+ ms of CPU; main thread [0-9.]+ ms in [0-9.]+ runs' \
  "$WORK/wakes.log" || fail "thread_wakes: no line for every agent"
cat "$out" "$WORK/wakes.log"
echo PASS
