#!/usr/bin/env bash
# Scale: ddswarm's lockstep and real-time figures for N agent
# processes, each beside the bare Fast DDS floor of the same run and beside
# that floor with a lockstep server's physics between its ticks (the most
# plain lockstep can tick on the machine), and Table 1's wall time split into
# start-up, flight and teardown.
#
# Usage: bench/swarm_bench.sh [options]
#   --bin DIR          built binaries (default: build/default/bin)
#   --out DIR          CSVs, logs and the plot data (default: a temporary directory)
#   --sizes "6 16 .."  agent-process counts (default: 6 16 32 64 110 128; past 116 agents
#                      Fast DDS 2.9 and dds.participant_id's range leave some unreachable)
#   --rt-sizes "..."   real-time counts (default: the same)
#   --time S           lockstep seconds measured per N (default 10)
#   --lockstep "plain pipelined hosts"   lockstep variants per N: plain (each command flies the
#                      step right after its state), pipelined (sim.lockstep_pipeline:
#                      physics runs while agents answer; commands act one tick later) and
#                      hosts (plain, the N drones' agents in --lockstep-hosts K agent-host
#                      processes, default 2: the same laws, far fewer DDS round trips)
#   --physics "1000 500 250"   lockstep physics rates (sim.physics_rate_hz), each flown with
#                      every variant against the same floor (default: the scenario's, 1000)
#   --rt-time S        real-time seconds measured per N (default 60)
#   --streams best-effort|reliable   every part (the floor, lockstep, real time, agent hosts, Table 1):
#                      how the server reads the commands and the agents the state (writers stay
#                      reliable) (dds.best_effort_streams; default best-effort, as shipped;
#                      --rt-streams is the same option under its older name)
#   --rt-grace G       real time (both): sim.realtime_grace, the share of a period the server waits
#                      for late answers (default 0.6; the shipped default is 0.25)
#   --floor-time S     floor seconds measured per N (default 5)
#   --floor-repeats K  floor runs per N and discovery, all sizes once per round (default 3);
#                      ratios use the median: one 5 s sample moved 1.7x within minutes
#   --skip floor,ceiling,lockstep,realtime,hosts,table1   parts to leave out (ceiling: the
#                      floor with the physics between ticks, once per lockstep physics rate,
#                      in --floor-repeats rounds; skipping floor skips it too)
#   --hosts-drones N   agent-host part: N drones of config/swarm_field.yaml in real time,
#                      flown by --agent-hosts K processes (default 512 and 2), physics and
#                      sensor rates --hosts-physics / --hosts-sensors Hz (default 250 / 10)
#   --table1-runs K    runs per set for Table 1 (default 15, the thesis's)
#   --table1-jobs J    Table 1 runs at a time, each on its own domain (default 2)
#   --plot FILE.png    real-time factor against N (gnuplot)
#   --set KEY=VALUE    scenario override for every swarm (ddswarm-launch --set), repeatable,
#                      e.g. --set sim.physics_rate_hz=500
#   --dds-profiles F   QoS profiles XML for every swarm process, the probe and the ground station
#   --quick            a smoke run: N = 4 and 8, a few seconds each, 1 run per Table 1 set
# Every process is started here or by ddswarm-launch and stopped by PID; every
# run is bounded in time.
set -u
SRC="$(cd "$(dirname "$0")/.." && pwd)"
BIN="$SRC/build/default/bin"
OUT=""
SIZES="6 16 32 64 110 128"
RT_SIZES=""
LS_TIME=10
RT_TIME=60
FLOOR_TIME=5
FLOOR_REPEATS=3
SKIP=""
T1_RUNS=15
PLOT=""
SETS=()
PROFILE_ARGS=()   # DDS options for the tools this script starts itself (probe, ground station)
HOSTS_N=512
HOSTS_K=2
HOSTS_PHYS=250
HOSTS_SENS=10
T1_JOBS=2
LS_VARIANTS="plain pipelined hosts"
LS_HOSTS_K=2
LS_PHYSICS=""
STREAMS=best-effort
RT_GRACE=0.6
while [ $# -gt 0 ]; do
  case "$1" in
    --bin) BIN="$2"; shift 2 ;;
    --out) OUT="$2"; shift 2 ;;
    --sizes) SIZES="$2"; shift 2 ;;
    --rt-sizes) RT_SIZES="$2"; shift 2 ;;
    --time) LS_TIME="$2"; shift 2 ;;
    --rt-time) RT_TIME="$2"; shift 2 ;;
    --floor-time) FLOOR_TIME="$2"; shift 2 ;;
    --floor-repeats) FLOOR_REPEATS="$2"; shift 2 ;;
    --skip) SKIP="$2"; shift 2 ;;
    --table1-runs) T1_RUNS="$2"; shift 2 ;;
    --plot) PLOT="$2"; shift 2 ;;
    --set) SETS+=(--set "$2"); shift 2 ;;
    --dds-profiles) SETS+=(--set "dds.profiles_file=$(realpath "$2")"); PROFILE_ARGS+=(--dds-profiles "$(realpath "$2")"); shift 2 ;;
    --lockstep-hosts) LS_HOSTS_K="$2"; shift 2 ;;
    --hosts-drones) HOSTS_N="$2"; shift 2 ;;
    --agent-hosts) HOSTS_K="$2"; shift 2 ;;
    --hosts-physics) HOSTS_PHYS="$2"; shift 2 ;;
    --hosts-sensors) HOSTS_SENS="$2"; shift 2 ;;
    --table1-jobs) T1_JOBS="$2"; shift 2 ;;
    --quick) SIZES="4 8"; LS_TIME=3; RT_TIME=5; FLOOR_TIME=2; FLOOR_REPEATS=1; T1_RUNS=1; HOSTS_N=16; shift ;;
    --lockstep) LS_VARIANTS="$2"; shift 2 ;;
    --physics) LS_PHYSICS="$2"; shift 2 ;;
    --streams|--rt-streams) STREAMS="$2"; shift 2 ;;
    --rt-grace) RT_GRACE="$2"; shift 2 ;;
    -h|--help) sed -n '2,/^set -u/{/^#/p}' "$0"; exit 0 ;;
    *) echo "swarm_bench: unknown option $1" >&2; exit 2 ;;
  esac
