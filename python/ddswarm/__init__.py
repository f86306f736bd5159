"""ddswarm from Python: fly, script and analyse a swarm (docs/python.md).

From the build tree: PYTHONPATH=build/default/python /usr/bin/python3
"""
from .recording import Recording, Table

__all__ = ["Recording", "Table"]
