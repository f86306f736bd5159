#!/usr/bin/env bash
# Secure bring-up: swarms of N secure agent processes (DDS Security, one
# process per drone, lockstep), each started either through ddswarm-launch
# exactly as a user runs it, or by hand (each process started on its own, as
# from one terminal each, then ddswarm-gs commands). Times each from the start
# to every agent online, to the take-off acknowledged, and to the thesis
# task's end. Prints one row per swarm and a summary per N and way
# (docs/security.md keeps the current table).
#
# usage: bench/secure_bringup.sh [--bin DIR] [--drones "64 128"] [--launches 5]
#          [--by-hand] [--both] [--no-task] [--task-time S] [--out DIR]
#   --drones "..."  swarm sizes (default 64 128)
#   --launches K    swarms per size and way (default 5)
#   --by-hand       start the processes one by one instead of through ddswarm-launch
#   --both          both ways, alternated
#   --no-task       stop after the take-off (bring-up only)
#   --task-time S   the task's time limit, sim seconds (task.task_timeout_s; default 60).
#                   The swarm condition is sized for N drones (task --epsilon: the
#                   thesis's 2 D + 1 m cannot hold for 64 drones 4 m apart; here
#                   1.05 D sqrt(N) + 1 m, a hexagonally packed disc's diameter)
#   --out DIR       certificates, logs and the CSV (default: a temporary directory)
set -u
SRC="$(cd "$(dirname "$0")/.." && pwd)"
source "$SRC/bench/bench_lib.sh"
BIN="$SRC/build/default/bin" SIZES="64 128" K=5 TASK=1 OUT="" WAYS="launcher" TT=60
while [ $# -gt 0 ]; do
  case "$1" in
    --bin) BIN="$2"; shift 2 ;;
    --drones) SIZES="$2"; shift 2 ;;
    --launches) K="$2"; shift 2 ;;
    --by-hand) WAYS="by-hand"; shift ;;
    --both) WAYS="launcher by-hand"; shift ;;
    --no-task) TASK=0; shift ;;
    --task-time) TT="$2"; shift 2 ;;
    --out) OUT="$2"; shift 2 ;;
    *) echo "secure_bringup.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
DIR="${OUT:-$(mktemp -d /tmp/secure_bringup.XXXXXX)}"
mkdir -p "$DIR"
max=0
for n in $SIZES; do [ "$n" -gt "$max" ] && max=$n; done
"$SRC/scripts/make-certs" --out "$DIR/certs" --agents "$max" >"$DIR/make-certs.log" 2>&1 ||
  { echo "secure_bringup.sh: make-certs failed ($DIR/make-certs.log)" >&2; exit 1; }
C="$DIR/certs"
scenario="$DIR/scenario.yaml"
bench_scenario "$scenario"
sed -i "s/^  task_timeout_s: .*/  task_timeout_s: $TT/" "$scenario"
grep -q "^  task_timeout_s: $TT$" "$scenario" || { echo "secure_bringup.sh: cannot set the task's time limit" >&2; exit 2; }
d_int=$(sed -n 's/^  inter_distance_m: \([0-9.]*\).*/\1/p' "$scenario" | head -1)
# epsilon N: the swarm condition's size for N drones (see --task-time).
epsilon() { awk -v n="$1" -v d="${d_int:-4}" 'BEGIN { printf "%.1f", 1.05 * d * sqrt(n) + 1 }'; }

PIDS=()
stop_all() {
  for p in "${PIDS[@]}"; do kill -TERM "$p" 2>/dev/null; done
  for _ in $(seq 100); do
    local alive=0
    for p in "${PIDS[@]}"; do kill -0 "$p" 2>/dev/null && alive=1; done
    [ $alive = 0 ] && break
    sleep 0.1
  done
  for p in "${PIDS[@]}"; do kill -KILL "$p" 2>/dev/null; done
  wait 2>/dev/null
  PIDS=()
}
trap stop_all EXIT
trap 'exit 130' INT TERM

T0=0
since() { echo "$(date +%s.%N) - $T0" | bc; }
# event RUN WHAT: seconds since the start, then WHAT, into RUN/events.
event() { printf '%.2f %s\n' "$(since)" "$2" >>"$1/events"; }
# stamp FILE: each line of stdin into FILE after the seconds since the start.
stamp() { while IFS= read -r l; do printf '%.2f %s\n' "$(since)" "$l"; done >>"$1"; }

