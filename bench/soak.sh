#!/usr/bin/env bash
# Chaos soak (docs/faults.md#chaos-soak): a real-time swarm, one agent process
# per drone, the recorder on, and a seeded schedule of faults for a set time:
#   agent_kill      an agent SIGKILLed, started again
#   agent_stop      an agent SIGSTOPped past its lease, then SIGCONT
#   server_kill     the server SIGKILLed, started again (a new world: take off again)
#   gs_kill         a ground station SIGKILLed in the middle of a command
#   recorder_kill   the recorder SIGKILLed, started again on a new file
#   hostile         a publisher of malformed and forged samples for 3 s
# An agent that dies of itself is started again and counted (agent_crash).
# Each fault must be detected and recovered within its bound; all along and
# at the end it checks: no process left, shared-memory files bounded, the RSS
# of every long-lived process flat, every hostile sample rejected and counted,
# every recording readable with the swarm states it should hold, the swarm
# flying at the end. It prints a table per fault kind and the checks.
#
#   bench/soak.sh [--minutes 30] [--drones 64] [--seed 1] [--interval 20]
#                 [--bin build/default/bin] [--out DIR] [--quick]
# --quick: 6 drones, every kind once, about a minute (the suite's mp_soak_short).
# Exit 0 when every check passed, 1 otherwise.
set -u
SRC="$(cd "$(dirname "$0")/.." && pwd)"
BIN="$SRC/build/default/bin"
MINUTES=30 DRONES=64 SEED=1 INTERVAL=20 OUT="" QUICK=0
while [ $# -gt 0 ]; do
  case "$1" in
    --minutes) MINUTES="$2"; shift 2 ;;
    --drones) DRONES="$2"; shift 2 ;;
    --seed) SEED="$2"; shift 2 ;;
    --interval) INTERVAL="$2"; shift 2 ;;
    --bin) BIN="$2"; shift 2 ;;
    --out) OUT="$2"; shift 2 ;;
    --quick) QUICK=1; DRONES=6; INTERVAL=1; shift ;;
    -h|--help) sed -n '2,20p' "$0"; exit 0 ;;
    *) echo "soak.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
for v in MINUTES DRONES SEED INTERVAL; do
  [[ "${!v}" =~ ^[0-9]+$ ]] && [ "${!v}" -gt 0 ] || { echo "soak.sh: --${v,,} ${!v}: must be a positive integer" >&2; exit 2; }
done
[ "$DRONES" -le 90 ] || { echo "soak.sh: --drones $DRONES: at most 90 (one agent process each, automatic participant ids)" >&2; exit 2; }
[ -x "$BIN/ddswarm-sim" ] || { echo "soak.sh: no $BIN/ddswarm-sim: build first (scripts/build)" >&2; exit 2; }
KINDS=(agent_kill agent_stop server_kill gs_kill recorder_kill hostile)
RANDOM=$SEED
WORK="${OUT:-$(mktemp -d /tmp/ddswarm-soak.XXXXXX)}"
mkdir -p "$WORK/rec"
# A domain block of its own when run from the suite (tests/lib.sh), else one
# below the ephemeral ports.
DOMAIN="${DDSWARM_DOMAIN:-$(( (RANDOM % 50) + 20 ))}"
scenario="$WORK/soak.yaml"
# Ground-station waits a loaded machine meets (bench/bench_lib.sh's), on the thesis course.
sed -e 's/^  ack_timeout_s: .*/  ack_timeout_s: 30.0\n  discovery_timeout_s: 60.0/' \
  -e 's/^\(    max_mps: 1.5\)$/\1\n    neighbours: 6/' "$SRC/config/thesis_course.yaml" >"$scenario"
grep -q "discovery_timeout_s: 60.0" "$scenario" || { echo "soak.sh: cannot derive $scenario" >&2; exit 2; }
GS=("$BIN/ddswarm-gs" --config "$scenario" --domain "$DOMAIN")
gs() { timeout 90 "${GS[@]}" "$@"; }
now() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.2f", b - a }'; }
note() { printf '[%6ss] %s\n' "$(elapsed "$T0")" "$*"; }

