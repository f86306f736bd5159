#!/usr/bin/env bash
# Scale under DDS Security: a secure swarm of 24 drones, one agent
# process each, comes online and takes off. Agents announce themselves to the
# server's and tools' participant ids only, so they never authenticate with
# one another; otherwise those handshakes and key exchanges (N² of them) keep
# a 24-drone secure swarm from ever coming up: the server hears 2 of the 24
# agents after 90 s (docs/security.md). Also on one host:
#  - a second secure agent for a flying drone is refused, since that drone's
#    participant id is taken;
#  - a discovery server, which Fast DDS 2.9 cannot secure, is refused in one
#    line (it would abort the swarm's processes otherwise).
# Its domain (lib.sh's pool) puts the agents' ports below the kernel's
# ephemeral range, where only a participant binds them, so the duplicate is
# told for sure.
source "$(dirname "$0")/lib.sh"
N=24
secure_swarm_setup $N

out=$("$BIN/ddswarm-launch" "$scenario" --drones $N --domain "$DOMAIN" --secure "$C" \
  --discovery-server on 2>&1); rc=$?
echo "$out"
[ $rc -eq 2 ] && [ "$(echo "$out" | wc -l)" -eq 1 ] && echo "$out" | grep -q -- "--discovery-server" ||
  fail "a discovery server under --secure was not refused in one line with exit 2 (exit $rc)"

t0=$SECONDS
start launch "$BIN/ddswarm-launch" "$scenario" --drones $N --domain "$DOMAIN" --secure "$C" \
  --log-dir "$WORK/launch"
timeout $(slow 100) "$BIN/ddswarm-gs" --config "$scenario" --domain "$DOMAIN" --secure "$C" \
  wait-agents --count $N --timeout $(slow 90) || fail "the $N secure agents did not come online"
echo "all $N secure agents online $((SECONDS - t0)) s after the launch"
gs takeoff --wait || fail "the secure swarm did not take off"

out=$(timeout 30 "$BIN/ddswarm-agent" --id 5 --config "$scenario" --drones $N --domain "$DOMAIN" \
  --secure "$C" --duration 5 2>&1); rc=$?
echo "$out" | tail -2
[ $rc -eq 3 ] && echo "$out" | grep -q "drone 5 is already flown on this host" ||
  fail "a second secure agent for drone 5 was not refused (exit $rc)"
gs status | head -3
echo PASS
