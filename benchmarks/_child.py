"""Child processes of the benchmarks, which import the package the benchmark
itself imported.

``python -c`` puts the working directory first on a process's module path,
so a child started from a clone's root imports that clone, whatever
``PYTHONPATH`` says: a comparison of two trees would time one of them twice.
A child here runs in a directory of its own, with the directory that holds
the parent's ``orbits`` first on ``PYTHONPATH``.
"""

import os
import pathlib
import subprocess
import sys
import tempfile


def run_child(args, env=None, **kwargs):
    """``subprocess.run([python, *args], env=env, **kwargs)`` importing the
    parent's ``orbits`` (``env`` defaults to this process's environment)."""
    import orbits
    root = str(pathlib.Path(orbits.__file__).resolve().parents[1])
    env = dict(os.environ if env is None else env)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (root, env.get("PYTHONPATH")) if p)
    with tempfile.TemporaryDirectory() as cwd:
        return subprocess.run([sys.executable, *args], env=env, cwd=cwd, **kwargs)