declare -A PID=()   # name -> pid of what runs now
declare -a ALL=()   # every pid ever started, for the final leak check
run() { # NAME CMD...: in the background, log appended to $WORK/NAME.log
  local name="$1"; shift
  "$@" >>"$WORK/$name.log" 2>&1 &
  PID[$name]=$!
  ALL+=($!)
}
stop_all() {
  for p in "${ALL[@]}"; do kill -TERM "$p" 2>/dev/null; kill -CONT "$p" 2>/dev/null; done
  local end=$((SECONDS + 10))
  for p in "${ALL[@]}"; do
    while kill -0 "$p" 2>/dev/null && [ $SECONDS -lt $end ]; do sleep 0.1; done
    kill -KILL "$p" 2>/dev/null; wait "$p" 2>/dev/null
  done
}
trap 'stop_all; exit 130' INT TERM

SERVER_N=0
start_server() {
  SERVER_N=$((SERVER_N + 1))
  SERVER_LOG="$WORK/sim$SERVER_N.log"
  "$BIN/ddswarm-sim" --scenario "$scenario" --drones "$DRONES" --mode realtime --domain "$DOMAIN" \
    >"$SERVER_LOG" 2>&1 &
  PID[sim]=$!; ALL+=($!)
}
start_agent() { run "agent$1" "$BIN/ddswarm-agent" --id "$1" --config "$scenario" --drones "$DRONES" --domain "$DOMAIN"; }
REC_N=0
start_recorder() {
  REC_N=$((REC_N + 1))
  REC_FILE="$WORK/rec/run$REC_N.mcap"
  REC_START=$(now)
  run recorder "$BIN/ddswarm-record" -o "$REC_FILE" --domain "$DOMAIN" --chunk-kb 256 \
    --topics ddswarm/swarm_state,ddswarm/status
  echo "$REC_FILE $REC_START" >>"$WORK/recordings.txt"
}
# online_count: agents the current server has said online (its log).
online_count() { grep -c "agent [0-9a-f]* online" "$SERVER_LOG" 2>/dev/null || echo 0; }
# wait_for SECONDS CMD...: polls CMD every 0.2 s; 0 when it held within SECONDS.
wait_for() {
  local end; end=$(awk -v t="$(now)" -v s="$1" 'BEGIN { printf "%.0f", t + s }'); shift
  until "$@"; do [ "$(date +%s)" -lt "$end" ] || return 1; sleep 0.2; done
}
server_hears_all() { gs status 2>/dev/null | grep -q "drones $DRONES/$DRONES online"; }
airborne_all() { gs status 2>/dev/null | grep -q "| $DRONES airborne"; }
takeoff() { gs takeoff --wait >>"$WORK/gs.log" 2>&1 && gs hold >>"$WORK/gs.log" 2>&1; }

RESULTS="$WORK/results.txt"; : >"$RESULTS"
record() { echo "$1 $2 $3" >>"$RESULTS"; note "$1: $3 in $2 s"; } # KIND SECONDS ok|FAILED
FAILS=0
check() { if [ "$2" = ok ]; then note "check $1: ok"; else note "check $1: FAILED ($3)"; FAILS=$((FAILS + 1)); fi; echo "check $1 $2 ${3:-}" >>"$WORK/checks.txt"; }

