"""Start-up: ``import orbits`` and ``orbits --help`` load none of the heavy
dependencies, and the names :mod:`orbits` exports lazily all resolve.

The timings live in ``benchmarks/bench_startup.py``; these tests only say which
modules a fresh interpreter has imported.
"""

import importlib
import pathlib
import subprocess
import sys

import pytest

import orbits

ROOT = pathlib.Path(__file__).resolve().parents[1]

#: what start-up must not import: each costs 0.1-0.5 s, and dask, matplotlib and
#: pandas are optional
HEAVY = ("astropy", "numba", "h5py", "dask", "matplotlib", "pandas")

COMMANDS = ("run", "resume", "info", "plot", "elements", "validate", "scenes",
            "integrators")


def _python(*args):
    # run in the repository root, so that this checkout's package is the one imported
    proc = subprocess.run([sys.executable, *args], cwd=ROOT, capture_output=True, text=True,
                          timeout=120)
    return proc


def test_import_orbits_loads_no_heavy_dependency():
    proc = _python("-c", "import orbits, sys; print(orbits.__file__); "
                         f"print(sorted(m for m in {HEAVY!r} if m in sys.modules))")
    assert proc.returncode == 0, proc.stderr
    where, loaded = proc.stdout.splitlines()
    assert pathlib.Path(where).parent == ROOT / "orbits"
    assert loaded == "[]"


def _imported(proc):
    # the top-level packages named in ``-X importtime``'s report on stderr
    names = set()
    for line in proc.stderr.splitlines():
        if line.startswith("import time:") and "|" in line:
            names.add(line.rsplit("|", 1)[1].strip().split(".")[0])
    return names


@pytest.mark.parametrize("command", [(), *((c,) for c in COMMANDS)],
                         ids=["orbits", *COMMANDS])
def test_help_loads_no_heavy_dependency(command):
    proc = _python("-X", "importtime", "-m", "orbits.cli", *command, "--help")
    assert proc.returncode == 0, proc.stderr
    assert "usage: orbits" in proc.stdout
    names = _imported(proc)
    assert "orbits" in names and "argparse" in names     # the report is read right
    assert sorted(names & set(HEAVY)) == []


def test_a_heavy_import_is_seen():
    # the check above can fail: a command that does import astropy is caught
    proc = _python("-X", "importtime", "-c", "import orbits; orbits.UnitSystem")
    assert proc.returncode == 0, proc.stderr
    assert "astropy" in _imported(proc)


def test_lazy_names_resolve():
    for name in orbits.__all__:
        value = getattr(orbits, name)
        assert name in dir(orbits)
        if name == "__version__":
            assert isinstance(value, str)
            continue
        # the same object as the module that defines it holds
        home = orbits._EXPORTS[name]
        module = importlib.import_module(home, "orbits")
        assert value is (module if home == f".{name}" else getattr(module, name))
    assert set(orbits._EXPORTS) == set(orbits.__all__) - {"__version__"}


def test_from_import_and_submodules():
    from orbits import Simulation, load, scenes, BodyError  # noqa: F401
    assert Simulation.__module__ == "orbits.simulation"
    assert orbits.bodies.BodySet is orbits.BodySet      # a submodule not in __all__
    with pytest.raises(AttributeError, match="no attribute 'no_such_name'"):
        orbits.no_such_name
    with pytest.raises(ImportError):
        from orbits import no_such_name  # noqa: F401


def test_a_run_loads_neither_tables_nor_other_integrators():
    # astropy.table (0.24 s a process) is imported where a table is made: an
    # encounter log, resolved collisions, a file's logs; a plain run makes
    # none.  An integrator's module (with its kernels) is imported when the
    # integrator is first asked for: a leapfrog run imports no other
    others = ["orbits.integrators." + m for m in ("wisdom_holman", "trace", "ias15", "taylor")]
    proc = _python("-c", "import sys, astropy.units as u, orbits; "
                         "sim = orbits.Simulation(orbits.scenes.outer_solar_system(), "
                         "'leapfrog', dt=10 * u.day); sim.run(until=100 * u.day, outputs=2, "
                         "progress=False); print('astropy.table' in sys.modules, "
                         f"[m for m in {others!r} if m in sys.modules])")
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["False", "[]"]


def test_the_tables_of_collisions_and_encounters_are_made_where_read():
    # a run with collisions and an encounter log keeps their rows; the
    # tables (astropy.table) are made where the result's fields are read
    proc = _python("-c", "import sys, astropy.units as u, orbits; "
                         "b = orbits.scenes.outer_solar_system(); "
                         "b = orbits.BodySet.from_arrays(b.masses, b.positions, b.velocities, "
                         "names=b.names, units=b.units, radii=[1e-3] * len(b) * u.au); "
                         "sim = orbits.Simulation(b, 'leapfrog', dt=10 * u.day, "
                         "collisions='merge', encounter_log=0.1 * u.au); "
                         "r = sim.run(until=100 * u.day, outputs=2, progress=False); "
                         "print('astropy.table' in sys.modules); "
                         "print(len(r.collisions), len(r.encounters), "
                         "type(r.encounters).__name__, 'astropy.table' in sys.modules)")
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["False", "0", "0", "QTable", "True"]


def test_integrate_without_units_imports_no_astropy():
    # orbits.integrate works on plain arrays: a user's system (here a Python
    # function, run as Python) never imports astropy (0.4 s a process); its
    # errors include one that is astropy's UnitsError, made when asked for
    proc = _python("-c", "import sys, numpy as np, orbits; "
                         "tr = orbits.integrate(lambda x, v, t: -x, np.ones(3), np.zeros(3), "
                         "dt=0.1, steps=5); print('astropy' in sys.modules); "
                         "from orbits.errors import BodyUnitsError; "
                         "import astropy.units as u; "
                         "print(issubclass(BodyUnitsError, u.UnitsError), "
                         "BodyUnitsError is orbits.BodyUnitsError)")
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["False", "True", "True"]


def test_the_registry_table_names_each_class_by_its_name():
    # the built-in table's names are the classes' own, in the registry's order
    from orbits import integrators
    assert [cls.name for cls in integrators._classes()] == list(integrators._BUILT_IN)
    assert integrators.IAS15 is type(integrators.get("ias15"))
