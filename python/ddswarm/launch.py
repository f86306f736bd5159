"""ddswarm.launch(): a whole swarm (server and one agent process per drone) for a with block."""
import atexit
import json
import os
import re
import shutil
import signal
import subprocess
import tempfile
import time
import weakref

from . import _ddswarm
from ._paths import BIN_DIR, CONFIG_DIR
from .ground_station import GroundStation


def bin_dir():
    """Where ddswarm's programs are: $DDSWARM_BIN, else the build tree's or
    the install prefix's bin/ (baked in at build time)."""
    return os.environ.get("DDSWARM_BIN") or BIN_DIR


def program(name):
    """The path of one of ddswarm's programs (ddswarm-launch, ddswarm-gs, ...)."""
    return os.path.join(bin_dir(), name)


def config_path(name):
    """A file of the source tree's config/ folder, e.g. config_path("thesis_course.yaml")."""
    return os.path.join(CONFIG_DIR, name)


_ERROR = re.compile(r"^ddswarm-[a-z-]+: error: (.*)$")


def error_line(text):
    """The first "ddswarm-X: error: ..." line of a program's output, without
    its "ddswarm-X: error: " prefix; None when there is none."""
    for line in text.splitlines():
        m = _ERROR.match(line.strip())
        if m:
            return m.group(1)
    return None


def _check_file(path):
    path = os.fspath(path)
    if not os.path.exists(path):
        raise FileNotFoundError(f"{path}: cannot open file")
    return path


def yaml_value(v):
    """A Python value as YAML text for a --set override."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float, str)):
        return str(v)
    return json.dumps(v)  # lists and mappings: JSON is YAML's flow style


def set_options(overrides):
    """{"agent.inter_distance_m": 6} -> ["agent.inter_distance_m=6"]."""
    return [f"{k}={yaml_value(v)}" for k, v in (overrides or {}).items()]


def session_pids(sid):
    """The processes of session sid (ddswarm-launch and every process it started)."""
    pids = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as f:
                stat = f.read()
        except OSError:
            continue
        fields = stat[stat.rfind(")") + 2:].split()
        # After the name: state, ppid, pgrp, session.
        if len(fields) > 3 and int(fields[3]) == sid and fields[0] != "Z":
            pids.append(int(entry))
    return pids


def _check_scenario(scenario, drones, mode, seed, original):
    """The scenario as the server and an agent will read it (their --check,
    no DDS): ValueError with their one-line error. A line of the copy with
    set= applied names the user's file instead (its lines are the copy's)."""
    extra = []
    if drones is not None:
        extra += ["--drones", str(drones)]
    for argv in ([program("ddswarm-sim"), "--check", "--scenario", scenario] + extra +
                 (["--mode", mode] if mode else []) + (["--seed", str(seed)] if seed is not None else []),
                 [program("ddswarm-agent"), "--check", "--config", scenario] + extra):
        r = subprocess.run(argv, capture_output=True, text=True, stdin=subprocess.DEVNULL)
        if r.returncode != 0:
            said = r.stdout + r.stderr
            line = error_line(said) or said.strip() or f"{argv[0]} exited with {r.returncode}"
            if scenario != original:
                line = re.sub("^" + re.escape(scenario) + r"(:\d+)*", f"{original} with set=", line)
            raise ValueError(line)


_live = weakref.WeakSet()


@atexit.register
def _stop_every_swarm():
    for s in list(_live):
        s.stop()


class Swarm:
    """A running swarm started by launch(). Use it in a with block, or call stop().

    domain: its DDS domain; scenario: the scenario file every process reads
    (with set= applied); log_dir: each process's log (<name>.log) and the
    launcher's (launch.log); pid: ddswarm-launch's pid, which leads a session
    holding every process of the swarm.
    """

    def __init__(self, pid, domain, scenario, log_dir, own_log_dir, secure, gs):
        self.pid, self.domain, self.scenario, self.log_dir = pid, domain, scenario, log_dir
        self._own_log_dir = own_log_dir
        self._secure = secure
        self._gs = gs
        self._stopped = False
        _live.add(self)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.stop()

    def __repr__(self):
        return f"Swarm(domain {self.domain}, pid {self.pid}{', stopped' if self._stopped else ''})"

    def ground_station(self):
        """The swarm's ground station (one per swarm, already connected to every agent)."""
        if self._stopped:
            raise RuntimeError("this swarm was stopped")
        return self._gs

    def alive(self):
        """Whether ddswarm-launch still runs (it stops everything when a process dies)."""
        return not self._stopped and _running(self.pid)

    def processes(self):
        """The pids of every process of the swarm still running."""
        return session_pids(self.pid)

    def log(self, name="launch"):
        """The text of one process's log (launch, sim, agent 0, ...)."""
        path = os.path.join(self.log_dir, name + ".log")
        try:
            with open(path, errors="replace") as f:
                return f.read()
        except FileNotFoundError:
            return ""

    def stop(self, timeout=10.0):
        """Stops every process of the swarm (SIGTERM to ddswarm-launch, which
        stops the rest in order; SIGKILL to whatever is left after timeout s)."""
        if self._stopped:
            return
        self._stopped = True
        _live.discard(self)
        try:
            self._gs.close()
        finally:
            _stop_session(self.pid, timeout)
            if self._own_log_dir:
                shutil.rmtree(self.log_dir, ignore_errors=True)


