#!/usr/bin/env bash
# The server's shared-memory port files are removed while it still listens on
# them, as Fast DDS 2.9 once left them after a stall (a sender made a port
# anew, a second found it a "Zombie" and removed it: docs/dds.md). The agents
# that are flying keep the ports they mapped; an agent that joins again as a
# new participant reaches only files nobody reads. It must notice that the
# server does not hear it (the server's scene writer matched, no scene), join
# again without the shared-memory transport, and fly its drone again; and a
# newcomer must not take the server's participant id for a free one.
source "$(dirname "$0")/lib.sh"
fly_six_realtime
sim=$(pgrep -f -- "ddswarm-sim .*--domain $DOMAIN\b") || fail "no server process"
# The server's own ports: those whose "_el" lock it holds open.
own=$(ls -l /proc/"$sim"/fd | grep -o "fastrtps_port[0-9]*_el" | sed 's/_el$//' | sort -u)
[ "$(echo "$own" | wc -w)" -eq 2 ] || fail "expected the server's 2 unicast ports, found: $own"
for p in $own; do rm -f "/dev/shm/$p"; done
agent=$(pgrep -f -- "ddswarm-agent --id 2 .*--domain $DOMAIN\b") || fail "no agent 2 process"
kill -USR1 "$agent"  # join again as a new participant
# Drone 2 is flown again once the server has heard the participant the agent
# made last (after it left the shared-memory transport), not merely while its
# row still shows the old participant's flight.
left_shm() { grep -q "joining again without the shared-memory transport" "$WORK/agent_2.log"; }
flown_again() {
  left_shm || return 1
  last=$(grep -o "agent [0-9a-f]\{16\} flying" "$WORK/agent_2.log" | tail -1 | awk '{print $2}')
  grep -q "drone 2: agent $last online" "$WORK/sim.log" || return 1
  status=$(gs status --drones 2>/dev/null)
  echo "$status" | awk '$1 == "2" && /airborne/ && !/failsafe/ && !/no-agent/ { found = 1 } END { exit !found }'
}
ok=0
for _ in $(seq 120); do flown_again && { ok=1; break; }; sleep 0.5; done
echo "${status:-no status read}"
grep -h "does not hear\|without the shared-memory\|init_port" "$WORK"/agent_2.log || true
left_shm || fail "agent 2 never left the shared-memory transport: the test did not take the path it tests"
[ $ok -eq 1 ] || { shm_ports "$sim" "$agent"; fail "drone 2 was not flown again by the agent's last participant (${last:-none})"; }
# The newcomer did not take the server's participant id for a free one (its
# port files were gone): Fast DDS then cannot lock those ports and says so.
! grep -q "Failed init_port" "$WORK/agent_2.log" || fail "agent 2's new participant took the server's participant id"
# Every drone flies on; the swarm still lands on command.
[ "$(echo "$status" | awk '$1 ~ /^[0-5]$/ && /airborne/ && !/failsafe/' | wc -l)" -eq 6 ] || fail "not all six drones airborne"
gs land --wait || fail "land"
echo PASS
