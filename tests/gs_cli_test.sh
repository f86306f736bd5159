#!/usr/bin/env bash
# The ground station's subcommands return 0 when every live agent
# acknowledged, non-zero on a missing ack or no server; the console runs
# from scripted stdin (bad input, EOF) against a real swarm.
source "$(dirname "$0")/lib.sh"
scenario="$SRC/config/thesis_course.yaml"
gs() { timeout 60 "$BIN/ddswarm-gs" --config "$scenario" --domain "$DOMAIN" "$@"; }

# No server: a clear error and exit 1, bounded by the discovery timeout.
out=$(timeout 30 "$BIN/ddswarm-gs" --domain "$DOMAIN" takeoff 2>&1); rc=$?
[ $rc -eq 1 ] || fail "takeoff without a server exited $rc: $out"
echo "$out" | grep -q "no simulation server" || fail "unclear error: $out"
# Bad usage: exit 2.
gs move --north abc --time 3 >/dev/null 2>&1; [ $? -eq 2 ] || fail "bad number not rejected with exit 2"
gs distance -3 >/dev/null 2>&1; [ $? -eq 2 ] || fail "negative distance not rejected with exit 2"

start launch "$BIN/ddswarm-launch" "$SRC/tests/scenarios/slow_liveness.yaml" --domain "$DOMAIN"
gs wait-agents --count 3 --timeout 30 || fail "agents not online"
# wait-agents shows its progress every 10 s; a timeout says so, and whose
# view (the server's): exit 1.
out=$(gs wait-agents --count 4 --timeout 11 2>&1); rc=$?
echo "$out"
[ $rc -eq 1 ] || fail "wait-agents for more agents than fly exited $rc: $out"
echo "$out" | grep -q "waiting for agents: the server hears 3 of 4 after 10 s (of 11 s)" ||
  fail "no progress from wait-agents: $out"
echo "$out" | grep -q "timed out after 11 s: the server hears 3 of the 4 agents asked for" ||
  fail "unclear wait-agents timeout: $out"
out=$(gs takeoff --wait); rc=$?
echo "$out"; [ $rc -eq 0 ] || fail "takeoff exited $rc"
echo "$out" | grep -q "takeoff 3/3 acknowledged" || fail "takeoff not acknowledged by all: $out"
# A rejected command exits 1 and names the reason.
out=$(gs takeoff); rc=$?
echo "$out"; [ $rc -eq 1 ] || fail "takeoff while airborne exited $rc"
echo "$out" | grep -q "already airborne" || fail "rejection reason missing: $out"

# The console, driven by a script: bad input re-prompts, EOF exits cleanly.
printf '3\nabc\n-2\n5\n2\n0.5\nx\n0\n0\n2\n7\n' | gs menu >"$WORK/menu.out" 2>&1; rc=$?
cat "$WORK/menu.out"
[ $rc -eq 0 ] || fail "menu exited $rc on EOF"
grep -q "distance 3/3 acknowledged" "$WORK/menu.out" || fail "menu's distance change not acknowledged"
grep -q "move 3/3 acknowledged" "$WORK/menu.out" || fail "menu's move not acknowledged"

# A frozen agent is still online for a moment but cannot answer: named, exit 1.
frozen=$(pgrep -f -- "ddswarm-agent --id 2 .*--domain $DOMAIN")
kill -STOP "$frozen"
out=$(timeout 60 "$BIN/ddswarm-gs" --config "$SRC/tests/scenarios/slow_liveness.yaml" --domain "$DOMAIN" hold); rc=$?
kill -CONT "$frozen"
echo "$out"
[ $rc -eq 1 ] || fail "hold with a frozen agent exited $rc"
echo "$out" | grep -q "no ack from drones 2" || fail "missing ack not named: $out"
# Status reports the server's command counts (applied; late = answered after their step).
out=$(gs status) || fail "status after the thaw: $out"
echo "$out"
applied=$(echo "$out" | sed -n 's/^commands: \([0-9]*\) applied, [0-9]* late.*/\1/p')
[ -n "$applied" ] && [ "$applied" -gt 0 ] || fail "no command count in status: $out"
out=$(gs land --wait); rc=$?
[ $rc -eq 0 ] || fail "land exited $rc: $out"
echo PASS
