#!/usr/bin/env bash
# dds.best_effort_streams (on by default) lets the swarm's own readers
# of the per-tick streams, the server's of the commands and each agent's of
# the swarm state, read them best-effort, in both time modes. Writers stay
# reliable.
# 1. Six agent processes fly with it in real time: every command is
#    acknowledged, every drone gets airborne, and a recorder, whose reader is
#    reliable, records the swarm state without a gap in its ticks.
# 2. Lockstep reads best-effort too, and a lost sample costs time, never the
#    result: the thesis task flown with every agent dropping 1 % of the swarm
#    states (agent.state_loss) ends exactly as without, the server publishing
#    the waiting ticks again (sim.lockstep_resend_s) and counting them.
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
agents_say rt "reading the swarm state best-effort"
"$BIN/record_check" "$WORK/rt.mcap" >"$WORK/rt.check" 2>&1; rc=$?
cat "$WORK/rt.check"
[ $rc -eq 0 ] || fail "the reliable recorder missed swarm states (record_check exit $rc)"
n=$(awk '$1 == "ddswarm/swarm_state" { print $2 }' "$WORK/rt.check")
[ "${n:-0}" -gt 200 ] || fail "the recorder holds only ${n:-0} swarm states"

# 2. Lockstep, the same default: best-effort; without loss, then with it.
task_result() {  # task_result RUN: the task's result line, wall time left out
  grep "task complete:" "$WORK/$1.log" | sed 's/ (wall [^)]*)//' >"$WORK/$1.result"
  [ -s "$WORK/$1.result" ] || fail "$1: no task result line"
}
launch ls --mode lockstep --gs "takeoff --wait; task; status"
agents_say ls "reading the swarm state best-effort"
task_result ls
launch lossy --mode lockstep --set agent.state_loss=0.01 --set sim.lockstep_resend_s=0.02 --gs "takeoff --wait; task; status"
agents_say lossy "dropping 1.0 % of swarm states"
task_result lossy
[ "$(cat "$WORK/ls.result")" = "$(cat "$WORK/lossy.result")" ] ||
  fail "lost samples changed the lockstep result: '$(cat "$WORK/ls.result")' vs '$(cat "$WORK/lossy.result")'"
resent=$(sed -n 's/.*; \([0-9]*\) ticks published again.*/\1/p' "$WORK/lossy.log" | tail -1)
[ "${resent:-0}" -gt 0 ] || fail "the server counted no tick published again"
if grep -q "ticks published again" "$WORK/ls.log"; then echo "(the lossless run published some ticks again too)"; fi
echo "lockstep with 1 % of swarm states lost: the same result, $resent ticks published again: $(cat "$WORK/ls.result")"

# 3. Turned off from the launcher's command line.
launch off --mode realtime --best-effort-streams=false --gs "takeoff --wait"
agents_say off "reading the swarm state reliably"
echo PASS