done
RT_SIZES="${RT_SIZES:-$SIZES}"
BIN="$(cd "$BIN" && pwd)" || { echo "swarm_bench: no binaries in $BIN" >&2; exit 2; }
for b in ddswarm-launch ddswarm-gs ddswarm-sim ddswarm-agent dds_floor swarm_probe; do
  [ -x "$BIN/$b" ] || { echo "swarm_bench: $BIN/$b missing (build targets dds_floor swarm_probe and the ddswarm binaries)" >&2; exit 2; }
done
TMP_OUT=0
if [ -z "$OUT" ]; then OUT="$(mktemp -d /tmp/ddswarm-bench.XXXXXX)"; TMP_OUT=1; fi
mkdir -p "$OUT"
skip() { [[ ",$SKIP," == *",$1,"* ]]; }
PY=/usr/bin/python3
source "$SRC/bench/bench_lib.sh"
SCENARIO="$OUT/bench_scenario.yaml"
bench_scenario "$SCENARIO"
# The rates the swarms fly (the scenario's, or the last --set of them), for the tables' titles.
set_value() {  # set_value KEY -> the value of the last --set KEY=..., or the scenario's sim.KEY
  local v="" a
  for a in "${SETS[@]}"; do [[ "$a" == "sim.$1="* ]] && v="${a#*=}"; done
  [ -n "$v" ] || v=$(sed -n "s/^  $1: *\([0-9.]*\).*/\1/p" "$SCENARIO")
  echo "$v"
}
PHYS_HZ=$(set_value physics_rate_hz)
SENS_HZ=$(set_value sensor_rate_hz)

LAUNCH_PID=""
cleanup() {
  if [ -n "$LAUNCH_PID" ] && kill -0 "$LAUNCH_PID" 2>/dev/null; then
    kill -TERM "$LAUNCH_PID" 2>/dev/null
    for _ in $(seq 100); do kill -0 "$LAUNCH_PID" 2>/dev/null || break; sleep 0.1; done
    kill -KILL "$LAUNCH_PID" 2>/dev/null
  fi
  [ "$TMP_OUT" = 1 ] && [ "${KEEP:-0}" != 1 ] && rm -rf "$OUT"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

echo "swarm_bench: load before start: $(cut -d' ' -f1-3 /proc/loadavg); results in $OUT"

# Every part reads the per-tick streams the same way, the floor too.
case "$STREAMS" in
  # Explicitly: config/swarm_field.yaml, which the agent-host part flies, ships best-effort.
  best-effort) STREAM_EXTRA=(--set dds.best_effort_streams=true); STREAM_TOOL_ARGS=(--best-effort-streams)
               FLOOR_STREAM_ARGS=(--best-effort-streams) ;;
  reliable) STREAM_EXTRA=(--set dds.best_effort_streams=false); STREAM_TOOL_ARGS=(--best-effort-streams=false)
            FLOOR_STREAM_ARGS=() ;;
  *) echo "swarm_bench: --streams must be best-effort or reliable, not '$STREAMS'" >&2; exit 2 ;;
esac