_exit_codes = {}  # pid -> exit code (128 + signal), once reaped


def _running(pid):
    if pid in _exit_codes:
        return False
    try:
        got, status = os.waitpid(pid, os.WNOHANG)
    except ChildProcessError:
        return False
    if got == 0:
        return True
    _exit_codes[pid] = os.waitstatus_to_exitcode(status) if os.WIFEXITED(status) else 128 + os.WTERMSIG(status)
    return False


def _stop_session(pid, timeout):
    """SIGTERM to the launcher, then SIGKILL to every process left in its session."""
    interrupted = None
    try:
        if _running(pid):
            os.kill(pid, signal.SIGTERM)
        end = time.monotonic() + timeout
        while _running(pid) and time.monotonic() < end:
            try:
                time.sleep(0.02)
            except KeyboardInterrupt as e:  # a second Ctrl-C: stop at once
                interrupted = e
                break
    finally:
        for _ in range(50):
            left = session_pids(pid)
            if not left:
                break
            for p in left:
                try:
                    os.kill(p, signal.SIGKILL)
                except ProcessLookupError:
                    pass
            time.sleep(0.02)
        _running(pid)  # reaps it
    if interrupted:
        raise interrupted


def _why_it_ended(log_dir):
    """What the launcher and the first process that failed said."""
    said = []
    try:
        with open(os.path.join(log_dir, "launch.log"), errors="replace") as f:
            text = f.read()
    except FileNotFoundError:
        text = ""
    line = error_line(text)
    if line:
        return line, text
    said = [l.replace("ddswarm-launch: ", "") for l in text.splitlines()
            if "exited" in l or "killed" in l]
    for name in sorted(os.listdir(log_dir)):
        if name.endswith(".log") and name != "launch.log":
            with open(os.path.join(log_dir, name), errors="replace") as f:
                e = error_line(f.read())
            if e:
                said.append(f"{name[:-4]}: {e}")
                break
    return "; ".join(said) or "ddswarm-launch ended", text


