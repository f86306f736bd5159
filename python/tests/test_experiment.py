"""ddswarm.experiment: an experiment file run by ddswarm-gs, its rows as the CSV's."""
import csv
import math
import os

import ddswarm

SRC = os.environ["DDSWARM_SRC"]


def test_rows_are_the_csv_rows(tmp_path):
    exp = tmp_path / "tiny.yaml"
    exp.write_text(f"""experiment:
  name: tiny
  scenario: {SRC}/config/thesis_course.yaml
  runs_per_set: 1
  base_seed: 7
  mode: lockstep
  sets:
    - name: two
      set: {{ scenario.drones: 2, task.speed_mps: 1.5 }}
""")
    lines = []
    rows = ddswarm.experiment(exp, jobs=1, out=tmp_path / "out", progress=lines.append)
    assert any(l.startswith("run 1 of 1") for l in lines)
    with open(tmp_path / "out" / "tiny.csv", newline="") as f:
        raw = list(csv.DictReader(f))
    assert len(rows) == len(raw) == 1
    r = rows[0]
    assert set(r) == set(raw[0])
    assert r["ok"] is True and r["set_name"] == "two" and r["seed"] == 7 and r["drones"] == 2
    assert math.isclose(r["task_time_s"], float(raw[0]["task_time_s"]))
    assert r["task_time_s"] > 20
    assert r["params"]["task.speed_mps"] == 1.5