# ---------------------------------------------------------------- floor
# floor_stats N DISCOVERY [any]: "median min max" ticks/s of the floor's good
# runs of N with that discovery ("any": all of N's runs when it has none), or "nan".
floor_stats() {
  [ -f "$FLOOR_CSV" ] || { echo nan; return; }
  $PY - "$FLOOR_CSV" "$@" <<'EOF'
import csv, statistics, sys
n, want = int(sys.argv[2]), sys.argv[3]
rows = [r for r in csv.DictReader(open(sys.argv[1])) if int(r["n"]) == n and r["ok"] == "1"]
pick = [r for r in rows if r["discovery"] == want] or (rows if sys.argv[4:] == ["any"] else [])
v = sorted(float(r["ticks_per_s"]) for r in pick)
print(f"{statistics.median(v)} {v[0]} {v[-1]}" if v else "nan")
EOF
}
FLOOR_CSV="$OUT/floor.csv"
if ! skip floor; then
  rm -f "$FLOOR_CSV"
  # Explicit participant ids, as ddswarm-launch gives large swarms' agents:
  # past ~100 participants automatic ids leave the rest unreachable.
  # Rounds over every size, so the repeats of one N lie minutes apart.
  for round in $(seq "$FLOOR_REPEATS"); do
    echo "swarm_bench: floor round $round of $FLOOR_REPEATS" >&2
    "$BIN/dds_floor" --drones "$(echo $SIZES | tr ' ' ',')" --discovery both --time "$FLOOR_TIME" \
      --explicit-ids --csv "$FLOOR_CSV" --log-dir "$OUT/floor-logs" "${FLOOR_STREAM_ARGS[@]}"
  done
  if [ "$FLOOR_REPEATS" -gt 1 ]; then
    echo
    echo "== the floor over $FLOOR_REPEATS rounds ($STREAMS state and commands): median (min-max) ticks/s; the ratios below use the median =="
    echo "| N | simple discovery | discovery server |"
    echo "|---|---|---|"
    floor_cell() { floor_stats "$1" "$2" | awk '{ print ($1 == "nan") ? "-" : sprintf("%.0f (%.0f-%.0f)", $1, $2, $3) }'; }
    for n in $SIZES; do echo "| $n | $(floor_cell "$n" simple) | $(floor_cell "$n" server) |"; done
  fi
fi
# floor_of N: median ticks/s of the floor runs with the discovery the launcher's auto picks.
floor_of() {
  local want=simple
  [ "$1" -gt 32 ] && want=server
  floor_stats "$1" "$want" any | cut -d' ' -f1
}

