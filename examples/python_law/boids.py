"""A swarm law in Python: Reynolds-style boids in a few lines of numpy.

Fly it (docs/laws.md, "A law in Python"):

  ddswarm-launch config/thesis_course.yaml --mode lockstep \
    --set agent.law.type=python --set agent.law.module=examples/python_law/boids.py \
    --set agent.law.class=Boids --gs 'takeoff --wait; task'

The framework adds the thesis's obstacle term, holds the altitude and limits
the speed; this law answers C + V_mission: separation from close peers,
cohesion toward the peers' centroid, on top of the mission velocity.
"""
import numpy as np


class Boids:
    # Every parameter with its default; agent.law.params may set them, and
    # any other name is refused with the scenario's file and line.
    PARAMS = {"separation_gain": 1.0, "cohesion_gain": 0.15, "radius_m": 10.0}

    def __init__(self, params, seed, context):
        if params["radius_m"] <= 0:
            raise ValueError(f"radius_m must be > 0, not {params['radius_m']}")
        self.p = params
        self.rng = np.random.default_rng(seed)  # the framework's seed: lockstep stays bit-identical

    def step(self, obs):
        v = obs.mission_velocity.copy()
        if len(obs.peers_id) == 0:
            return v
        d = obs.peers_p - obs.p                 # N×3, m, to each peer
        dist = np.linalg.norm(d, axis=1)
        near = (dist > 1e-6) & (dist < self.p["radius_m"])
        if not near.any():
            return v
        d, dist = d[near], dist[near]
        close = dist < obs.inter_distance_m
        if close.any():                         # push away, stronger the closer
            push = (obs.inter_distance_m / dist[close] - 1.0)[:, None] * d[close] / dist[close][:, None]
            v -= self.p["separation_gain"] * push.sum(axis=0)
        v += self.p["cohesion_gain"] * d.mean(axis=0)
        return v
