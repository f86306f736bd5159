"""ddswarm.Recording against a recording of known content (recording_fixture)."""
import os
import subprocess

import numpy as np
import pytest

import ddswarm

BIN = os.environ["DDSWARM_BIN"]


def fixture(path, *args):
    out = subprocess.run([os.path.join(BIN, "py_recording_fixture"), str(path), *args],
                         check=True, capture_output=True, text=True).stdout
    return int(out.strip().split("=")[1])


def test_topics_and_counts(tmp_path):
    f = tmp_path / "run.mcap"
    assert fixture(f) == 300
    rec = ddswarm.Recording(f)
    assert rec.topics == {"ddswarm/swarm_state": 300, "ddswarm/status": 30, "ddswarm/task": 1}
    assert not rec.truncated
    assert rec.types["ddswarm/status"].endswith("SimStatus")


def test_swarm_state_as_arrays(tmp_path):
    f = tmp_path / "run.mcap"
    fixture(f, "--drones", "4")
    s = ddswarm.Recording(f).swarm_state()
    assert len(s) == 300
    assert s.positions.shape == (300, 4, 3)
    assert s.attitudes.shape == (300, 4, 4)
    np.testing.assert_array_equal(s.tick, np.arange(300))
    np.testing.assert_allclose(s.t, 0.02 * np.arange(300))
    # Drone k at (k, 0.01 tick, 2).
    np.testing.assert_allclose(s.positions[150, :, 0], [0, 1, 2, 3])
    np.testing.assert_allclose(s.positions[:, 2, 1], 0.01 * np.arange(300))
    np.testing.assert_allclose(s.velocities[..., 1][20:], 0.5)
    # Drone 3 joins at tick 10: padded before.
    assert np.isnan(s.positions[:10, 3]).all() and not np.isnan(s.positions[10:, 3]).any()
    np.testing.assert_allclose(s.attitudes[50, 0], [1, 0, 0, 0])
    # Scans: (T, N, rays), range 1 + k + 0.1 ray.
    assert s.scan_ranges.shape == (300, 4, 8)
    np.testing.assert_allclose(s.scan_ranges[200, 1], 2 + 0.1 * np.arange(8), rtol=1e-6)
    assert s["scans.hit"][200, 0].tolist() == [0, 1, 0, 1, 0, 1, 0, 1]
    assert np.all(np.diff(s.log_time_s) > 0)
    assert s.undecodable == 0
    # The ring: every ray level, at its body yaw.
    assert s.scan_elevations.shape == (300, 4, 8) and (s.scan_elevations[200] == 0).all()
    np.testing.assert_allclose(s.scan_angles[200, 0], 0.785398 * np.arange(8), rtol=1e-6)


def test_a_recording_from_before_scan_elevations_reads_as_a_level_ring(tmp_path):
    f = tmp_path / "old.mcap"
    fixture(f, "--ring64")
    s = ddswarm.Recording(f).swarm_state()
    assert s.undecodable == 0 and len(s) == 300
    np.testing.assert_allclose(s.scan_ranges[200, 1], 2 + 0.1 * np.arange(8), rtol=1e-6)
    assert (s.scan_elevations[200] == 0).all()


def test_other_topics(tmp_path):
    f = tmp_path / "run.mcap"
    fixture(f)
    rec = ddswarm.Recording(f)
    st = rec.status()
    np.testing.assert_array_equal(st.tick, np.arange(0, 300, 10))
    assert st.state == ["running"] * 30
    assert st.live_agents.shape == (30, 4)
    task = rec.task()
    assert task.elapsed_s.tolist() == [81.06]
    assert task.reason == ["complete"]


def test_a_crashed_recording_reads_up_to_its_last_complete_chunk(tmp_path):
    f = tmp_path / "crashed.mcap"
    durable = fixture(f, "--crash-after-chunks", "3", "--ticks", "3000")
    rec = ddswarm.Recording(f)
    assert rec.truncated
    assert "truncated" in rec.how_read
    s = rec.swarm_state()
    assert len(s) == durable > 0
    np.testing.assert_array_equal(s.tick, np.arange(durable))


def test_bad_input_is_a_python_exception(tmp_path):
    with pytest.raises(FileNotFoundError, match="no such file"):
        ddswarm.Recording(tmp_path / "missing.mcap")
    junk = tmp_path / "junk.mcap"
    junk.write_bytes(b"this is not an MCAP file at all")
    with pytest.raises(ValueError, match="magic"):
        ddswarm.Recording(junk)
    f = tmp_path / "run.mcap"
    fixture(f)
    with pytest.raises(KeyError, match="no topic 'ddswarm/scene'"):
        ddswarm.Recording(f).topic("ddswarm/scene")
