#!/usr/bin/python3
"""Splits an experiment's wall time (ddswarm-gs experiment --out DIR) into
start-up, take-off, task flight and teardown, per run, from the run CSV's
wall_time_s, each run's sim.log timestamps, and the birth time of sim.log
(the launcher creates it as it starts the server, at the start of the run).

Usage: table1_split.py OUT_DIR [TOTAL_WALL_S]
"""
import csv
import datetime as dt
import glob
import os
import re
import statistics
import subprocess
import sys

STAMP = re.compile(r"^\[(\d{4}-\d\d-\d\d \d\d:\d\d:\d\d\.\d+)\]")


def birth(path):
    text = subprocess.run(["stat", "-c", "%w", path], capture_output=True, text=True).stdout.strip()
    if not text or text == "-":
        return None
    day, clock, _tz = text.split()
    return dt.datetime.fromisoformat(f"{day} {clock[:15]}").timestamp()


def stamp(line):
    m = STAMP.match(line)
    return dt.datetime.fromisoformat(m.group(1)).timestamp() if m else None


def slug(s):
    return "".join(c if c.isalnum() else "_" for c in s)


def main():
    out = sys.argv[1]
    total = float(sys.argv[2]) if len(sys.argv) > 2 else None
    rows = []
    for path in glob.glob(os.path.join(out, "*.csv")):
        rows += list(csv.DictReader(open(path)))
    parts = {"start-up": [], "take-off": [], "task flight": [], "teardown": []}
    walls, failed = [], 0
    for r in rows:
        tag = f"{slug(r['set_name'])}-{int(r['run_index']):02d}"
        log = os.path.join(out, "logs", tag, "sim.log")
        wall = float(r["wall_time_s"])
        walls.append(wall)
        if r["ok"] not in ("1", "true", "yes"):
            failed += 1
        if not os.path.exists(log):
            continue
        t0 = birth(log)
        online, task, complete = [], None, None
        for line in open(log, errors="replace"):
            t = stamp(line)
            if t is None:
                continue
            if re.search(r"drone \d+: agent [0-9a-f]+ online", line):
                online.append(t)
            elif "task released" in line and task is None:
                task = t
            elif "task complete" in line and complete is None:
                complete = t
        n = int(r["drones"])
        if t0 is None or len(online) < n or task is None or complete is None:
            continue
        t_online = sorted(online)[n - 1]
        parts["start-up"].append(t_online - t0)
        parts["take-off"].append(task - t_online)
        parts["task flight"].append(complete - task)
        parts["teardown"].append(t0 + wall - complete)
    if not walls:
        print("no runs found in", out)
        return 1
    measured = len(parts["start-up"])
    print(f"| part | mean per run (s) | min (s) | max (s) | total over {len(walls)} runs (s) | share |")
    print("|---|---|---|---|---|---|")
    runs_total = sum(walls)
    for name, v in parts.items():
        if not v:
            continue
        # Scale the measured runs' sum to all runs (runs without a full log are rare).
        tot = sum(v) * len(walls) / len(v)
        print(f"| {name} | {statistics.mean(v):.2f} | {min(v):.2f} | {max(v):.2f} | {tot:.1f} | {100 * tot / runs_total:.0f} % |")
    print(f"| runs (sum of wall_time_s) | {statistics.mean(walls):.2f} | {min(walls):.2f} | {max(walls):.2f} | {runs_total:.1f} | 100 % |")
    if total is not None:
        if runs_total <= total:
            print(f"| between runs (CSV, plots, report) | - | - | - | {total - runs_total:.1f} | - |")
        else:  # --jobs: runs overlapped, so their sum exceeds the wall time
            print(f"| runs overlapped (--jobs): sum of runs / wall time | - | - | - | {runs_total / total:.2f}x | - |")
        m, s = divmod(round(total), 60)
        print(f"experiment wall time: {total:.1f} s ({m}:{s:02d}); {len(walls)} runs, {failed} failed; "
              f"split measured on {measured} runs")
    return 0


if __name__ == "__main__":
    sys.exit(main())
