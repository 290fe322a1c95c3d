"""Output files are data, never code: reading one imports nothing it names,
reads nothing outside it, allocates no more than it holds, and checks every
value it acts on.

Each crafted file is a small finished run (the Kepler problem with leapfrog,
the configuration the doctests compile) edited with h5py the way an attacker
or a damaged disk would.
"""

import json
import pickle
import shutil
import tracemalloc
import uuid

import astropy.units as u
import h5py
import numba
import numpy as np
import pytest

import orbits
from orbits import forces
from orbits.cli import main
from orbits.errors import ForceTermError, SimulationOptionError
from orbits.io.h5md import OrbitsFileError, safety

#: what a reader may allocate for a crafted file of a few hundred kB: the
#: finished run's own arrays take a few kB and load's Quantities and tables a
#: few hundred kB more (measured peak: 1.0 MB); the crafted shapes below
#: declare 200 MB and more
PEAK_BYTES = 16 * 2 ** 20
#: rows a crafted series declares: 2**22 rows of 2 bodies' positions are
#: 200 MB that the file does not hold
DECLARED_ROWS = 2 ** 22

READERS = {"load": orbits.load, "describe": orbits.io.describe,
           "from_file": orbits.Simulation.from_file}


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    path = tmp_path_factory.mktemp("finished") / "run.h5"
    sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
    sim.run(until=10 * u.day, outputs=3, output=path, progress=False)
    return path


def craft(finished, tmp_path, edit, name="crafted.h5"):
    """A copy of the finished run, changed by ``edit(h5py.File)``."""
    path = tmp_path / name
    shutil.copy(finished, path)
    with h5py.File(path, "a") as f:
        edit(f)
    return path


def set_json(f, key, change):
    par = f["parameters"]
    value = json.loads(par.attrs[key])
    par.attrs[key] = json.dumps(change(value))


def replace(f, name, **kw):
    unit = f[name].attrs.get("unit")
    del f[name]
    ds = f.create_dataset(name, **kw)
    if unit is not None:
        ds.attrs["unit"] = unit
    return ds


# -- 1. opening a file runs no code ----------------------------------------------------------

def _trap(tmp_path, monkeypatch):
    """A module that would leave a flag file behind if it were imported, on
    sys.path and in the working directory; its name is new to this process
    (tests/helpers.py is already imported as ``helpers``)."""
    module = f"orbits_trap_{uuid.uuid4().hex}"
    flag = tmp_path / "imported"
    (tmp_path / f"{module}.py").write_text(
        f"import pathlib\npathlib.Path({str(flag)!r}).write_text('imported')\n"
        f"def f(x, v, t, m):\n    return 0 * x\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.chdir(tmp_path)
    return module, flag


def _names_user_force(ref):
    record = {"type": "UserForce", "func": ref, "velocity_dependent": False,
              "potential": None}

    def edit(f):
        set_json(f, "config", lambda c: dict(c, forces=c["forces"] + [record]))
        set_json(f, "forces", lambda fs: fs + [record])
    return edit


def test_reading_a_file_that_names_a_module_imports_nothing(finished, tmp_path,
                                                             monkeypatch, capsys):
    module, flag = _trap(tmp_path, monkeypatch)
    path = craft(finished, tmp_path, _names_user_force(f"{module}:f"))
    assert len(orbits.load(path)) == 3
    info = orbits.io.describe(path)
    assert f"forces          Newtonian gravity + UserForce({module}:f)" in info
    with pytest.raises(SimulationOptionError, match=f"'{module}:f' .UserForce func") as exc:
        orbits.Simulation.from_file(path)
    assert "functions={'f': ...}" in str(exc.value)
    assert main(["info", str(path)]) == 0
    assert main(["resume", str(path)]) != 0      # an error that names the function
    assert f"{module}:f" in capsys.readouterr().err
    assert not flag.exists()


@numba.njit
def _pull(x, v, t, m):
    return -1e-9 * x


@numba.njit
def _three(x, v, t):
    return 0 * x


def _plain(x, v, t, m):
    return 0 * x


def test_user_functions_come_from_the_caller_and_are_checked(finished, tmp_path,
                                                             monkeypatch):
    module, flag = _trap(tmp_path, monkeypatch)

    def naming(qualname):
        return craft(finished, tmp_path, _names_user_force(f"{module}:{qualname}"),
                     name=f"{qualname}.h5")

    with pytest.raises(ForceTermError, match="the record names one of qualname 'f'"):
        orbits.Simulation.from_file(naming("f"), functions={"f": _pull})
    with pytest.raises(ForceTermError, match=r"takes \(x, v, t\); a UserForce func takes "
                                             r"\(x, v, t, m\)"):
        orbits.Simulation.from_file(naming("_three"), functions={f"{module}:_three": _three})
    with pytest.raises(ForceTermError, match="numba"):
        orbits.Simulation.from_file(naming("_plain"), functions={"_plain": _plain})
    with pytest.raises(SimulationOptionError, match="'drag', which its run did not use"):
        orbits.Simulation.from_file(naming("f"), functions={"f": _pull, "drag": _pull})
    with pytest.raises(SimulationOptionError, match="must map"):
        orbits.Simulation.from_file(naming("f"), functions=[_pull])
    with pytest.raises(ForceTermError, match="cannot hold"):
        forces.from_dict({"type": "UserForce", "func": f"{module}:f",
                          "velocity_dependent": False, "potential": None})
    assert not flag.exists()


def test_an_ensemble_ships_the_functions_themselves():
    # the perturbed copies are rebuilt on a worker from the configuration and
    # the functions, pickled by reference; nothing is imported from a name
    from orbits.ensemble import _Perturbation
    sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day,
                            forces=[forces.UserForce(_pull)])
    recipe = pickle.loads(pickle.dumps(_Perturbation(sim, 0.0, 1)))
    assert list(recipe.functions) == [f"{__name__}:_pull"]
    rebuilt = forces.from_dict(recipe.config.forces[1], recipe.functions)
    assert rebuilt == sim.forces[0] and rebuilt.func.py_func is _pull.py_func


