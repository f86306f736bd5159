#!/usr/bin/env bash
# The default DDS set-up never leaves the machine: inside a network namespace
# whose only links are loopback and a veth (IPv6 off, so the kernel adds no
# chatter of its own), a server and a commander fly a drone over localhost
# DDS and the veth transmits nothing. Then the check proves it can fail: a
# server opted in to the veth's address (--dds-interface) does transmit.
# The veth's far end sits in a second namespace, so the host's own network
# is never touched. Needs root and `ip netns`; skips (77) otherwise.
if [ "$(id -u)" -ne 0 ] || ! command -v ip >/dev/null || ! command -v sysctl >/dev/null; then
  echo "SKIP: needs root, ip and sysctl"; exit 77
fi
probe="ddsw-probe-$$"
if ! ip netns add "$probe" 2>/dev/null; then echo "SKIP: cannot create a network namespace"; exit 77; fi
if ! ip -n "$probe" link add "ddswp$$a" type veth peer name "ddswp$$b" 2>/dev/null; then
  ip netns del "$probe"; echo "SKIP: cannot create a veth pair"; exit 77
fi
ip netns del "$probe"  # takes the probe veth with it

# A domain no other test draws (docs/testing.md): shared memory crosses namespaces.
DDSWARM_DOMAIN="${DDSWARM_DOMAIN:-229}"
source "$(dirname "$0")/lib.sh"
# No shared memory for the server: its DDS traffic must be UDP, on loopback only.
scenario="$SRC/tests/scenarios/robust_udp_only.yaml"
NS="ddsw-$$-in"       # where the processes run
NS_OUT="ddsw-$$-out"  # the veth's far end
VIN="ddsw-$$-b"       # inside: 10.213.0.2/24
VOUT="ddsw-$$-a"      # outside: 10.213.0.1/24

stop_all() {  # TERM every started process, KILL stragglers after 5 s
  for pid in "${PIDS[@]:-}"; do [ -n "$pid" ] && kill -TERM "$pid" 2>/dev/null; done
  local deadline=$((SECONDS + 5))
  for pid in "${PIDS[@]:-}"; do
    [ -z "$pid" ] && continue
    while kill -0 "$pid" 2>/dev/null && [ $SECONDS -lt $deadline ]; do sleep 0.1; done
    kill -KILL "$pid" 2>/dev/null
    wait "$pid" 2>/dev/null
  done
  PIDS=()
}
on_exit() {
  local rc=$?
  stop_all
  ip -n "$NS_OUT" link del "$VOUT" 2>/dev/null  # takes its peer with it
  ip -n "$NS" link del "$VIN" 2>/dev/null
  ip netns del "$NS" 2>/dev/null
  ip netns del "$NS_OUT" 2>/dev/null
  if ip netns list | grep -q "ddsw-$$-"; then
    echo "FAIL: namespaces left behind: $(ip netns list | grep "ddsw-$$-" | tr '\n' ' ')"
    rc=1
  elif ip link show "$VOUT" >/dev/null 2>&1 || ip link show "$VIN" >/dev/null 2>&1; then
    echo "FAIL: veth left behind"; rc=1
  else
    echo "namespaces and veth removed (ip netns list has no ddsw-$$-*)"
  fi
  (exit $rc)
  cleanup
}
trap on_exit EXIT

in_ns() { ip netns exec "$NS" "$@"; }
# For start: `ip netns exec` execs the command (no fork), so the PID start records is the binary's.
IN_NS=(ip netns exec "$NS")
tx() { in_ns cat "/sys/class/net/$VIN/statistics/tx_packets"; }
rx_out() { ip netns exec "$NS_OUT" cat "/sys/class/net/$VOUT/statistics/rx_packets"; }

ip netns add "$NS" || fail "ip netns add $NS"
ip netns add "$NS_OUT" || fail "ip netns add $NS_OUT"
ip -n "$NS" link add "$VIN" type veth peer name "$VOUT" netns "$NS_OUT" || fail "cannot create the veth pair"
in_ns sysctl -qw "net.ipv6.conf.$VIN.disable_ipv6=1" || fail "cannot disable IPv6 inside"
ip netns exec "$NS_OUT" sysctl -qw "net.ipv6.conf.$VOUT.disable_ipv6=1" || fail "cannot disable IPv6 outside"
ip -n "$NS" addr add 10.213.0.2/24 dev "$VIN"
ip -n "$NS_OUT" addr add 10.213.0.1/24 dev "$VOUT"
ip -n "$NS" link set lo up
ip -n "$NS_OUT" link set lo up
ip -n "$NS_OUT" link set "$VOUT" up
ip -n "$NS" link set "$VIN" up
sleep 1  # let the links settle

# 1. Localhost defaults: DDS must work (the server adopts the commander, over
#    UDP since the server has no shared memory) and the veth stays silent.
idle0=$(tx); sleep 1; idle1=$(tx)
[ "$idle1" -eq "$idle0" ] || fail "the veth transmits on its own ($idle0 -> $idle1 packets in 1 s idle): cannot judge"
tx0=$(tx); rx0=$(rx_out)
start sim_local "${IN_NS[@]}" "$BIN/ddswarm-sim" --scenario "$scenario" --domain "$DOMAIN" --duration 6
start cmd_local "${IN_NS[@]}" "$BIN/scripted_commander" --domain "$DOMAIN" --z 1.0 --hold 1 --tolerance 0.1 --timeout 5
wait_pid "$PID_cmd_local" 15
wait_pid "$PID_sim_local" 15 || fail "the localhost server did not finish cleanly"
tx1=$(tx); rx1=$(rx_out)
echo "localhost defaults: veth tx_packets $tx0 -> $tx1 (far end rx $rx0 -> $rx1)"
grep -q 'drone 0: agent [0-9a-f]* online' "$WORK/sim_local.log" ||
  fail "DDS over loopback did not work inside the namespace (the server never heard the commander): the check would be vacuous"
t_cmd=$(sed -n 's/^final t=\([0-9.]*\) .*/\1/p' "$WORK/cmd_local.log")
awk -v t="${t_cmd:-0}" 'BEGIN { exit !(t > 0.5) }' ||
  fail "the commander never received the server's state over loopback: the check would be vacuous"
[ "$tx1" -eq "$tx0" ] || fail "localhost-only DDS sent $((tx1 - tx0)) packets out of the veth"
[ "$rx1" -eq "$rx0" ] || fail "the far end received $((rx1 - rx0)) packets"

# 2. Opted in to the veth's address: the same counter must move, or the check above proves nothing.
tx2=$(tx)
start sim_iface "${IN_NS[@]}" "$BIN/ddswarm-sim" --scenario "$scenario" --domain "$DOMAIN" \
  --duration 3 --dds-interface 10.213.0.2
wait_pid "$PID_sim_iface" 15 || fail "the opted-in server did not finish cleanly"
tx3=$(tx)
echo "--dds-interface 10.213.0.2: veth tx_packets $tx2 -> $tx3"
[ "$tx3" -gt "$tx2" ] || fail "a server opted in to 10.213.0.2 sent nothing on the veth: the counter does not see DDS"
echo PASS
