#!/usr/bin/env bash
# Bad command-line input, in subcommands and in the console, and Ctrl-C:
#  - garbage, NaN, inf, huge and out-of-range numbers in any subcommand's
#    options exit 2 at once (before any DDS wait) with stderr naming the
#    option and the value; the other binaries' numeric options likewise;
#  - Ctrl-C (SIGINT) on a subcommand that waits (for a server that is not
#    there; for agents that never come) ends it within a second, exit 130,
#    with "interrupted" on stderr;
#  - the console, fed garbage, NaN, inf and huge numbers then end of input,
#    re-asks with a reason, commands nothing, and exits 0.
source "$(dirname "$0")/lib.sh"
gs() { timeout 20 "$BIN/ddswarm-gs" --domain "$DOMAIN" "$@"; }
problems=()

# expect_usage_error LABEL CULPRIT CMD...: exit 2 within 3 s, stderr names CULPRIT.
expect_usage_error() {
  local label="$1" culprit="$2"; shift 2
  local t0=$SECONDS
  "$@" >"$WORK/u.out" 2>"$WORK/u.err" </dev/null
  local rc=$?
  echo "$label: exit $rc after $((SECONDS - t0)) s: $(head -1 "$WORK/u.err")"
  [ $rc -eq 2 ] || problems+=("$label: exit $rc, expected 2")
  [ $((SECONDS - t0)) -le 3 ] || problems+=("$label: took $((SECONDS - t0)) s (waited for DDS?)")
  grep -qF -- "$culprit" "$WORK/u.err" || problems+=("$label: stderr does not name '$culprit'")
}
for v in nan -nan inf 1e999 99999999999999999999 abc ''; do
  expect_usage_error "gs move --north '$v'" "--north" gs move --north "$v" --time 1
done
expect_usage_error "gs teleop --north nan" "nan" gs teleop --north nan
expect_usage_error "gs distance nan" "nan" gs distance nan
expect_usage_error "gs distance -inf" "-inf" gs distance -- -inf
expect_usage_error "gs hold --time nan" "nan" gs hold --time nan
expect_usage_error "gs task --speed nan" "nan" gs task --speed nan
expect_usage_error "gs takeoff --altitude 1e400" "1e400" gs takeoff --altitude 1e400
expect_usage_error "gs follow --leader 99999999999" "99999999999" gs follow --leader 99999999999
expect_usage_error "gs wait-agents --timeout nan" "nan" gs wait-agents --timeout nan
expect_usage_error "gs trace --duration inf" "inf" gs trace --out "$WORK/t.csv" --duration inf
expect_usage_error "gs experiment --set without =" "--set = sim.physics_rate_hz: must be key.path=value" \
  gs experiment "$SRC/config/table1.yaml" --out "$WORK/exp" --set sim.physics_rate_hz
# A bad value in an experiment's set is found before any run, in well under a second, not after
# each run's wait for a swarm whose server exited at once (4 runs would take 4 minutes).
expect_usage_error "gs experiment --set a bad rate" "ddswarm-gs: error: --set sim.control_rate_hz=70: must divide physics_rate_hz (1000)" \
  gs experiment "$SRC/tests/scenarios/short_experiment.yaml" --out "$WORK/exp-bad" --set sim.control_rate_hz=70
expect_usage_error "gs experiment --set an unknown agent key" "ddswarm-gs: error: --set agent.no_such_key=1: unknown key" \
  gs experiment "$SRC/tests/scenarios/short_experiment.yaml" --out "$WORK/exp-bad" --set agent.no_such_key=1
[ ! -e "$WORK/exp-bad/short.csv" ] || problems+=("experiment with a bad set ran runs anyway")
# A bad DDSWARM_FASTDDS_LOG (docs/dds.md) is named, before any DDS wait.
t0=$SECONDS
out=$(DDSWARM_FASTDDS_LOG=loud timeout 10 "$BIN/ddswarm-gs" --domain "$DOMAIN" status 2>&1)
rc=$?
echo "DDSWARM_FASTDDS_LOG=loud: exit $rc after $((SECONDS - t0)) s: $out"
{ [ $rc -ne 0 ] && [ $rc -ne 124 ] && [ $((SECONDS - t0)) -le 3 ] &&
  echo "$out" | grep -qF "DDSWARM_FASTDDS_LOG: 'loud' is not one of off, error, warning, info"; } ||
  problems+=("DDSWARM_FASTDDS_LOG=loud: exit $rc, '$out'")