# ---------------------------------------------------------------- ceiling
# The floor with a lockstep server's physics between its ticks (dds_floor
# --physics-hz: the bench scenario's N drones hovering in its scene, every
# drone's controller and Bullet for one 50 Hz tick, then its sensors): what
# plain lockstep could tick were ddswarm's own DDS path and agents as cheap
# as the floor's. In rounds like the floor's, at each lockstep physics rate,
# with the discovery the launcher's auto picks.
CEIL_CSV="$OUT/ceiling.csv"
ceiling_of() {  # ceiling_of N HZ: median ticks/s of the good runs, or nan
  [ -f "$CEIL_CSV" ] || { echo nan; return; }
  $PY - "$CEIL_CSV" "$1" "$2" <<'EOF'
import csv, statistics, sys
n, hz = int(sys.argv[2]), float(sys.argv[3])
v = [float(r["ticks_per_s"]) for r in csv.DictReader(open(sys.argv[1]))
     if int(r["n"]) == n and r["ok"] == "1" and float(r["physics_hz"]) == hz]
print(statistics.median(v) if v else "nan")
EOF
}
if ! skip floor && ! skip ceiling; then
  rm -f "$CEIL_CSV"
  small="" large=""
  for n in $SIZES; do
    if [ "$n" -gt 32 ]; then large+="${large:+,}$n"; else small+="${small:+,}$n"; fi
  done
  for round in $(seq "$FLOOR_REPEATS"); do
    for hz in ${LS_PHYSICS:-$PHYS_HZ}; do
      echo "swarm_bench: ceiling round $round of $FLOOR_REPEATS, $hz Hz physics" >&2
      for part in "simple $small" "server $large"; do
        set -- $part
        [ $# -eq 2 ] || continue
        "$BIN/dds_floor" --drones "$2" --discovery "$1" --physics-hz "$hz" --physics-scenario "$SCENARIO" --time "$FLOOR_TIME" \
          --explicit-ids --csv "$CEIL_CSV" --log-dir "$OUT/floor-logs" "${FLOOR_STREAM_ARGS[@]}" >/dev/null
      done
    done
  done
  echo
  echo "== the ceiling of lockstep: the floor with a lockstep server's physics between ticks (the scenario's N drones hovering, their controllers, Bullet and sensors), median of $FLOOR_REPEATS round(s); plain lockstep can tick no faster, and no lockstep on $(nproc) cores faster than with the physics hidden; a lockstep that keeps the cores as busy as the floor does, costs nothing beyond the floor and the physics and hides the physics, ticks at floor CPU ÷ (floor CPU + physics CPU) of the floor =="
  echo "| N | physics (Hz) | floor ticks/s | floor with physics ticks/s | its ratio to the floor (plain lockstep's ceiling) | floor CPU per tick (µs) | physics CPU per tick (µs) | physics hidden: $(nproc) cores ÷ both (ticks/s) | its ratio to the floor | cores the floor keeps busy | physics hidden at the floor's use of the cores: ratio to the floor |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|"
  $PY - "$FLOOR_CSV" "$CEIL_CSV" "$(nproc)" "$SIZES" "${LS_PHYSICS:-$PHYS_HZ}" <<'EOF'
import csv, statistics, sys
floor = [r for r in csv.DictReader(open(sys.argv[1])) if r["ok"] == "1"]
ceil = [r for r in csv.DictReader(open(sys.argv[2])) if r["ok"] == "1"]
cores = int(sys.argv[3])
med = lambda v: statistics.median(v) if v else float("nan")
cell = lambda v, f: "-" if v != v else f.format(v)
for n in map(int, sys.argv[4].split()):
    want = "server" if n > 32 else "simple"  # as ddswarm-launch's auto
    f = [r for r in floor if int(r["n"]) == n and r["discovery"] == want] or \
        [r for r in floor if int(r["n"]) == n]
    f_tps = med([float(r["ticks_per_s"]) for r in f])
    f_us = med([float(r["busy_cores"]) / float(r["ticks_per_s"]) * 1e6 for r in f])
    f_busy = med([float(r["busy_cores"]) for r in f])
    for hz in map(float, sys.argv[5].split()):
        c = [r for r in ceil if int(r["n"]) == n and float(r["physics_hz"]) == hz]
        c_tps = med([float(r["ticks_per_s"]) for r in c])
        p_us = med([float(r["physics_us"]) for r in c])
        hidden = cores * 1e6 / (f_us + p_us)
        print(f"| {n} | {hz:.0f} | {cell(f_tps, '{:.0f}')} | {cell(c_tps, '{:.0f}')} | "
              f"{cell(c_tps / f_tps, '{:.2f}')} | {cell(f_us, '{:.0f}')} | {cell(p_us, '{:.0f}')} | "
              f"{cell(hidden, '{:.0f}')} | {cell(hidden / f_tps, '{:.2f}')} | "
              f"{cell(f_busy, '{:.2f}')} | {cell(f_us / (f_us + p_us), '{:.2f}')} |")
EOF
fi

# ---------------------------------------------------------------- one swarm
# run_swarm MODE N SECONDS: launches N agents, takes off, holds, probes; prints the probe line.
RUN_SCENARIO=""   # run_swarm's scenario (default: $SCENARIO)
RUN_EXTRA=()      # run_swarm's extra ddswarm-launch arguments
RUN_TAG=""        # run_swarm's log directory suffix
RUN_TOOL_ARGS=()  # run_swarm's extra DDS options for the probe and the ground station
run_swarm() {
  local mode="$1" n="$2" secs="$3"
  local scenario="${RUN_SCENARIO:-$SCENARIO}"
  local dom; dom=$(bench_domain)
  local log="$OUT/$mode-$n$RUN_TAG"
  rm -rf "$log"; mkdir -p "$log"
  local bound=$(( secs + 400 ))
  local t0; t0=$(date +%s.%N)
  "$BIN/ddswarm-launch" "$scenario" --drones "$n" --mode "$mode" --domain "$dom" --log-dir "$log" \
    --discovery-server auto --duration "$bound" "${SETS[@]}" "${RUN_EXTRA[@]}" >"$log/launch.out" 2>"$log/launch.err" &
  LAUNCH_PID=$!
  local ds=()
  for _ in $(seq 50); do
    grep -q "started .* process" "$log/launch.err" 2>/dev/null && break; sleep 0.1
  done
  local addr; addr=$(sed -n 's/.*discovery server on \([0-9.:]*\) .*/\1/p' "$log/launch.err")
  [ -n "$addr" ] && ds=(--discovery-server "$addr")
  local gs=("$BIN/ddswarm-gs" --config "$scenario" --domain "$dom" "${ds[@]}" "${PROFILE_ARGS[@]}" "${RUN_TOOL_ARGS[@]}")
  local up="nan" why=""
  if timeout 200 "${gs[@]}" wait-agents --count "$n" --timeout 180 >"$log/gs-wait.log" 2>&1; then
    up=$(echo "$(date +%s.%N) - $t0" | bc)
  else
    why="agents not online: $(tail -1 "$log/gs-wait.log")"
  fi
  local probe_args=(--drones "$n" --launcher-pid "$LAUNCH_PID" --domain "$dom" "${ds[@]}" "${PROFILE_ARGS[@]}" "${RUN_TOOL_ARGS[@]}" --time "$secs"
                    --settle 3 --timeout 240)
  [ "$mode" = realtime ] && probe_args+=(--ages)
  local line=""
  if [ -z "$why" ]; then
    "$BIN/swarm_probe" "${probe_args[@]}" >"$log/probe.out" 2>"$log/probe.err" &
    local probe=$!
    if timeout 260 "${gs[@]}" takeoff --wait >"$log/gs-takeoff.log" 2>&1; then
      local hold=86400
      [ "$mode" = realtime ] && hold=$(( secs + 60 ))
      timeout 60 "${gs[@]}" hold --time "$hold" >"$log/gs-hold.log" 2>&1 || why="hold failed: $(tail -1 "$log/gs-hold.log")"
    else
      why="takeoff failed: $(tail -1 "$log/gs-takeoff.log")"
    fi
    local end=$((SECONDS + secs + 300))
    while kill -0 "$probe" 2>/dev/null && [ $SECONDS -lt $end ]; do sleep 0.2; done
    kill -KILL "$probe" 2>/dev/null
    wait "$probe" 2>/dev/null
    line=$(grep '^probe ' "$log/probe.out" | tail -1)
    [ -z "$line" ] && why="${why:-probe failed: $(tail -1 "$log/probe.err")}"
  fi
  kill -TERM "$LAUNCH_PID" 2>/dev/null
  for _ in $(seq 150); do kill -0 "$LAUNCH_PID" 2>/dev/null || break; sleep 0.1; done
  kill -KILL "$LAUNCH_PID" 2>/dev/null
  wait "$LAUNCH_PID" 2>/dev/null
  LAUNCH_PID=""
  # Drone-drone contacts begun in the whole run (take-off included): the sim logs each one.
  local contacts; contacts=$(grep -c "collision: drone [0-9]* with drone" "$log/sim.log" 2>/dev/null)
  # A failed run's logs, kept before the next run of the same N reuses its directory.
  if [ -n "$why" ]; then
    {
      echo "===== $mode N=$n$RUN_TAG ${SETS[*]} ${RUN_EXTRA[*]}: $why"
      for f in "$log"/*.log "$log"/*.err "$log"/*.out; do
        [ -s "$f" ] || continue
        echo "----- ${f##*/} (last 40 lines) -----"
        tail -n 40 "$f"
      done
    } >>"$OUT/failed_runs.log"
  fi
  echo "mode=$mode n=$n up_s=$up ds=${addr:-none} contacts=${contacts:-0} why=\"$why\" $line"
}

