#!/usr/bin/env bash
# The recorder under SIGTERM and a disk that fills mid-run.
# SIGTERM finalizes like SIGINT: every sample received is in the file.
# A full disk (a 2 MB tmpfs this test mounts) stops the recording with one
# clear error naming the file and the counts, exit non-zero, and the file
# still reads up to its last complete chunk.
source "$(dirname "$0")/lib.sh"
mnt="$WORK/small"
cleanup_mount() { mountpoint -q "$mnt" 2>/dev/null && umount "$mnt"; }
trap 'rc=$?; cleanup_mount; (exit $rc); cleanup' EXIT

# 1. SIGTERM: exact counts, summary written.
start rec1 "$BIN/ddswarm-record" -o "$WORK/a.mcap" --domain "$DOMAIN" --topics ddswarm/collision,ddswarm/swarm_state
sleep 1
"$BIN/count_publisher" --domain "$DOMAIN" --count 500 || fail "publisher"
kill -TERM "$PID_rec1"; wait_pid "$PID_rec1" 15 || fail "recorder did not finish on SIGTERM"
"$BIN/ddswarm-record" info "$WORK/a.mcap" | tee "$WORK/a.info"
grep -q "(summary)" "$WORK/a.info" || fail "SIGTERM did not finalize the summary"
grep -Eq "ddswarm/swarm_state +500 messages" "$WORK/a.info" || fail "samples lost on SIGTERM"
grep -Eq "ddswarm/collision +500 messages" "$WORK/a.info" || fail "samples lost on SIGTERM"

# 2. The disk fills while recording a live swarm.
mkdir -p "$mnt"
if ! mount -t tmpfs -o size=2m tmpfs "$mnt" 2>/dev/null; then
  echo "SKIP: cannot mount a tmpfs here (needs root)"; exit 77
fi
start sim "$BIN/ddswarm-sim" --scenario "$SRC/config/thesis_course.yaml" --domain "$DOMAIN" --drones 64 --mode realtime
start rec2 "$BIN/ddswarm-record" -o "$mnt/full.mcap" --domain "$DOMAIN" --compression none --chunk-kb 64
wait_pid "$PID_rec2" 90; rc=$?
cat "$WORK/rec2.log"
[ $rc -ne 0 ] && [ $rc -ne 124 ] || fail "the recorder should fail with a non-zero exit when the disk is full (rc $rc)"
grep -q "$mnt/full.mcap" "$WORK/rec2.log" || fail "the error does not name the file"
grep -q "No space left on device" "$WORK/rec2.log" || fail "the error does not say the disk is full"
grep -Eq "recording stopped: [0-9]+ messages were handed to the file, [0-9]+ more received were not written" "$WORK/rec2.log" \
  || fail "the error does not give the counts"
[ "$(grep -c "error" "$WORK/rec2.log")" -eq 1 ] || fail "expected one error line"
"$BIN/ddswarm-record" info "$mnt/full.mcap" | tee "$WORK/full.info" || fail "the file is unreadable after the disk filled"
n=$(awk 'NR == 1 { print $2 }' "$WORK/full.info")
[ "${n:-0}" -gt 100 ] || fail "only ${n:-0} messages readable"
echo PASS
