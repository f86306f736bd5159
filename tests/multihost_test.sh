#!/usr/bin/env bash
# Agents on separate machines. Three network namespaces joined by
# veth pairs and a bridge act as three hosts with their own addresses: the
# server (and ground station) on one, agents 0-2 on a second, 3-5 on a third.
# Shared memory is off, so every sample crosses the bridge over UDP. The task
# must complete; the namespaces are removed whatever happens.
# Usage: multihost_test.sh interface|peers|server (how the hosts find each other).
source "$(dirname "$0")/lib.sh"
how="${1:-interface}"
[ "$(id -u)" -eq 0 ] && command -v ip >/dev/null || { echo "SKIP: needs root and iproute2"; exit 77; }
tag="ddsw$$"
SW="$tag-sw"; H=("$tag-h1" "$tag-h2" "$tag-h3"); IPS=(10.214.0.1 10.214.0.2 10.214.0.3)
teardown() {
  for ns in "${H[@]}" "$SW"; do
    for pid in $(ip netns pids "$ns" 2>/dev/null); do kill -KILL "$pid" 2>/dev/null; done
    ip netns del "$ns" 2>/dev/null
  done
  ip netns list | grep -q "$tag" && echo "WARNING: namespaces left: $(ip netns list | grep "$tag")"
}
finish() {
  local rc=$?
  for pid in "${PIDS[@]:-}"; do [ -n "$pid" ] && kill -TERM "$pid" 2>/dev/null; done
  sleep 1
  teardown
  (exit $rc)
  cleanup  # the harness: kills what is left by PID, prints logs on failure, exits rc
}
trap finish EXIT

ip netns add "$SW" || { echo "SKIP: cannot create namespaces"; exit 77; }
ip netns exec "$SW" ip link add br0 type bridge
ip netns exec "$SW" ip link set br0 up
for i in 0 1 2; do
  ns="${H[$i]}"; ip netns add "$ns"
  ip link add "$tag-e$i" type veth peer name "$tag-p$i"
  ip link set "$tag-e$i" netns "$ns"; ip link set "$tag-p$i" netns "$SW"
  ip netns exec "$SW" ip link set "$tag-p$i" master br0
  ip netns exec "$SW" ip link set "$tag-p$i" up
  ip netns exec "$ns" sysctl -qw net.ipv6.conf.all.disable_ipv6=1
  ip netns exec "$ns" ip link set lo up
  ip netns exec "$ns" ip addr add "${IPS[$i]}/24" dev "$tag-e$i"
  ip netns exec "$ns" ip link set "$tag-e$i" up
  ip netns exec "$ns" ip route add 224.0.0.0/4 dev "$tag-e$i"
done

# The course with shared memory off: UDP is the only way between hosts.
scenario="$WORK/multihost.yaml"
sed '/^dds:/,$d' "$SRC/config/thesis_course.yaml" >"$scenario"
printf 'dds:\n  shared_memory: false\n' >>"$scenario"
# The networking flags of a process on host i, for each way of finding each other.
net() {
  local i=$1
  case "$how" in
    interface) echo --dds-interface "${IPS[$i]}" ;;
    peers)  # the server's host knows both agent hosts; agent hosts know the server's
      if [ "$i" -eq 0 ]; then echo --dds-peers "${IPS[1]},${IPS[2]}" --dds-local-ip "${IPS[0]}"
      else echo --dds-peers "${IPS[0]}" --dds-local-ip "${IPS[$i]}"; fi ;;
    server) echo --discovery-server "${IPS[0]}:11811" --dds-local-ip "${IPS[$i]}" ;;
    *) fail "unknown mode $how" ;;
  esac
}
if [ "$how" = server ]; then
  start discovery ip netns exec "${H[0]}" fast-discovery-server -i 0 -l "${IPS[0]}" -p 11811
fi
start server ip netns exec "${H[0]}" "$BIN/ddswarm-launch" "$scenario" --mode lockstep --only server \
  --domain "$DOMAIN" $(net 0)
start agents_a ip netns exec "${H[1]}" "$BIN/ddswarm-launch" "$scenario" --only agents --ids 0-2 \
  --domain "$DOMAIN" $(net 1)
start agents_b ip netns exec "${H[2]}" "$BIN/ddswarm-launch" "$scenario" --only agents --ids 3-5 \
  --domain "$DOMAIN" $(net 2)
gs() { timeout 240 ip netns exec "${H[0]}" "$BIN/ddswarm-gs" --config "$scenario" --domain "$DOMAIN" \
  $(net 0) "$@"; }
# Packets the server's host receives from the other hosts (commands, heartbeats, acks).
rx_count() { ip netns exec "${H[0]}" cat "/sys/class/net/$tag-e0/statistics/rx_packets"; }
rx_before=$(rx_count)
gs wait-agents --count 6 --timeout 60 || fail "agents on the other hosts never came online"
gs takeoff --wait || fail "takeoff"
out=$(gs task); rc=$?
echo "$out"
[ $rc -eq 0 ] || fail "task failed across hosts"
echo "$out" | grep -q "task complete:" || fail "no result"
rx_after=$(rx_count)
echo "the server's host received $((rx_after - rx_before)) UDP packets from the agents' hosts"
[ $((rx_after - rx_before)) -gt 1000 ] || fail "too little traffic crossed the bridge: the hosts did not talk over UDP"
grep -h "agent .* online" "$WORK/server.log" | head -6
echo "PASS ($how)"
