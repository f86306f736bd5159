#!/usr/bin/env bash
# Short-lived ground-station processes against a flying lockstep swarm: how
# often does a departure crash a peer inside Fast DDS 2.9.1?
#
# Each departing participant sends a goodbye, and every peer removes it in its
# discovery thread. If that peer's lease timer for it fires at that moment, the
# timer's callback waits on the discovery mutex, then finds the participant
# already cleared and Debian's build aborts:
#   PDP.cpp:1140: check_remote_participant_liveliness: Assertion
#   `GUID_t::unknown() != remote_participant->m_guid' failed.
# A peer's timer for a participant first fires one lease (the lease that
# participant announces) after discovering it, and about once a lease after
# that. This bench keeps CHURNERS `ddswarm-gs wait-agents` processes coming
# and going, each stopped by SIGTERM after a random LIFE seconds, and counts
# the processes that died by SIGABRT (docs/dds.md, "A participant that leaves
# as its peers check its lease aborts them").
#
# usage: bench/lease_race.sh [--bin DIR] [--time SECS] [--mode lockstep|realtime]
#          [--drones N] [--churners K] [--life "MIN MAX"] [--out DIR]
set -u
SRC="$(cd "$(dirname "$0")/.." && pwd)"
source "$SRC/bench/bench_lib.sh"
bench_swarm_options 300 "$@"
N=32 K=6 LIFE="2.0 4.5"
set -- "${BENCH_REST[@]}"
while [ $# -gt 0 ]; do
  case "$1" in
    --drones) N="$2"; shift 2 ;;
    --churners) K="$2"; shift 2 ;;
    --life) LIFE="$2"; shift 2 ;;
    *) echo "lease_race.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
[ "$SECS" -le 840 ] ||
  { echo "lease_race.sh: --time $SECS: at most 840 (the swarm holds 900 s)" >&2; exit 2; }
read -r LIFE_MIN LIFE_MAX <<<"$LIFE"
DIR="${OUT:-$(mktemp -d /tmp/lease_race.XXXXXX)}"
mkdir -p "$DIR"
scenario="$DIR/scenario.yaml"
bench_scenario "$scenario"
churn_pids=()
cleanup() {
  for p in "${churn_pids[@]}"; do kill -KILL "$p" 2>/dev/null; done
  bench_stop_launch
}
trap cleanup EXIT
trap 'exit 130' INT TERM
# --on-death keep: a swarm process that aborts is counted, and the rest fly on.
bench_hold_swarm "$MODE" "$N" "$DIR" "$scenario" --on-death keep || exit 1

life() {
  awk -v a="$LIFE_MIN" -v b="$LIFE_MAX" -v r="$RANDOM" 'BEGIN { printf "%.2f", a + (b - a) * r / 32767 }'
}
# One slot: ground stations that wait for agents that never come, each
# stopped by SIGTERM; each exit status goes to gs_rc_SLOT (134: SIGABRT).
churner() {
  local slot="$1" end="$2"
  while [ "$(date +%s)" -lt "$end" ]; do
    timeout -s TERM "$(life)" "${GS[@]}" wait-agents --count 100000 --timeout 600 \
      >/dev/null 2>"$DIR/gs_$slot.err"
    echo $? >>"$DIR/gs_rc_$slot"
  done
}
# Sets GONE (ground stations that came and went) and ABORTED (swarm processes
# that died by SIGABRT, as the launcher reports them).
count() {
  GONE=$(cat "$DIR"/gs_rc_* 2>/dev/null | wc -l)
  ABORTED=$(grep -c "killed by SIGABRT" "$DIR/launch.err")
}
end=$(( $(date +%s) + SECS ))
echo "lease_race: $N agents in $MODE hold, $K ground stations at a time" \
  "living $LIFE_MIN-$LIFE_MAX s, for $SECS s"
for k in $(seq "$K"); do churner "$k" "$end" & churn_pids+=($!); done
while left=$(( end - $(date +%s) )); [ "$left" -gt 0 ]; do
  sleep $(( left < 30 ? left : 30 ))
  left=$(( end - $(date +%s) )); [ "$left" -lt 0 ] && left=0
  count
  echo "lease_race: ${left}s left: $GONE ground stations came and went;" \
    "$ABORTED swarm process(es) aborted"
done
wait "${churn_pids[@]}" 2>/dev/null
churn_pids=()
count
gs_abort=$(cat "$DIR"/gs_rc_* | grep -c '^134$')
asserts=$(grep -l "check_remote_participant_liveliness" "$DIR"/*.log 2>/dev/null | wc -l)
echo "ground stations that came and went: $GONE (each one a departure for $((N + 1)) peers)"
echo "swarm processes that died by SIGABRT: $ABORTED (logs with the PDP assertion: $asserts)"
echo "ground stations that died by SIGABRT: $gs_abort"
echo "logs: $DIR"
