#!/usr/bin/env bash
# Checked before starting: ddswarm-launch and ddswarm-gs experiment read the
# whole scenario, with every --set and set, as each of their processes will,
# before they start any. A bad value is one line on stderr naming what the
# user typed (the --set flag, the experiment file's set, or the scenario
# file and its line, never a copy of it), exit 2, in seconds, with no process
# started. `ddswarm-launch --check` does only that. The launcher's copy of a
# scenario goes to --log-dir, or is removed at exit (normal end, error,
# SIGINT, SIGTERM): nothing is left in the temp directory.
source "$(dirname "$0")/lib.sh"
scenario="$SRC/config/thesis_course.yaml"
# Every launch below writes its copy here, not in /tmp, so that what is left is the tests' own.
export TMPDIR="$WORK/tmp"
mkdir -p "$TMPDIR"
problems=()

# refused LABEL EXPECTED CMD...: exit 2 within 3 s, stderr exactly the line EXPECTED, and
# no process started: nothing said of one, no log in $logs (launch_logged's --log-dir).
refused() {
  local label="$1" expected="$2"; shift 2
  logs="$WORK/logs-${label//[^a-zA-Z0-9]/_}"
  local t0 ms
  t0=$(date +%s%N)
  "$@" >"$WORK/r.out" 2>"$WORK/r.err" </dev/null
  local rc=$?
  ms=$((($(date +%s%N) - t0) / 1000000))
  echo "$label: exit $rc after $ms ms: $(head -3 "$WORK/r.err")"
  [ $rc -eq 2 ] || problems+=("$label: exit $rc, expected 2")
  [ $ms -le 3000 ] || problems+=("$label: took $ms ms")
  [ "$(cat "$WORK/r.err")" = "$expected" ] || problems+=("$label: stderr is not '$expected'")
  local started
  started=$(find "$logs" -name '*.log' 2>/dev/null)
  [ -z "$started" ] || problems+=("$label: processes were started: $started")
  grep -q "started\|^\[" "$WORK/r.out" "$WORK/r.err" && problems+=("$label: said it started something")
}
launch() { timeout 20 "$BIN/ddswarm-launch" "$@" --domain "$DOMAIN"; }
launch_logged() { launch "$@" --log-dir "$logs"; }

# Through the agent's section, the server's (sensors), an unknown key, a malformed --set.
refused "agent value" "ddswarm-launch: error: --set agent.inter_distance_m=-1: must be > 0" \
  launch "$scenario" --set agent.inter_distance_m=-1 --gs "takeoff --wait"
refused "sensors value" "ddswarm-launch: error: --set sensors.count=100000: must be in [1, 256]" \
  launch "$scenario" --set sensors.count=100000 --gs "takeoff --wait"
refused "unknown key" "ddswarm-launch: error: --set agent.inter_distanse_m=3: unknown key" \
  launch_logged "$scenario" --set agent.inter_distanse_m=3
refused "unknown section" "ddswarm-launch: error: --set agnet.inter_distance_m=3: agnet: unknown section" \
  launch "$scenario" --set agnet.inter_distance_m=3
refused "malformed set" "ddswarm-launch: error: --set = agent.inter_distance_m: must be key.path=value" \
  launch "$scenario" --set agent.inter_distance_m
refused "through a value" \
  "ddswarm-launch: error: --set agent.inter_distance_m.x=1: agent.inter_distance_m is a value, not a mapping" \
  launch_logged "$scenario" --set agent.inter_distance_m.x=1
refused "ground station" "ddswarm-launch: error: --set ground_station.ack_timeout_s=-2: must be in [0.1, 600]" \
  launch_logged "$scenario" --set ground_station.ack_timeout_s=-2
# A bad value in the file itself: the user's file and its line there, also with a --set of
# another key (whose copy of the file every process would read).
sed 's/^  inter_distance_m: 4.0 /  inter_distance_m: -1  /' "$scenario" >"$WORK/bad.yaml"
line=$(grep -n '^  inter_distance_m: -1' "$WORK/bad.yaml" | cut -d: -f1)
[ -n "$line" ] || fail "could not write the bad scenario"
refused "file value" "ddswarm-launch: error: $WORK/bad.yaml:$line: agent.inter_distance_m = -1: must be > 0" \
  launch "$WORK/bad.yaml"
refused "file value with --set" \
  "ddswarm-launch: error: $WORK/bad.yaml:$line: agent.inter_distance_m = -1: must be > 0 (with --set agent.max_speed_mps=2)" \
  launch_logged "$WORK/bad.yaml" --set agent.max_speed_mps=2 --set comm.latency_s=0.1
# The same through agent hosts and --only agents.
refused "agent hosts" "ddswarm-launch: error: --set agent.inter_distance_m=0: must be > 0" \
  launch_logged "$scenario" --set agent.inter_distance_m=0 --agent-hosts 2
