#!/usr/bin/env bash
# With beacons through a communication model (latency, loss, noise),
# six agent processes still complete the thesis task in lockstep, and two runs
# with the same seed give the same result.
source "$(dirname "$0")/lib.sh"
run() {  # run TAG SET...: flies the task, leaves the result line in $WORK/TAG.result
  local tag="$1"; shift
  local args=()
  for kv in "$@"; do args+=(--set "$kv"); done
  timeout 300 "$BIN/ddswarm-launch" "$SRC/config/thesis_course.yaml" --mode lockstep --domain "$DOMAIN" \
    --seed 21 --log-dir "$WORK/logs-$tag" "${args[@]}" --set sim.agent_timeout_s=5 \
    --gs "takeoff --wait; task --csv $WORK/comm.csv" >"$WORK/$tag.log" 2>&1
  local rc=$?
  cat "$WORK/$tag.log"
  [ $rc -eq 0 ] || { cp "$WORK"/logs-"$tag"/*.log "$WORK/" 2>/dev/null; fail "$tag: launch exited $rc"; }
  grep "task complete:" "$WORK/$tag.log" | sed 's/(wall [0-9.]* s), //' >"$WORK/$tag.result"
}
run delayed comm.source=beacons comm.latency_s=0.3 comm.loss_probability=0.2 comm.beacon_rate_hz=10 comm.peer_timeout_s=2
grep -q "peers from beacons" "$WORK"/logs-delayed/agent_0.log || fail "agents did not use beacons"
run noisy comm.source=beacons comm.latency_s=0.1 comm.jitter_s=0.1 comm.loss_probability=0.1 comm.position_noise_sigma_m=0.3
run noisy_again comm.source=beacons comm.latency_s=0.1 comm.jitter_s=0.1 comm.loss_probability=0.1 comm.position_noise_sigma_m=0.3
cmp -s "$WORK/noisy.result" "$WORK/noisy_again.result" || fail "same seed, different results: $(cat "$WORK/noisy.result") vs $(cat "$WORK/noisy_again.result")"
echo "300 ms latency, 20 % loss: $(cat "$WORK/delayed.result")"
echo "deterministic with beacons: $(cat "$WORK/noisy.result")"
rows=$(($(wc -l <"$WORK/comm.csv") - 1))
[ "$rows" -eq 3 ] || fail "expected 3 recorded results, got $rows"
echo PASS
