#!/usr/bin/python3
"""The thesis task from Python: launch the swarm, take off, fly the pillar
course north, print the referee's result.

    PYTHONPATH=build/default/python /usr/bin/python3 examples/python/fly_task.py
"""
import argparse
import json

import ddswarm

p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
p.add_argument("--scenario", default=ddswarm.config_path("thesis_course.yaml"))
p.add_argument("--drones", type=int, default=6)
p.add_argument("--mode", default="lockstep", choices=["lockstep", "realtime"])
p.add_argument("--seed", type=int, default=3)
p.add_argument("--speed", type=float, default=0.8, help="m/s toward the goal")
p.add_argument("--d-int", type=float, default=4.0, help="agent.inter_distance_m (m)")
p.add_argument("--json", help="also write the result to this JSON file")
a = p.parse_args()

with ddswarm.launch(a.scenario, drones=a.drones, mode=a.mode, seed=a.seed,
                    set={"agent.inter_distance_m": a.d_int}) as swarm:
    gs = swarm.ground_station()
    print(gs.takeoff(wait=True))
    result = gs.task(speed=a.speed, progress=lambda line: print(" ", line))
    print(result.line)
    print(f"task time {result.task_time_s:.2f} s, collisions {result.collisions}, "
          f"min inter-drone distance {result.min_inter_drone_m:.2f} m")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(result.as_dict(), f, indent=1)
