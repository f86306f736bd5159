#!/usr/bin/env bash
# An agent's shared-memory outbox is sized for the drones it flies.
# Fast DDS makes each process's transport segment resident in /dev/shm as it
# starts; at 4 MiB for every process, 128 agents would hold 540 MB. So the server
# keeps 4 MiB, an agent of one drone 272 KiB and an agent host 16 KiB more per
# drone, and a six-drone real-time swarm still flies without missing commands.
source "$(dirname "$0")/lib.sh"

# own_segment PID: the bytes of the transport segment whose lock PID holds
# (Fast DDS flocks fastrtps_<id>_el for its own segment fastrtps_<id>).
own_segment() {
  local el ino
  for el in /dev/shm/fastrtps_[0-9a-f]*_el; do
    [ -e "$el" ] || continue
    ino=$(stat -c %i "$el" 2>/dev/null) || continue
    if awk -v p="$1" -v i="$ino" '$5 == p && $6 ~ (":" i "$") { f = 1 } END { exit !f }' \
      /proc/locks; then
      stat -c %s "${el%_el}"
      return 0
    fi
  done
  return 1
}
kib() { echo $(( $1 / 1024 )); }
# Fast DDS adds about 25 KB of its own to the size asked for, and about 48
# bytes for each buffer the outbox may hold in flight, which is as many as
# the process's port holds: 8,192 for the server (384 KiB), 512 for an agent
# of up to 32 drones (24 KiB; common/dds_config.hpp).
within() { [ "$1" -ge "$2" ] && [ "$1" -le $(( $2 + 64 * 1024 )) ]; }

fly_six_realtime
sim=$(pgrep -P "$PID_launch" -x ddswarm-sim) || fail "no server under the launcher"
agents=$(pgrep -P "$PID_launch" -x ddswarm-agent) || fail "no agents under the launcher"
[ "$(echo "$agents" | wc -w)" -eq 6 ] || fail "expected 6 agent processes: $agents"
size=$(own_segment "$sim") || fail "the server (pid $sim) holds no shared-memory segment"
within "$size" $(( (4096 + 352) * 1024 )) ||
  fail "the server's segment is $(kib "$size") KiB, expected 4 MiB and its table of 8,192 buffers"
total=$size
for p in $agents; do
  size=$(own_segment "$p") || fail "agent pid $p holds no shared-memory segment"
  within "$size" $(( 272 * 1024 )) ||
    fail "agent pid $p's segment is $(kib "$size") KiB, expected 272 KiB"
  total=$(( total + size ))
done
probe_swarm 6
echo "the server and 6 agents hold $(( total / 1024 )) KiB of transport segments (7 x 4 MiB before);" \
  "rtf $(probe_val rtf), command age p99 $(probe_val age_p99_periods) periods, missed $(probe_val missed)"
commands_fresh
gs land --wait || fail "land"

# An agent host of six drones asks for 256 + 6 x 16 KiB as it starts.
start host "$BIN/ddswarm-agent" --ids 0-5 --config "$scenario" --domain $(( DOMAIN + 1 ))
for _ in $(seq 100); do size=$(own_segment "$PID_host") && break; sleep 0.1; done
[ -n "${size:-}" ] || fail "the agent host holds no shared-memory segment after 10 s"
within "$size" $(( 352 * 1024 )) ||
  fail "the agent host's segment is $(kib "$size") KiB, expected 352 KiB"
echo "an agent host of 6 drones holds $(kib "$size") KiB"
echo PASS
