"""MCAP recordings (ddswarm-record's) as numpy arrays."""
import os

from . import _ddswarm


class Table(dict):
    """One topic's samples: {field: array}, samples first; fields also as attributes.

    A field inside a sequence of structs is (samples, N, ...): drones.position
    of the swarm state is (T, N, 3). Shorter sequences are padded with NaN
    (0 or False for 64-bit integers and booleans). log_time_s is each
    sample's recording time, from the first message of the file.
    """

    def __getattr__(self, name):
        try:
            return self[name]
        except KeyError:
            raise AttributeError(name) from None

    def __len__(self):
        """Samples of a recorded topic; fields of a live one (GroundStation.state)."""
        if "log_time_s" not in self:
            return super().__len__()
        return len(self["log_time_s"])


class Recording:
    """A recording: its topics and counts, and any topic decoded into arrays.

    A recording a crashed recorder left behind reads up to its last complete
    chunk (truncated is then True), as ddswarm-record info does.
    Raises FileNotFoundError for a missing file and ValueError for a file that
    is not MCAP, naming the reason.
    """

    def __init__(self, path):
        self.path = os.fspath(path)
        info = _ddswarm.recording_info(self.path)
        self.topics = {t: v["count"] for t, v in info["topics"].items()}
        self.types = {t: v["type"] for t, v in info["topics"].items()}
        self.how_read = info["how_read"]
        self.truncated = info["truncated"]
        self.duration_s = (info["end_ns"] - info["start_ns"]) * 1e-9

    def __repr__(self):
        return f"Recording({self.path!r}: {sum(self.topics.values())} messages, {len(self.topics)} topics)"

    def topic(self, name):
        """Every sample of topic `name` (e.g. "ddswarm/status") as a Table."""
        return Table(_ddswarm.read_topic(self.path, name))

    def swarm_state(self):
        """The swarm state (ddswarm/swarm_state), with short names added:
        t (sim time, s), tick, positions and velocities (T, N, 3, m and m/s,
        world ENU), attitudes (T, N, 4, w x y z), flags and phases (T, N),
        scan_ranges (T, N, rays, m), scan_angles and scan_elevations (T, N,
        rays; rad body yaw, rad up from the body x-y plane; 0 in recordings
        made before scans carried elevations)."""
        s = self.topic("ddswarm/swarm_state")
        for short, field in (("t", "sim_time_s"), ("positions", "drones.position"),
                             ("velocities", "drones.velocity"), ("attitudes", "drones.orientation"),
                             ("flags", "drones.flags"), ("phases", "drones.phase"),
                             ("scan_ranges", "scans.range_m"),
                             ("scan_angles", "scans.angle_body_rad"),
                             ("scan_elevations", "scans.elevation_body_rad")):
            if field in s:
                s[short] = s[field]
        return s

    def status(self):
        """The server's status (ddswarm/status)."""
        return self.topic("ddswarm/status")

    def task(self):
        """The referee's task status (ddswarm/task)."""
        return self.topic("ddswarm/task")
