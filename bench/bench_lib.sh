# Shared by the bench scripts (source it after setting SRC).

# A random DDS domain whose RTPS ports stay below the kernel's ephemeral port
# range for the explicit participant ids of a 128-agent swarm (ids up to 159;
# see ddswarm-launch's ephemeral-port warning and docs/networking.md).
bench_domain() { echo $(( (RANDOM % 60) + 20 )); }

# bench_scenario FILE: writes the thesis course with ground-station timeouts
# that a loaded machine and a 128-process bring-up can meet, and the law for
# dense swarms (agent.activation.neighbours: 6): the thesis's sum over every
# peer packs 16 and more drones until they touch, and the contacts, not the
# swarm, would dominate the server's cost. With 7 drones or fewer the two
# laws are the same. --set agent.activation.neighbours=0 flies the thesis's.
bench_scenario() {
  sed -e 's/^  ack_timeout_s: .*/  ack_timeout_s: 30.0\n  discovery_timeout_s: 60.0/' \
    -e 's/^\(    max_mps: 1.5\)$/\1\n    neighbours: 6/' \
    "$SRC/config/thesis_course.yaml" >"$1"
  grep -q "discovery_timeout_s: 60.0" "$1" && grep -q "^    neighbours: 6$" "$1" ||
    { echo "$(basename "$0"): cannot derive $1" >&2; exit 2; }
}

# bench_hold_swarm MODE N DIR SCENARIO [LAUNCH_ARGS...]: starts ddswarm-launch
# (N agent processes, MODE lockstep|realtime, logs in DIR, LAUNCH_ARGS added)
# in the background for up to 900 s, waits for every agent, takes off and
# holds. Sets LAUNCH_PID and GS (the ground-station command line for this
# swarm); returns 1 with a message when the swarm did not come up.
# bench_stop_launch stops it by PID.
LAUNCH_PID=""
bench_hold_swarm() {
  local mode="$1" n="$2" dir="$3" scenario="$4" dom addr
  shift 4
  dom=$(bench_domain)
  "$BIN/ddswarm-launch" "$scenario" --drones "$n" --mode "$mode" --domain "$dom" --log-dir "$dir" \
    --discovery-server auto --duration 900 "$@" >"$dir/launch.out" 2>"$dir/launch.err" &
  LAUNCH_PID=$!
  for _ in $(seq 50); do grep -q "started .* process" "$dir/launch.err" 2>/dev/null && break; sleep 0.1; done
  local ds=()
  addr=$(sed -n 's/.*discovery server on \([0-9.:]*\) .*/\1/p' "$dir/launch.err")
  [ -n "$addr" ] && ds=(--discovery-server "$addr")
  GS=("$BIN/ddswarm-gs" --config "$scenario" --domain "$dom" "${ds[@]}")
  timeout 320 "${GS[@]}" wait-agents --count "$n" --timeout 300 >/dev/null 2>&1 ||
    { echo "N=$n: agents not online (logs in $dir)"; return 1; }
  timeout 260 "${GS[@]}" takeoff --wait >/dev/null 2>&1 || { echo "N=$n: takeoff failed (logs in $dir)"; return 1; }
  timeout 60 "${GS[@]}" hold --time 86400 >/dev/null 2>&1
  return 0
}
bench_stop_launch() {
  [ -n "$LAUNCH_PID" ] || return 0
  kill -TERM "$LAUNCH_PID" 2>/dev/null
  for _ in $(seq 150); do kill -0 "$LAUNCH_PID" 2>/dev/null || break; sleep 0.1; done
  kill -KILL "$LAUNCH_PID" 2>/dev/null
  wait "$LAUNCH_PID" 2>/dev/null
  LAUNCH_PID=""
}

# bench_swarm_options DEFAULT_SECS ARGS...: the options every one-swarm bench
# takes. Sets BIN (--bin, default build/default/bin), MODE (--mode, default
# lockstep), SECS (--time), OUT (--out, default empty) and leaves the other
# arguments, in order, in BENCH_REST for the script's own.
bench_swarm_options() {
  BIN="$SRC/build/default/bin"; MODE=lockstep; SECS="$1"; OUT=""; BENCH_REST=()
  shift
  while [ $# -gt 0 ]; do
    case "$1" in
      --bin) BIN="$2"; shift 2 ;;
      --mode) MODE="$2"; shift 2 ;;
      --time) SECS="$2"; shift 2 ;;
      --out) OUT="$2"; shift 2 ;;
      *) BENCH_REST+=("$1"); shift ;;
    esac
  done
}

# bench_swarm_pids: after bench_hold_swarm and 2 s of ticking, sets SIM_PID and
# AGENT_PID (drone 1's agent); returns 1 when either is missing.
bench_swarm_pids() {
  sleep 2
  SIM_PID=$(pgrep -P "$LAUNCH_PID" -x ddswarm-sim | head -1)
  AGENT_PID=$(pgrep -P "$LAUNCH_PID" -f "ddswarm-agent --id 1 " | head -1)
  [ -n "$SIM_PID" ] && [ -n "$AGENT_PID" ]
}
