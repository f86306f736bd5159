#!/usr/bin/env bash
# A law for dense swarms: 32 agent processes take off from the thesis course's
# 2 m start grid and hold for 30 s of sim time (lockstep). With
# agent.activation.neighbours: 6 no two drones touch and every pair stays more
# than 0.6 D_int apart. The same run with the thesis's sum over every peer
# shows the scenario is dense enough to tell: its drones collide.
source "$(dirname "$0")/lib.sh"
# fly K: takeoff, hold 30 s, status; sets COLL and MIN_PAIR. Runs in this shell
# (never in $(...) or <(...)), so its fail ends the test with the logs.
fly() {
  local k=$1 log="$WORK/k$1.log"
  timeout 200 "$BIN/ddswarm-launch" "$SRC/config/thesis_course.yaml" --drones 32 --mode lockstep \
    --domain "$DOMAIN" --log-dir "$WORK/logs-k$k" --set agent.activation.neighbours="$k" \
    --gs "takeoff --wait; hold --time 30 --wait; status --drones" >"$log" 2>&1
  local rc=$?
  [ $rc -eq 0 ] || { cat "$log"; tail -n 20 "$WORK"/logs-k"$k"/*.log; fail "neighbours $k: launch exited $rc"; }
  grep -q "32 airborne" "$log" || { cat "$log"; fail "neighbours $k: not all 32 drones airborne"; }
  COLL=$(sed -n 's/.*| \([0-9]*\) collisions |.*/\1/p' "$log" | tail -1)
  MIN_PAIR=$(sed -n 's/^pairwise distance: min \([0-9.]*\) m, max .*/\1/p' "$log" | tail -1)
  [ -n "$COLL" ] && [ -n "$MIN_PAIR" ] || { cat "$log"; fail "neighbours $k: no collision count or pair distance in the status"; }
}
fly 6; c6=$COLL; m6=$MIN_PAIR
echo "neighbours 6: $c6 collisions, closest pair $m6 m"
fly 0; c0=$COLL; m0=$MIN_PAIR
echo "every peer (thesis): $c0 collisions, closest pair $m0 m"
[ "$c6" -eq 0 ] || fail "neighbours 6: $c6 collisions"
awk -v a="$m6" 'BEGIN{exit !(a > 2.4)}' || fail "neighbours 6: closest pair $m6 m, under 0.6 D_int (2.4 m)"
[ "$c0" -gt 0 ] || fail "the thesis law did not collide here either: the scenario no longer tells the laws apart"
echo PASS
