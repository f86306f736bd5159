#!/usr/bin/python3
"""How long ddswarm.Recording takes to read a swarm state into arrays.

Usage: PYTHONPATH=build/default/python bench/python_recording.py [BIN_DIR]
Writes recordings of known content (py_recording_fixture) and prints, per
size, the samples, drones, seconds and samples per second.
"""
import os
import subprocess
import sys
import tempfile
import time

import ddswarm

BIN = sys.argv[1] if len(sys.argv) > 1 else "build/default/bin"
print("| samples | drones | read (s) | samples/s |")
print("|---|---|---|---|")
with tempfile.TemporaryDirectory() as d:
    for ticks, drones in ((4000, 6), (3000, 64), (500, 512)):
        f = os.path.join(d, f"{ticks}x{drones}.mcap")
        subprocess.run([os.path.join(BIN, "py_recording_fixture"), f, "--ticks", str(ticks),
                        "--drones", str(drones)], check=True, capture_output=True)
        t = time.perf_counter()
        s = ddswarm.Recording(f).swarm_state()
        dt = time.perf_counter() - t
        assert s.positions.shape == (ticks, drones, 3)
        print(f"| {ticks} | {drones} | {dt:.3f} | {ticks / dt:,.0f} |")
