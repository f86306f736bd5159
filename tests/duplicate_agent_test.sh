#!/usr/bin/env bash
# Two agents cannot fly one drone: with a server and an agent flying drone 3,
# a second `ddswarm-agent --id 3` exits with code 3 within a few seconds,
# printing one line on stderr that names drone 3 as already flown (and the
# first agent's pid); the first agent keeps flying and stays the drone's owner.
# A second server, or a second whole launch, on the domain refuses too.
source "$(dirname "$0")/lib.sh"
config="$SRC/config/thesis_course.yaml"
start sim "$BIN/ddswarm-sim" --scenario "$config" --domain "$DOMAIN" --duration 40
start first "$BIN/ddswarm-agent" --id 3 --config "$config" --domain "$DOMAIN" --duration 40
# The first agent is flying once it has passed its own probe and the server adopted it.
end=$((SECONDS + 15))
until grep -q 'drone 3: agent [0-9a-f]* online' "$WORK/sim.log"; do
  [ $SECONDS -lt $end ] || fail "the server never saw the first agent for drone 3"
  kill -0 "$PID_first" 2>/dev/null || fail "the first agent exited early"
  sleep 0.1
done
first_instance=$(sed -n 's/.*drone 3: agent \([0-9a-f]*\) flying.*/\1/p' "$WORK/first.log")
echo "first agent: pid $PID_first, instance $first_instance"

t0=$SECONDS
"$BIN/ddswarm-agent" --id 3 --config "$config" --domain "$DOMAIN" --duration 30 \
  >"$WORK/second.out.log" 2>"$WORK/second.err.log" &
second=$!
PIDS+=("$second")
wait_pid "$second" "$(slow 20)"  # a few seconds; more beside another test on 2 cores
rc=$?
echo "second agent exited with $rc after $((SECONDS - t0)) s; its stderr:"
cat "$WORK/second.err.log"
echo "its stdout:"
cat "$WORK/second.out.log"
[ $rc -eq 3 ] || fail "the second agent for drone 3 exited with $rc, expected 3 (duplicate)"
lines=$(wc -l <"$WORK/second.err.log")
[ "$lines" -eq 1 ] || fail "expected one line on stderr, got $lines"
grep -q 'drone 3 .*already flown' "$WORK/second.err.log" || fail "stderr does not name drone 3 as already flown"
grep -q "pid $PID_first\b" "$WORK/second.err.log" || fail "stderr does not name the first agent (pid $PID_first)"

sleep 1.5  # longer than the server's agent timeout: a lost owner would show by now
kill -0 "$PID_first" 2>/dev/null || fail "the first agent stopped"
online=$(grep -c 'drone 3: agent [0-9a-f]* online' "$WORK/sim.log")
[ "$online" -eq 1 ] || fail "the server adopted drone 3's agent $online times"
grep -q "drone 3: agent $first_instance online" "$WORK/sim.log" || fail "drone 3 is not owned by the first agent"
grep -q 'drone 3: agent lost' "$WORK/sim.log" && fail "the server lost the first agent"

# Two swarms on one domain would be one swarm in two worlds. A second server
# exits 3 with one line naming the first; the first keeps its drone. A whole
# second launch (whose agents skip their duplicate probe) ends with it.
t0=$SECONDS
"$BIN/ddswarm-sim" --scenario "$config" --domain "$DOMAIN" --duration 30 >"$WORK/sim2.out.log" 2>"$WORK/sim2.err.log" &
sim2=$!
PIDS+=("$sim2")
wait_pid "$sim2" 20
rc=$?
echo "second server exited with $rc after $((SECONDS - t0)) s: $(cat "$WORK/sim2.err.log")"
[ $rc -eq 3 ] || fail "a second server on the domain exited with $rc, expected 3"
grep -q "error: another server (instance [0-9a-f]*) is already on DDS domain $DOMAIN" "$WORK/sim2.err.log" ||
  fail "the second server did not say why"
timeout 60 "$BIN/ddswarm-launch" "$config" --drones 2 --domain "$DOMAIN" --duration 30 --log-dir "$WORK/launch2" \
  >"$WORK/launch2.log" 2>&1
rc=$?
tail -3 "$WORK/launch2.log"
[ $rc -ne 0 ] && [ $rc -ne 124 ] || fail "a second launch on the domain ran (rc $rc)"
grep -q "already on DDS domain" "$WORK/launch2/sim.log" "$WORK/launch2.log" 2>/dev/null || fail "the second launch does not say why"
kill -0 "$PID_first" 2>/dev/null || fail "the first agent stopped"
kill -0 "$PID_sim" 2>/dev/null || fail "the first server stopped"
grep -q 'drone 3: agent lost' "$WORK/sim.log" && fail "the first server lost its agent to the second swarm"
echo PASS
