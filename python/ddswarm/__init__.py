"""ddswarm from Python: fly, script and analyse a swarm (docs/python.md).

From the build tree: PYTHONPATH=build/default/python /usr/bin/python3
"""
from .experiment import experiment, parse_params, read_table
from .ground_station import Ack, CommandError, GroundStation, TaskFailed, TaskResult
from .launch import Swarm, bin_dir, config_path, launch, program
from .recording import Recording, Table

__all__ = ["Ack", "CommandError", "GroundStation", "Recording", "Swarm", "Table", "TaskFailed",
           "TaskResult", "bin_dir", "config_path", "experiment", "launch", "parse_params",
           "program", "read_table"]
