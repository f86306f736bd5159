#!/usr/bin/env bash
# Broken configuration is refused up front: every binary given a scenario with
# a bad field in a section it reads exits with code 2 and prints exactly one
# line on stderr naming the file, the line (where known), the field and the
# value; bad command-line usage exits 2 too. Cases that misbehave are listed
# at the end; each case prints what the binary said.
source "$(dirname "$0")/lib.sh"
S="$SRC/tests/scenarios"
failures=()

# case LABEL PATTERN... -- CMD... : CMD must exit 2 with one stderr line matching every PATTERN (grep -E).
case_() {
  local label="$1"; shift
  local patterns=()
  while [ "$1" != "--" ]; do patterns+=("$1"); shift; done
  shift
  local t0=$SECONDS
  "$@" >"$WORK/case.out" 2>"$WORK/case.err" </dev/null
  local rc=$? problems=()
  local lines
  lines=$(wc -l <"$WORK/case.err")
  [ $rc -eq 2 ] || problems+=("exit $rc, expected 2")
  [ "$lines" -eq 1 ] || problems+=("$lines lines on stderr, expected 1")
  for p in "${patterns[@]}"; do
    grep -qE -- "$p" "$WORK/case.err" || problems+=("stderr lacks /$p/")
  done
  if [ ${#problems[@]} -eq 0 ]; then
    echo "ok   $label: $(head -c 300 "$WORK/case.err")"
  else
    local why
    why=$(IFS=';'; echo "${problems[*]}")
    echo "BAD  $label ($((SECONDS - t0)) s): $why"
    sed 's/^/       stderr: /' "$WORK/case.err" | head -5
    sed 's/^/       stdout: /' "$WORK/case.out" | head -3
    failures+=("$label: $why")
  fi
}

# A refused file exits at once; one wrongly accepted stops by itself (--duration)
# or is stopped by timeout (exit 124): the ground station would wait 5 s for a server.
ulimit -c 0  # a crash should not spend seconds dumping core
bounded() { timeout 10 "$@"; }
run_sim() { bounded "$BIN/ddswarm-sim" --scenario "$1" --domain "$DOMAIN" --duration 1; }
run_agent() { bounded "$BIN/ddswarm-agent" --id 0 --config "$1" --domain "$DOMAIN" --duration 1; }
run_gs() { timeout 3 "$BIN/ddswarm-gs" --config "$1" --domain "$DOMAIN" status; }

# Sections every process reads (scenario:, the document itself).
for b in sim agent gs; do
  case_ "$b: unknown key" 'bad_unknown_key\.yaml:4:' 'scenario\.dronez' 'unknown key' -- run_$b "$S/bad_unknown_key.yaml"
  case_ "$b: zero drones" 'bad_zero_drones\.yaml:4:' 'scenario\.drones' '= 0\b' -- run_$b "$S/bad_zero_drones.yaml"
  case_ "$b: missing file" 'bad_no_such_file\.yaml' 'cannot open' -- run_$b "$S/bad_no_such_file.yaml"
  case_ "$b: malformed YAML" 'bad_malformed\.yaml:[67]:' 'invalid YAML' -- run_$b "$S/bad_malformed.yaml"
  case_ "$b: wrong type" 'bad_wrong_type\.yaml:4:' 'scenario\.drones' 'many' -- run_$b "$S/bad_wrong_type.yaml"
  case_ "$b: unknown section" 'bad_unknown_section\.yaml:5:' 'physics' 'unknown section' -- run_$b "$S/bad_unknown_section.yaml"
  case_ "$b: duplicate key" 'bad_duplicate_key\.yaml:[56]:' 'scenario\.drones' -- run_$b "$S/bad_duplicate_key.yaml"
  case_ "$b: a directory, not a file" 'tests/scenarios' -- run_$b "$S"
  case_ "$b: recursive alias" 'bad_recursive_alias\.yaml:[0-9]+:' -- run_$b "$S/bad_recursive_alias.yaml"
  case_ "$b: missing QoS profiles file" 'profiles_file' '/nonexistent/ddswarm_profiles\.xml' -- run_$b "$S/bad_profiles_file.yaml"
done

# Sections only the server reads (agents get the scene from the server over DDS).
case_ "sim: negative radius" 'bad_negative_radius\.yaml:8:' 'scene\.cylinders\[1\]\.radius_m' '-2\.5' -- run_sim "$S/bad_negative_radius.yaml"
case_ "sim: missing mesh file" 'bad_mesh_file\.yaml:8:' 'scene\.meshes\[1\]\.file' 'no_such_bridge\.stl' 'no such file' -- run_sim "$S/bad_mesh_file.yaml"
case_ "sim: rate does not divide" 'bad_rate\.yaml:7:' 'sim\.control_rate_hz' '\b70\b' -- run_sim "$S/bad_rate.yaml"
case_ "sim: negative sensor range" 'bad_sensor_range\.yaml:7:' 'sensors\.max_range_m' '-6' -- run_sim "$S/bad_sensor_range.yaml"
case_ "sim: sensor range beyond the world" 'bad_sensor_beyond_world\.yaml:10:' 'sensors\.max_range_m' '\b600\b' "world's size" -- \
  run_sim "$S/bad_sensor_beyond_world.yaml"
# A file that is fine alone, made invalid by a command-line option: the error names the file too.
case_ "sim: --drones beyond the limit" 'thesis_course\.yaml: ' 'scenario\.drones = 2000' '\[1, 1024\]' -- \
  bounded "$BIN/ddswarm-sim" --scenario "$SRC/config/thesis_course.yaml" --drones 2000 --domain "$DOMAIN" --duration 1

# The agent's own section and its drone id.
case_ "agent: wrong type" 'bad_agent_wrong_type\.yaml:6:' 'agent\.inter_distance_m' 'far' -- run_agent "$S/bad_agent_wrong_type.yaml"
case_ "agent: --id 99 out of range" 'thesis_course\.yaml' '--id' '\b99\b' -- \
  bounded "$BIN/ddswarm-agent" --id 99 --config "$SRC/config/thesis_course.yaml" --domain "$DOMAIN" --duration 1

# The ground station's own section.
case_ "gs: unknown key" 'bad_gs_unknown_key\.yaml:6:' 'ground_station\.ack_timeout' 'unknown key' -- run_gs "$S/bad_gs_unknown_key.yaml"

# Bad command-line usage: exit 2 (CLI11 adds a "Run with --help" line, so only the code and the culprit are checked).
timeout 15 "$BIN/ddswarm-gs" --domain "$DOMAIN" move --north abc --time 1 >"$WORK/cli.out" 2>"$WORK/cli.err" </dev/null
rc=$?
echo "gs move --north abc --time 1: exit $rc, stderr: $(tr '\n' '|' <"$WORK/cli.err")"
if [ $rc -ne 2 ] || ! grep -q -- '--north' "$WORK/cli.err" || ! grep -q 'abc' "$WORK/cli.err"; then
  failures+=("gs: bad CLI usage: exit $rc, expected 2 with a message naming --north and abc")
fi

if [ ${#failures[@]} -gt 0 ]; then
  echo "${#failures[@]} case(s) misbehaved:"
  printf '  %s\n' "${failures[@]}"
  fail "broken configuration was not refused cleanly"
fi
echo PASS
