"""Ensemble.run(..., batch=B): runs integrated together in vector lanes give the
rows of the runs made one by one."""

import sys

import astropy.units as u
import cloudpickle
import h5py
import numpy as np
import pytest

import orbits
from orbits.ensemble import Ensemble, EnsembleOptionError, local_cluster
from orbits.ensemble import batch as _batch
from orbits.ensemble.tasks import _Chunks
from orbits.ensemble.worker import _Spec

cloudpickle.register_pickle_by_value(sys.modules[__name__])

# columns that say where and how fast a run went, not what it computed
WHERE = ["wall_time_s", "worker", "kernels_compiled", "kernels_loaded"]


def three_planets(a, e, integrator="wh", dt=30.0, **options):
    """The Sun, Jupiter, Saturn and a 10-Earth-mass planet at (a, e)."""
    b = orbits.BodySet()
    b.add("Sun", mass=1 * u.Msun)
    b.add("Jupiter", mass=1 * u.Mjup, primary="Sun", a=5.2 * u.au, e=0.048)
    b.add("Saturn", mass=0.2994 * u.Mjup, primary="Sun", a=9.58 * u.au, e=0.056, f=2 * u.rad)
    b.add("planet", mass=10 * u.Mearth, primary="Sun", a=a * u.au, e=e, f=1 * u.rad)
    b.move_to_com()
    return orbits.Simulation(b, integrator=integrator, dt=dt * u.day, **options)


def mixed(a, e, kind):
    # runs that batch and runs that do not, interleaved: another step, another
    # integrator, a corrector, a stopping condition, a test particle less
    if kind == "wh":
        return three_planets(a, e)
    if kind == "dt":
        return three_planets(a, e, dt=20.0)
    if kind == "leapfrog":
        return three_planets(a, e, integrator="leapfrog")
    if kind == "corrector":
        return three_planets(a, e, integrator=orbits.integrators.get("wh", corrector=5))
    if kind == "escape":
        return three_planets(a, e, escape_distance=100 * u.au)
    raise orbits.SimulationOptionError(f"unknown kind {kind!r}")


SWEEP = [{"a": 2.0 + 0.4 * k, "e": 0.02 * (k % 5)} for k in range(20)]
# a thousand years in 12175.33 steps of 30 days: a shortened last step too
UNTIL = 365_260 * u.day


def assert_same_rows(alone, batched):
    assert list(alone.columns) == list(batched.columns)
    # bit for bit: every lane does the scalar kernels' operations in their
    # order (orbits._kernels.wh_batch), so no tolerance (measured: equal)
    a = alone.drop(columns=WHERE)
    b = batched.drop(columns=WHERE)
    for col in a.columns:
        x, y = a[col].to_numpy(), b[col].to_numpy()
        if x.dtype.kind == "f":
            assert np.array_equal(x, y, equal_nan=True), col
        else:
            assert list(x) == list(y), col


@pytest.fixture(scope="module")
def alone():
    return Ensemble(three_planets, SWEEP).run(UNTIL, client="serial", outputs=37,
                                              progress=False)


@pytest.mark.parametrize("batch", [4, 8])
def test_batched_rows_equal_the_rows_of_runs_made_alone(alone, batch):
    df = Ensemble(three_planets, SWEEP).run(UNTIL, client="serial", outputs=37,
                                            progress=False, batch=batch)
    assert_same_rows(alone, df)
    assert (df.outcome == "completed").all() and (df.steps == 12176).all()
    # the batch's wall time is shared out among its runs
    assert (df.wall_time_s > 0).all()
    assert df.wall_time_s.iloc[:batch].nunique() == 1


def test_a_partial_batch_runs_in_a_power_of_two_of_lanes(alone, monkeypatch):
    # five runs at batch=8 take eight lanes, three of them idle, so that the
    # loop compiled for 8 serves them (a loop of five lanes would compile anew)
    widths = []
    made = _batch._lanes.advance_loop
    monkeypatch.setattr(_batch._lanes, "advance_loop",
                        lambda n, n_active, nb: widths.append(nb) or made(n, n_active, nb))
    df = Ensemble(three_planets, SWEEP[:5]).run(UNTIL, client="serial", outputs=37,
                                                progress=False, batch=8)
    assert widths == [8]
    assert_same_rows(alone.iloc[:5].reset_index(drop=True), df)
    assert [_batch.lane_width(n, 6) for n in (1, 3, 4, 5, 6)] == [1, 4, 4, 6, 6]


def test_runs_that_cannot_be_batched_run_alone_and_keep_their_rows():
    kinds = ["wh", "dt", "leapfrog", "wh", "corrector", "wh", "escape", "dt", "bad", "wh"]
    params = [dict(p, kind=k) for p, k in zip(SWEEP, kinds)]
    alone = Ensemble(mixed, params).run(100 * u.yr, client="serial", outputs=5,
                                        progress=False)
    df = Ensemble(mixed, params).run(100 * u.yr, client="serial", outputs=5,
                                     progress=False, batch=4)
    assert_same_rows(alone, df)
    # the unknown kind is invalid; 'wh' with an escape distance runs alone, and
    # its planet, at 4.4 au beside Jupiter, passes 100 au in step 720 of its
    # 30-day steps (as a run without the condition shows)
    assert df.outcome[df.outcome == "invalid"].index.tolist() == [8]
    assert df.outcome[6] == "escape" and df.steps[6] == 720


