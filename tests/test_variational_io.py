"""Variations and chaos monitors in files and ensembles: the HDF5 series, the
derivatives a file keeps, bit-exact restarts, the ensemble's chaos columns.

Every comparison here is exact (``np.array_equal``, ``==``): a file stores
the float64s a run computed, a restart puts back every array the loop reads,
and an ensemble member runs the same arithmetic as the simulation run alone,
so no rounding can come between them.
"""

import sys

import astropy.units as u
import cloudpickle
import h5py
import numpy as np
import pytest

import orbits
from orbits.ensemble import Ensemble
from orbits.io.h5md import TangentShapeError

from helpers import jupiter_saturn

# builds defined here travel to the workers by value (the workers cannot import
# this test module by name)
cloudpickle.register_pickle_by_value(sys.modules[__name__])

CHAOS = ["energy", "megno", "lyapunov", "fli"]
DT = 20 * u.day
#: 3652 steps of DT: a split point on a step boundary, so that the run to it
#: and the run from it take the steps of one run to SPLIT + ... (200 yr, the
#: obvious split, is 3652.5 steps: a shortened step there changes the orbit)
SPLIT = 3652 * DT
UNTIL = 400 * u.yr          # 7305 steps of DT exactly


def _planets(a_saturn=6.6):
    return jupiter_saturn(a_saturn)


def _sim(variations="state", seed=4, **kw):
    return orbits.Simulation(_planets(), "leapfrog", dt=DT, monitors=CHAOS,
                             variations=variations, seed=seed, **kw)


# -- the file ------------------------------------------------------------------------------

def test_file_keeps_the_chaos_series_and_the_derivatives(tmp_path):
    path = tmp_path / "run.h5"
    memory = _sim(monitor_every=100).run(until=100 * u.yr, outputs=6, progress=False)
    sim = _sim(monitor_every=100)
    last = sim.run(until=100 * u.yr, outputs=6, output=path, progress=False)
    loaded = orbits.load(path)
    for r in (loaded, last):
        assert np.array_equal(r.jacobian, memory.jacobian)
        assert np.array_equal(r.tangent_vectors, memory.tangent_vectors)
        assert r.seed == memory.seed == 4
        assert r.lyapunov.unit == memory.lyapunov.unit
    # the file-backed run's result holds its last output; the file, all of them
    for name in ("megno", "fli"):
        assert np.array_equal(getattr(loaded, name), getattr(memory, name))
        assert getattr(last, name)[-1] == getattr(memory, name)[-1]
        assert isinstance(getattr(loaded, name), np.ndarray)    # dimensionless, as in memory
        assert np.array_equal(loaded.monitor[name], memory.monitor[name])
    assert np.array_equal(loaded.lyapunov.value, memory.lyapunov.value)
    assert last.lyapunov[-1] == memory.lyapunov[-1]
    assert np.array_equal(loaded.monitor["lyapunov"].value, memory.monitor["lyapunov"].value)
    assert np.array_equal(loaded.monitor["times"].value, memory.monitor["times"].value)
    assert loaded.megno[-1] > 0 and np.isfinite(loaded.fli).all()
    with h5py.File(path, "r") as f:
        obs = f["observables"]
        assert obs["lyapunov/value"].attrs["unit"] == "1 / d"
        assert obs["megno/value"].attrs["unit"] == "1"
        assert obs["in_loop/fli/value"].shape == memory.monitor["fli"].shape
        assert f["restart/tangent_vectors"].attrs["layout"].tolist() == [1, 0, 18, 0]
    assert "19 tangent vectors" in orbits.io.h5md.describe(path)