# --- bring-up ---
T0=$(now)
: >"$WORK/checks.txt"; : >"$WORK/recordings.txt"
touch "$WORK/t0"
# orphans: shared-memory files the soak's processes used (as sampled) that no
# live process maps or holds open: what a killed process leaves until a start
# clears it. Other processes' files (a test beside this one) do not count.
: >"$WORK/shm_seen.txt"
shm_refs() { # PIDS...: the /dev/shm files they map or hold open
  for p in "$@"; do
    awk '$6 ~ /^\/dev\/shm\// { print $6 }' "/proc/$p/maps" 2>/dev/null
    find "/proc/$p/fd" -lname '/dev/shm/*' -printf '%l\n' 2>/dev/null
  done
}
orphans() {
  local refs="$WORK/.shm_refs"
  shm_refs $(ls /proc | grep -E '^[0-9]+$') | sort -u >"$refs"
  # Domain claims (ddswarm_domain_N.lock) stay by design: an flock, not a segment.
  sort -u "$WORK/shm_seen.txt" | grep -v '/ddswarm_domain_[0-9]*\.lock$' |
    while read -r f; do [ -e "$f" ] && echo "$f"; done | comm -23 - "$refs"
}
start_server
for i in $(seq 0 $((DRONES - 1))); do start_agent "$i"; done
start_recorder
gs wait-agents --count "$DRONES" --timeout 85 >>"$WORK/gs.log" 2>&1 || { note "the swarm did not come up (logs in $WORK)"; stop_all; exit 1; }
takeoff || { note "the swarm did not take off (logs in $WORK)"; stop_all; exit 1; }
note "$DRONES agents online and airborne; faults every ~${INTERVAL} s for ${MINUTES} min, seed $SEED, domain $DOMAIN"

# --- RSS samples: pid name kB at t joins (the participants its log says it
# made anew so far: joined again, or started again) ---
RSS="$WORK/rss.txt"; : >"$RSS"
sample_rss() {
  local t; t=$(elapsed "$T0")
  for name in "${!PID[@]}"; do
    local p=${PID[$name]} kb joins
    kb=$(awk '/^VmRSS:/ { print $2 }' "/proc/$p/status" 2>/dev/null) || continue
    joins=$(grep -c "joining again as a new participant\|started again" "$WORK/$name.log" 2>/dev/null)
    [ -n "$kb" ] && echo "$p $name $kb $t ${joins:-0}" >>"$RSS"
  done
  shm_refs "${PID[@]}" >>"$WORK/shm_seen.txt"
  echo "shm $(orphans | wc -l) $t" >>"$WORK/shm.txt"
}

