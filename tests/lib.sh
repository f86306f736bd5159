# Shared harness for multi-process tests: start processes by PID, bound
# their time, clean up every one of them, print their logs on failure.
# Usage: source tests/lib.sh; then start NAME CMD...; expect ...; finish.
set -u
BIN="${DDSWARM_BIN:?DDSWARM_BIN must point at the build bin directory}"
SRC="${DDSWARM_SRC:?DDSWARM_SRC must point at the source tree}"
WORK="$(mktemp -d /tmp/ddswarm-test.XXXXXX)"
# Each test claims its own block of DDS domains, so tests that run at once
# (ctest -j) never see each other: an flock on a file per block, held by this
# shell (and the processes it starts) until the test ends, even by SIGKILL.
# DOMAIN is the block's first domain; a test may use the next ones too
# (DDSWARM_DOMAIN_POOL "first last step": the blocks it draws from). The
# pools stay clear of the unit tests' domains (docs/testing.md).
claim_domain_block() {
  local first last step d
  read -r first last step <<<"${DDSWARM_DOMAIN_POOL:-30 87 3}"
  mkdir -p /tmp/ddswarm-test-domains
  for d in $(seq "$first" "$step" "$last"); do
    exec {DOMAIN_LOCK_FD}>"/tmp/ddswarm-test-domains/$d.lock"
    if flock -n "$DOMAIN_LOCK_FD"; then DOMAIN=$d; return 0; fi
    exec {DOMAIN_LOCK_FD}>&-
  done
  echo "FAIL: every test domain block in ${first}-${last} is held by a running test"
  exit 1
}
if [ -n "${DDSWARM_DOMAIN:-}" ]; then DOMAIN="$DDSWARM_DOMAIN"; else claim_domain_block; fi
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
  # What the test and every process it waited for cost, for ctest's
  # scheduling (tests/CMakeLists.txt, heavy tests): user and system seconds.
  times >"$WORK/.times"  # the builtin, in this shell (a $(...) would be a subshell's)
  echo "cpu: $(tail -1 "$WORK/.times") in ${SECONDS} s"
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

# fly_six_realtime ARGS...: ddswarm-launch of the thesis scenario in real
# time with ARGS (logs in $WORK), every agent online and the swarm airborne.
# gs runs the ground station on the test's domain.
fly_six_realtime() {
  scenario="$SRC/config/thesis_course.yaml"
  start launch "$BIN/ddswarm-launch" "$scenario" --mode realtime --domain "$DOMAIN" "$@" --log-dir "$WORK"
  gs wait-agents --count 6 --timeout 60 || fail "agents not online"
  gs takeoff --wait || fail "takeoff"
}
gs() { timeout 60 "$BIN/ddswarm-gs" --config "$scenario" --domain "$DOMAIN" "$@"; }

# fly_six_own_server [ARGS...]: the thesis scenario in real time, its server
# started by the test itself (sim1, for the test to kill and replace), its six
# agents by ddswarm-launch --only agents ARGS (logs in $WORK); every agent
# online and the swarm airborne.
fly_six_own_server() {
  scenario="$SRC/config/thesis_course.yaml"
  start sim1 "$BIN/ddswarm-sim" --scenario "$scenario" --mode realtime --domain "$DOMAIN"
  start agents "$BIN/ddswarm-launch" "$scenario" --only agents --domain "$DOMAIN" "$@" --log-dir "$WORK"
  gs wait-agents --count 6 --timeout 60 || fail "agents not online"
  gs takeoff --wait || fail "takeoff"
}

# secure_swarm_setup N: DDS Security for N agents (docs/security.md): the
# secure test scenario, certificates in $C for this test's domain, and gs as
# the authenticated ground station.
secure_swarm_setup() {
  scenario="$SRC/tests/scenarios/secure_small.yaml"  # 3 drones unless told, real time
  C="$WORK/certs"
  "$SRC/scripts/make-certs" --out "$C" --agents "$1" --domain "$DOMAIN" || fail "make-certs failed"
  gs() { timeout 40 "$BIN/ddswarm-gs" --config "$scenario" --domain "$DOMAIN" --secure "$C" "$@"; }
}

# xy K: "x y" of drone K as the test's ground station (gs) sees it;
# moved "X0 Y0" "X1 Y1": the distance between two such positions, in m.
xy() { gs status --drones | awk -v d="$1" '$1 == d && NF >= 8 { print $2, $3 }'; }
moved() { /usr/bin/python3 -c "import math; a=list(map(float,'$1'.split())); b=list(map(float,'$2'.split())); print('%.3f' % math.dist(a,b))"; }

