"""Bad input is a Python exception with the CLI's one-line message, fast, never a hang."""
import os
import time

import pytest

import ddswarm

SRC = os.environ["DDSWARM_SRC"]
SCENARIO = os.path.join(SRC, "config", "thesis_course.yaml")


def test_an_unknown_scenario_key_in_set(tmp_path):
    t0 = time.monotonic()
    with pytest.raises(ValueError, match=r"agent\.inter_distanc_m.*unknown") as e:
        ddswarm.launch(SCENARIO, set={"agent.inter_distanc_m": 6}, log_dir=tmp_path)
    assert "\n" not in str(e.value)
    with pytest.raises(ValueError, match=r"agent\.inter_distance_m = -4"):
        ddswarm.launch(SCENARIO, set={"agent.inter_distance_m": -4}, log_dir=tmp_path)
    assert time.monotonic() - t0 < 10
    assert not os.path.exists(tmp_path / "launch.log")  # nothing was started


def test_a_scenario_file_that_does_not_exist(tmp_path):
    with pytest.raises(FileNotFoundError, match="nowhere.yaml: cannot open file"):
        ddswarm.launch(tmp_path / "nowhere.yaml")
    with pytest.raises(FileNotFoundError, match="nowhere.yaml: cannot open file"):
        ddswarm.GroundStation(tmp_path / "nowhere.yaml")
    with pytest.raises(FileNotFoundError, match="nowhere.yaml: cannot open file"):
        ddswarm.experiment(tmp_path / "nowhere.yaml", out=tmp_path)


def test_a_recording_that_is_not_mcap(tmp_path):
    junk = tmp_path / "run.mcap"
    junk.write_text("hello\n")
    with pytest.raises(ValueError, match="magic"):
        ddswarm.Recording(junk)


def test_a_domain_with_no_swarm():
    from ddswarm import _ddswarm
    domain, _ = _ddswarm.free_domain(160)
    t0 = time.monotonic()
    with pytest.raises(TimeoutError,
                       match=f"^no simulation server found on domain {domain} within 1 s: "
                             "no server's participant discovered$"):
        ddswarm.GroundStation(SCENARIO, domain=domain, timeout=1)
    assert time.monotonic() - t0 < 5


def test_bad_launch_options(tmp_path):
    with pytest.raises(ValueError, match="mode = fast"):
        ddswarm.launch(SCENARIO, mode="fast")
    with pytest.raises(ValueError, match="drones"):
        ddswarm.launch(SCENARIO, drones=0, log_dir=tmp_path)


def test_a_bad_experiment(tmp_path):
    exp = tmp_path / "exp.yaml"
    exp.write_text(f"experiment:\n  name: x\n  scenario: {SCENARIO}\n  runs_per_set: 1\n"
                   "  sets:\n    - name: a\n      set: { agent.no_such_key: 1 }\n")
    with pytest.raises(ValueError, match="no_such_key"):
        ddswarm.experiment(exp, out=tmp_path / "out", progress=False)