# --- the faults ---
fault_agent_kill() {
  local k=$((RANDOM % DRONES)) n0 t; n0=$(online_count); t=$(now)
  kill -KILL "${PID[agent$k]}"; wait "${PID[agent$k]}" 2>/dev/null
  start_agent "$k"
  # Recovered: the server says a new agent for drone k is online, and the drone flies on.
  if wait_for 60 bash -c "[ \$(grep -c 'drone $k: agent [0-9a-f]* online' '$SERVER_LOG') -gt $(grep -c "drone $k: agent [0-9a-f]* online" "$SERVER_LOG") ]" &&
    wait_for 60 airborne_all; then record agent_kill "$(elapsed "$t")" ok; else record agent_kill "$(elapsed "$t")" FAILED; fi
}
fault_agent_stop() {
  local k=$((RANDOM % DRONES)) t c0
  c0=$(grep -c "drone $k: agent [0-9a-f]* online" "$SERVER_LOG"); t=$(now)
  kill -STOP "${PID[agent$k]}"
  wait_for 20 grep -q "drone $k: agent lost" "$SERVER_LOG" || true
  sleep 4  # past the participant's 3 s lease (dds.lease_duration_s)
  kill -CONT "${PID[agent$k]}"
  if wait_for 60 bash -c "[ \$(grep -c 'drone $k: agent [0-9a-f]* online' '$SERVER_LOG') -gt $c0 ]" &&
    wait_for 60 server_hears_all; then record agent_stop "$(elapsed "$t")" ok; else record agent_stop "$(elapsed "$t")" FAILED; fi
}
fault_server_kill() {
  local t; t=$(now)
  kill -KILL "${PID[sim]}"; wait "${PID[sim]}" 2>/dev/null
  start_server
  # A new world: every agent joins it, then the swarm takes off again.
  if gs wait-agents --count "$DRONES" --timeout 85 >>"$WORK/gs.log" 2>&1 && takeoff; then
    record server_kill "$(elapsed "$t")" ok; else record server_kill "$(elapsed "$t")" FAILED; fi
}
fault_gs_kill() {
  local t; t=$(now)
  "${GS[@]}" move --north 0.2 --time 3 --wait >>"$WORK/gs_killed.log" 2>&1 &
  local g=$!; ALL+=($g)
  sleep $(( (RANDOM % 3) + 1 ))
  kill -KILL "$g" 2>/dev/null; wait "$g" 2>/dev/null
  # Recovered: the next ground station commands the whole swarm.
  if gs hold >>"$WORK/gs.log" 2>&1 && wait_for 30 airborne_all; then record gs_kill "$(elapsed "$t")" ok
  else record gs_kill "$(elapsed "$t")" FAILED; fi
}
fault_recorder_kill() {
  local t; t=$(now)
  kill -KILL "${PID[recorder]}"; wait "${PID[recorder]}" 2>/dev/null
  echo "end $(now)" >>"$WORK/recordings.txt"
  start_recorder
  # Recovered: the new file grows.
  if wait_for 30 bash -c "[ -s '$REC_FILE' ] && [ \$(stat -c %s '$REC_FILE') -gt 4096 ]"; then
    record recorder_kill "$(elapsed "$t")" ok; else record recorder_kill "$(elapsed "$t")" FAILED; fi
}
rejected_total() { gs status 2>/dev/null | sed -n 's/^rejected samples: \([0-9]*\).*/\1/p'; }
fault_hostile() {
  local t r0 r1; t=$(now); r0=$(rejected_total)
  timeout 30 "$BIN/malformed_publisher" --domain "$DOMAIN" --id $((RANDOM % DRONES)) --attack 3 >>"$WORK/hostile.log" 2>&1
  timeout 30 "$BIN/forged_swarm_state" --domain "$DOMAIN" --attack 3 >>"$WORK/hostile.log" 2>&1
  r1=$(rejected_total)
  # Every sample rejected and counted, and the swarm flies on.
  if [ -n "$r0" ] && [ -n "$r1" ] && [ "$r1" -gt "$r0" ] && wait_for 30 airborne_all; then
    echo "$((r1 - r0))" >>"$WORK/rejected.txt"; record hostile "$(elapsed "$t")" ok
  else record hostile "$(elapsed "$t")" FAILED; fi
}

# An agent that died of itself, not by a fault the soak made (Fast DDS 2.9's
# PDP.cpp:1140 abort, docs/dds.md): its exit and last log line are kept, and
# it is started again, as `ddswarm-launch --on-death restart` would. Its
# recovery is timed as a row of its own, and the check "no agent died of
# itself" fails: the soak says it, it does not hide it.
CRASHES="$WORK/crashes.txt"; : >"$CRASHES"
revive_crashed() {
  local k rc c0 t
  for k in $(seq 0 $((DRONES - 1))); do
    kill -0 "${PID[agent$k]}" 2>/dev/null && continue
    wait "${PID[agent$k]}" 2>/dev/null; rc=$?
    echo "agent $k (exit $rc): $(grep -v '^[[:space:]]*$' "$WORK/agent$k.log" | tail -1 | cut -c1-160)" >>"$CRASHES"
    note "agent $k died of itself (exit $rc); starting it again"
    c0=$(grep -c "drone $k: agent [0-9a-f]* online" "$SERVER_LOG"); t=$(now)
    start_agent "$k"
    if wait_for 60 bash -c "[ \$(grep -c 'drone $k: agent [0-9a-f]* online' '$SERVER_LOG') -gt $c0 ]" &&
      wait_for 60 airborne_all; then record agent_crash "$(elapsed "$t")" ok; else record agent_crash "$(elapsed "$t")" FAILED; fi
  done
}

