#!/usr/bin/env bash
# A frozen agent (SIGSTOP: a debugger, a swapped-out or overloaded process)
# must not stall a real-time swarm. Its swarm-state reader holds samples of
# the server's data-sharing pool without taking them; the server must keep
# publishing at real time, the other five drones keep flying, drone 3 enters
# failsafe (hovering), and once the agent runs again (SIGCONT) it answers
# and flies its drone again. Stopped longer than its DDS lease, its peers
# dropped it while it still held them; Fast DDS 2.9 once left it deaf to the
# server for good that way (CI), so it joins again as a new participant.
source "$(dirname "$0")/lib.sh"
scenario="$SRC/config/thesis_course.yaml"
gs() { timeout 60 "$BIN/ddswarm-gs" --config "$scenario" --domain "$DOMAIN" "$@"; }
sim_time() { gs status 2>/dev/null | sed -n 's/.*\[sim \([0-9.]*\) s .*/\1/p' | tail -1; }
start launch "$BIN/ddswarm-launch" "$scenario" --mode realtime --domain "$DOMAIN" --ids 0-2,4-5 \
  --set sim.agent_timeout_s=0.5 --set sim.failsafe_land_after_s=60 --log-dir "$WORK"
start agent3 "$BIN/ddswarm-agent" --id 3 --config "$scenario" --domain "$DOMAIN"
gs wait-agents --count 6 --timeout 60 || fail "agents not online"
gs takeoff --wait || fail "takeoff"

kill -STOP "$PID_agent3"
# Each status call takes a while to discover the server: the window is
# long enough that its jitter stays small, and a writer blocked on its pool
# (100 ms per write) would show as x0.2 real time.
t0=$(sim_time); w0=$(date +%s.%N)
sleep 6  # 300 ticks: far more than the pool's 4 samples
t1=$(sim_time); w1=$(date +%s.%N)
status=$(gs status --drones 2>&1)
echo "$status"
[ -n "$t0" ] && [ -n "$t1" ] || fail "no status from the server"
rtf=$(echo "($t1 - $t0) / ($w1 - $w0)" | bc -l)
printf 'while agent 3 was stopped: sim %.2f -> %.2f s in %.2f s of wall time (x%.2f real time)\n' \
  "$t0" "$t1" "$(echo "$w1 - $w0" | bc -l)" "$rtf"
echo "$rtf >= 0.8" | bc -l | grep -q 1 || fail "the server slowed to x$rtf real time behind a stopped agent"
echo "$status" | awk '$1 ~ /^[0-5]$/ && $1 != 3 && (/failsafe/ || !/airborne/) { bad = 1; print "drone " $1 ": " $0 } END { exit bad }' ||
  fail "another drone suffered from the stopped agent"
echo "$status" | awk '$1 == 3' | grep -q failsafe || fail "drone 3 is not in failsafe while its agent is stopped"

kill -CONT "$PID_agent3"
resumed=$(date +%s.%N)
ok=0
for _ in $(seq 40); do
  row=$(gs status --drones 2>/dev/null | awk '$1 == 3')
  if echo "$row" | grep -q airborne && ! echo "$row" | grep -q failsafe; then ok=1; break; fi
  sleep 0.25
done
printf 'drone 3 %.1f s after SIGCONT: %s\n' "$(echo "$(date +%s.%N) - $resumed" | bc -l)" "$row"
[ $ok -eq 1 ] || fail "agent 3 did not fly its drone again after SIGCONT"
kill -0 "$PID_agent3" 2>/dev/null || fail "agent 3 died"
grep "joining again" "$WORK/agent3.log" ||
  fail "agent 3 outlived its 3 s lease but did not join again as a new participant"
echo PASS
