# Shared harness for multi-process tests: start processes by PID, bound
# their time, clean up every one of them, print their logs on failure.
# Usage: source tests/lib.sh; then start NAME CMD...; expect ...; finish.
set -u
BIN="${DDSWARM_BIN:?DDSWARM_BIN must point at the build bin directory}"
SRC="${DDSWARM_SRC:?DDSWARM_SRC must point at the source tree}"
WORK="$(mktemp -d /tmp/ddswarm-test.XXXXXX)"
# Each test uses its own DDS domain so parallel tests never see each other.
DOMAIN="${DDSWARM_DOMAIN:-$(( (RANDOM % 200) + 20 ))}"
# Sanitizer builds run several times slower: scale wall-clock bounds with slow N.
SLOWDOWN="${DDSWARM_SLOWDOWN:-1}"
slow() { echo $(( $1 * SLOWDOWN )); }
declare -a PIDS=()
declare -a NAMES=()

print_logs() {
  # The test's own logs, and those a launcher wrote into a subdirectory (--log-dir).
  for f in "$WORK"/*.log "$WORK"/*/*.log; do
    [ -f "$f" ] || continue
    echo "----- ${f#"$WORK"/} (last 60 lines) -----"
    tail -n 60 "$f"
  done
}

cleanup() {
  local rc=$?
  for pid in "${PIDS[@]:-}"; do
    # SIGCONT too: a process a test stopped (SIGSTOP) gets its SIGTERM only once it runs.
    [ -n "$pid" ] && kill -TERM "$pid" 2>/dev/null && kill -CONT "$pid" 2>/dev/null
  done
  local deadline=$((SECONDS + 5))
  for pid in "${PIDS[@]:-}"; do
    [ -z "$pid" ] && continue
    while kill -0 "$pid" 2>/dev/null && [ $SECONDS -lt $deadline ]; do sleep 0.1; done
    kill -KILL "$pid" 2>/dev/null
    wait "$pid" 2>/dev/null
  done
  if [ $rc -ne 0 ]; then
    echo "FAILED (exit $rc); process logs follow"
    print_logs
  fi
  rm -rf "$WORK"
  exit $rc
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# start NAME CMD... : runs CMD in the background, output to $WORK/NAME.log
start() {
  local name="$1"; shift
  "$@" >"$WORK/$name.log" 2>&1 &
  PIDS+=($!)
  NAMES+=("$name")
  eval "PID_${name//[^a-zA-Z0-9]/_}=$!"
}

# wait_pid PID SECONDS : waits for PID to exit within SECONDS; returns its status (124 on timeout)
wait_pid() {
  local pid="$1" limit="$2" end=$((SECONDS + $2))
  while kill -0 "$pid" 2>/dev/null; do
    if [ $SECONDS -ge $end ]; then echo "timeout: pid $pid still running after ${limit}s"; return 124; fi
    sleep 0.1
  done
  wait "$pid"
}

fail() { echo "FAIL: $*"; exit 1; }
