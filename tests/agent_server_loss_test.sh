#!/usr/bin/env bash
# When the server's samples stop, the agent says so once, stops
# commanding and waits; when a server comes back it resumes. SIGTERM exits 0.
source "$(dirname "$0")/lib.sh"
scenario="$SRC/tests/scenarios/one_drone.yaml"
start sim1 "$BIN/ddswarm-sim" --scenario "$scenario" --domain "$DOMAIN"
start agent "$BIN/ddswarm-agent" --id 0 --config "$scenario" --domain "$DOMAIN"
for _ in $(seq 50); do grep -q "agent .* online" "$WORK/sim1.log" && break; sleep 0.2; done
grep -q "agent .* online" "$WORK/sim1.log" || fail "server never heard the agent"
kill -TERM "$PID_sim1"; wait_pid "$PID_sim1" 10 || fail "server did not stop on SIGTERM"
sleep 3
[ "$(grep -c "no server samples" "$WORK/agent.log")" -eq 1 ] || fail "the agent should report the loss exactly once"
kill -0 "$PID_agent" 2>/dev/null || fail "the agent died with the server"
start sim2 "$BIN/ddswarm-sim" --scenario "$scenario" --domain "$DOMAIN"
for _ in $(seq 50); do grep -q "server samples resumed" "$WORK/agent.log" && break; sleep 0.2; done
grep -q "server samples resumed" "$WORK/agent.log" || fail "the agent did not resume with the new server"
for _ in $(seq 50); do grep -q "agent .* online" "$WORK/sim2.log" && break; sleep 0.2; done
grep -q "agent .* online" "$WORK/sim2.log" || fail "the new server never heard the agent"
kill -TERM "$PID_agent"; wait_pid "$PID_agent" 10; rc=$?
[ $rc -eq 0 ] || fail "agent exit $rc on SIGTERM"
cat "$WORK/agent.log"
echo PASS
