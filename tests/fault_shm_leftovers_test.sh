#!/usr/bin/env bash
# Shared-memory leftovers from crashed processes do not break the
# next run. A whole swarm is killed with SIGKILL (nobody unlinks its
# segments); the next server clears the zombies (as `fastdds shm clean`
# does, plus data-sharing pools) and the next swarm flies on the same domain.
source "$(dirname "$0")/lib.sh"
scenario="$SRC/config/thesis_course.yaml"
gs() { timeout 60 "$BIN/ddswarm-gs" --config "$scenario" --domain "$DOMAIN" "$@"; }
start sim1 "$BIN/ddswarm-sim" --scenario "$scenario" --mode realtime --domain "$DOMAIN"
for i in 0 1 2 3 4 5; do start "a$i" "$BIN/ddswarm-agent" --id $i --config "$scenario" --domain "$DOMAIN"; done
gs wait-agents --count 6 --timeout 60 || fail "agents not online"
gs takeoff --wait || fail "takeoff"
# Which segments do our processes map? They become zombies when we kill them.
ours=$(for p in $PID_sim1 $PID_a0 $PID_a1 $PID_a2 $PID_a3 $PID_a4 $PID_a5; do
  grep -o '/dev/shm/fast[^ ]*' /proc/$p/maps 2>/dev/null; done | sort -u)
n_ours=$(echo "$ours" | grep -c fast)
echo "the swarm maps $n_ours shared-memory files"
[ "$n_ours" -gt 0 ] || fail "expected the swarm to use shared memory"
kill -KILL $PID_sim1 $PID_a0 $PID_a1 $PID_a2 $PID_a3 $PID_a4 $PID_a5
for p in $PID_sim1 $PID_a0 $PID_a1 $PID_a2 $PID_a3 $PID_a4 $PID_a5; do wait "$p" 2>/dev/null; done
left=$(for f in $ours; do [ -e "$f" ] && echo "$f"; done | wc -l)
echo "$left of them left behind by the kill"
[ "$left" -gt 0 ] || fail "SIGKILL left nothing behind; the test proves nothing"
# The clean-up leaves files younger than 2 s (a starting participant's).
sleep 2
start sim2 "$BIN/ddswarm-sim" --scenario "$scenario" --mode realtime --domain "$DOMAIN"
for i in 0 1 2 3 4 5; do start "b$i" "$BIN/ddswarm-agent" --id $i --config "$scenario" --domain "$DOMAIN"; done
for _ in $(seq 50); do grep -q "left by crashed processes" "$WORK/sim2.log" && break; sleep 0.1; done
# (Another ddswarm-sim starting meanwhile on this machine may have cleaned them first.)
grep "left by crashed processes" "$WORK/sim2.log" || echo "note: the new server found nothing to clean"
gs wait-agents --count 6 --timeout 60 || fail "the next swarm's agents are not online"
gs takeoff --wait || fail "the next swarm did not take off"
# Port files are named by domain and participant: the new swarm opens the
# same names again (checked once it flies, so none is caught half-opened).
# What must not remain is a file nobody maps.
live_maps=$(cat /proc/[0-9]*/maps 2>/dev/null | grep -o '/dev/shm/fast[^ ]*' | sort -u)
still=$(for f in $ours; do [ -e "$f" ] && ! grep -qxF "$f" <<<"$live_maps" && echo "$f"; done)
[ -z "$still" ] || fail "zombie files of the killed swarm remain: $still"
echo PASS
