"""ddswarm.launch and the GroundStation against real processes (lockstep, small swarms)."""
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time

import numpy as np
import pytest

import ddswarm
from ddswarm.launch import session_pids

SCENARIO = os.path.join(os.environ["DDSWARM_SRC"], "config", "thesis_course.yaml")


def gone_within(sid, seconds):
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if not session_pids(sid):
            return True
        time.sleep(0.05)
    return False


def test_fly_look_and_stop():
    with ddswarm.launch(SCENARIO, drones=3, mode="lockstep", seed=3) as swarm:
        gs = swarm.ground_station()
        # One process per drone and the server, all in the launcher's session.
        assert len(swarm.processes()) >= 5
        st = gs.status()
        assert st.live_agents == 3 and st.drones_total == 3 and "lockstep" in st.mode
        # A second ground station attaches to it by its domain, as from another terminal.
        with ddswarm.GroundStation(SCENARIO, domain=swarm.domain) as other:
            assert other.status().live_agents == 3
        # A move before take-off: every drone rejects it, and says why.
        with pytest.raises(ddswarm.CommandError, match="rejected by 0: not airborne") as e:
            gs.move(north=1, time=1)
        assert e.value.rejected == {0: "not airborne", 1: "not airborne", 2: "not airborne"}
        assert gs.takeoff(wait=True).message.startswith("takeoff 3/3 acknowledged")
        s = gs.state()
        assert s.positions.shape == (3, 3) and s.velocities.shape == (3, 3)
        assert s.attitudes.shape == (3, 4) and s.scan_ranges.shape[0] == 3
        assert (s.positions[:, 2] > 1.0).all()  # airborne
        np.testing.assert_allclose(np.linalg.norm(s.attitudes, axis=1), 1, atol=1e-6)
        y0 = s.positions[:, 1].mean()
        gs.move(north=1.0, time=3, wait=True)
        after = gs.state()
        assert after.t >= s.t + 3
        assert after.positions[:, 1].mean() - y0 > 1.5  # flew north
        # Lockstep pauses the clock while the swarm is idle: hold for a time.
        gs.hold(time=60)
        ticks = [x.tick for x in gs.states(hz=20, count=3)]
        assert ticks == sorted(set(ticks))
        assert gs.distance(4.5).message.startswith("distance 3/3 acknowledged")
        # A wait longer than its timeout: TimeoutError, and the swarm carries
        # on. The GIL is free meanwhile: another thread runs.
        stamps, done = [], threading.Event()

        def tick_along():
            while not done.is_set():
                stamps.append(time.monotonic())
                time.sleep(0.005)

        worker = threading.Thread(target=tick_along)
        worker.start()
        t0 = time.monotonic()
        with pytest.raises(TimeoutError, match="did not pass within 0.5 s"):
            gs.hold(time=80000, wait=True, timeout=0.5)
        t1 = time.monotonic()
        done.set()
        worker.join()
        assert t1 - t0 < 3
        assert sum(t0 + 0.05 < t < t1 - 0.05 for t in stamps) >= 5, (t1 - t0, len(stamps))
        assert gs.land(wait=True).ok
        with pytest.raises(ValueError, match="north = 99: must be in"):
            gs.move(north=99, time=1)
        sid = swarm.pid
    assert gone_within(sid, 1), session_pids(sid)


def test_an_exception_stops_every_process():
    with pytest.raises(ZeroDivisionError):
        with ddswarm.launch(SCENARIO, drones=2, mode="lockstep") as swarm:
            sid = swarm.pid
            assert len(swarm.processes()) >= 4
            1 / 0
    assert gone_within(sid, 1), session_pids(sid)


def child(code):
    """A Python process running code, which prints the swarm's pid first."""
    env = dict(os.environ)
    return subprocess.Popen([sys.executable, "-c", textwrap.dedent(code)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env)


def test_ctrl_c_interrupts_a_blocking_call_and_stops_the_swarm():
    p = child(f"""
        import ddswarm
        with ddswarm.launch({SCENARIO!r}, drones=2, mode="lockstep") as swarm:
            gs = swarm.ground_station()
            print(swarm.pid, flush=True)
            gs.takeoff(wait=True)
            print("holding", flush=True)
            gs.hold(time=80000, wait=True)   # most of a day of sim time
        """)
    sid = int(p.stdout.readline())
    assert p.stdout.readline().strip() == "holding"
    time.sleep(0.3)
    t0 = time.monotonic()
    p.send_signal(signal.SIGINT)
    _, err = p.communicate(timeout=15)
    assert time.monotonic() - t0 < 8
    assert "KeyboardInterrupt" in err and p.returncode != 0
    assert gone_within(sid, 1), session_pids(sid)


def test_the_swarm_dies_with_its_python_process():
    p = child(f"""
        import time, ddswarm
        swarm = ddswarm.launch({SCENARIO!r}, drones=2, mode="lockstep")
        print(swarm.pid, flush=True)
        time.sleep(600)
        """)
    sid = int(p.stdout.readline())
    assert len(session_pids(sid)) >= 4
    p.kill()  # SIGKILL: no atexit, no finally
    p.wait()
    assert gone_within(sid, 10), session_pids(sid)
