"""The Python examples (examples/python/), run as a user would, small and lockstep."""
import json
import os
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.image  # noqa: E402
import numpy as np  # noqa: E402

EXAMPLES = os.path.join(os.environ["DDSWARM_SRC"], "examples", "python")


def run(name, *args, cwd):
    r = subprocess.run([sys.executable, os.path.join(EXAMPLES, name), *args], cwd=cwd,
                       capture_output=True, text=True, timeout=120)
    print(r.stdout, r.stderr)
    assert r.returncode == 0, r.stderr
    return r.stdout


def assert_a_real_plot(png):
    """A PNG of some size that is not one flat colour: lines and patches were drawn."""
    assert os.path.getsize(png) > 10_000
    img = matplotlib.image.imread(png)
    assert img.shape[0] >= 300 and img.shape[1] >= 300
    colours = np.unique((img[..., :3] * 255).astype(np.uint8).reshape(-1, 3), axis=0)
    assert len(colours) > 50
    white = (img[..., :3] > 0.98).all(axis=-1).mean()
    assert white < 0.97  # more than a blank canvas


def test_fly_task(tmp_path):
    out = run("fly_task.py", "--json", "result.json", cwd=tmp_path)
    assert "takeoff 6/6 acknowledged" in out
    r = json.load(open(tmp_path / "result.json"))
    # The thesis's Sim 1 (82.6 s +- 2.75 s), with no collision.
    assert r["ok"] and r["drones"] == 6
    assert 70 < r["task_time_s"] < 95
    assert r["collisions_obstacle"] + r["collisions_drone"] == 0
    assert r["min_inter_drone_m"] > 0.5
    assert "task complete" in out


def test_plot_trajectories(tmp_path):
    out = run("plot_trajectories.py", "--drones", "4", "--speed", "1.2", "--out", "traj.png",
              "--record-dir", "rec", cwd=tmp_path)
    assert "task complete" in out
    assert "of 4 drones plotted to traj.png" in out
    assert_a_real_plot(tmp_path / "traj.png")


def test_sweep(tmp_path):
    out = run("sweep.py", "--d-int", "3", "6", "--drones", "3", "--out", "sweep.png",
              "--results", "res", cwd=tmp_path)
    assert "2 of 2 runs plotted to sweep.png" in out
    assert "D_int 3 m: " in out and "D_int 6 m: " in out
    assert_a_real_plot(tmp_path / "sweep.png")