def launch(scenario, drones=None, mode=None, seed=None, set=None, secure=None, timeout=60.0,
           log_dir=None, domain=None, agent_hosts=None, record=None):
    """Starts a swarm: ddswarm-launch (the server and one agent process per
    drone) on a free DDS domain, and waits up to `timeout` s until every agent
    is online; returns a Swarm, a context manager that stops every process on
    exit, on an exception and on Ctrl-C. The processes die with this Python
    process, however it ends.

    scenario: the scenario file; drones, mode ("lockstep" | "realtime"),
    seed: as ddswarm-launch's options; set: {"key.path": value} overrides,
    as --set; secure: a --secure directory; log_dir: keep the logs there
    (default: a temporary directory, removed at stop); domain: this DDS
    domain (default: the first free one from the scenario's dds.domain_id
    up); agent_hosts: K agent-host processes; record: record the run to
    DIR/run-<time>.mcap.

    Raises FileNotFoundError (no scenario file), ValueError (a bad key or
    value, with the line the CLI prints), TimeoutError (the swarm did not
    come up in time) and RuntimeError (a process died before it was up).
    """
    scenario = _check_file(scenario)
    if mode is not None and mode not in ("lockstep", "realtime"):
        raise ValueError(f"mode = {mode}: must be lockstep or realtime")
    own = log_dir is None
    log_dir = tempfile.mkdtemp(prefix="ddswarm-launch-") if own else os.fspath(log_dir)
    os.makedirs(log_dir, exist_ok=True)
    try:
        return _launch(scenario, drones, mode, seed, set, secure, timeout, log_dir, own, domain,
                       agent_hosts, record)
    except BaseException:
        if own:
            shutil.rmtree(log_dir, ignore_errors=True)
        raise


def _launch(scenario, drones, mode, seed, overrides, secure, timeout, log_dir, own, domain,
            agent_hosts, record):
    original = scenario
    if overrides:
        derived = os.path.join(log_dir, "scenario.yaml")
        _ddswarm.derive_scenario(scenario, set_options(overrides), derived)
        scenario = derived
    _check_scenario(scenario, drones, mode, seed, original)
    # The ground station's sections, and the first domain to try.
    info = _ddswarm.scenario_info(scenario)
    first = info["domain"]
    wanted = drones if drones is not None else info["drones"]
    argv_base = [program("ddswarm-launch"), scenario, "--log-dir", log_dir]
    for opt, v in (("--drones", drones), ("--mode", mode), ("--seed", seed), ("--secure", secure),
                   ("--agent-hosts", agent_hosts), ("--record", record)):
        if v is not None:
            argv_base += [opt, os.fspath(v) if isinstance(v, os.PathLike) else str(v)]
    deadline = time.monotonic() + float(timeout)
    for _attempt in range(8):
        if domain is None:
            d, skipped = _ddswarm.free_domain(first)
            if d < 0:
                raise RuntimeError(f"no free DDS domain from {first} to 232 on this host"
                                   + (f" ({skipped[0]}, ...)" if skipped else ""))
        else:
            d = domain
        with open(os.path.join(log_dir, "launch.log"), "w"):
            pass
        pid = _ddswarm.spawn_session(argv_base + ["--domain", str(d)],
                                     os.path.join(log_dir, "launch.log"))
        gs = None
        try:
            gs = GroundStation(scenario, d, secure, 0, _wait=False)
            left = max(deadline - time.monotonic(), 0.0)
            try:
                gs._gs.wait_agents(wanted, left, True, pid)
                if _running(pid):
                    return Swarm(pid, d, scenario, log_dir, own, secure, gs)
            except TimeoutError as e:
                if _running(pid):
                    raise TimeoutError(f"the swarm did not come up within {timeout:g} s: {e}") from None
            why, text = _why_it_ended(log_dir)
            # Another swarm took the domain between our look and the launcher's claim.
            if domain is None and "claimed on this host" in why:
                first = d + 1
                gs.close()
                _stop_session(pid, 5)
                continue
            if _exit_codes.get(pid) == 2 and error_line(text):
                raise ValueError(why)
            where = "" if own else f" (logs in {log_dir})"
            raise RuntimeError(f"the swarm stopped before it was up: {why}{where}")
        except BaseException:
            if gs is not None:
                gs.close()
            _stop_session(pid, 10)
            raise
    raise RuntimeError(f"no DDS domain could be claimed from {first} up")
