"""The ground station from Python: every ddswarm-gs mission command as a method."""
import math
import os
import time

from . import _ddswarm
from .recording import Table


class CommandError(RuntimeError):
    """A command that some drone rejected or did not acknowledge.

    The message is the line ddswarm-gs prints ("takeoff 5/6 acknowledged; no
    ack from drones 3; rejected by 2: not airborne"); missing lists the
    drones that did not answer, rejected maps each rejecting drone to its reason.
    """

    def __init__(self, message, missing=(), rejected=None):
        super().__init__(message)
        self.missing = list(missing)
        self.rejected = dict(rejected or {})


class TaskFailed(RuntimeError):
    """The referee ended the task without success (or the server was lost);
    result is the TaskResult, with its reason."""

    def __init__(self, result):
        super().__init__(result.line)
        self.result = result


class Ack:
    """Every addressed drone accepted a command: message is ddswarm-gs's line."""

    def __init__(self, d):
        self.ok = d["ok"]
        self.message = d["message"]

    def __repr__(self):
        return f"Ack({self.message!r})"

    def __str__(self):
        return self.message


class TaskResult:
    """The referee's result of a task: task_time_s (sim s; NaN when failed),
    wall_time_s, drones, speed_mps, epsilon_m, collisions_obstacle,
    collisions_drone, collisions_ground, collisions (their sum),
    min_inter_drone_m, min_clearance_m, the swarm metrics (order_mean,
    order_min, speed_mean_mps, near_misses, components_max, lambda2_min),
    seed, scenario, lost_drones, ok, reason, and line (ddswarm-gs's line)."""

    def __init__(self, d):
        self.__dict__.update(d)
        self.collisions = self.collisions_obstacle + self.collisions_drone + self.collisions_ground

    def as_dict(self):
        return dict(self.__dict__)

    def __repr__(self):
        return f"TaskResult({self.line!r})"


def _ack(d):
    if not d["ok"]:
        raise CommandError(d["message"], d["missing"], dict(d["rejected"]))
    return Ack(d)


