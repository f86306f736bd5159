#!/usr/bin/env bash
# Issue 8: dds.best_effort_streams (on by default) lets the swarm's own readers
# of the per-tick streams, the server's of the commands and each agent's of
# the swarm state, read them best-effort in real time. Writers stay reliable.
# 1. Six agent processes fly with it in real time: every command is
#    acknowledged, every drone gets airborne, and a recorder, whose reader is
#    reliable, records the swarm state without a gap in its ticks.
# 2. In lockstep the same setting leaves both streams reliable: the agents say
#    so, and the swarm flies.
# 3. --best-effort-streams=false reaches every child of the launcher.
source "$(dirname "$0")/lib.sh"
launch() {  # launch NAME ARGS...: a bounded launch of the thesis course; its output in $WORK/NAME.log
  local name="$1"; shift
  timeout 120 "$BIN/ddswarm-launch" "$SRC/config/thesis_course.yaml" --domain "$DOMAIN" \
    --log-dir "$WORK/$name" "$@" >"$WORK/$name.log" 2>&1
  local rc=$?
  cat "$WORK/$name.log"
  [ $rc -eq 0 ] || { tail -n 20 "$WORK/$name"/*.log; fail "$name: launch exited $rc"; }
}
agents_say() {  # agents_say RUN TEXT: every one of the six agents logged TEXT
  local n; n=$(grep -l -- "$2" "$WORK/$1"/agent_*.log 2>/dev/null | wc -l)
  [ "$n" -eq 6 ] || fail "$1: $n of 6 agents logged '$2'"
}

# 1. Real time, the default.
start rec "$BIN/ddswarm-record" -o "$WORK/rt.mcap" --domain "$DOMAIN" --topics ddswarm/swarm_state
launch rt --mode realtime --gs "takeoff --wait; hold --time 3 --wait; status --drones; land --wait"
kill -INT "$PID_rec"; wait_pid "$PID_rec" 15 || fail "the recorder did not finish on SIGINT"
grep -q "takeoff 6/6 acknowledged" "$WORK/rt.log" || fail "not every drone acknowledged the take-off"
grep -q "| 6 airborne |" "$WORK/rt.log" || fail "not all 6 drones were airborne"
agents_say rt "reading the swarm state best-effort (real time)"
"$BIN/record_check" "$WORK/rt.mcap" >"$WORK/rt.check" 2>&1; rc=$?
cat "$WORK/rt.check"
[ $rc -eq 0 ] || fail "the reliable recorder missed swarm states (record_check exit $rc)"
n=$(awk '$1 == "ddswarm/swarm_state" { print $2 }' "$WORK/rt.check")
[ "${n:-0}" -gt 200 ] || fail "the recorder holds only ${n:-0} swarm states"

# 2. Lockstep, the same default: reliable.
launch ls --mode lockstep --gs "takeoff --wait; hold --time 2 --wait; status --drones"
grep -q "| 6 airborne |" "$WORK/ls.log" || fail "lockstep: not all 6 drones were airborne"
agents_say ls "reading the swarm state reliably"

# 3. Turned off from the launcher's command line.
launch off --mode realtime --best-effort-streams=false --gs "takeoff --wait"
agents_say off "reading the swarm state reliably"
echo PASS