field() {  # field KEY LINE
  echo "$2" | tr ' ' '\n' | sed -n "s/^$1=//p" | head -1
}
# The cells every swarm table formats the same way, from a run_swarm line.
up_cell() { field up_s "$1" | awk '{ printf "%.1f", $1 }'; }
missed_cell() { field missed_frac "$1" | awk '{ if ($1 != "") printf "%.3f %%", 100 * $1; else print "-" }'; }
# The share of the misses that fell in samples where half the swarm or more
# missed at once (a machine-wide stall), and the kernel threads' CPU with the busiest.
stall_cell() { field missed_in_stalls "$1" | awk '{ if ($1 != "") printf "%.0f %%", 100 * $1; else print "-" }'; }
kernel_cell() {
  local k top; k=$(field cpu_kernel "$1"); top=$(field cpu_kernel_top "$1")
  if [ -n "$k" ]; then echo "$k (${top%:*} ${top##*:})"; else echo "-"; fi
}
note_cell() { echo "$1" | sed -n 's/.*why="\([^"]*\)".*/\1/p'; }

# ---------------------------------------------------------------- lockstep
if ! skip lockstep; then
  : >"$OUT/lockstep.txt"
  for n in $SIZES; do
    for hz in ${LS_PHYSICS:-$PHYS_HZ}; do
      for v in $LS_VARIANTS; do
        case "$v" in
          plain) RUN_EXTRA=("${STREAM_EXTRA[@]}"); RUN_TAG="" ;;
          pipelined) RUN_EXTRA=("${STREAM_EXTRA[@]}" --set sim.lockstep_pipeline=true); RUN_TAG="-pipelined" ;;
          hosts) RUN_EXTRA=("${STREAM_EXTRA[@]}" --agent-hosts "$LS_HOSTS_K"); RUN_TAG="-lockstep-hosts" ;;
          *) echo "swarm_bench: unknown lockstep variant '$v' (plain, pipelined, hosts)" >&2; exit 2 ;;
        esac
        # After SETS on the launcher's command line, so this rate wins.
        [ -n "$LS_PHYSICS" ] && { RUN_EXTRA+=(--set "sim.physics_rate_hz=$hz"); RUN_TAG+="-${hz}hz"; }
        echo "swarm_bench: lockstep N=$n, $v, physics $hz Hz (load $(cut -d' ' -f1 /proc/loadavg)) ..." >&2
        RUN_TOOL_ARGS=("${STREAM_TOOL_ARGS[@]}")
        echo "variant=$v physics=$hz $(run_swarm lockstep "$n" "$LS_TIME") load=$(cut -d' ' -f1 /proc/loadavg) floor=$(floor_of "$n") ceiling=$(ceiling_of "$n" "$hz")" >>"$OUT/lockstep.txt"
      done
    done
  done
  RUN_EXTRA=(); RUN_TAG=""; RUN_TOOL_ARGS=()
  echo
  echo "== lockstep: $STREAMS state and commands; ticks/s with physics (Hz as given) and sensors (8 rays, $SENS_HZ Hz), N agent processes (hosts: the N drones in $LS_HOSTS_K agent-host processes); ${LS_TIME} s measured while holding =="
  echo "| N | variant | physics (Hz) | ticks/s | real-time factor | floor ticks/s | ratio to floor | floor with physics (ticks/s) | ratio to it | CPU sim | CPU agents (each) | CPU discovery server | agent RSS (MB) | agent PSS (MB) | bring-up + discovery (s) | drone contacts | load | note |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
  while read -r l; do
    n=$(field n "$l"); t=$(field ticks_per_s "$l"); f=$(field floor "$l"); c=$(field ceiling "$l")
    ratio=$(echo "$t $f" | awk '{ if ($1+0 > 0 && $2+0 > 0) printf "%.2f", $1 / $2; else print "-" }')
    cratio=$(echo "$t $c" | awk '{ if ($1+0 > 0 && $2+0 > 0) printf "%.2f", $1 / $2; else print "-" }')
    rtf=$(echo "$t" | awk '{ if ($1+0 > 0) printf "%.1f", $1 / 50; else print "-" }')
    printf "| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s (%s) | %s | %s | %s | %s | %s | %s | %s |\n" "$n" "$(field variant "$l")" "$(field physics "$l")" "${t:--}" "$rtf" \
      "$(echo "$f" | awk '{ printf "%.0f", $1 }')" "$ratio" "$(echo "${c:-nan}" | awk '{ print ($1 == "nan") ? "-" : sprintf("%.0f", $1) }')" "$cratio" "$(field cpu_sim "$l")" "$(field cpu_agents "$l")" \
      "$(field cpu_agent_each "$l")" "$(field cpu_ds "$l")" "$(field rss_agent_mb "$l")" "$(field pss_agent_mb "$l")" \
      "$(up_cell "$l")" "$(field contacts "$l")" "$(field load "$l")" \
      "$(note_cell "$l")"
  done <"$OUT/lockstep.txt"