# probe_swarm N: 5 s of swarm_probe --ages on a flying swarm of N, printed;
# probe_val KEY then prints one of its figures (rtf, age_p99_periods, ...).
probe_swarm() {
  timeout 60 "$BIN/swarm_probe" --drones "$1" --settle 1 --time 5 --ages --domain "$DOMAIN" \
    >"$WORK/probe.out" 2>&1
  cat "$WORK/probe.out"
  PROBE_LINE=$(grep "^probe ok=1" "$WORK/probe.out") || fail "the probe did not measure the swarm"
}
probe_val() { echo "$PROBE_LINE" | tr ' ' '\n' | sed -n "s/^$1=//p"; }
# web_url: the address `start web ddswarm-gs ... --web 127.0.0.1:0` printed,
# waited for up to 30 s; returns 1, saying why on stderr, if the bridge exits
# or prints none (call it as url=$(web_url) || fail ...).
web_url() {
  local url=""
  for _ in $(seq 1 150); do
    url=$(grep -o 'http://127\.0\.0\.1:[0-9]*/' "$WORK/web.log" | head -1)
    [ -n "$url" ] && { echo "$url"; return 0; }
    kill -0 "$PID_web" 2>/dev/null || { echo "ddswarm-gs --web exited" >&2; return 1; }
    sleep 0.2
  done
  echo "ddswarm-gs --web printed no URL" >&2
  return 1
}
# commands_fresh: after probe_swarm of a plain real-time swarm, its commands
# act on the next period (median age 1), in real time, none going stale and
# few missed. Bounds for a test that may share 2 cores with another: the
# figures on a quiet machine are a benchmark's (bench/swarm_bench.sh).
commands_fresh() {
  [ "$(probe_val age_p50_periods)" -le 1 ] || fail "command age p50 $(probe_val age_p50_periods) periods"
  [ "$(probe_val age_p99_periods)" -le 5 ] || fail "command age p99 $(probe_val age_p99_periods) periods"
  echo "$(probe_val rtf) >= 0.9" | bc -l | grep -q 1 || fail "real-time factor $(probe_val rtf)"
  awk -v m="$(probe_val missed_frac)" 'BEGIN { exit !(m < 0.05) }' || fail "missed $(probe_val missed_frac) of commands"
}

# unmatched_profiles OUT ENDPOINT:PROFILE...: the shipped QoS profiles with
# EXCLUSIVE ownership on each named endpoint (e.g. data_writer:command), so
# it matches none of the swarm's SHARED peers; written to OUT.
unmatched_profiles() {
  /usr/bin/python3 - "$SRC/config/dds_profiles.xml" "$@" <<'PY'
import re, sys
xml = open(sys.argv[1]).read()
for spec in sys.argv[3:]:
    kind, name = spec.split(":")
    pat = r'(<%s profile_name="%s">.*?<qos>)' % (kind, name)
    xml, n = re.subn(pat, r'\1<ownership><kind>EXCLUSIVE</kind></ownership>', xml, count=1, flags=re.S)
    assert n == 1, spec
open(sys.argv[2], "w").write(xml)
PY
}

# shm_ports PID...: the Fast DDS shared-memory ports each process maps. A
# port listed "(deleted)" was removed and made anew by another process while
# this one still used it: peers that open it now reach the new one, not this
# process (docs/dds.md, "A live port found unhealthy").
shm_ports() {
  for pid in "$@"; do
    echo "-- pid $pid ($(tr '\0' ' ' </proc/"$pid"/cmdline 2>/dev/null | cut -c1-60)):"
    grep -o '/dev/shm/fastrtps_port[0-9]*\( (deleted)\)\?' /proc/"$pid"/maps 2>/dev/null | sort -u
  done
}

# launch_lockstep NAME ARGS...: ddswarm-launch of $scenario in lockstep on the
# test's domain, logs in $WORK/NAME/, its output in $WORK/NAME.log (printed);
# returns the launcher's exit code. Set LAUNCH_AGENT_TIMEOUT_S (default 5).
launch_lockstep() {
  local name=$1
  shift
  timeout "$(slow 300)" "$BIN/ddswarm-launch" "$scenario" --mode lockstep --domain "$DOMAIN" \
    --set sim.agent_timeout_s="${LAUNCH_AGENT_TIMEOUT_S:-5}" --log-dir "$WORK/$name" "$@" >"$WORK/$name.log" 2>&1
  local rc=$?
  cat "$WORK/$name.log"
  return $rc
}

# refused_law LAW EXPECTED: ddswarm-agent refuses $scenario with agent.law LAW
# (inserted at the agent section's first line, line 64 of thesis_course.yaml)
# before anything flies: exit 2 and one line that contains EXPECTED.
refused_law() {
  sed "s#^agent:#agent:\n  law: $1#" "$scenario" >"$WORK/refused.yaml"
  timeout 60 "$BIN/ddswarm-agent" --id 0 --config "$WORK/refused.yaml" --domain "$DOMAIN" >"$WORK/refused.log" 2>&1
  local rc=$?
  cat "$WORK/refused.log"
  [ $rc -eq 2 ] || fail "ddswarm-agent with law $1 exited $rc, not 2"
  [ "$(wc -l <"$WORK/refused.log")" -eq 1 ] || fail "the refusal is not one line"
  grep -qF "$2" "$WORK/refused.log" || fail "the refusal does not say: $2"
}
