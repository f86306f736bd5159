"""A Python law that raises mid-flight, for testing that a failing law takes
down its own drone only (its traceback goes to the agent's log)."""


class RaisesLater:
    PARAMS = {"after_s": 10.0}

    def __init__(self, params, seed, context):
        self.after_s = params["after_s"]

    def step(self, obs):
        if obs.sim_time_s >= self.after_s:
            return self.divide(obs)
        return obs.mission_velocity

    def divide(self, obs):
        return obs.mission_velocity / 0 if obs.tick < 0 else 1 / 0