fi

# ---------------------------------------------------------------- real time
# Real time, process per drone and agent hosts alike: the streams' QoS and the grace.
RT_EXTRA=("${STREAM_EXTRA[@]}" --set "sim.realtime_grace=$RT_GRACE")
RT_TOOL_ARGS=("${STREAM_TOOL_ARGS[@]}")

if ! skip realtime; then
  : >"$OUT/realtime.txt"
  RUN_EXTRA=("${RT_EXTRA[@]}"); RUN_TOOL_ARGS=("${RT_TOOL_ARGS[@]}")
  for n in $RT_SIZES; do
    echo "swarm_bench: real time N=$n, ${RT_TIME} s (load $(cut -d' ' -f1 /proc/loadavg)) ..." >&2
    echo "$(run_swarm realtime "$n" "$RT_TIME") load=$(cut -d' ' -f1 /proc/loadavg) floor=$(floor_of "$n")" >>"$OUT/realtime.txt"
  done
  RUN_EXTRA=(); RUN_TOOL_ARGS=()
  echo
  echo "== real time: ${RT_TIME} s per N, $STREAMS state and commands, realtime_grace $RT_GRACE; criteria RTF >= 0.99, command age p99 <= 2 periods, missed < 0.1 % =="
  echo "| N | RTF | command age p50 / p99 / max (periods) | missed commands | of them in swarm-wide stalls | CPU sim | CPU agents (each) | CPU discovery server | CPU probe | CPU kernel threads (busiest) | agent RSS (MB) | agent PSS (MB) | bring-up + discovery (s) | floor RTF (ticks/s / 50) | meets criteria | drone contacts | load | note |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
  best=0
  while read -r l; do
    n=$(field n "$l"); rtf=$(field rtf "$l"); p99=$(field age_p99_periods "$l"); mf=$(field missed_frac "$l")
    ok=$(echo "${rtf:-0} ${p99:-99} ${mf:-1}" | awk '{ print ($1 >= 0.99 && $2 <= 2 && $3 < 0.001) ? "yes" : "no" }')
    [ "$ok" = yes ] && [ "$n" -gt "$best" ] && best=$n
    printf "| %s | %s | %s / %s / %s | %s (%s of %s) | %s | %s | %s (%s) | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |\n" \
      "$n" "${rtf:--}" "$(field age_p50_periods "$l")" "${p99:--}" "$(field age_max_periods "$l")" \
      "$(missed_cell "$l")" \
      "$(field missed "$l")" "$(field drone_ticks "$l")" "$(stall_cell "$l")" "$(field cpu_sim "$l")" "$(field cpu_agents "$l")" \
      "$(field cpu_agent_each "$l")" "$(field cpu_ds "$l")" "$(field cpu_probe "$l")" "$(kernel_cell "$l")" "$(field rss_agent_mb "$l")" \
      "$(field pss_agent_mb "$l")" "$(up_cell "$l")" \
      "$(field floor "$l" | awk '{ if ($1+0 > 0) printf "%.1f", $1 / 50; else print "-" }')" "$ok" \
      "$(field contacts "$l")" "$(field load "$l")" "$(note_cell "$l")"
  done <"$OUT/realtime.txt"
  echo "largest N meeting the real-time criteria: $best"
