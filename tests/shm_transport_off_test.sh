#!/usr/bin/env bash
# Issue 8: dds.shm_transport: false. Every process leaves out Fast DDS's
# shared-memory transport, so no RTPS port of the domain is a file in
# /dev/shm, while the swarm state still comes by data-sharing (the readers'
# segments are there); velocity commands go over UDP on 127.0.0.1, and a
# six-drone real-time swarm takes off, holds without missing commands and
# lands.
source "$(dirname "$0")/lib.sh"
scenario="$SRC/config/thesis_course.yaml"
gs() { timeout 60 "$BIN/ddswarm-gs" --config "$scenario" --domain "$DOMAIN" "$@"; }
start launch "$BIN/ddswarm-launch" "$scenario" --mode realtime --domain "$DOMAIN" \
  --set dds.shm_transport=false --log-dir "$WORK"
gs wait-agents --count 6 --timeout 60 || fail "agents not online"
gs takeoff --wait || fail "takeoff"
# What each process maps from /dev/shm: the transport's segments and ports
# are fastrtps_*, data-sharing's pools and reader segments fast_datasharing_*.
procs=$(pgrep -P "$PID_launch" -f "ddswarm-(sim|agent) ") || fail "no server or agent under the launcher"
[ "$(echo "$procs" | wc -w)" -eq 7 ] || fail "expected the server and 6 agents under the launcher: $procs"
for p in $procs; do
  transport=$(grep -c "/dev/shm/fastrtps_" "/proc/$p/maps")
  shared=$(grep -c "/dev/shm/fast_datasharing_" "/proc/$p/maps")
  [ "$transport" -eq 0 ] || fail "pid $p maps $transport shared-memory transport regions"
  [ "$shared" -ge 1 ] || fail "pid $p maps no data-sharing segment: the swarm state should come by data-sharing"
done
timeout 60 "$BIN/swarm_probe" --drones 6 --settle 1 --time 5 --ages --domain "$DOMAIN" >"$WORK/probe.out" 2>&1
cat "$WORK/probe.out"
line=$(grep "^probe ok=1" "$WORK/probe.out") || fail "the probe did not measure the swarm"
val() { echo "$line" | tr ' ' '\n' | sed -n "s/^$1=//p"; }
echo "rtf $(val rtf), command age p99 $(val age_p99_periods) periods, missed $(val missed);" \
  "7 processes, each with data-sharing and without the shared-memory transport"
[ "$(val age_p99_periods)" -le 2 ] || fail "command age p99 $(val age_p99_periods) periods"
echo "$(val rtf) >= 0.9" | bc -l | grep -q 1 || fail "real-time factor $(val rtf)"
awk -v m="$(val missed_frac)" 'BEGIN { exit !(m < 0.01) }' || fail "missed $(val missed_frac) of commands"
gs land --wait || fail "land"
echo PASS