refused "only the server" "ddswarm-launch: error: --set sensors.count=0: must be in [1, 256]" \
  launch_logged "$scenario" --set sensors.count=0 --only server

# --check: one line and 0, or the error and 2; it starts nothing either.
t0=$(date +%s%N)
out=$(launch "$scenario" --check --set agent.inter_distance_m=3 --drones 8 2>"$WORK/c.err")
rc=$?
ms=$((($(date +%s%N) - t0) / 1000000))
echo "--check ok: exit $rc after $ms ms: $out"
[ $rc -eq 0 ] || problems+=("--check of a valid scenario: exit $rc: $(cat "$WORK/c.err")")
[ "$out" = "ddswarm-launch: ok: $scenario with --set agent.inter_distance_m=3 is valid as the server, 8 agent(s) and the ground station will read it (8 drones)" ] ||
  problems+=("--check of a valid scenario said '$out'")
[ ! -s "$WORK/c.err" ] || problems+=("--check of a valid scenario wrote to stderr: $(cat "$WORK/c.err")")
refused "--check bad" "ddswarm-launch: error: --set comm.latency_s=-0.3: must be in [0, 60]" \
  launch "$scenario" --check --set comm.latency_s=-0.3

# The ground station's experiment: a bad value in one of the file's sets, before any run, naming
# the experiment file's line and the set; a bad --set, naming the flag.
cat >"$WORK/exp.yaml" <<EOF
experiment:
  name: bad
  scenario: $scenario
  runs_per_set: 2
  sets:
    - name: Good
      set: { agent.inter_distance_m: 4 }
    - name: Tight
      set: { agent.inter_distance_m: 0, task.speed_mps: 0.8 }
EOF
experiment() { timeout 20 "$BIN/ddswarm-gs" --domain "$DOMAIN" experiment "$WORK/exp.yaml" "$@"; }
refused "experiment set" \
  "ddswarm-gs: error: $WORK/exp.yaml:9: set 'Tight': agent.inter_distance_m = 0: must be > 0" \
  experiment --out "$WORK/exp1"
refused "experiment --set" "ddswarm-gs: error: --set sensors.count=100000: must be in [1, 256]" \
  experiment --out "$WORK/exp2" --set sensors.count=100000
[ ! -e "$WORK/exp1/bad.csv" ] && [ ! -e "$WORK/exp1/logs" ] || problems+=("the bad experiment ran a run")
# A bad value of the experiment's scenario file itself names that file and its line, and the
# set that changed its section.
sed "s|scenario: .*|scenario: $WORK/bad.yaml|; s|agent.inter_distance_m: [0-9]*|agent.max_speed_mps: 2|" \
  "$WORK/exp.yaml" >"$WORK/exp-badfile.yaml"
refused "experiment scenario file" \
  "ddswarm-gs: error: $WORK/bad.yaml:$line: agent.inter_distance_m = -1: must be > 0 (with $WORK/exp-badfile.yaml:7: set 'Good')" \
  timeout 20 "$BIN/ddswarm-gs" --domain "$DOMAIN" experiment "$WORK/exp-badfile.yaml" --out "$WORK/exp3"

# The scenario's copy: kept in --log-dir, else removed at exit, whichever way the launch ends.
# One agent on a domain without a server: it waits, and the launch ends as told.
agent_only=(--only agents --ids 0 --set agent.max_speed_mps=2)
launch "$scenario" "${agent_only[@]}" --duration 1 >"$WORK/d.log" 2>&1 ||
  problems+=("a launch with --set and --duration 1 failed: $(tail -3 "$WORK/d.log")")
grep -q "agent.max_speed_mps\|--set overrides" "$WORK/d.log" || problems+=("the launch did not say where its copy is")
launch "$scenario" "${agent_only[@]}" --duration 1 --log-dir "$WORK/kept" >/dev/null 2>&1
[ -n "$(find "$WORK/kept" -name 'scenario-*.yaml')" ] || problems+=("no copy of the scenario in --log-dir")
for sig in INT TERM; do
  start "sig$sig" "$BIN/ddswarm-launch" "$scenario" "${agent_only[@]}" --domain "$DOMAIN"
  pid_var="PID_sig$sig"
  for _ in $(seq 100); do grep -q "started 1 process" "$WORK/sig$sig.log" && break; sleep 0.1; done
  grep -q "started 1 process" "$WORK/sig$sig.log" || problems+=("SIG$sig: the launch did not start")
  kill -"$sig" "${!pid_var}"
  wait_pid "${!pid_var}" 10 >/dev/null
  echo "SIG$sig: $(tail -1 "$WORK/sig$sig.log")"
done
left=$(find "$TMPDIR" -mindepth 1)
echo "left in the temp directory: ${left:-nothing}"
[ -z "$left" ] || problems+=("left in the temp directory: $left")

if [ ${#problems[@]} -gt 0 ]; then
  printf '  %s\n' "${problems[@]}"
  fail "${#problems[@]} case(s) misbehaved"
fi
echo PASS