END=$(awk -v t="$T0" -v m="$MINUTES" 'BEGIN { printf "%.0f", t + m * 60 }')
i=0
while :; do
  sample_rss
  if [ $QUICK -eq 1 ]; then
    [ $i -lt ${#KINDS[@]} ] || break
    kind=${KINDS[$i]}
  else
    [ "$(date +%s)" -lt "$END" ] || break
    kind=${KINDS[$((RANDOM % ${#KINDS[@]}))]}
  fi
  i=$((i + 1))
  revive_crashed
  "fault_$kind"
  [ $QUICK -eq 1 ] || sleep $(( INTERVAL / 2 + RANDOM % (INTERVAL + 1) ))
done
sample_rss
revive_crashed

# --- the end: checks ---
[ -s "$CRASHES" ] && check "no agent died of itself" FAILED "$(wc -l <"$CRASHES") did, each started again: $(head -3 "$CRASHES" | tr '\n' ';')" ||
  check "no agent died of itself" ok
airborne_all && check "swarm flying at the end" ok || check "swarm flying at the end" FAILED "not all $DRONES airborne"
kill -INT "${PID[recorder]}"; wait "${PID[recorder]}" 2>/dev/null
echo "end $(now)" >>"$WORK/recordings.txt"
stop_all
sleep 1
left=$(for p in "${ALL[@]}"; do kill -0 "$p" 2>/dev/null && echo "$p"; done; pgrep -f -- "--domain $DOMAIN\b")
[ -z "$left" ] && check "no process left" ok || check "no process left" FAILED "$(echo $left)"
shm_max=$(awk '{ print $2 }' "$WORK/shm.txt" | sort -n | tail -1)
# What killed processes left, the next start clears (docs/faults.md): one
# more server start, and none of the soak's files may be left.
sleep 3  # older than the 2 s a file must be to count as a zombie
timeout 30 "$BIN/ddswarm-sim" --scenario "$scenario" --drones 1 --mode realtime --domain "$DOMAIN" \
  --duration 1 >"$WORK/sim_cleanup.log" 2>&1
left_files=$(orphans | wc -l)
[ "$left_files" -eq 0 ] && check "no shared-memory file leaked (at most $shm_max orphans during the soak, 0 after a start)" ok ||
  check "no shared-memory file leaked" FAILED "$left_files files no process holds: $(orphans | head -3 | tr '\n' ' ')"
# RSS slope per process (least squares, MB per minute) over its samples after
# its warm-up: its first two minutes (pools, histories, the law's first
# neighbours) and its first two participants made anew, if it made any. An
# agent's RSS steps up at its first two re-joins and then stays: one agent
# made to join again 25 times (SIGUSR1, one drone) went 20.7, 34.2, 37.8 MB,
# then 38.1 MB after the 25th. Judged for a process sampled over at least
# five minutes past its warm-up.
awk -v bound=1.0 '
  { pid = $1; kb[pid] = kb[pid] " " $3; t[pid] = t[pid] " " $4; j[pid] = j[pid] " " ($5 + 0); name[pid] = $2 }
  END {
    worst = 0; judged = 0
    for (p in kb) {
      n = split(kb[p], K); split(t[p], T); split(j[p], J)
      made = J[n] - J[1]; if (made > 2) made = 2
      sx = sy = sxx = sxy = m = 0
      first = -1; last = -1
      for (i = 1; i <= n; i++) if (T[i] - T[1] >= 120 && J[i] - J[1] >= made) { x = T[i] / 60; y = K[i] / 1024; sx += x; sy += y; sxx += x * x; sxy += x * y; m++; if (first < 0) first = T[i]; last = T[i] }
      if (m < 5 || last - first < 300 || sxx * m - sx * sx <= 0) continue
      s = (m * sxy - sx * sy) / (m * sxx - sx * sx); judged++
      if (s > worst) { worst = s; wn = name[p] }
    }
    if (judged == 0) { print "n/a (no process sampled over 5 min past its first 2)"; exit 0 }
    printf "%.3f MB/min (%s; %d processes judged)\n", worst, wn, judged; exit !(worst < bound)
  }' "$RSS" >"$WORK/rss_slope.txt"
slope_rc=$?
[ $slope_rc -eq 0 ] && check "RSS flat: worst slope $(cat "$WORK/rss_slope.txt"), bound 1 MB/min" ok ||
  check "RSS flat" FAILED "$(cat "$WORK/rss_slope.txt")"
# Every recording readable (a killed recorder's up to its last chunk), and
# holding every swarm state the server published while it recorded: within
# each server's run (ticks restart at 0 with a new server), no tick missing
# between the first and the last recorded.
PYTHONPATH="$BIN/../python" /usr/bin/python3 - "$WORK/recordings.txt" >"$WORK/recordings_check.txt" 2>&1 <<'PY'
import sys, ddswarm
ok = True
for l in open(sys.argv[1]):
    path = l.split()[0]
    if path == "end":
        continue
    try:
        s = ddswarm.Recording(path).swarm_state()
        # The server's own: sim time = tick x 20 ms (the forger's are not).
        ticks = [int(k) for k, t in zip(s.tick, s.t) if abs(t - int(k) * 0.02) < 1e-3]
        forged = len(s.tick) - len(ticks)
    except Exception as e:
        print(f"{path}: unreadable: {e}"); ok = False; continue
    runs, missing = 1, 0
    for a, b in zip(ticks, ticks[1:]):
        if b < a:
            runs += 1
        elif b > a + 1:
            missing += b - a - 1
    print(f"{path}: {len(ticks)} swarm states from {runs} server run(s), {missing} ticks missing"
          f" ({forged} forged samples beside them)")
    ok &= len(ticks) > 0 and missing == 0
sys.exit(0 if ok else 1)
PY
rec_rc=$?
cat "$WORK/recordings_check.txt"
[ $rec_rc -eq 0 ] && check "every recording readable ($(grep -c . "$WORK/recordings_check.txt") files)" ok ||
  check "every recording readable" FAILED "$WORK/recordings_check.txt"
[ -s "$WORK/rejected.txt" ] || [ "$(grep -c '^hostile' "$RESULTS")" -eq 0 ] &&
  check "hostile samples rejected and counted: $(paste -sd+ "$WORK/rejected.txt" 2>/dev/null | bc 2>/dev/null || echo 0)" ok ||
  check "hostile samples rejected and counted" FAILED "no rejection counted"

# --- the table ---
echo
echo "soak: $DRONES drones, real time, $(elapsed "$T0") s, seed $SEED, $(wc -l <"$RESULTS") faults (logs in $WORK)"
echo "| fault | count | recovered | p50 s | max s |"
echo "|---|---|---|---|---|"
for kind in "${KINDS[@]}" agent_crash; do
  times=$(awk -v k="$kind" '$1 == k { print $2 }' "$RESULTS" | sort -n)
  n=$(echo "$times" | grep -c .)
  if [ "$n" -eq 0 ]; then echo "| $kind | 0 | - | - | - |"; continue; fi
  ok=$(awk -v k="$kind" '$1 == k && $3 == "ok"' "$RESULTS" | wc -l)
  echo "| $kind | $n | $ok | $(echo "$times" | sed -n "$(( (n + 1) / 2 ))p") | $(echo "$times" | tail -1) |"
done
failed=$(awk '$3 != "ok"' "$RESULTS" | wc -l)
echo
sed 's/^check /- /' "$WORK/checks.txt"
[ "$failed" -eq 0 ] && [ $FAILS -eq 0 ] && { echo "soak: PASS"; exit 0; }
echo "soak: FAIL ($failed faults not recovered, $FAILS checks failed)"
exit 1
