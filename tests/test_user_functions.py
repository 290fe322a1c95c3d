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

@numba.njit
def spring_jacobian(x, v, t):
    return -np.eye(x.size), np.zeros((x.size, x.size))
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
        compiled.append(ev.data["dispatcher"].py_func.__qualname__)

    def on_end(self, ev):
        pass

with event.install_listener("numba:compile", Listener()):
    sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day,
                            forces=[orbits.forces.UserForce(userforces.drag,
                                                            velocity_dependent=True)])
    sim.run(until=10 * u.day, outputs=2, progress=False)
    tr = orbits.integrate(userforces.spring, np.ones(3), np.zeros(3), dt=0.01, steps=10,
                          method="rk4")
    tr = orbits.integrate(userforces.spring, np.ones(3), np.zeros(3), dt=0.01, steps=10,
                          method="implicit-midpoint", jacobian=userforces.spring_jacobian)
# the first process leaves its simulation pickled; the second runs it on
# beside its own (its user term's pointer made again there, from the cache)
import pathlib, pickle
saved = pathlib.Path("sim.pickle")
same = None
if saved.exists():
    other = pickle.loads(saved.read_bytes())
    with event.install_listener("numba:compile", Listener()):
        for s in (sim, other):
            s.run(until=20 * u.day, outputs=2, progress=False)
    same = bool(np.array_equal(sim.state.x, other.state.x))
else:
    saved.write_bytes(pickle.dumps(sim))
print(json.dumps([compiled, same]))
"""


def test_user_functions_from_a_module_compile_once_and_load_in_a_new_process(tmp_path):
    # the second process compiles nothing: the package's loops and the
    # pointers to the users' functions (a force term, a force, a Jacobian) come
    # from numba's cache, and the checks on the initial state call those
    # pointers, not the functions (which the user compiles without a cache,
    # so a call from Python would compile them in every process); and a
    # simulation pickled by the first runs on in the second to the bits of
    # the second's own
    (tmp_path / "userforces.py").write_text(_MODULE)
    env = dict(os.environ, PYTHONPATH=str(tmp_path) + os.pathsep
               + os.environ.get("PYTHONPATH", ""))
    runs = []
    for _ in range(2):
        out = subprocess.run([sys.executable, "-c", _CHILD], env=env, cwd=tmp_path,
                             capture_output=True, text=True, check=True)
        runs.append(json.loads(out.stdout.strip().splitlines()[-1]))
    assert runs[1] == [[], True]


@numba.njit
def _module_level_drag(x, v, t, m):
    return -1e-9 * v


def test_a_function_made_outside_any_module_is_not_cached_on_disk():
    # a function that exec made in a namespace that is no module cannot be
    # found again by name in another process: code calling it compiles anew
    ns = {"__name__": "<no module>"}
    exec("import numba\n@numba.njit\ndef drag(x, v, t, m):\n    return -1e-9 * v\n", ns)
    assert not _user_functions.cacheable(ns["drag"])
    assert _user_functions.cacheable(_module_level_drag)


_EXEC_CHILD = textwrap.dedent("""
    import astropy.units as u
    import orbits
    ns = {"__name__": "<no module>"}
    exec("import numba\\n@numba.njit\\ndef drag(x, v, t, m):\\n    return -1e-9 * v\\n", ns)
    force = orbits.forces.UserForce(ns["drag"], velocity_dependent=True)
    sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day, forces=[force])
    sim.run(until=5 * u.day, progress=False)
    print(repr(float(sim.state.x[1, 0])))
""")


def test_a_user_force_made_by_exec_runs_again_in_a_new_process():
    # the second process once failed to load what the first had cached
    # (numba looked for the module "<no module>"); both now give the same
    # state.  The package's own cache, as a user's session has it
    outs = [subprocess.run([sys.executable, "-c", _EXEC_CHILD], capture_output=True,
                           text=True, timeout=600) for _ in range(2)]
    assert [o.returncode for o in outs] == [0, 0], outs[1].stderr[-2000:]
    assert outs[0].stdout == outs[1].stdout


def test_a_table_with_user_terms_does_not_pickle_and_its_simulation_does():
    # a table of user terms holds the addresses of compiled code in this
    # process, which another process would call blindly: it refuses; the
    # simulation holding it pickles and deep-copies by its configuration and
    # exact state (see tests/test_simulation.py), its pointers made anew
    import copy
    import pickle

    import astropy.units as u

    sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day,
                            forces=[orbits.forces.UserForce(_module_level_drag,
                                                            velocity_dependent=True)])
    table = sim._fargs[1]
    with pytest.raises(TypeError, match="UserForce terms .* cannot be pickled"):
        pickle.dumps(table)
    twin = copy.deepcopy(table)           # in this process the addresses stay good
    assert np.array_equal(twin.user.ints, table.user.ints)
    sim.run(until=3 * u.day, outputs=2, progress=False)
    copies = [pickle.loads(pickle.dumps(sim)), copy.deepcopy(sim)]
    for s in [sim] + copies:
        s.run(until=8 * u.day, outputs=2, progress=False)
    for c in copies:
        assert np.array_equal(sim.state.x, c.state.x) and np.array_equal(sim.state.v, c.state.v)
        assert c.forces[0].func is _module_level_drag
    # a table without user terms pickles
    plain = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day,
                              forces=[orbits.forces.GR("Star")])
    pickle.loads(pickle.dumps(plain._fargs[1]))