# Through the launcher: its stderr, each line timed, gives the events.
launched() {
  local n="$1" run="$2" dom="$3" steps="takeoff --wait"
  [ "$TASK" = 1 ] && steps="takeoff --wait; task --epsilon $(epsilon "$n")"
  "$BIN/ddswarm-launch" "$scenario" --drones "$n" --mode lockstep --domain "$dom" --secure "$C" \
    --log-dir "$run/logs" --gs "$steps" > >(stamp "$run/gs.out") 2> >(stamp "$run/launch.err") &
  PIDS=($!)
  # It ends by itself, its --gs steps done or failed; 900 s bounds a hang.
  for _ in $(seq 9000); do kill -0 "${PIDS[0]}" 2>/dev/null || break; sleep 0.1; done
  stop_all
  sleep 0.5  # the stderr reader flushes its last lines
  awk '/ddswarm-launch: gs takeoff --wait/ { print $1, "online" }
       /ddswarm-launch: gs task/ { print $1, "takeoff" }
       /failed \(exit/ && !/ddswarm-gs task/ { print $1, "failed" }' "$run/launch.err" >>"$run/events"
  [ "$TASK" = 1 ] || awk 'END { print $1, "takeoff" }' "$run/launch.err" >>"$run/events"
}

# By hand: the server, then each agent, as from a terminal each; then the
# ground station's commands, each a process of its own.
by_hand() {
  local n="$1" run="$2" dom="$3" gs
  mkdir -p "$run/logs"
  "$BIN/ddswarm-sim" --scenario "$scenario" --drones "$n" --mode lockstep --domain "$dom" \
    --secure "$C" >"$run/logs/sim.log" 2>&1 &
  PIDS=($!)
  for id in $(seq 0 $((n - 1))); do
    "$BIN/ddswarm-agent" --id "$id" --config "$scenario" --drones "$n" --domain "$dom" \
      --secure "$C" >"$run/logs/agent_$id.log" 2>&1 &
    PIDS+=($!)
  done
  gs=("$BIN/ddswarm-gs" --config "$scenario" --domain "$dom" --secure "$C")
  if timeout 200 "${gs[@]}" wait-agents --count "$n" --timeout 90 > >(stamp "$run/gs.out") 2>&1; then
    event "$run" online
    if timeout 200 "${gs[@]}" takeoff --wait > >(stamp "$run/gs.out") 2>&1; then
      event "$run" takeoff
      # Its result line says how the task ended.
      [ "$TASK" = 1 ] && timeout 700 "${gs[@]}" task --epsilon "$(epsilon "$n")" > >(stamp "$run/gs.out") 2>&1
    else
      event "$run" failed
    fi
  else
    event "$run" failed
  fi
  stop_all
}

csv="$DIR/secure_bringup.csv"
echo "drones,way,run,ok,online_s,takeoff_s,task_end_s,task_result,rejoins" >"$csv"
printf "%-6s %-8s %-4s %-3s %-9s %-10s %-11s %-8s %s\n" drones way run flew online_s takeoff_s \
  task_end_s rejoins result
for n in $SIZES; do
  for i in $(seq "$K"); do
    for way in $WAYS; do
      run="$DIR/n${n}_${way}_$i"
      rm -rf "$run"
      mkdir -p "$run"
      : >"$run/events"
      T0=$(date +%s.%N)
      if [ "$way" = launcher ]; then launched "$n" "$run" "$(bench_domain)"; else by_hand "$n" "$run" "$(bench_domain)"; fi
      at() { awk -v w="$1" '$2 == w { print $1; exit }' "$run/events"; }
      online=$(at online) took=$(at takeoff) ended="" result=""
      ok=0
      [ -n "$online" ] && [ -n "$took" ] && [ -z "$(at failed)" ] && ok=1
      if [ "$TASK" = 1 ]; then
        line=$(grep -m1 -E "^[0-9.]+ task (complete|failed)" "$run/gs.out")
        ended=${line%% *}
        result=$(echo "${line#* }" | tr ',' ';')
        # Flown: the task ran to its end, completed or out of time, with no drone lost.
        [ -n "$result" ] && ! echo "$result" | grep -q "lost drones\|interrupted" || ok=0
      fi
      rejoins=$(cat "$run"/logs/agent_*.log 2>/dev/null | grep -c "joining again as a new participant")
      echo "$n,$way,$i,$ok,${online:-},${took:-},${ended:-},$result,$rejoins" >>"$csv"
      printf "%-6s %-8s %-4s %-3s %-9s %-10s %-11s %-8s %s\n" "$n" "$way" "$i" "$ok" "${online:--}" \
        "${took:--}" "${ended:--}" "$rejoins" "${result:0:60}"
    done
  done
done
echo
echo "summary (seconds from the start; logs and CSV in $DIR):"
awk -F, 'NR > 1 {
    k = $1 " drones, " $2; n[k]++; ok[k] += $4
    if ($4 == 1) { on[k] = on[k] " " $5; to[k] = to[k] " " $6 }
  }
  END { for (k in n) printf "  %s: %d of %d flew; online at%s s; take-off acknowledged at%s s\n",
          k, ok[k], n[k], on[k], to[k] }' "$csv" | sort -n -k1