# -- 3. small files do not exhaust memory -------------------------------------------------------

def _peak(call, *args):
    tracemalloc.start()
    try:
        out = call(*args)
        return out, tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_series_declared_longer_than_stored_are_read_as_stored(finished, tmp_path):
    # every time series resized without data: the file stays a few hundred kB
    def edit(f):
        def grow(name, obj):
            if isinstance(obj, h5py.Dataset) and obj.maxshape[:1] == (None,):
                obj.resize(DECLARED_ROWS, axis=0)
        f.visititems(grow)
    path = craft(finished, tmp_path, edit)
    assert path.stat().st_size < 10 * 2 ** 20
    # what is read is what the file stores: the one chunk of each series that
    # was written (1024 rows of the times, of which 3 hold outputs)
    result, peak = _peak(orbits.load, path)
    assert 3 <= len(result) <= 1024 and peak < PEAK_BYTES, peak
    assert np.array_equal(result.positions.value[:3], orbits.load(finished).positions.value)
    text, peak = _peak(orbits.io.describe, path)
    assert f"outputs         {len(result)}," in text and peak < PEAK_BYTES, peak


@pytest.mark.parametrize("name, shape, chunks, dtype", [
    ("restart/ws/acc", (2, DECLARED_ROWS, 3), (1, 1024, 3), "f8"),
    ("restart/x", (2, DECLARED_ROWS, 3), (1, 1024, 3), "f8"),
    ("particles/bodies/names", (DECLARED_ROWS,), (1024,), h5py.string_dtype()),
], ids=["workspace", "restart", "names"])
def test_declared_shapes_beyond_the_file_are_refused_before_reading(
        finished, tmp_path, name, shape, chunks, dtype):
    # chunked, with no chunk written: the file stays a few hundred kB
    path = craft(finished, tmp_path, lambda f: replace(
        f, name, shape=shape, maxshape=(None,) * len(shape), dtype=dtype, chunks=chunks))
    assert path.stat().st_size < 10 * 2 ** 20
    for call in READERS.values():
        tracemalloc.start()
        try:
            with pytest.raises(OrbitsFileError, match=f"/{name} (declares|has) shape"):
                call(path)
            peak = tracemalloc.get_traced_memory()[1]
        finally:
            tracemalloc.stop()
        # refused before anything of that size was read
        assert peak < PEAK_BYTES, (call, peak)


