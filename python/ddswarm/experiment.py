"""ddswarm.experiment(): an experiment file run by ddswarm-gs experiment, its table read back."""
import csv
import os
import re
import signal
import time

from . import _ddswarm
from .launch import _check_file, _running, _exit_codes, _stop_session, error_line, program, set_options

_CSV_LINE = re.compile(r"CSV (\S+)\s*$")
_INT = re.compile(r"^-?\d+$")
_TEXT = {"set_name", "sensor_function", "mode", "failure_reason"}


def _value(column, text):
    """One CSV cell as Python: ok as bool, params as a dict, numbers as int or float."""
    if column == "ok":
        return text == "1"
    if column == "params":
        return parse_params(text)
    if column in _TEXT:
        return text
    if _INT.match(text):
        return int(text)
    try:
        return float(text)  # also nan, inf
    except ValueError:
        return text


def parse_params(text):
    """The CSV's params cell ("k=v;k=v", '\\' escaping '\\', ';', '=') as a dict."""
    out, key, cur, esc = {}, None, "", False
    for ch in text:
        if esc:
            cur += ch
            esc = False
        elif ch == "\\":
            esc = True
        elif ch == "=" and key is None:
            key, cur = cur, ""
        elif ch == ";":
            if key is not None:
                out[key] = _value("", cur)
            key, cur = None, ""
        else:
            cur += ch
    if key is not None:
        out[key] = _value("", cur)
    return out


def read_table(path):
    """An experiment CSV (ddswarm-gs experiment's) as a list of dicts, one per
    run, with the CSV's columns; a pandas DataFrame when pandas is installed."""
    with open(_check_file(path), newline="") as f:
        rows = [{k: _value(k, v) for k, v in row.items()} for row in csv.DictReader(f)]
    try:
        import pandas
    except ImportError:
        return rows
    return pandas.DataFrame(rows)


def experiment(file, jobs=1, out="results", set=None, record=None, agent_hosts=None, domain=None,
               progress=True, timeout=None):
    """Runs an experiment file (e.g. config/table1.yaml) as `ddswarm-gs
    experiment` does, and returns its per-run table (read_table: the rows of
    its CSV, out/<name>.csv).

    jobs: runs at a time, each on a free DDS domain of its own (from `domain`,
    default 0, up); set: {"key.path": value} over every set, as --set;
    record: each run's DDS traffic to DIR/<run>.mcap; agent_hosts: each
    run's agents in K processes; progress: True prints ddswarm-gs's lines,
    a callable gets each, False prints nothing; timeout: wall seconds for
    the whole experiment (TimeoutError).

    Runs that fail are rows with ok False and their failure_reason. Raises
    FileNotFoundError (no such file), ValueError (a bad experiment or set,
    with the CLI's line), RuntimeError (ddswarm-gs failed otherwise); Ctrl-C
    stops every run's processes and raises KeyboardInterrupt.
    """
    file = _check_file(file)
    os.makedirs(out, exist_ok=True)
    argv = [program("ddswarm-gs")]
    if domain is not None:
        argv += ["--domain", str(domain)]
    argv += ["experiment", file, "--out", os.fspath(out), "--jobs", str(jobs)]
    for s in set_options(set):
        argv += ["--set", s]
    if record is not None:
        argv += ["--record", os.fspath(record)]
    if agent_hosts is not None:
        argv += ["--agent-hosts", str(agent_hosts)]
    log = os.path.join(out, "experiment.log")
    open(log, "w").close()
    say = (lambda line: print(line, flush=True)) if progress is True else (progress or None)
    pid = _ddswarm.spawn_session(argv, log)
    end = None if timeout is None else time.monotonic() + float(timeout)
    text, done = "", 0
    try:
        with open(log, errors="replace") as f:
            while True:
                running = _running(pid)
                text += f.read()
                lines = text.split("\n")
                for line in lines[done:-1]:
                    if say:
                        say(line)
                done = len(lines) - 1
                if not running:
                    break
                if end is not None and time.monotonic() > end:
                    raise TimeoutError(f"the experiment did not end within {timeout:g} s")
                time.sleep(0.1)
    except BaseException:
        if _running(pid):
            os.kill(pid, signal.SIGINT)  # as Ctrl-C: every run's processes stop
        _stop_session(pid, 15)
        raise
    code = _exit_codes.get(pid)
    if code == 2:
        raise ValueError(error_line(text) or text.strip())
    m = None
    for line in reversed(text.splitlines()):
        m = _CSV_LINE.search(line)
        if m:
            break
    if not m:
        raise RuntimeError(error_line(text) or f"ddswarm-gs experiment exited with {code}: {text[-500:]}")
    return read_table(m.group(1))
