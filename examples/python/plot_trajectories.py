#!/usr/bin/python3
"""Record a run of the thesis task, then plot every drone's trajectory over
the course's pillars (matplotlib, to a PNG).

    PYTHONPATH=build/default/python /usr/bin/python3 examples/python/plot_trajectories.py --out traj.png
"""
import argparse
import glob
import os
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import ddswarm  # noqa: E402

p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
p.add_argument("--scenario", default=ddswarm.config_path("thesis_course.yaml"))
p.add_argument("--drones", type=int, default=6)
p.add_argument("--seed", type=int, default=3)
p.add_argument("--speed", type=float, default=0.8)
p.add_argument("--record-dir", help="keep the recording here (default: a temporary folder)")
p.add_argument("--out", default="trajectories.png")
a = p.parse_args()

record_dir = a.record_dir or tempfile.mkdtemp(prefix="ddswarm-rec-")
with ddswarm.launch(a.scenario, drones=a.drones, mode="lockstep", seed=a.seed,
                    record=record_dir) as swarm:
    gs = swarm.ground_station()
    gs.takeoff(wait=True)
    result = gs.task(speed=a.speed)
    print(result.line)
# The recorder finalizes its file as the swarm stops.
path = max(glob.glob(os.path.join(record_dir, "*.mcap")), key=os.path.getmtime)
rec = ddswarm.Recording(path)
print(rec)
s = rec.swarm_state()
scene = rec.topic("ddswarm/scene")

fig, ax = plt.subplots(figsize=(6, 9))
for x, y, r in zip(scene["cylinders.x"][-1], scene["cylinders.y"][-1],
                   scene["cylinders.radius_m"][-1]):
    if np.isfinite(r):
        ax.add_patch(plt.Circle((x, y), r, color="0.55"))
for k in range(s.positions.shape[1]):
    xy = s.positions[:, k, :2]
    ax.plot(xy[:, 0], xy[:, 1], lw=1.2, label=f"drone {k}")
fa, fb = scene["finish_a"][-1], scene["finish_b"][-1]
ax.plot([fa[0], fb[0]], [fa[1], fb[1]], "k--", lw=1, label="finish")
ax.set_aspect("equal")
ax.set_xlabel("east (m)")
ax.set_ylabel("north (m)")
ax.set_title(f"{a.drones} drones at {a.speed} m/s: {result.task_time_s:.1f} s, "
             f"{result.collisions} collisions")
ax.legend(loc="lower right", fontsize=7)
fig.tight_layout()
fig.savefig(a.out, dpi=100)
print(f"{len(s)} states of {s.positions.shape[1]} drones plotted to {a.out}")