def test_which_simulations_batch():
    spec = _Spec(100 * u.yr, 5, None)
    assert _batch.batch_key(three_planets(3.0, 0.1), spec) is not None
    others = [three_planets(3.0, 0.1, integrator="leapfrog"),
              three_planets(3.0, 0.1, integrator="saba2"),
              three_planets(3.0, 0.1, integrator=orbits.integrators.get(
                  "wh", coordinates="democratic-heliocentric")),
              three_planets(3.0, 0.1, softening=1e-3 * u.au),
              three_planets(3.0, 0.1, monitor_every=10),
              three_planets(3.0, 0.1, monitors=("energy", "megno"), seed=1),
              three_planets(3.0, 0.1, variations="state"),
              three_planets(3.0, 0.1, forces=[orbits.forces.GRPotential("Sun")])]
    for sim in others:
        assert _batch.batch_key(sim, spec) is None, sim
    # a run to a time before its start raises alone: it is left to do so
    assert _batch.batch_key(three_planets(3.0, 0.1), _Spec(-1 * u.yr, 5, None)) is None
    # the same system with another step or number of outputs: another batch
    k1 = _batch.batch_key(three_planets(3.0, 0.1), spec)[0]
    assert _batch.batch_key(three_planets(3.5, 0.2), spec)[0] == k1
    assert _batch.batch_key(three_planets(3.0, 0.1, dt=20.0), spec)[0] != k1
    assert _batch.batch_key(three_planets(3.0, 0.1), _Spec(100 * u.yr, 6, None))[0] != k1


def runaway(member, blow):
    # a run whose Saturn starts at an absurd speed: its Kepler drift overflows in
    # the first step and the state turns non-finite
    sim = three_planets(2.0 + 0.3 * member, 0.05)
    if blow:
        state = sim.state
        v = state.v.copy()
        v[2] *= 1e160
        sim.set_state(state._replace(v=v))
    return sim


@pytest.mark.filterwarnings("ignore:overflow encountered:RuntimeWarning")
def test_a_run_that_turns_non_finite_has_the_outcome_it_has_alone():
    params = [{"member": k, "blow": k in (1, 4)} for k in range(6)]
    alone = Ensemble(runaway, params).run(50 * u.yr, client="serial", outputs=5,
                                          progress=False)
    df = Ensemble(runaway, params).run(50 * u.yr, client="serial", outputs=5,
                                       progress=False, batch=4)
    assert_same_rows(alone, df)
    assert df.outcome.tolist() == ["completed", "non-finite-state", "completed", "completed",
                                   "non-finite-state", "completed"]


def test_files_in_out_dir_hold_the_same_outputs(tmp_path):
    ens = Ensemble(three_planets, SWEEP[:5])
    alone = ens.run(100 * u.yr, client="serial", outputs=9, progress=False,
                    out_dir=tmp_path / "alone")
    df = ens.run(100 * u.yr, client="serial", outputs=9, progress=False,
                 out_dir=tmp_path / "batched", batch=4)
    assert_same_rows(alone, df)
    for name in df.file:
        with h5py.File(tmp_path / "alone" / name) as f, \
                h5py.File(tmp_path / "batched" / name) as g:
            for key in ("particles/bodies/position/value", "particles/bodies/velocity/value",
                        "observables/energy/value", "observables/energy/time"):
                assert np.array_equal(f[key][()], g[key][()]), key
        assert orbits.load(tmp_path / "batched" / name).times.size == 9


@pytest.mark.parametrize("bad", [0, -2, 2.5, True, "4", 4.0])
def test_batch_must_be_a_whole_number_of_systems(bad):
    ens = Ensemble(three_planets, SWEEP[:2])
    with pytest.raises(EnsembleOptionError, match=r"batch must be None or a whole number "
                                                  r"of systems per batch >= 1, got"):
        ens.run(10 * u.yr, client="serial", outputs=2, progress=False, batch=bad)


def test_tasks_on_a_cluster_hold_whole_batches():
    chunks = _Chunks(list(range(100)), workers=2, batch=8)
    first = chunks.first()
    assert [len(c) for c in first] == [8, 8, 8, 8]
    chunks.took([{"wall_time_s": 0.01}] * 32)
    later = chunks.next(queued=0)
    assert later and all(len(c) % 8 == 0 or c[-1] == 99 for c in later)
    assert sorted(sum(first + later, [])) == list(range(sum(map(len, first + later))))


def test_a_cluster_runs_batches_and_gives_the_same_rows(alone):
    client = local_cluster(1)
    try:
        df = Ensemble(three_planets, SWEEP).run(UNTIL, client=client, outputs=37,
                                                progress=False, batch=8)
    finally:
        cluster = client.cluster
        client.close()
        cluster.close()
    assert_same_rows(alone, df)
