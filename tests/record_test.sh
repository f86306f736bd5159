#!/usr/bin/env bash
# The recorder writes every sample it receives to an MCAP file that
# an independent reader (npm @mcap/core) reads back exactly; SIGINT finalizes;
# after SIGKILL the file still reads up to its last chunk; a full disk is a
# clear error; replay reproduces the same sample sequence, and refuses a
# domain where a server is live.
source "$(dirname "$0")/lib.sh"
reader="$SRC/tests/mcap_independent_reader.mjs"
node_ok=1
command -v node >/dev/null && [ -d "$SRC/tests/node_modules/@mcap/core" ] || node_ok=0

# 1. Exact counts and values, finalized by SIGINT.
start rec1 "$BIN/ddswarm-record" -o "$WORK/a.mcap" --domain "$DOMAIN" --topics ddswarm/collision,ddswarm/mission_ack,ddswarm/swarm_state
sleep 1
"$BIN/count_publisher" --domain "$DOMAIN" --count 300 || fail "publisher"
kill -INT "$PID_rec1"; wait_pid "$PID_rec1" 15 || fail "recorder did not finish on SIGINT"
"$BIN/ddswarm-record" info "$WORK/a.mcap" | tee "$WORK/a.info"
grep -q "(summary)" "$WORK/a.info" || fail "SIGINT did not finalize the summary"
for t in collision mission_ack swarm_state; do
  grep -Eq "ddswarm/$t +300 messages" "$WORK/a.info" || fail "ddswarm/$t: expected 300 messages"
done
if [ $node_ok -eq 1 ]; then
  timeout 60 node --single-threaded "$reader" "$WORK/a.mcap" --expect-count ddswarm/collision=300 --expect-count ddswarm/mission_ack=300 \
    --expect-count ddswarm/swarm_state=300 --expect-u64-first ddswarm/swarm_state=1 \
    --expect-u64-first ddswarm/collision=1 || fail "the independent reader disagrees"
else
  echo "note: node or @mcap/core not installed; independent reader skipped"
fi

grep -q "never received" "$WORK/rec1.log" && fail "the recorder missed samples of an unhurried publisher"

# 1b. A recorder frozen for a second while samples flow keeps what the
#     writers still hold and says exactly how many it never received: per
#     topic, written + missed = sent.
start rec4 "$BIN/ddswarm-record" -o "$WORK/d.mcap" --domain "$DOMAIN" --topics ddswarm/collision,ddswarm/mission_ack,ddswarm/swarm_state
sleep 1
start freezer bash -c "sleep 2; kill -STOP $PID_rec4; sleep 1; kill -CONT $PID_rec4"
"$BIN/count_publisher" --domain "$DOMAIN" --count 1000 || fail "publisher"
wait_pid "$PID_freezer" 10 || fail "freezer"
kill -INT "$PID_rec4"; wait_pid "$PID_rec4" 15 || fail "the frozen recorder did not finish on SIGINT"
for t in collision mission_ack swarm_state; do
  line=$(grep -E "^  ddswarm/$t " "$WORK/rec4.log") || fail "no count for ddswarm/$t"
  read -r _ written missed <<<"$(echo "$line" | sed -E 's/\((.*) more.*/\1/')"
  echo "ddswarm/$t: written $written, reported missed ${missed:-0}"
  [ $((written + ${missed:-0})) -eq 1000 ] || fail "ddswarm/$t: $written written + ${missed:-0} reported missed != 1000 sent"
done

# 2. Replay reproduces the same sequence (recorded again, compared message by message).
start rec2 "$BIN/ddswarm-record" -o "$WORK/b.mcap" --domain "$DOMAIN" --topics ddswarm/collision,ddswarm/mission_ack,ddswarm/swarm_state
sleep 1
"$BIN/ddswarm-replay" "$WORK/a.mcap" --domain "$DOMAIN" --rate 4 || fail "replay failed"
kill -INT "$PID_rec2"; wait_pid "$PID_rec2" 15 || fail "second recorder did not finish"
seq_of() { "$BIN/ddswarm-record" info --messages "$1" | awk 'NF == 4 && $1 ~ /^[0-9]+$/ { print $2, $3, $4 }'; }
seq_of "$WORK/a.mcap" >"$WORK/a.seq"; seq_of "$WORK/b.mcap" >"$WORK/b.seq"
[ "$(wc -l <"$WORK/a.seq")" -eq 900 ] || fail "first recording has $(wc -l <"$WORK/a.seq") messages"
for t in collision mission_ack swarm_state; do
  diff <(grep "ddswarm/$t " "$WORK/a.seq") <(grep "ddswarm/$t " "$WORK/b.seq") >/dev/null || fail "replayed $t differs"
done

