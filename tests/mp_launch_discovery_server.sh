#!/usr/bin/env bash
# Issue 8: the launcher runs a Fast DDS discovery server for the swarm. Forced
# on for six drones, every child is pointed at it, the lockstep task
# completes, and the server process is gone when the launcher is; with auto,
# six drones stay on simple discovery.
source "$(dirname "$0")/lib.sh"
scenario="$SRC/config/thesis_course.yaml"

start launch "$BIN/ddswarm-launch" "$scenario" --domain "$DOMAIN" --drones 6 --mode lockstep \
  --discovery-server on --log-dir "$WORK/logs" --gs "takeoff --wait; task"
# The server is up and every agent was told where it is.
for _ in $(seq 100); do grep -q "discovery server on" "$WORK/launch.log" && break; sleep 0.1; done
addr=$(sed -n 's/.*discovery server on \([0-9.:]*\) .*/\1/p' "$WORK/launch.log")
[ -n "$addr" ] || fail "the launcher did not start a discovery server"
ds_pid=$(pgrep -f -- "fast-discovery-server -i 0 -l 127.0.0.1 -p ${addr#*:} ")
[ -n "$ds_pid" ] || fail "no fast-discovery-server process on $addr"
for _ in $(seq 100); do
  [ "$(pgrep -f -- "ddswarm-agent .*--domain $DOMAIN" | wc -l)" -ge 6 ] && break; sleep 0.1
done
clients=$(pgrep -f -- "ddswarm-agent .*--discovery-server $addr" | wc -l)
[ "$clients" -eq 6 ] || fail "$clients of 6 agents use the discovery server $addr"
# It listens on loopback only (config/discovery_server.xml).
if command -v ss >/dev/null; then
  bad=$(ss -uanp 2>/dev/null | grep "pid=$ds_pid," | awk '{ print $4 }' | grep -v '^127\.0\.0\.1:' || true)
  [ -z "$bad" ] || fail "discovery server bound to non-loopback addresses: $bad"
fi
wait_pid "$PID_launch" 150; rc=$?
[ $rc -eq 0 ] || fail "launcher exit $rc"
grep -q "task complete" "$WORK/launch.log" || fail "the task did not complete"
grep -q "at shutdown" "$WORK/launch.log" && fail "a process (maybe the server) did not stop cleanly"
kill -0 "$ds_pid" 2>/dev/null && fail "discovery server (pid $ds_pid) still running after the launcher"

# auto: six drones do not need one.
start launch2 "$BIN/ddswarm-launch" "$scenario" --domain "$DOMAIN" --drones 6 --mode lockstep \
  --discovery-server auto --log-dir "$WORK/logs2" --gs "takeoff --wait"
wait_pid "$PID_launch2" 90; rc=$?
[ $rc -eq 0 ] || fail "launcher (auto) exit $rc"
grep -q "discovery server on" "$WORK/launch2.log" && fail "auto started a discovery server for 6 drones"
echo PASS
