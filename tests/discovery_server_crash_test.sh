#!/usr/bin/env bash
# Issue 8: the launcher's discovery server crashed once under a 128-process
# bring-up (Fast DDS 2.9.1's fast-discovery-server aborts on an assertion in
# its statistics module; docs/faults.md). The launcher starts it again on the
# same port, whatever --on-death says, and the swarm does not notice:
#   1. aborted as the swarm joins, the lockstep task still completes;
#   2. aborted in flight, no drone loses its agent, and a ground station that
#      joins afterwards finds the server and lands the swarm.
source "$(dirname "$0")/lib.sh"
scenario="$SRC/config/thesis_course.yaml"

ds_address() { # LOG: the address the launcher announced
  for _ in $(seq 100); do grep -q "discovery server on" "$1" && break; sleep 0.05; done
  sed -n 's/.*discovery server on \([0-9.:]*\) .*/\1/p' "$1"
}
ds_pid() { pgrep -f -- "fast-discovery-server -i 0 -l 127.0.0.1 -p ${1#*:} " || true; }

# 1. At bring-up.
start launch1 "$BIN/ddswarm-launch" "$scenario" --domain "$DOMAIN" --drones 6 --mode lockstep \
  --discovery-server on --log-dir "$WORK/logs1" --gs "takeoff --wait; task"
addr=$(ds_address "$WORK/launch1.log")
[ -n "$addr" ] || fail "the launcher did not start a discovery server"
first=$(ds_pid "$addr")
[ -n "$first" ] || fail "no discovery server process on $addr"
sleep 0.5
kill -ABRT "$first"
wait_pid "$PID_launch1" "$(slow 120)"; rc=$?
[ $rc -eq 0 ] || fail "launcher exit $rc after its discovery server was aborted at bring-up"
grep -q "discovery-server (pid $first) was killed by SIGABRT" "$WORK/launch1.log" || fail "the abort was not reported"
grep -q "restarting discovery-server (1 of 3)" "$WORK/launch1.log" || fail "the discovery server was not started again"
grep -q "task complete" "$WORK/launch1.log" || fail "the task did not complete"
grep -q "a process died" "$WORK/launch1.log" && fail "the launcher counted the discovery server's abort as a death"
[ -z "$(ds_pid "$addr")" ] || fail "the restarted discovery server outlived the launcher"

# 2. In flight, real time.
start launch2 "$BIN/ddswarm-launch" "$scenario" --domain "$DOMAIN" --drones 6 --mode realtime \
  --discovery-server on --log-dir "$WORK/logs2" --duration 150
addr=$(ds_address "$WORK/launch2.log")
[ -n "$addr" ] || fail "the launcher did not start a discovery server"
gs_ds() { timeout "$(slow 100)" "$BIN/ddswarm-gs" --config "$WORK/gs.yaml" --domain "$DOMAIN" --discovery-server "$addr" "$@"; }
sed 's/^  ack_timeout_s: 5.0$/&\n  discovery_timeout_s: 90/' "$scenario" >"$WORK/gs.yaml"
grep -q "discovery_timeout_s: 90" "$WORK/gs.yaml" || fail "could not write the ground station's scenario"
gs_ds wait-agents --count 6 --timeout 60 >"$WORK/gs_wait.log" 2>&1 || fail "agents not online"
gs_ds takeoff --wait >"$WORK/gs_takeoff.log" 2>&1 || fail "the swarm did not take off"
first=$(ds_pid "$addr")
kill -ABRT "$first"
for _ in $(seq 50); do [ -n "$(ds_pid "$addr")" ] && [ "$(ds_pid "$addr")" != "$first" ] && break; sleep 0.1; done
second=$(ds_pid "$addr")
[ -n "$second" ] && [ "$second" != "$first" ] || fail "no new discovery server on $addr after the abort"
# A ground station that joins now: it may join again by itself (20 s) while the
# new server learns the swarm from the participants' announcements.
gs_ds land --wait >"$WORK/gs_land.log" 2>&1 || fail "a ground station joining after the restart could not land the swarm"
grep -q "land 6/6 acknowledged" "$WORK/gs_land.log" || fail "not every drone acknowledged the landing"
kill -0 "$PID_launch2" 2>/dev/null || fail "the launcher stopped when its discovery server was aborted"
grep -h "agent lost\|no fresh command" "$WORK"/logs2/sim.log && fail "a drone lost its agent while the discovery server restarted"
kill -INT "$PID_launch2"
wait_pid "$PID_launch2" 20; rc=$?
[ $rc -eq 0 ] || fail "launcher exit $rc after SIGINT"
[ -z "$(ds_pid "$addr")" ] || fail "the restarted discovery server outlived the launcher"
echo PASS
