#!/usr/bin/env bash
# The launcher prefixes logs, says which process died and why,
# applies its policy (stop, keep, restart), and leaves no child behind on a
# death or on SIGINT.
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

# 3. Policy "restart": an agent killed by a signal is started again with its
#    log kept, and its drone has an agent again; the launcher keeps running.
start launch3 "$BIN/ddswarm-launch" "$scenario" --domain "$DOMAIN" --drones 3 --on-death restart \
  --log-dir "$WORK/l3"
online() { cat "$WORK/l3/sim.log" 2>/dev/null | grep -c "drone 1: agent [0-9a-f]* online"; }
for _ in $(seq 150); do [ "$(online)" -ge 1 ] && break; sleep 0.1; done
[ "$(online)" -ge 1 ] || fail "agent 1 never came online"
victim=$(pgrep -f -- "ddswarm-agent --id 1 .*--domain $DOMAIN")
kill -KILL "$victim"
for _ in $(seq 200); do [ "$(online)" -ge 2 ] && break; sleep 0.1; done
grep -q "agent 1 (pid $victim) was killed by SIGKILL" "$WORK/launch3.log" || fail "death not reported under restart"
grep -q "restarting agent 1 (1 of 3)" "$WORK/launch3.log" || fail "agent 1 was not restarted"
[ "$(online)" -ge 2 ] || fail "the restarted agent 1 did not come online at the server"
[ "$(grep -c "flying (pid" "$WORK/l3/agent_1.log")" -eq 2 ] || fail "agent 1's log does not hold both runs"
kill -0 "$PID_launch3" 2>/dev/null || fail "launcher stopped under policy restart"
kill -INT "$PID_launch3"
wait_pid "$PID_launch3" 15; rc=$?
[ $rc -eq 0 ] || fail "launcher exit $rc after SIGINT under policy restart, expected 0"
sleep 0.5
[ -z "$(children x)" ] || fail "children left behind under restart: $(children x)"
echo PASS
