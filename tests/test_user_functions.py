"""A user's compiled functions run through cached pointers (orbits._user_functions)."""

import json
import os
import subprocess
import sys
import textwrap

import numba
import numpy as np
import pytest

import orbits
from orbits import _user_functions
from orbits.errors import ForceTermError


def _make(src, name="f", **glob):
    ns = dict(glob, numba=numba, np=np)
    exec(textwrap.dedent(src), ns)
    return ns[name]


def test_the_code_key_follows_the_code_and_the_frozen_globals():
    f1 = _make("""
        @numba.njit
        def f(x, v, t, m):
            return -K * x
    """, K=1.0)
    f2 = _make("""
        @numba.njit
        def f(x, v, t, m):
            return -K * x
    """, K=1.0)
    f3 = _make("""
        @numba.njit
        def f(x, v, t, m):
            return -K * x
    """, K=2.0)             # numba freezes K: another compiled function
    f4 = _make("""
        @numba.njit
        def f(x, v, t, m):
            return -K * v
    """, K=1.0)
    assert _user_functions.code_key(f1) == _user_functions.code_key(f2)
    assert _user_functions.code_key(f1) != _user_functions.code_key(f3)
    assert _user_functions.code_key(f1) != _user_functions.code_key(f4)


def test_a_compiled_accel_whose_shape_changes_during_the_run_is_a_named_error():
    @numba.njit
    def accel(x, v, t):
        return -x if t < 0.05 else -x[:2]

    with pytest.raises(ForceTermError, match="during the run"):
        orbits.integrate(accel, np.ones(3), np.zeros(3), dt=0.01, steps=10)


_MODULE = """
import numba
import numpy as np

@numba.njit
def drag(x, v, t, m):
    return -1e-9 * v

@numba.njit
def spring(x, v, t):
    return -x
"""

_CHILD = """
import json, sys
import numpy as np
from numba.core import event
import astropy.units as u
import orbits
import userforces

compiled = []

class Listener(event.Listener):
    def on_start(self, ev):
        func = ev.data["dispatcher"].py_func
        if func.__module__.startswith("orbits"):
            compiled.append(func.__qualname__)

    def on_end(self, ev):
        pass

sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day,
                        forces=[orbits.forces.UserForce(userforces.drag,
                                                        velocity_dependent=True)])
with event.install_listener("numba:compile", Listener()):
    sim.run(until=10 * u.day, outputs=2, progress=False)
    tr = orbits.integrate(userforces.spring, np.ones(3), np.zeros(3), dt=0.01, steps=10,
                          method="rk4")
print(json.dumps(compiled))
"""


def test_user_functions_from_a_module_compile_once_and_load_in_a_new_process(tmp_path):
    # the second process compiles none of the package's code: its loops and the
    # pointers to the users' functions come from numba's cache (the user's own
    # functions compile as the user declared them, here without a cache)
    (tmp_path / "userforces.py").write_text(_MODULE)
    env = dict(os.environ, PYTHONPATH=str(tmp_path) + os.pathsep
               + os.environ.get("PYTHONPATH", ""))
    runs = []
    for _ in range(2):
        out = subprocess.run([sys.executable, "-c", _CHILD], env=env, cwd=tmp_path,
                             capture_output=True, text=True, check=True)
        runs.append(json.loads(out.stdout.strip().splitlines()[-1]))
    assert runs[1] == []
