"""A run's result makes its Quantities and monitor series when they are first
read (orbits.result.Result's deferred fields): the same values as made at
once, carried by copies and pickles, and a field set before it is read kept."""

import copy
import itertools
import pickle

import astropy.units as u
import numpy as np
import pytest

import orbits
from orbits._kernels import invariants as _inv
from orbits.monitors import CHAOS_MONITORS, MONITORS, monitor_field_names, monitor_fields

DEFERRED = ("times", "masses", "radii", "start_time", "dt", "positions", "velocities",
            "energy", "energy_error", "angular_momentum", "angular_momentum_error")


def _run(**kw):
    sim = orbits.Simulation(orbits.scenes.outer_solar_system(), "wh", dt=10 * u.day, **kw)
    return sim, sim.run(until=1 * u.yr, outputs=5, progress=False)


def test_fields_are_made_when_read_and_equal_the_simulation_state():
    sim, r = _run()
    # nothing made yet
    assert not set(DEFERRED) & set(vars(r))
    assert r.positions.unit == u.au and r.positions.shape == (5, 6, 3)
    # reading one field makes its group only
    assert {"times", "positions", "velocities", "dt"} <= set(vars(r))
    assert "energy" not in vars(r)
    # the last output is the simulation's state, in the bodies' order, bit for bit
    assert np.array_equal(r.positions[-1].to_value(u.au), sim.bodies.positions.to_value(u.au))
    assert np.array_equal(r.velocities[-1].value,
                          sim.bodies.velocities.to_value(r.velocities.unit))
    assert r.times[-1] == sim.time and r.dt == sim.dt and r.start_time == 0 * u.day
    assert np.array_equal(r.masses.value, sim.bodies.masses.to_value(r.masses.unit))
    # monitors: the errors from the recorded energies (wh keeps them near round-off
    # times the step's splitting error, far below 1e-6 over a year at 10 days)
    assert r.energy_error[0] == 0.0 and 0 < np.max(np.abs(r.energy_error)) < 1e-6
    assert r.max_energy_error() == np.max(np.abs(r.energy_error))


def test_unknown_names_still_raise():
    _, r = _run()
    with pytest.raises(AttributeError, match="no attribute 'nonsense'"):
        r.nonsense
    assert not hasattr(r, "nonsense")


def test_copies_and_pickles_carry_the_values():
    _, r = _run()
    _, ref = _run()
    for other in (copy.copy(r), copy.deepcopy(r), pickle.loads(pickle.dumps(r))):
        for name in DEFERRED:
            a, b = getattr(other, name), getattr(ref, name)
            assert np.array_equal(np.asarray(getattr(a, "value", a)),
                                  np.asarray(getattr(b, "value", b))), name
        assert other._deferred == {}


def test_a_field_set_before_it_is_read_is_kept():
    _, r = _run()
    r.positions = "mine"
    assert r.velocities.shape == (5, 6, 3)      # makes the group, positions kept
    assert r.positions == "mine"
    clone = pickle.loads(pickle.dumps(r))
    assert clone.positions == "mine"


def test_files_and_file_results_read_the_same(tmp_path):
    sim, r = _run()
    path = tmp_path / "run.h5"
    r2 = orbits.Simulation(orbits.scenes.outer_solar_system(), "wh", dt=10 * u.day).run(
        until=1 * u.yr, outputs=5, progress=False, output=path)
    assert np.array_equal(orbits.load(path).positions.value, r.positions.value)
    # a run written to a file returns its last output
    assert np.array_equal(r2.energy_error, r.energy_error[-1:])


@pytest.mark.parametrize("work", [False, True])
@pytest.mark.parametrize("columns", [10, _inv.MONITOR_WIDTH])
def test_monitor_field_names_are_the_keys_monitor_fields_returns(work, columns):
    rng = np.random.default_rng(0)
    rows = rng.random((3, columns)) + 1.0
    names = sorted(MONITORS) + list(CHAOS_MONITORS)
    for k in range(len(names) + 1):
        for chosen in itertools.combinations(dict.fromkeys(names), k):
            out = monitor_fields(rows, chosen, rows[0], (1.0, 1.0), orbits.UnitSystem(),
                                 work=work)
            assert monitor_field_names(chosen, columns, work) == tuple(out), chosen
