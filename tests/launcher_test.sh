#!/usr/bin/env bash
# Issue 4: the launcher prefixes logs, says which process died and why,
# applies its policy, and leaves no child behind on a death or on SIGINT.
source "$(dirname "$0")/lib.sh"
scenario="$SRC/config/thesis_course.yaml"
children() { pgrep -f -- "--domain $DOMAIN" | grep -v "^$1\$" || true; }

# 1. Policy "stop": SIGKILL one agent; the launcher names it and stops everything.
start launch1 "$BIN/ddswarm-launch" "$scenario" --domain "$DOMAIN" --drones 3 --on-death stop
sleep 4
grep -q "^\[agent 1\] " "$WORK/launch1.log" || fail "agent logs are not prefixed"
victim=$(pgrep -f -- "ddswarm-agent --id 1 .*--domain $DOMAIN")
[ -n "$victim" ] || fail "agent 1 not running"
kill -KILL "$victim"
wait_pid "$PID_launch1" 15; rc=$?
[ $rc -eq 1 ] || fail "launcher exit $rc after a death under policy stop, expected 1"
grep -q "agent 1 (pid $victim) was killed by SIGKILL" "$WORK/launch1.log" || fail "death not reported"
sleep 0.5
[ -z "$(children x)" ] || fail "children left behind: $(children x)"

# 2. Policy "keep": the rest keep flying; SIGINT then stops everything, exit 0.
start launch2 "$BIN/ddswarm-launch" "$scenario" --domain "$DOMAIN" --drones 3 --on-death keep
sleep 4
kill -KILL "$(pgrep -f -- "ddswarm-agent --id 2 .*--domain $DOMAIN")"
sleep 1.5
kill -0 "$PID_launch2" 2>/dev/null || fail "launcher stopped under policy keep"
grep -q "agent 2 (pid [0-9]*) was killed by SIGKILL" "$WORK/launch2.log" || fail "death not reported under keep"
[ "$(pgrep -f -- "ddswarm-agent --id 0 .*--domain $DOMAIN" | wc -l)" -eq 1 ] || fail "agent 0 should still fly"
kill -INT "$PID_launch2"
wait_pid "$PID_launch2" 15; rc=$?
[ $rc -eq 0 ] || fail "launcher exit $rc after SIGINT, expected 0"
sleep 0.5
[ -z "$(children x)" ] || fail "children left behind after SIGINT: $(children x)"
grep -q "all processes stopped" "$WORK/launch2.log" || fail "no shutdown report"
# Every survivor exited cleanly (code 0) on SIGTERM.
grep "at shutdown" "$WORK/launch2.log" && fail "a process did not shut down cleanly"
echo PASS
