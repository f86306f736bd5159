#!/usr/bin/env bash
# The launcher runs a Fast DDS discovery server for the swarm. Forced
# on for six drones, every child is pointed at it, the lockstep task
# completes, and the server process is gone when the launcher is; with auto,
# six drones stay on simple discovery. A swarm with a discovery server leaves
# out the shared-memory transport (its port opens stalled 128-process
# bring-ups) and keeps data-sharing, unless the scenario names the transport.
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

# transport_maps LAUNCH_PID: "T D" per server and agent under the launcher,
# once each maps a data-sharing segment (its participants are up): T regions
# of the shared-memory transport (fastrtps_*), D of data-sharing.
transport_maps() {
  local procs p
  for _ in $(seq 150); do
    procs=$(pgrep -P "$1" -f "ddswarm-(sim|agent) ")
    if [ "$(echo "$procs" | wc -w)" -eq 4 ]; then
      local ready=1
      for p in $procs; do grep -q "/dev/shm/fast_datasharing_" "/proc/$p/maps" 2>/dev/null || ready=0; done
      if [ $ready -eq 1 ]; then
        for p in $procs; do
          echo "$(grep -c "/dev/shm/fastrtps_" "/proc/$p/maps") $(grep -c "/dev/shm/fast_datasharing_" "/proc/$p/maps")"
        done
        return 0
      fi
    fi
    sleep 0.1
  done
  return 1
}
start launch3 "$BIN/ddswarm-launch" "$scenario" --domain "$DOMAIN" --drones 3 --mode realtime \
  --discovery-server on --duration 30 --log-dir "$WORK/logs3"
maps=$(transport_maps "$PID_launch3") || fail "the server and 3 agents did not all map data-sharing within 15 s"
grep -q "dds.shm_transport: false" "$WORK/launch3.log" || fail "the launcher did not say it left out the transport"
echo "$maps" | awk '$1 != 0 { exit 1 }' || fail "with a discovery server, a process maps the shared-memory transport: $maps"
kill -INT "$PID_launch3"; wait_pid "$PID_launch3" 30 || fail "launcher 3 did not stop"
# Named by the scenario (here by --set), the transport stays.
start launch4 "$BIN/ddswarm-launch" "$scenario" --domain "$DOMAIN" --drones 3 --mode realtime \
  --discovery-server on --duration 30 --log-dir "$WORK/logs4" --set dds.shm_transport=true
maps=$(transport_maps "$PID_launch4") || fail "the server and 3 agents did not all map data-sharing within 15 s (transport named)"
echo "$maps" | awk '$1 == 0 { exit 1 }' || fail "dds.shm_transport=true named, yet a process maps no shared-memory transport: $maps"
kill -INT "$PID_launch4"; wait_pid "$PID_launch4" 30 || fail "launcher 4 did not stop"
echo PASS
