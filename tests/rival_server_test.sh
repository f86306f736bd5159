#!/usr/bin/env bash
# Two servers on one domain, on hosts whose clocks differ: the scenes'
# timestamps alone would pick the wrong one to leave. A server whose swarm
# has a mission stays, even against a scene stamped an hour before its own;
# a server with no mission leaves for one whose status shows a mission, even
# when that one's scene is stamped an hour after its own.
source "$(dirname "$0")/lib.sh"
config="$SRC/config/thesis_course.yaml"
# 1. A server with a mission (one agent's take-off) and a rival whose clock
#    is an hour behind: the rival's scene looks the older one.
start sim "$BIN/ddswarm-sim" --scenario "$config" --domain "$DOMAIN" --duration 40
start agent0 "$BIN/ddswarm-agent" --id 0 --config "$config" --domain "$DOMAIN" --duration 40
timeout 30 "$BIN/ddswarm-gs" --config "$config" --domain "$DOMAIN" wait-agents --count 1 --timeout 25 ||
  fail "agent 0 not online"
timeout 20 "$BIN/ddswarm-gs" --config "$config" --domain "$DOMAIN" takeoff >"$WORK/takeoff.log" 2>&1
grep -q "mission seq .* takeoff released" "$WORK/sim.log" || fail "the server did not take the take-off"
start rival1 "$BIN/rival_server" --domain "$DOMAIN" --clock-offset -3600 --duration 4
wait_pid "$PID_rival1" 20 || fail "the first rival did not run"
sleep 1
kill -0 "$PID_sim" 2>/dev/null || fail "the server with a mission left for a newcomer whose clock is behind"
grep -q "another server (instance [0-9a-f]*) is on DDS domain $DOMAIN.*this one stays: its swarm has a mission" \
  "$WORK/sim.log" || fail "the server did not say why it stays"
echo "1: the server with a mission stayed: $(grep -o 'this one stays: [a-z ]*' "$WORK/sim.log" | head -1)"
kill -INT "$PID_sim" "$PID_agent0"; wait_pid "$PID_sim" 10 >/dev/null; wait_pid "$PID_agent0" 10 >/dev/null

# 2. A server without a mission, and a rival with one whose clock is an hour
#    ahead: its scene looks the newer one, its status shows the mission.
start sim2 "$BIN/ddswarm-sim" --scenario "$config" --domain "$DOMAIN" --duration 40
sleep 2
start rival2 "$BIN/rival_server" --domain "$DOMAIN" --clock-offset 3600 --mission --duration 10
wait_pid "$PID_sim2" 15; rc=$?
echo "2: the server without a mission exited with $rc: $(grep 'error:' "$WORK/sim2.log")"
[ $rc -eq 3 ] || fail "the server without a mission did not leave (exit $rc, expected 3)"
grep -q "error: another server (instance [0-9a-f]*) is already on DDS domain $DOMAIN" "$WORK/sim2.log" ||
  fail "the server did not say why it left"
echo PASS