fi

# ---------------------------------------------------------------- agent hosts
if ! skip hosts; then
  RUN_SCENARIO="$SRC/config/swarm_field.yaml"  # its ground-station timeouts already allow 512 drones
  RUN_EXTRA=("${RT_EXTRA[@]}" --agent-hosts "$HOSTS_K" --set "sim.physics_rate_hz=$HOSTS_PHYS"
             --set "sim.sensor_rate_hz=$HOSTS_SENS")
  RUN_TOOL_ARGS=("${RT_TOOL_ARGS[@]}")
  RUN_TAG="-hosts"
  echo "swarm_bench: agent hosts, $HOSTS_N drones in $HOSTS_K processes, real time ${RT_TIME} s (load $(cut -d' ' -f1 /proc/loadavg)) ..." >&2
  l="$(run_swarm realtime "$HOSTS_N" "$RT_TIME") load=$(cut -d' ' -f1 /proc/loadavg)"
  RUN_SCENARIO=""; RUN_EXTRA=(); RUN_TOOL_ARGS=(); RUN_TAG=""
  echo "$l" >"$OUT/hosts.txt"
  rtf=$(field rtf "$l"); p99=$(field age_p99_periods "$l")
  echo
  echo "== agent hosts: $HOSTS_N drones (config/swarm_field.yaml) in $HOSTS_K ddswarm-agent --ids processes, real time, physics $HOSTS_PHYS Hz, sensors $HOSTS_SENS Hz, $STREAMS state and commands, realtime_grace $RT_GRACE, ${RT_TIME} s =="
  echo "| drones | agent processes | RTF | command age p50 / p99 / max (periods) | missed commands | CPU sim | CPU agent hosts (each) | CPU kernel threads (busiest) | host RSS (MB) | bring-up + discovery (s) | drone contacts | load | note |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|"
  printf "| %s | %s | %s | %s / %s / %s | %s | %s | %s (%s) | %s | %s | %s | %s | %s | %s |\n" "$HOSTS_N" "$HOSTS_K" "${rtf:--}" \
    "$(field age_p50_periods "$l")" "${p99:--}" "$(field age_max_periods "$l")" \
    "$(missed_cell "$l")" \
    "$(field cpu_sim "$l")" "$(field cpu_agents "$l")" "$(field cpu_agent_each "$l")" "$(kernel_cell "$l")" "$(field rss_agent_mb "$l")" \
    "$(up_cell "$l")" "$(field contacts "$l")" "$(field load "$l")" \
    "$(note_cell "$l")"
fi