def test_file_keeps_the_derivatives_with_respect_to_the_masses(tmp_path):
    # variations="all" without chaos monitors: the Jacobian's mass columns
    path = tmp_path / "run.h5"
    memory = orbits.Simulation(_planets(), "leapfrog", dt=DT, variations="all").run(
        until=10 * u.yr, outputs=2, progress=False)
    orbits.Simulation(_planets(), "leapfrog", dt=DT, variations="all").run(
        until=10 * u.yr, outputs=2, output=path, progress=False)
    loaded = orbits.load(path)
    assert loaded.jacobian.shape == (18, 21)
    assert np.array_equal(loaded.jacobian, memory.jacobian)
    assert loaded.megno is None
    assert loaded.seed is None and memory.seed is None    # no random vectors


@pytest.mark.parametrize("variations", ["state", 2])
def test_restart_with_variations_and_chaos_monitors_is_bit_identical(tmp_path, variations):
    # tests/test_variational.py's restart test, split on a step boundary; and
    # with random tangent vectors (an int variations) besides the state's
    path = tmp_path / "run.h5"
    ref = _sim(variations)
    r_ref = ref.run(until=UNTIL, outputs=5, progress=False)
    first = _sim(variations)
    first.run(until=SPLIT, outputs=3, output=path, progress=False)
    again = orbits.Simulation.from_file(path)
    # the variations and the seed come back from the file's configuration
    assert again.config == first.config
    assert (again.config.variations, again.config.seed) == (variations, 4)
    r = again.run(until=UNTIL, outputs=3, output=path, progress=False)
    assert again.steps == ref.steps
    assert np.array_equal(r.positions[-1].value, r_ref.positions[-1].value)
    assert np.array_equal(again.tangent_vectors, ref.tangent_vectors)
    if variations == "state":
        assert np.array_equal(again.jacobian, ref.jacobian)
    for name in ("megno", "fli"):
        assert getattr(r, name)[-1] == getattr(r_ref, name)[-1]
    assert r.lyapunov[-1] == r_ref.lyapunov[-1]
    loaded = orbits.load(path)
    assert np.array_equal(loaded.tangent_vectors, r_ref.tangent_vectors)
    assert loaded.megno[-1] == r_ref.megno[-1]


def test_a_seed_drawn_by_the_simulation_survives_the_file(tmp_path):
    # no seed given: the simulation draws one, and the file's configuration
    # keeps it, so the restored run continues with the same vectors
    path = tmp_path / "run.h5"
    sim = orbits.Simulation(_planets(), "leapfrog", dt=DT, monitors=CHAOS)
    sim.run(until=10 * u.yr, outputs=2, output=path, progress=False)
    assert isinstance(sim.config.seed, int)
    assert orbits.Simulation.from_file(path).config.seed == sim.config.seed
    assert orbits.load(path).seed == sim.config.seed


def _replace(f, name, shape):
    # a dataset of another shape in place of ``name``: a damaged or hand-edited file
    attrs = dict(f[name].attrs)
    del f[name]
    d = f.create_dataset(name, shape=shape, dtype=np.float64)
    for k, val in attrs.items():
        d.attrs[k] = val


def test_tangent_shapes_that_do_not_match_are_named_errors(tmp_path):
    path = tmp_path / "run.h5"
    _sim().run(until=10 * u.yr, outputs=2, output=path, progress=False)
    bad = tmp_path / "bad-derivatives.h5"
    bad.write_bytes(path.read_bytes())
    with h5py.File(bad, "a") as f:
        _replace(f, "restart/tangent_vectors", (2, 5, 3, 6))     # 19 vectors expected
    with pytest.raises(TangentShapeError, match=r"shape \(5, 3, 6\).*calls for \(19, 3, 6\)"):
        orbits.load(bad)

    bad = tmp_path / "bad-rows.h5"
    bad.write_bytes(path.read_bytes())
    with h5py.File(bad, "a") as f:
        _replace(f, "restart/ws/tangent", (2, 2, 30, 3))         # 19 x 3 rows expected
    with pytest.raises(TangentShapeError, match="10 vectors of 3 bodies") as info:
        orbits.Simulation.from_file(bad)
    assert info.value.expected == (2, 57, 3) and info.value.found == (2, 30, 3)

    # appending a run with other variations to the file
    other = orbits.Simulation(_planets(), "leapfrog", dt=DT, monitors=["energy"])
    other.output_path = str(path)
    with pytest.raises(TangentShapeError, match="appending"):
        other.run(until=10 * u.yr, outputs=2, output=path, progress=False)


