#!/usr/bin/env bash
# From a scattered start six agent processes settle with every pair
# farther apart than a safety distance and closer than epsilon; after D_int
# changes to 6 m the swarm re-forms at the new spacing.
source "$(dirname "$0")/lib.sh"
scenario="$SRC/tests/scenarios/scattered.yaml"
gs() { timeout 120 "$BIN/ddswarm-gs" --config "$scenario" --domain "$DOMAIN" "$@"; }
pairs() {  # prints "min max" pairwise distance
  gs status --drones >"$WORK/status.out" || fail "status failed: $(cat "$WORK/status.out")"
  cat "$WORK/status.out" >&2
  sed -n 's/^pairwise distance: min \([0-9.]*\) m, max \([0-9.]*\) m$/\1 \2/p' "$WORK/status.out"
}
start launch timeout 300 "$BIN/ddswarm-launch" "$scenario" --domain "$DOMAIN" --log-dir "$WORK/logs"
gs wait-agents --count 6 --timeout 60 || fail "agents did not come online"
read min0 max0 < <(pairs)
echo "scattered start: min $min0 m, max $max0 m"
gs takeoff --wait || fail "takeoff"
gs hold --time 60 --wait || fail "hold"
read min4 max4 < <(pairs)
echo "D_int 4 m: min $min4 m, max $max4 m"
awk -v a="$min4" 'BEGIN{exit !(a > 2.4)}' || fail "pairs closer than the 2.4 m safety distance: $min4"
awk -v b="$max4" 'BEGIN{exit !(b < 9.0)}' || fail "swarm wider than epsilon 9 m: $max4"
gs distance 6 || fail "distance"
gs hold --time 60 --wait || fail "hold after distance change"
read min6 max6 < <(pairs)
echo "D_int 6 m: min $min6 m, max $max6 m"
awk -v a="$min6" -v b="$min4" 'BEGIN{exit !(a > 1.3 * b && a > 3.6)}' || fail "swarm did not spread to D_int 6: min $min6 vs $min4"
awk -v b="$max6" 'BEGIN{exit !(b < 13.0)}' || fail "swarm wider than epsilon 13 m at D_int 6: $max6"
gs land --wait || fail "land"
echo PASS
