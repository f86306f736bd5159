#!/usr/bin/env bash
# Follow the leader (the thesis's RC drone). Drone 0 is flown
# by velocity commands from the ground station; the others swarm around it.
source "$(dirname "$0")/lib.sh"
scenario="$SRC/tests/scenarios/scattered.yaml"
gs() { timeout 60 "$BIN/ddswarm-gs" --config "$scenario" --domain "$DOMAIN" "$@"; }
# Each teleop is its own process here (0.5-2 s apart under load): give the link 5 s before it lapses.
start launch "$BIN/ddswarm-launch" "$scenario" --mode realtime --domain "$DOMAIN" --drones 4 \
  --set agent.teleop_timeout_s=5 --log-dir "$WORK/logs"
gs wait-agents --count 4 --timeout 60 || fail "agents not online"
gs takeoff --wait || fail "takeoff"
gs hold --time 5 --wait || fail "hold"
centroid() {  # sets LEADER_Y and FOLLOWERS_Y (their mean); runs in this shell, so fail ends the test
  gs status --drones >"$WORK/status.txt" || fail "status --drones: $(cat "$WORK/status.txt")"
  read -r LEADER_Y FOLLOWERS_Y < <(awk '$1 ~ /^[0-9]+$/ { if ($1 == 0) l = $3; else { s += $3; n++ } }
    END { if (n > 0 && l != "") printf "%.2f %.2f\n", l, s / n }' "$WORK/status.txt")
  [ -n "${FOLLOWERS_Y:-}" ] || fail "no drone rows in the status: $(cat "$WORK/status.txt")"
}
centroid; l0=$LEADER_Y; c0=$FOLLOWERS_Y
gs follow --leader 0 || fail "follow"
# Fly the leader north at 1 m/s for ~12 s, keeping the teleop link fresh.
end=$((SECONDS + 12))
while [ $SECONDS -lt $end ]; do gs teleop --north 1.0 >/dev/null || fail "teleop"; sleep 0.3; done
# Stop the leader, and wait (up to 20 s) for the followers to gather round it:
# their mean within D_int (4 m) + 1 m of it.
gs teleop --north 0 >/dev/null || fail "teleop stop"
gathered() { awk -v b="$LEADER_Y" -v d="$FOLLOWERS_Y" 'BEGIN{x = b - d; if (x < 0) x = -x; exit !(x < 5.0)}'; }
end=$((SECONDS + 20))
while centroid && ! gathered && [ $SECONDS -lt $end ]; do sleep 0.5; done
l1=$LEADER_Y; c1=$FOLLOWERS_Y
echo "leader y $l0 -> $l1, followers' mean y $c0 -> $c1"
awk -v a="$l0" -v b="$l1" 'BEGIN{exit !(b - a > 4.0)}' || fail "the leader did not fly north"
# The followers came along and gathered round their leader: their mean is
# within D_int (4 m) + 1 m of it.
awk -v c="$c0" -v d="$c1" 'BEGIN{exit !(d - c > 4.0)}' || fail "the followers stayed behind"
gathered || fail "the followers did not gather round their leader within 20 s"
out=$(gs hold 2>&1) || fail "hold after follow: $out"
gs status --drones
echo PASS