# ---------------------------------------------------------------- plot
if [ -n "$PLOT" ] && [ -f "$OUT/lockstep.txt" ]; then
  : >"$OUT/plot.dat"
  # One row per N: plain, floor, pipelined, hosts (? where a variant was not
  # run, or its run failed: a swarm that never took off measures nothing),
  # at the first physics rate flown.
  plot_hz=$(echo ${LS_PHYSICS:-$PHYS_HZ} | cut -d' ' -f1)
  for n in $SIZES; do
    t="?"; p="?"; f="?"; h="?"
    while read -r l; do
      [ "$(field n "$l")" = "$n" ] && [ "$(field physics "$l")" = "$plot_hz" ] || continue
      f=$(field floor "$l")
      [ -n "$(note_cell "$l")" ] && continue
      case "$(field variant "$l")" in
        plain) t=$(field ticks_per_s "$l") ;;
        pipelined) p=$(field ticks_per_s "$l") ;;
        hosts) h=$(field ticks_per_s "$l") ;;
      esac
    done <"$OUT/lockstep.txt"
    echo "$n ${t:-?} ${f:-?} ${p:-?} ${h:-?}" | sed 's/nan/?/g' |
      awk '{ for (i = 2; i <= 5; ++i) if ($i != "?") $i = $i / 50; print }' >>"$OUT/plot.dat"
  done
  : >"$OUT/plot_rt.dat"
  [ -f "$OUT/realtime.txt" ] && while read -r l; do
    r=$(field rtf "$l")
    [ -n "$(note_cell "$l")" ] && r="?"
    echo "$(field n "$l") ${r:-?}" >>"$OUT/plot_rt.dat"
  done <"$OUT/realtime.txt"
  gnuplot <<EOF
set terminal pngcairo size 900,600 font ",11" noenhanced
set output "$PLOT"
set title "Real-time factor against swarm size (2 cores; one process per drone unless said)"
set xlabel "drones"
set ylabel "real-time factor (sim s per wall s, 50 Hz control)"
set logscale xy
set datafile missing "?"
set xtics (6, 10, 16, 32, 64, 128)
set xrange [4:180]
set grid
set key bottom right box opaque
set yrange [0.03:150]
plot "$OUT/plot.dat" using 1:3 with linespoints lw 2 title "bare Fast DDS floor (ticks/s / 50)", \
     "$OUT/plot.dat" using 1:2 with linespoints lw 2 title "ddswarm lockstep (ticks/s / 50)", \
     "$OUT/plot.dat" using 1:4 with linespoints lw 2 title "ddswarm lockstep, pipelined (ticks/s / 50)", \
     "$OUT/plot.dat" using 1:5 with linespoints lw 2 title "ddswarm lockstep, $LS_HOSTS_K agent hosts (ticks/s / 50)", \
     "$OUT/plot_rt.dat" using 1:2 with linespoints lw 2 title "ddswarm real time (paced, target 1)", \
     "-" using 1:2 with points pt 7 ps 1.6 title "gym-pybullet-drones: 10 at about 2x", \
     "-" using 1:2 with points pt 5 ps 1.6 title "SwarmLab: 16 at about 1x", \
     "-" using 1:2 with points pt 9 ps 1.6 title "Crazyswarm2 sim: 16 at 0.6x"
10 2
e
16 1
e
16 0.6
e
EOF
  echo "plot: $PLOT"
fi

# ---------------------------------------------------------------- Table 1
if ! skip table1; then
  T1="$OUT/table1"
  rm -rf "$T1"; mkdir -p "$T1"
  sed -e "s#^\( *scenario:\) *thesis_course.yaml#\1 $SRC/config/thesis_course.yaml#" \
      -e "s#^\( *runs_per_set:\) *[0-9]*#\1 $T1_RUNS#" "$SRC/config/table1.yaml" >"$T1/table1.yaml"
  # Reliable streams: every set's scenario says so (the CSV's params name it too).
  [ "$STREAMS" = reliable ] && sed -i "s#^\( *set: {.*\) }#\1, dds.best_effort_streams: false }#" "$T1/table1.yaml"
  dom=$(bench_domain)
  echo "swarm_bench: Table 1, 4 sets x $T1_RUNS runs (load $(cut -d' ' -f1 /proc/loadavg)) ..." >&2
  t0=$(date +%s.%N)
  timeout $(( 60 * T1_RUNS + 300 )) "$BIN/ddswarm-gs" --domain "$dom" experiment "$T1/table1.yaml" --out "$T1/out" \
    --jobs "$T1_JOBS" \
    >"$T1/experiment.log" 2>&1
  rc=$?
  total=$(echo "$(date +%s.%N) - $t0" | bc)
  echo
  echo "== Table 1: 4 sets x $T1_RUNS lockstep runs of the six-drone task, $STREAMS state and commands, $T1_JOBS at a time (exit $rc, load $(cut -d' ' -f1 /proc/loadavg)) =="
  $PY "$SRC/bench/table1_split.py" "$T1/out" "$total"
fi
if [ -s "$OUT/failed_runs.log" ]; then
  echo
  echo "swarm_bench: $(grep -c '^===== ' "$OUT/failed_runs.log") swarm run(s) failed; their logs: $OUT/failed_runs.log"
fi
