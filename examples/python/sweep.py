#!/usr/bin/python3
"""A small sweep: the thesis task at several inter-drone distances D_int
(agent.inter_distance_m), one seeded lockstep run each, and a plot of the
task time against D_int.

    PYTHONPATH=build/default/python /usr/bin/python3 examples/python/sweep.py --out sweep.png
"""
import argparse
import os
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import ddswarm  # noqa: E402

p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
p.add_argument("--scenario", default=ddswarm.config_path("thesis_course.yaml"))
p.add_argument("--d-int", type=float, nargs="+", default=[3.0, 4.5, 6.0], help="m")
p.add_argument("--runs", type=int, default=1, help="seeded runs per value")
p.add_argument("--drones", type=int, default=4)
p.add_argument("--speed", type=float, default=1.2)
p.add_argument("--jobs", type=int, default=2)
p.add_argument("--results", help="the experiment's folder (default: a temporary one)")
p.add_argument("--out", default="sweep.png")
a = p.parse_args()

out = a.results or tempfile.mkdtemp(prefix="ddswarm-sweep-")
os.makedirs(out, exist_ok=True)
exp = os.path.join(out, "sweep.yaml")
with open(exp, "w") as f:
    f.write(f"experiment:\n  name: sweep\n  scenario: {os.path.abspath(a.scenario)}\n"
            f"  runs_per_set: {a.runs}\n  mode: lockstep\n  sets:\n")
    for d in a.d_int:
        f.write(f"    - name: D_int {d:g}\n      set: {{ scenario.drones: {a.drones}, "
                f"agent.inter_distance_m: {d}, task.speed_mps: {a.speed} }}\n")
rows = ddswarm.experiment(exp, jobs=a.jobs, out=out)
if not isinstance(rows, list):  # a pandas DataFrame
    rows = rows.to_dict("records")

ok = [r for r in rows if r["ok"]]
for r in rows:
    print(f"D_int {r['d_int_m']:g} m: " + (f"{r['task_time_s']:.2f} s" if r["ok"]
                                            else f"failed: {r['failure_reason']}"))
fig, ax = plt.subplots(figsize=(5, 3.5))
ax.plot([r["d_int_m"] for r in ok], [r["task_time_s"] for r in ok], "o-")
ax.set_xlabel("D_int, agent.inter_distance_m (m)")
ax.set_ylabel("task time (s, sim)")
ax.set_title(f"{a.drones} drones at {a.speed} m/s, {a.runs} run(s) per value")
ax.grid(alpha=0.3)
fig.tight_layout()
fig.savefig(a.out, dpi=100)
print(f"{len(ok)} of {len(rows)} runs plotted to {a.out}")
