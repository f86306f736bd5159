#!/usr/bin/env bash
# A short experiment (2 sets x 2 runs, real multi-process lockstep
# runs) produces a CSV, a Markdown table and plot files with the right counts.
# When it runs two at a time (--jobs 2, each on its own domain), or with each
# run's agents in two agent-host processes (--agent-hosts 2), it gives the very
# same results, and it says where the wall time went. Every run's server
# stops cleanly, and no process outlives the experiment. A swarm launched on
# the experiment's domain keeps it (common/domain_claim.hpp).
source "$(dirname "$0")/lib.sh"
out="$WORK/results"
out2="$WORK/results2"
timeout "$(slow 400)" "$BIN/ddswarm-gs" --domain "$DOMAIN" experiment "$SRC/tests/scenarios/short_experiment.yaml" --out "$out" \
  >"$WORK/experiment.log" 2>&1
rc=$?
cat "$WORK/experiment.log"
[ $rc -eq 0 ] || fail "experiment exited $rc"
grep -q "run 4 of 4" "$WORK/experiment.log" || fail "no progress line for run 4 of 4"
grep -q "ETA" "$WORK/experiment.log" || fail "no ETA in the progress lines"
rows=$(($(wc -l <"$out/short.csv") - 1))
[ "$rows" -eq 4 ] || fail "CSV has $rows rows, expected 4"
grep -q "| Slow | Fast |" "$out/short.md" || grep -q "Slow.*Fast" "$out/short.md" || fail "table lacks the two set columns"
grep -q "Avg. task time" "$out/short.md" || fail "table lacks Table 1's task-time row"
pngs=$(ls "$out"/plots/*.png 2>/dev/null | wc -l)
svgs=$(ls "$out"/plots/*.svg 2>/dev/null | wc -l)
[ "$pngs" -ge 3 ] && [ "$svgs" -ge 3 ] || fail "expected a PNG and an SVG per set plus the summary, found $pngs PNG, $svgs SVG"
[ -s "$out/plots/summary.png" ] || fail "no summary plot"
ls "$out"/runs/*.yaml | wc -l | grep -qx 4 || fail "expected 4 per-run scenarios"
grep -Eq "wall time per run .*start-up .*flight .*teardown" "$WORK/experiment.log" || fail "no wall-time split"
stopped=$(grep -l "ddswarm-sim: stopped at tick" "$out"/logs/*/sim.log | wc -l)
[ "$stopped" -eq 4 ] || fail "only $stopped of 4 servers logged a clean stop"
left=$(pgrep -f -- "$out/runs/" | wc -l)
[ "$left" -eq 0 ] || fail "$left processes of the experiment still run after it: $(pgrep -af -- "$out/runs/")"
timeout "$(slow 400)" "$BIN/ddswarm-gs" --domain "$DOMAIN" experiment "$SRC/tests/scenarios/short_experiment.yaml" --out "$out2" \
  --jobs 2 >"$WORK/experiment2.log" 2>&1 || { cat "$WORK/experiment2.log"; fail "experiment --jobs 2 failed"; }
tail -3 "$WORK/experiment2.log"
results() { awk -F, 'NR > 1 { print $1, $2, $3, $9, $11, $13, $14, $15, $16 }' "$1" | sort; }
diff <(results "$out/short.csv") <(results "$out2/short.csv") || fail "two at a time gave other results"
# A swarm already on the domain (a launch, idle on the ground) is not the
# experiment's: the experiment passes over its domain, saying whose it is,
# and the swarm is left as it was. A second launch on it refuses, naming it.
start idle "$BIN/ddswarm-launch" "$SRC/config/thesis_course.yaml" --drones 2 --mode lockstep --domain "$DOMAIN" \
  --log-dir "$WORK/idle"
timeout 60 "$BIN/ddswarm-gs" --domain "$DOMAIN" wait-agents --count 2 >/dev/null 2>&1 || fail "the idle swarm never came up"
# The drones' agents in two agent-host processes: the very same results too.
# --set reaches every set's runs (a failsafe delay no run needs: results stay).
out3="$WORK/results3"
timeout "$(slow 400)" "$BIN/ddswarm-gs" --domain "$DOMAIN" experiment "$SRC/tests/scenarios/short_experiment.yaml" --out "$out3" \
  --agent-hosts 2 --set sim.failsafe_land_after_s=7 >"$WORK/experiment3.log" 2>&1 ||
  { cat "$WORK/experiment3.log"; fail "experiment --agent-hosts 2 failed"; }
tail -3 "$WORK/experiment3.log"
grep -q "not on domain $DOMAIN: pid $PID_idle: .*ddswarm-launch" "$WORK/experiment3.log" ||
  { head -5 "$WORK/experiment3.log"; fail "the experiment did not pass over the launched swarm's domain $DOMAIN"; }
grep -q "runs on DDS domain $DOMAIN\$" "$WORK/experiment3.log" && fail "the experiment ran on the launched swarm's domain"
timeout 30 "$BIN/ddswarm-gs" --domain "$DOMAIN" status >"$WORK/idle_status.log" 2>&1 || fail "no status from the idle swarm"
grep -q "drones 2/2 online | 0 airborne" "$WORK/idle_status.log" ||
  { cat "$WORK/idle_status.log"; fail "the idle swarm was disturbed by the experiment"; }
grep -q "sim 0.0 s" "$WORK/idle_status.log" || { cat "$WORK/idle_status.log"; fail "the idle swarm's clock moved"; }
timeout 30 "$BIN/ddswarm-launch" "$SRC/config/thesis_course.yaml" --drones 2 --domain "$DOMAIN" --duration 5 \
  --log-dir "$WORK/second" >"$WORK/second.log" 2>&1
rc=$?
[ $rc -eq 2 ] || { cat "$WORK/second.log"; fail "a second launch on the claimed domain exited $rc, expected 2"; }
grep -q "error: --domain = $DOMAIN: claimed on this host by pid $PID_idle: " "$WORK/second.log" ||
  { cat "$WORK/second.log"; fail "the second launch did not name the first"; }
kill -TERM "$PID_idle"
wait_pid "$PID_idle" 30 >/dev/null || fail "the idle launch did not stop"
ls "$out3"/logs/*/ | grep -q "agent_host_1" || fail "no agent-host logs: were the agents one process per drone?"
diff <(results "$out/short.csv") <(results "$out3/short.csv") || fail "agent hosts gave other results"
[ "$(grep -l "failsafe_land_after_s: 7" "$out3"/runs/*.yaml | wc -l)" -eq 4 ] || fail "--set did not reach all 4 runs"
[ "$(grep -c "sim.failsafe_land_after_s=7" "$out3/short.csv")" -eq 4 ] || fail "the CSV does not record --set"
# compare: the same experiment run two ways is the same, set by set, and plotted.
"$BIN/ddswarm-gs" compare "$out/short.csv" "$out3/short.csv" --labels "one process per drone,agent hosts" \
  --plot "$WORK/compare" --fail-if-different >"$WORK/compare.md" 2>&1 ||
  { cat "$WORK/compare.md"; fail "compare found a difference, or failed"; }
cat "$WORK/compare.md"
[ "$(grep -cE "^\| (Slow|Fast) \|.*\| same \| 0.00 \(0.00\) s, 2 runs \|" "$WORK/compare.md")" -eq 2 ] ||
  fail "compare did not call both sets the same with 2 identical same-seed runs"
[ -s "$WORK/compare/compare.png" ] || fail "compare wrote no plot"
echo PASS
