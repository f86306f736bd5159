#!/usr/bin/env bash
# dds.shm_transport: false. Every process leaves out Fast DDS's
# shared-memory transport, so no RTPS port of the domain is a file in
# /dev/shm, while the swarm state still comes by data-sharing (the readers'
# segments are there); velocity commands go over UDP on 127.0.0.1, and a
# six-drone real-time swarm takes off, holds without missing commands and
# lands.
source "$(dirname "$0")/lib.sh"
fly_six_realtime --set dds.shm_transport=false
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
probe_swarm 6
echo "rtf $(probe_val rtf), command age p99 $(probe_val age_p99_periods) periods, missed $(probe_val missed);" \
  "7 processes, each with data-sharing and without the shared-memory transport"
commands_fresh
gs land --wait || fail "land"
echo PASS