class GroundStation:
    """ddswarm-gs's DDS commander: attaches to the swarm on `domain` (default:
    the scenario's dds.domain_id) that `config` (the scenario file, for its
    ground_station, task and dds sections; None = the defaults) describes.

    Waits up to `timeout` s (default ground_station.discovery_timeout_s) for
    the server: TimeoutError "no simulation server found on domain N within
    T s: what was found" (as ddswarm-gs says it); without a `timeout`, a server
    coming up (discovered, not yet heard) is waited for up to 120 s more. `secure` is a --secure directory (scripts/make-certs).
    Every blocking call releases the GIL, takes a timeout (TimeoutError) and
    ends at Ctrl-C (KeyboardInterrupt).
    """

    def __init__(self, config=None, domain=None, secure=None, timeout=None, _wait=True):
        self.config = os.fspath(config) if config is not None else None
        self._gs = _ddswarm.GroundStation(self.config or "", domain,
                                          os.fspath(secure) if secure else "", timeout, _wait)

    @property
    def domain(self):
        """The DDS domain it is on."""
        return self._gs.domain

    def close(self):
        """Leaves DDS (also on exit of a with block, and when collected)."""
        self._gs.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def wait_agents(self, count=None, timeout=30.0):
        """Until the server and `count` agents (default: every drone of the
        server's scenario) are online and this station's connections to them
        are up. TimeoutError with ddswarm-gs wait-agents's line."""
        self._gs.wait_agents(-1 if count is None else int(count), float(timeout))

    def takeoff(self, altitude=0.0, wait=False, timeout=None):
        """Take off and hold at `altitude` m (0: the agents' default). With
        wait, until every drone has reached it (timeout default 120 s)."""
        return _ack(self._gs.takeoff(float(altitude), bool(wait), timeout))

    def move(self, north=0.0, east=0.0, up=0.0, time=0.0, wait=False, timeout=None):
        """Fly the swarm at (north, east, up) m/s for `time` s, then hold. With
        wait, until that much sim time has passed (timeout default 100 time + 60 s)."""
        return _ack(self._gs.move(float(north), float(east), float(up), float(time), bool(wait),
                                  timeout))

    def distance(self, metres, timeout=None):
        """Change the wanted inter-drone distance D_int (m, in [0.31, 1000])."""
        return _ack(self._gs.distance(float(metres), timeout))

    set_distance = distance

    def land(self, wait=False, timeout=None):
        """Land every drone; with wait, until all are on the ground (timeout default 120 s)."""
        return _ack(self._gs.land(bool(wait), timeout))

    def hold(self, time=0.0, wait=False, timeout=None):
        """Stop mission motion and swarm in place (for `time` sim s; with wait, until it passed)."""
        return _ack(self._gs.hold(float(time), bool(wait), timeout))

    def follow(self, leader, timeout=None):
        """Drone `leader` flies by teleop(); the others swarm around it."""
        return _ack(self._gs.follow(int(leader), timeout))

    def teleop(self, north=0.0, east=0.0, up=0.0, timeout=None):
        """The leader's velocity (m/s) while following."""
        return _ack(self._gs.teleop(float(north), float(east), float(up), timeout))

    def task(self, speed=None, epsilon=None, wait=True, takeoff=False, timeout=None,
             progress=None):
        """Run the thesis task at `speed` m/s (default task.speed_mps) with
        swarm condition `epsilon` m (default 2 D_int + 1); blocks until the
        referee's result and returns a TaskResult (wait=False: returns the
        Ack once accepted). takeoff=True first waits for every agent and takes
        off, as `ddswarm-gs task --takeoff`. progress(line) gets ddswarm-gs's
        progress lines. Raises CommandError (rejected / unacknowledged),
        TaskFailed (the task failed; .result), TimeoutError (no result within
        timeout s, default ground_station.task_timeout_s)."""
        if takeoff:
            self.wait_agents()
            self.takeoff(wait=True)
        d = self._gs.task(speed, epsilon, bool(wait), timeout, progress)
        ack = _ack(d["command"])
        if not wait:
            return ack
        result = TaskResult(d["outcome"])
        if not result.ok:
            if result.reason.startswith("no result within"):
                raise TimeoutError(result.reason)
            raise TaskFailed(result)
        return result

    def status(self, timeout=None):
        """The server's status as a Table: sim_time_s, real_time_factor,
        live_agents (the server's count; -1: no server heard), drones_online,
        drones_total, airborne, failsafe, collisions, mode, phases, d_int_m,
        rejected ({reason: count}), commands_applied, commands_late,
        lockstep_resends, task, laws, law_faults. Waits up to timeout s
        (default 10) for the server's first status."""
        return Table(self._gs.status(10.0 if timeout is None else float(timeout)))

    def state(self, timeout=5.0):
        """The latest swarm state as a Table of numpy arrays (N drones,
        by drone id): t (sim s), tick, ids, positions (N, 3; m, world ENU),
        velocities (N, 3; m/s), attitudes (N, 4; w x y z), flags, phases
        (N,) and phase_names, scan_ranges, scan_angles and scan_elevations
        (N, rays; m, rad body yaw, rad up from the body x-y plane; ray k is
        row k // columns, column k % columns; NaN where a drone has fewer
        rays). TimeoutError when none arrives within timeout s."""
        return Table(self._gs.state(float(timeout)))

    def states(self, hz=None, timeout=5.0, count=None):
        """Iterates over swarm states: every new one (hz None), or the latest
        at most hz times a wall second; count bounds how many. A state is
        never given twice; TimeoutError when none newer comes within timeout s.
        In lockstep the server pauses its clock while every drone is idle
        (on the ground, or holding with no time left): no new state comes
        until a command with an end (hold(time=...), move, task)."""
        period = 0.0 if hz is None else 1.0 / float(hz)
        if period < 0 or math.isnan(period):
            raise ValueError(f"hz = {hz}: must be > 0")
        tick, n = -1, 0
        while count is None or n < count:
            start = time.monotonic()
            s = Table(self._gs.state(float(timeout), tick))
            tick = s["tick"]
            n += 1
            yield s
            left = period - (time.monotonic() - start)
            if left > 0:
                time.sleep(left)