for b in sim agent; do
  flag=--scenario; [ $b = agent ] && flag=--config
  out=$(timeout 5 "$BIN/ddswarm-$b" --check $flag "$SRC/config/thesis_course.yaml" 2>&1)
  rc=$?
  echo "ddswarm-$b --check thesis_course.yaml: exit $rc: $out"
  [ $rc -eq 0 ] && [[ "$out" == *"sections are valid"* ]] || problems+=("ddswarm-$b --check rejected a valid scenario")
done
expect_usage_error "launch --set bad YAML" "--set = sim.physics_rate_hz=[1: value is not YAML" \
  timeout 5 "$BIN/ddswarm-launch" "$SRC/config/thesis_course.yaml" --domain "$DOMAIN" --set "sim.physics_rate_hz=[1"
expect_usage_error "gs no-such-subcommand" "no-such-subcommand" gs no-such-subcommand
expect_usage_error "sim --duration nan" "nan" timeout 5 "$BIN/ddswarm-sim" --scenario "$SRC/tests/scenarios/one_drone.yaml" --domain "$DOMAIN" --duration nan
expect_usage_error "agent --duration -1" "-1" timeout 5 "$BIN/ddswarm-agent" --id 0 --domain "$DOMAIN" --duration -1
expect_usage_error "replay --rate nan" "nan" timeout 5 "$BIN/ddswarm-replay" "$WORK/none.mcap" --rate nan
expect_usage_error "record --duration nan" "nan" timeout 5 "$BIN/ddswarm-record" -o "$WORK/r.mcap" --domain "$DOMAIN" --duration nan

# interrupt LABEL CMD...: SIGINT after 1 s; must end within 1.5 s more, exit 130, say "interrupted".
interrupt() {
  local label="$1"; shift
  "$@" >"$WORK/i.out" 2>"$WORK/i.err" </dev/null &
  local pid=$!
  PIDS+=("$pid")
  sleep 1
  kill -INT "$pid"
  local t0=$(date +%s%N)
  wait_pid "$pid" 5
  local rc=$? ms=$((($(date +%s%N) - t0) / 1000000))
  echo "$label: SIGINT -> exit $rc after $ms ms: $(tr '\n' '|' <"$WORK/i.err")"
  [ $rc -eq 130 ] || problems+=("$label: exit $rc after SIGINT, expected 130")
  [ $ms -le 1500 ] || problems+=("$label: took $ms ms to stop after SIGINT")
  grep -q interrupted "$WORK/i.err" || problems+=("$label: no 'interrupted' line on stderr")
}
interrupt "gs takeoff --wait, no server" "$BIN/ddswarm-gs" --domain "$DOMAIN" takeoff --wait

start sim "$BIN/ddswarm-sim" --scenario "$SRC/tests/scenarios/one_drone.yaml" --domain "$DOMAIN" --duration 60
gs wait-agents --count 0 --timeout 15 >/dev/null || fail "no server"
interrupt "gs wait-agents --count 3 (never come)" "$BIN/ddswarm-gs" --domain "$DOMAIN" wait-agents --count 3 --timeout 30

# The console: every answer below is bad, then the input ends.
printf '2\nnan\n\x01\x02garbage\ninf\n3\nNaN\n1e308\n-0\n99999999999999999999999\n42\n%s\n' \
  "$(head -c 300 /dev/zero | tr '\0' 9)" | gs menu >"$WORK/menu.out" 2>&1
rc=$?
tail -25 "$WORK/menu.out"
[ $rc -eq 0 ] || problems+=("menu: exit $rc at end of input, expected 0")
grep -q "End of input" "$WORK/menu.out" || problems+=("menu: did not say the input ended")
for reason in "nan: must be a finite number" "inf: must be a finite number" "garbage' is not a number" \
    "NaN: must be a finite number" "1e308: must be at most" "Unknown option '42'" "Unknown option '9999"; do
  grep -qF -- "$reason" "$WORK/menu.out" || problems+=("menu: no '$reason'")
done
grep -qE "acknowledged|FAILED" "$WORK/menu.out" && problems+=("menu: a command was sent from bad input")
kill -0 "$PID_sim" 2>/dev/null || problems+=("the server died")

if [ ${#problems[@]} -gt 0 ]; then
  printf '  %s\n' "${problems[@]}"
  fail "${#problems[@]} bad-input case(s) misbehaved"
fi
echo PASS