# -- 4. nothing outside the file is read ---------------------------------------------------------

def _outside(tmp_path):
    """A file of two floats beside the run, and an HDF5 file holding them."""
    secret = tmp_path / "secret.bin"
    secret.write_bytes(np.array([7.0, 8.0]).tobytes())
    other = tmp_path / "other.h5"
    with h5py.File(other, "w") as f:
        f["data"] = np.array([7.0, 8.0])
        f["data"].attrs["unit"] = "solMass"
    return secret, other


def _external_storage(f, secret, other):
    replace(f, "particles/bodies/mass", shape=(2,), dtype="f8",
            external=[(str(secret), 0, 16)])


def _virtual(f, secret, other):
    layout = h5py.VirtualLayout(shape=(2,), dtype="f8")
    layout[:] = h5py.VirtualSource(str(other), "data", shape=(2,))
    del f["particles/bodies/mass"]
    f.create_virtual_dataset("particles/bodies/mass", layout).attrs["unit"] = "solMass"


def _external_link(f, secret, other):
    del f["particles/bodies/mass"]
    f["particles/bodies/mass"] = h5py.ExternalLink(str(other), "data")


def _plugin_filter(f, secret, other):
    # a filter HDF5 would look for as a plugin (optional, so that it can be
    # made here without one)
    del f["particles/bodies/radius"]
    dcpl = h5py.h5p.create(h5py.h5p.DATASET_CREATE)
    dcpl.set_chunk((2,))
    dcpl.set_filter(32123, h5py.h5z.FLAG_OPTIONAL)
    h5py.h5d.create(f.id, b"particles/bodies/radius", h5py.h5t.IEEE_F64LE,
                    h5py.h5s.create_simple((2,), (2,)), dcpl=dcpl)
    f["particles/bodies/radius"].attrs["unit"] = "AU"


@pytest.mark.parametrize("edit, message", [
    (_external_storage, "/particles/bodies/mass keeps its data in external files"),
    (_virtual, "/particles/bodies/mass is a virtual dataset"),
    (_external_link, "/particles/bodies/mass is an external link, which leaves the file"),
    (_plugin_filter, "/particles/bodies/radius is stored through HDF5 filter 32123"),
], ids=["external-storage", "virtual", "external-link", "plugin-filter"])
def test_data_outside_the_file_is_refused(finished, tmp_path, edit, message):
    secret, other = _outside(tmp_path)
    path = craft(finished, tmp_path, lambda f: edit(f, secret, other))
    for call in READERS.values():
        with pytest.raises(OrbitsFileError, match=message):
            call(path)


# -- 5. every value is checked -------------------------------------------------------------------

def _slot(f):
    return (int(f["restart/count"][()]) - 1) % 2


def _set_row(name, column, value):
    def edit(f):
        d = f[name]
        row = d[_slot(f)]
        row[column] = value
        d[_slot(f)] = row
    return edit


def _count(value):
    def edit(f):
        f["restart/count"][()] = value
    return edit


