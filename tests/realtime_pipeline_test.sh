#!/usr/bin/env bash
# Issue 8: pipelined real time (sim.realtime_pipeline). Each state goes out on
# its period's edge and the world steps after it, so an agent has a whole
# period plus the grace to answer, and every command acts one period later:
# the probe reads a command age of 2 periods (plain real time: 1) and no
# missed command in a six-drone swarm that takes off and holds.
source "$(dirname "$0")/lib.sh"
scenario="$SRC/config/thesis_course.yaml"
gs() { timeout 60 "$BIN/ddswarm-gs" --config "$scenario" --domain "$DOMAIN" "$@"; }
start launch "$BIN/ddswarm-launch" "$scenario" --mode realtime --domain "$DOMAIN" \
  --set sim.realtime_pipeline=true --log-dir "$WORK"
gs wait-agents --count 6 --timeout 60 || fail "agents not online"
gs takeoff --wait || fail "takeoff"
grep -q "realtime mode (pipelined" "$WORK/sim.log" || fail "the server did not run pipelined"
timeout 60 "$BIN/swarm_probe" --drones 6 --settle 1 --time 5 --ages --domain "$DOMAIN" >"$WORK/probe.out" 2>&1
cat "$WORK/probe.out"
line=$(grep "^probe ok=1" "$WORK/probe.out") || fail "the probe did not measure the swarm"
val() { echo "$line" | tr ' ' '\n' | sed -n "s/^$1=//p"; }
echo "rtf $(val rtf), command age p50 $(val age_p50_periods) / max $(val age_max_periods) periods, missed $(val missed)"
[ "$(val age_p50_periods)" = 2 ] || fail "commands should act one period later than in plain real time (age 2 periods)"
[ "$(val age_max_periods)" -le 3 ] || fail "a command aged $(val age_max_periods) periods"
echo "$(val rtf) >= 0.9" | bc -l | grep -q 1 || fail "real-time factor $(val rtf)"
awk -v m="$(val missed_frac)" 'BEGIN { exit !(m < 0.01) }' || fail "missed $(val missed_frac) of commands"
gs land --wait || fail "land"
echo PASS