# 3. SIGKILL: readable up to the last complete chunk.
start sim "$BIN/ddswarm-sim" --scenario "$SRC/config/thesis_course.yaml" --domain "$DOMAIN"
start rec3 "$BIN/ddswarm-record" -o "$WORK/c.mcap" --domain "$DOMAIN" --chunk-kb 32
sleep 4
kill -KILL "$PID_rec3"; wait "$PID_rec3" 2>/dev/null
"$BIN/ddswarm-record" info "$WORK/c.mcap" | tee "$WORK/c.info" || fail "the killed recording is unreadable"
grep -q "scanned" "$WORK/c.info" || fail "expected a scanned (summary-less) read"
n=$(awk 'NR == 1 { print $2 }' "$WORK/c.info")
[ "${n:-0}" -gt 100 ] || fail "only ${n:-0} messages survived the kill"
if [ $node_ok -eq 1 ]; then timeout 60 node --single-threaded "$reader" "$WORK/c.mcap" --stream-only >/dev/null || fail "independent reader cannot read the killed file"; fi
kill -TERM "$PID_sim"; wait_pid "$PID_sim" 10 || fail "server did not stop"

# 4. A full disk and an unwritable path are clear errors, never a silent truncation.
out=$(timeout 20 "$BIN/ddswarm-record" -o /dev/full --domain "$DOMAIN" --duration 3 2>&1); rc=$?
[ $rc -ne 0 ] || fail "recording to a full disk reported success"
echo "$out" | grep -q "/dev/full" || fail "full-disk error does not name the file: $out"
out=$(timeout 20 "$BIN/ddswarm-record" -o /nonexistent/dir/x.mcap --domain "$DOMAIN" --duration 1 2>&1); rc=$?
[ $rc -ne 0 ] && echo "$out" | grep -q "/nonexistent/dir/x.mcap" || fail "unwritable path: rc $rc: $out"
# 5. A live run recorded by the launcher, then replayed: the ground station's
#    status works on the replay as on the live run.
timeout 120 "$BIN/ddswarm-launch" "$SRC/config/thesis_course.yaml" --drones 3 --mode lockstep --domain "$DOMAIN" \
  --record "$WORK/runs" --log-dir "$WORK/logs" --gs "takeoff --wait; land --wait" >"$WORK/launch.log" 2>&1 || fail "recorded run failed"
run=$(ls "$WORK"/runs/*.mcap | head -1)
"$BIN/ddswarm-record" info "$run" | tee "$WORK/run.info" | head -3
grep -Eq "ddswarm/swarm_state +[1-9][0-9]* messages" "$WORK/run.info" || fail "the launcher's recording has no swarm state"
start replay "$BIN/ddswarm-replay" "$run" --domain "$DOMAIN" --loop
sleep 2.5
out=$(timeout 30 "$BIN/ddswarm-gs" --domain "$DOMAIN" status 2>&1) || fail "status on a replay failed: $out"
echo "status on the replay: $out"
echo "$out" | grep -q "3/3 online\|drones [0-9]/3" || fail "status does not show the replayed swarm: $out"
kill -TERM "$PID_replay"; wait_pid "$PID_replay" 10 || fail "replay did not stop"
# 5b. The lockstep run replayed 1000x faster would write the swarm state
#     hundreds of thousands of times a second, a rate at which Fast DDS
#     2.9.1 may crash a joining data-sharing reader: the rate is held, and
#     the replay says so and plays it all (docs/dds.md).
out=$(timeout 120 "$BIN/ddswarm-replay" "$run" --domain "$DOMAIN" --rate 1000 2>&1) || fail "fast replay failed: $out"
echo "fast replay: $out"
echo "$out" | grep -q -- "--rate 1000 held to .*times a second" || fail "a 1000x replay was not held: $out"
echo "$out" | grep -q "[1-9][0-9]* messages published" || fail "the held replay published nothing: $out"
# 6. A replay onto a domain with a live server publishes nothing: the
#    server's swarm would fly the recorded missions.
start sim2 "$BIN/ddswarm-sim" --scenario "$SRC/config/thesis_course.yaml" --drones 3 --domain "$DOMAIN"
timeout 30 "$BIN/ddswarm-gs" --domain "$DOMAIN" status >/dev/null 2>&1 || fail "no live server"
out=$(timeout 30 "$BIN/ddswarm-replay" "$run" --domain "$DOMAIN" 2>&1); rc=$?
echo "replay beside a live server: rc $rc: $out"
[ $rc -ne 0 ] && [ $rc -ne 124 ] || fail "a replay onto a live server's domain ran (rc $rc)"
echo "$out" | grep -q "live server.*domain $DOMAIN.*--domain" || fail "the refusal does not say why: $out"
echo "$out" | grep -q "messages published" && fail "the refused replay published: $out"
echo PASS