CRAFTED = [
    # the older slot restored, silently
    ("count", _count(-1), "/restart/count is -1"),
    # the time set back: steps since the time base below 0
    ("clock", _set_row("restart/clock", 1, -10), "/restart/clock at the last checkpoint"),
    ("plan", _set_row("restart/plan", 1, 0.5), "/restart/plan at the last checkpoint"),
    ("progress", _set_row("restart/progress", 1, 7), "/restart/progress at the last"),
    ("order", lambda f: f["restart/order"].__setitem__(slice(None), [5, 7]),
     "/restart/order is not an order of the 2 bodies"),
    ("clock-shape", lambda f: replace(f, "restart/clock", data=np.zeros((2, 4), np.int64)),
     r"/restart/clock has shape \(2, 4\); expected \(2, 5\)"),
    ("mass-type", lambda f: replace(f, "particles/bodies/mass", data=np.array([b"a", b"b"])),
     "/particles/bodies/mass holds values of type"),
    ("mass-shape", lambda f: replace(f, "particles/bodies/mass", data=[1.0, 2.0, 3.0]),
     r"/particles/bodies/mass has shape \(3,\); expected \(2,\)"),
    ("units", lambda f: f["parameters"].attrs.__setitem__("units", "[]"),
     "the 'units' attribute of /parameters is list"),
    ("unit", lambda f: f["particles/bodies/position/value"].attrs.__setitem__("unit", "kg"),
     "/particles/bodies/position/value has the unit 'kg'; expected a unit of length"),
    ("monitors", lambda f: f["parameters"].attrs.__setitem__("monitors", '{"energy": 1}'),
     "the 'monitors' attribute of /parameters is dict"),
    ("forces", lambda f: f["parameters"].attrs.__setitem__("forces", "[1]"),
     "the 'forces' attribute of /parameters"),
    ("integrator-info", lambda f: f["parameters"].attrs.__setitem__("integrator_info", "{}"),
     "the 'integrator_info' attribute"),
    ("config", lambda f: set_json(f, "config", lambda c: {"integrator": "leapfrog"}),
     "the configuration in /parameters lacks 'integrator_options'"),
    ("dt", lambda f: f["parameters"].attrs.__setitem__("dt", "1 day"),
     "the 'dt' attribute of /parameters is '1 day'"),
    ("mixed-plain-units", lambda f: set_json(f, "units", lambda us: dict(us, mass="")),
     "plain numbers for some of length, mass and time but not all"),
    ("version", lambda f: f.attrs.__setitem__("orbits_format_version", "1"),
     "layout version '1'"),
    ("body-axes", lambda f: f["restart/ws/acc"].attrs.__setitem__("body_axes", [7]),
     "/restart/ws/acc has body_axes"),
]


@pytest.mark.parametrize("edit, message", [c[1:] for c in CRAFTED],
                         ids=[c[0] for c in CRAFTED])
def test_crafted_values_are_named_errors(finished, tmp_path, edit, message):
    path = craft(finished, tmp_path, edit)
    for call in READERS.values():
        with pytest.raises(OrbitsFileError, match=message):
            call(path)


def test_a_workspace_of_another_shape_is_refused(finished, tmp_path):
    # the integrator's arrays are put back whole: one of another shape would
    # be broadcast into them
    path = craft(finished, tmp_path, lambda f: replace(
        f, "restart/ws/acc", data=np.zeros((2, 1, 3))))
    with pytest.raises(OrbitsFileError, match=r"/restart/ws/acc holds float64 values of "
                                              r"shape \(1, 3\)"):
        orbits.Simulation.from_file(path)


def test_a_clock_beyond_the_outputs_is_refused_on_restore(finished, tmp_path):
    path = craft(finished, tmp_path, _set_row("restart/clock", 3, 1000))
    with pytest.raises(OrbitsFileError, match="counts 1000 output rows, but the file "
                                              "holds 3"):
        orbits.Simulation.from_file(path)


def test_the_finished_run_reads_as_before(finished):
    # the checks refuse nothing an orbits run writes
    again = orbits.Simulation.from_file(finished)
    assert again.time == 10 * u.day and again.resume_point.finished
    assert len(orbits.load(finished)) == 3
    assert "status          completed" in orbits.io.describe(finished)
    with h5py.File(finished, "r") as f:
        assert safety._inventory(f, finished).groups >= {"restart/ws", "parameters"}


def test_a_run_in_n_body_units_reads_back(tmp_path):
    # N-body units write plain numbers (an empty unit) for every kind of
    # quantity; the unit checks above accept them
    b = orbits.BodySet.from_arrays([1.0, 1e-3], [[0, 0, 0], [1, 0, 0]],
                                   [[0, 0, 0], [0, 1, 0]], units=orbits.UnitSystem.nbody())
    path = tmp_path / "nbody.h5"
    orbits.Simulation(b, "leapfrog", dt=0.01).run(until=1.0, outputs=3, output=path,
                                                  progress=False)
    assert list(orbits.load(path).times) == [0.0, 0.5, 1.0]
    assert orbits.Simulation.from_file(path).time == 1.0
    assert "completed" in orbits.io.describe(path)