def test_a_file_without_the_kept_derivatives_still_loads_and_restarts(tmp_path):
    # as written before the derivatives were kept: the checkpoints' tangent
    # rows only; the restart needs no more
    path = tmp_path / "run.h5"
    _sim().run(until=10 * u.yr, outputs=2, output=path, progress=False)
    with h5py.File(path, "a") as f:
        del f["restart/tangent_vectors"]
    loaded = orbits.load(path)
    assert loaded.jacobian is None and loaded.tangent_vectors is None
    assert loaded.seed == 4 and loaded.megno.shape == (2,)
    again = orbits.Simulation.from_file(path)
    ref = _sim()
    ref.run(until=10 * u.yr, outputs=2, progress=False)
    assert np.array_equal(again.jacobian, ref.jacobian)


# -- ensembles -----------------------------------------------------------------------------

def stability(a_saturn, seed=7):
    """One point of a stability map: MEGNO of Jupiter and a Saturn at a_saturn au."""
    return orbits.Simulation(_planets(a_saturn), "leapfrog", dt=DT, monitors=CHAOS, seed=seed)


MAP = [{"a_saturn": 6.6}, {"a_saturn": 9.5}]
MAP_UNTIL = 300 * u.yr
CHAOS_COLUMNS = ["megno", "lyapunov_per_day", "fli"]


def _direct(params):
    r = stability(**params).run(until=MAP_UNTIL, outputs=3, progress=False)
    return [r.megno[-1], r.lyapunov[-1].to_value(1 / u.day), r.fli[-1]]


def test_ensemble_tabulates_the_chaos_indicators_of_each_run(tmp_path):
    df = Ensemble(stability, MAP).run(MAP_UNTIL, client="serial", outputs=3, progress=False)
    assert list(df.columns[df.columns.get_loc("angular_momentum_error_max") + 1:][:3]) \
        == CHAOS_COLUMNS
    assert np.isfinite(df[CHAOS_COLUMNS].to_numpy()).all()
    for i, params in enumerate(MAP):
        assert df.loc[i, CHAOS_COLUMNS].tolist() == _direct(params)
    # the chaotic member stands out from the regular one: measured 5.6 against
    # 2.07 (which tends to 2 from above as the run lengthens)
    assert df.megno[0] > df.megno[1]
    again = Ensemble(stability, MAP).run(MAP_UNTIL, client="serial", outputs=3,
                                         progress=False)
    assert again[CHAOS_COLUMNS].equals(df[CHAOS_COLUMNS])
    # written to files, read back from them: the same numbers
    files = Ensemble(stability, MAP).run(MAP_UNTIL, client="serial", outputs=3,
                                         progress=False, out_dir=tmp_path)
    assert files[CHAOS_COLUMNS].equals(df[CHAOS_COLUMNS])
    # and the index the sweep resumes from keeps them
    resumed = Ensemble(stability, MAP).run(MAP_UNTIL, client="serial", outputs=3,
                                           progress=False, out_dir=tmp_path)
    assert resumed[CHAOS_COLUMNS].equals(df[CHAOS_COLUMNS])


@pytest.mark.slow
def test_two_worker_ensemble_tabulates_the_same_chaos_indicators():
    serial = Ensemble(stability, MAP).run(MAP_UNTIL, client="serial", outputs=3,
                                          progress=False)
    df = Ensemble(stability, MAP).run(MAP_UNTIL, client=None, n_workers=2, outputs=3,
                                      progress=False)
    assert df[CHAOS_COLUMNS].equals(serial[CHAOS_COLUMNS])
