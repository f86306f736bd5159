#!/usr/bin/env bash
# The server and a scripted plain-DDS commander fly one drone to 2 m
# and hover within 0.1 m, in both time modes; lockstep reruns are identical.
source "$(dirname "$0")/lib.sh"
mode="$1"
run() {  # run TAG: one server + commander; leaves the commander's output in $WORK/TAG.out
  local tag="$1"
  start "sim_$tag" "$BIN/ddswarm-sim" --scenario "$SRC/tests/scenarios/one_drone.yaml" --mode "$mode" --domain "$DOMAIN" --duration 120
  local sim_pid=$!
  "$BIN/scripted_commander" --domain "$DOMAIN" --z 2.0 --hold 5 --tolerance 0.1 --timeout 90 >"$WORK/$tag.log" 2>&1
  local rc=$?
  kill -TERM "$sim_pid"; wait_pid "$sim_pid" 10 || fail "server did not stop on SIGTERM"
  cat "$WORK/$tag.log"
  [ $rc -eq 0 ] || fail "$tag: drone did not hover at 2 m within 0.1 m"
}
run first
if [ "$mode" = lockstep ]; then
  run second
  a=$(grep '^final' "$WORK/first.log"); b=$(grep '^final' "$WORK/second.log")
  [ "$a" = "$b" ] || fail "lockstep reruns differ: '$a' vs '$b'"
  echo "lockstep reruns identical: $a"
fi
echo PASS
