#!/usr/bin/env bash
# A server stopped (SIGSTOP) longer than the agents' DDS lease drops every
# agent's participant, while the agents, whose lease of the server it kept
# renewing until then, may still hold it. After SIGCONT the server's samples
# say that it hears no agent: each agent must notice, join again as a new
# participant, and fly its drone again; the swarm keeps its mission.
source "$(dirname "$0")/lib.sh"
scenario="$SRC/config/thesis_course.yaml"
gs() { timeout 60 "$BIN/ddswarm-gs" --config "$scenario" --domain "$DOMAIN" "$@"; }
start launch "$BIN/ddswarm-launch" "$scenario" --mode realtime --domain "$DOMAIN" \
  --set sim.failsafe_land_after_s=60 --log-dir "$WORK"
gs wait-agents --count 6 --timeout 60 || fail "agents not online"
gs takeoff --wait || fail "takeoff"
sim=$(pgrep -f -- "ddswarm-sim .*--domain $DOMAIN\b") || fail "no server process"

kill -STOP "$sim"
sleep 8  # longer than the 3 s lease (dds.lease_duration_s), on either side
kill -CONT "$sim"
resumed=$(date +%s.%N)
ok=0
for _ in $(seq 60); do
  status=$(gs status --drones 2>/dev/null)
  if [ "$(echo "$status" | awk '$1 ~ /^[0-5]$/ && /airborne/ && !/failsafe/ && !/no-agent/' | wc -l)" -eq 6 ]; then
    ok=1
    break
  fi
  sleep 0.5
done
echo "$status"
printf 'all six drones flown by their agents again %.1f s after SIGCONT\n' \
  "$(echo "$(date +%s.%N) - $resumed" | bc -l)"
[ $ok -eq 1 ] || fail "the swarm did not fly again after the server's SIGCONT"
grep -h "joining again\|lease\|not heard" "$WORK"/agent_*.log || true
# The swarm still has its mission: it lands on command.
gs land --wait || fail "land after the freeze"
echo PASS
