#!/usr/bin/env bash
# The server is SIGKILLed at the worst moment: while its swarm-state write
# holds the lock of an agent's data-sharing notification, in that agent's
# shared memory (gdb stops it there; docs/faults.md). Nothing ever releases
# that lock, and Fast DDS 2.9 throws when it has waited 1 s for it, on its
# own threads as well, which ended the agent in std::terminate (and, with the
# launcher's default policy, the whole swarm). Every agent must live through
# it, as the same process, and fly again with a new server.
source "$(dirname "$0")/lib.sh"
command -v gdb >/dev/null || fail "gdb is missing (scripts/setup installs it)"
# gdb stops the server for a second or more each time it attaches. An agent
# that counted that as a lost server would make its swarm-state reader anew
# (docs/faults.md) while the server stood stopped, and the lock the server
# then died holding would be a deleted reader's: with a 4 s timeout the
# agents keep their readers until after the kill.
fly_six_own_server --set agent.server_timeout_s=4
agent_pids=$(pgrep -f -- "ddswarm-agent .*--domain $DOMAIN\b" | sort)
[ "$(echo "$agent_pids" | wc -w)" -eq 6 ] || fail "not 6 agent processes: $agent_pids"

# The agents' notification segments as the server maps them: readers' (an
# entity id ending in .4) whose participant is not the server's own, that of
# its writer pools (ending in .3).
# Not one the kernel marks deleted: an agent that joined again before the kill
# leaves its old reader's segment mapped in the server, where nothing takes
# its lock any more, and gdb would wait for it in vain (one run in 20 under
# two busy loops timed out with such an agent's fourth participant's segment).
maps=$(awk '$6 ~ /\/fast_datasharing_/ && $7 != "(deleted)" { print $1, $6 }' "/proc/$PID_sim1/maps" | sort -u -k2,2)
own=$(echo "$maps" | awk '$2 ~ /\.3$/ { n = $2; sub(/.*fast_datasharing_/, "", n); sub(/_.*/, "", n); print n; exit }')
target=$(echo "$maps" | awk -v own="$own" '$2 ~ /\.4$/ && index($2, own) == 0 { print; exit }')
[ -n "$own" ] && [ -n "$target" ] || { echo "$maps"; fail "no agent's notification segment in the server's maps"; }
range=${target%% *}
echo "the lock to die holding: ${target#* } at $range"
ulimit -c 0  # gdb's own aborts leave no core behind
cond="\$rdi >= 0x${range%-*} && \$rdi < 0x${range#*-}"
# First the call that releases that lock: a breakpoint on pthread_mutex_unlock
# itself would hold every other thread that calls it with its own lock held
# (gdb stops them all), other agents' shared-memory ports among them, which a
# SIGKILL at one instant does not do. So learn where Fast DDS calls it for
# this lock, let the server go on, then stop it at that call alone.
timeout 30 gdb -p "$PID_sim1" -batch -ex "set pagination off" -ex "break pthread_mutex_unlock if $cond" \
  -ex continue -ex "frame 1" -ex "x/i \$pc-5" >"$WORK/gdb_find.log" 2>&1
if grep -q "ptrace: Operation not permitted" "$WORK/gdb_find.log"; then
  echo "SKIP: gdb may not attach to a process here (ptrace not permitted)"; exit 77
fi
call=$(awk '/^=> |^   0x/ && /call/ { for (i = 1; i <= NF; i++) if ($i ~ /^0x[0-9a-f]+/) { sub(/:$/, "", $i); print $i; exit } }' "$WORK/gdb_find.log")
[ -n "$call" ] || { cat "$WORK/gdb_find.log"; fail "no call to pthread_mutex_unlock found for the lock"; }
timeout 30 gdb -p "$PID_sim1" -batch -ex "set pagination off" -ex "break *$call if $cond" \
  -ex continue -ex "bt 4" -ex "shell kill -KILL $PID_sim1" >"$WORK/gdb.log" 2>&1
wait "$PID_sim1" 2>/dev/null
kill -0 "$PID_sim1" 2>/dev/null && fail "the server is still running"
grep -q "deliver_sample_to_datasharing" "$WORK/gdb.log" ||
  { cat "$WORK/gdb.log"; fail "the server was not stopped in a swarm-state write holding the lock"; }
echo "server killed holding the lock, at the call $call in:"
grep -m2 "^#[01] " "$WORK/gdb.log" | cut -c1-160

sleep 2
start sim2 "$BIN/ddswarm-sim" --scenario "$scenario" --mode realtime --domain "$DOMAIN"
# The agent whose lock it was meets it on a Fast DDS thread as it matches the
# new server, and starts again.
for _ in $(seq 150); do grep -q "starting this process again" "$WORK"/agent_*.log && break; sleep 0.1; done
grep -q "starting this process again" "$WORK"/agent_*.log || fail "no agent met the dead lock in 15 s"
gs wait-agents --count 6 --timeout 60 || fail "the agents did not come back with the new server"
kill -0 "$PID_agents" 2>/dev/null || fail "the launcher stopped the swarm: an agent died"
[ "$(pgrep -f -- "ddswarm-agent .*--domain $DOMAIN\b" | sort)" = "$agent_pids" ] ||
  fail "the agent processes are not the same ones"
grep -h "owner died\|joining again" "$WORK"/agent_*.log || true
# An agent the new server's first seconds left deaf (it stalls 1 s per write
# on the dead lock until the old participant's lease ends) makes its reader
# anew 4 s later (agent.server_timeout_s above), then acknowledges: the
# ground station's 5 s ack timeout ended 2.6 s after such a renewal in 1 run
# of 20 under two busy loops. It waits 15 s.
sed 's/^  ack_timeout_s: .*/  ack_timeout_s: 15.0/' "$scenario" >"$WORK/patient_gs.yaml"
grep -q "ack_timeout_s: 15.0" "$WORK/patient_gs.yaml" || fail "cannot derive patient_gs.yaml"
gs() { timeout 60 "$BIN/ddswarm-gs" --config "$WORK/patient_gs.yaml" --domain "$DOMAIN" "$@"; }
gs takeoff --wait || fail "takeoff with the new server"
gs status | tee "$WORK/status.txt"
grep -q "6 airborne" "$WORK/status.txt" || fail "the swarm did not take off with the new server"
echo PASS
