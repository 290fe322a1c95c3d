"""The work of non-conservative force terms: E + W is conserved to the integration error.

A drag ``a = -k v`` on the Kepler problem takes energy out of the orbit; the
loops integrate its work ``W = -int sum m a . v dt`` with each integrator's own
quadrature, so that ``|E + W - E0| / |E0|`` (the energy error the monitor
reports) stays at the level of the same integrator's conservative run.
"""

import math

import astropy.units as u
import numba
import numpy as np
import pytest

import orbits
from orbits._kernels import ias15 as kias15
from orbits.errors import IntegratorOptionError, NonFiniteState

#: the drag rate, per day: over ten years it takes 2.2 % of the orbit's energy
#: out, a hundred times the largest conservative error of these runs
DRAG = 3e-6
#: from this time on the drag turns to NaN (only the non-finite test gets there)
BLOW_UP = 20000.0


@numba.njit
def drag(x, v, t, m):
    k = DRAG if t < BLOW_UP else math.nan
    return -k * v


def _sim(integrator, dt=None, drag_on=True, **kw):
    """The Kepler orbit of e = 0.5, with the drag or without."""
    forces = [orbits.forces.UserForce(drag, velocity_dependent=True)] if drag_on else []
    return orbits.Simulation(orbits.scenes.kepler(e=0.5), integrator=integrator, dt=dt,
                             forces=forces, **kw)


# -- the quadrature of IAS15 ----------------------------------------------------------------

def test_radau_weights_integrate_polynomials_to_degree_14():
    # eight nodes, one fixed at 0: the left Radau rule integrates t^j exactly
    # for j <= 2 * 8 - 2 = 14 (Abramowitz & Stegun 25.4.31), and not t^15; the
    # weights come from the float nodes, so "exactly" means to a few roundings
    w = kias15.RADAU_WEIGHTS
    nodes = np.concatenate([[0.0], kias15.SPACINGS])
    assert len(w) == 8 and abs(w.sum() - 1.0) < 4e-16
    for j in range(15):
        assert abs(w @ nodes ** j - 1.0 / (j + 1)) < 4e-16, j
    assert abs(w @ nodes ** 15 - 1.0 / 16) > 1e-10  # the degree is sharp (1.5e-9 off)
    assert abs(w[0] - 1.0 / 64) < 1e-16                # the end node's weight, 1 / n^2
    assert np.all(w > 0)


# -- E + W at the conservative level -------------------------------------------------------

#: (integrator, options, dt in days): fixed steps of a day (365 a period), or
#: tolerances that give a few hundred steps a period
METHODS = [("leapfrog", {}, 1.0), ("rk4", {}, 1.0), ("implicit-midpoint", {}, 1.0),
           ("dopri5", {"rtol": 1e-10, "atol": 1e-13}, None), ("ias15", {}, None)]


def _run(name, options, dt, drag_on):
    integ = orbits.integrators.get(name, **options)
    sim = _sim(integ, None if dt is None else dt * u.day, drag_on)
    # an output at every step of the fixed-step runs (2000 for the adaptive
    # ones), so that the largest error is the largest of the run, not of a few
    # orbital phases that outputs at a fixed spacing would sample
    outputs = 3653 if dt is not None else 2000
    r = sim.run(until=10 * u.yr, outputs=outputs, progress=False)
    return r


@pytest.mark.parametrize("name, options, dt", METHODS, ids=[m[0] for m in METHODS])
def test_energy_plus_work_is_conserved_at_the_conservative_level(name, options, dt):
    free = _run(name, options, dt, drag_on=False)
    dragged = _run(name, options, dt, drag_on=True)
    level = free.energy_error.max()
    e = dragged.energy.value
    lost = abs(e[-1] - e[0]) / abs(e[0])
    # the drag does something the monitor would see without W: 2.2e-2 of E0,
    # 38 times the largest conservative level here (implicit midpoint, 5.8e-4)
    assert lost > 20 * level
    assert dragged.work is not None and free.work is None
    assert np.allclose(dragged.work.value[-1], e[0] - e[-1], rtol=1e-2)
    # E + W: measured 1.00 (leapfrog), 1.14 (rk4), 1.15 (implicit midpoint) and
    # 1.08 (dopri5) times the conservative run's largest error, the orbit
    # being 2 % tighter at the end; IAS15's are both rounding (1.6e-15 and
    # 1.8e-15), which scatter by a few
    factor = 3.0 if name == "ias15" else 1.5
    assert dragged.energy_error.max() < factor * level
    assert dragged.max_energy_error() == dragged.energy_error.max()


def test_work_converges_at_the_integrators_order():
    # W against IAS15's (exact to rounding): the leapfrog's and the implicit
    # midpoint's error falls 4 times a halving of dt (order 2; measured 4.01
    # and 4.00, 3.96 and 3.99), rk4's 16 times (order 4; measured 21.5 and
    # 19.4, coming down to 16)
    ref = _sim("ias15")
    ref.run(until=10 * u.yr, outputs=2, progress=False)
    w_ref = ref.work.value

    def order(name):
        errs = []
        for dt in (1.0, 0.5, 0.25):
            sim = _sim(name, dt * u.day)
            r = sim.run(until=10 * u.yr, outputs=2, progress=False)
            errs.append((abs(sim.work.value - w_ref) / w_ref, r.energy_error[-1]))
        w_err, e_err = np.array(errs).T
        return np.log2(w_err[:-1] / w_err[1:]), np.log2(e_err[:-1] / e_err[1:])

    w_order, e_order = order("leapfrog")
    assert np.all(abs(w_order - 2) < 0.1) and np.all(abs(e_order - 2) < 0.1)
    w_order, _ = order("rk4")
    assert np.all((w_order > 3.6) & (w_order < 4.7))


# -- state, files and failures -------------------------------------------------------------

@pytest.mark.parametrize("name", ["leapfrog", "ias15"])
def test_restart_from_a_file_continues_the_work_bit_for_bit(tmp_path, name):
    path = tmp_path / "run.h5"
    dt = None if name == "ias15" else 1 * u.day
    ref = _sim(name, dt)
    ref.run(until=100 * u.day, outputs=5, progress=False)
    r_ref = ref.run(until=200 * u.day, outputs=5, progress=False)
    first = _sim(name, dt)
    first.run(until=100 * u.day, outputs=5, output=path, progress=False)
    again = orbits.Simulation.from_file(path, functions={"drag": drag})
    assert again.work == first.work and first.work.value > 0
    r = again.run(until=200 * u.day, outputs=5, output=path, progress=False)
    assert np.array_equal(again.state.x, ref.state.x)
    assert again.work == ref.work
    assert np.array_equal(again.state.workspace["work"], ref.state.workspace["work"])
    # the file keeps W beside E, and its energy errors are those of E + W
    loaded = orbits.load(path)
    assert np.array_equal(loaded.work.value[-5:], r_ref.work.value)
    assert np.array_equal(loaded.energy_error[-5:], r_ref.energy_error)
    assert r.max_energy_error() == loaded.energy_error.max()
    assert loaded.work.unit == loaded.energy.unit


class _Crash(Exception):
    pass


def test_interrupted_run_resumes_to_the_same_work_series(tmp_path, monkeypatch):
    # a run killed after an output and resumed from the checkpoint writes the
    # same file, its work series and the errors of E + W included
    from orbits.io.h5md import FileRecorder
    whole = tmp_path / "whole.h5"
    cut = tmp_path / "cut.h5"
    r_whole = _sim("leapfrog", 1 * u.day, monitor_every=10).run(
        until=400 * u.day, outputs=21, output=whole, progress=False, checkpoint_interval=0)
    real = FileRecorder.output
    seen = []

    def crashing(self, sim, final=False):
        real(self, sim, final)
        seen.append(1)
        if len(seen) == 9:
            raise _Crash()
    monkeypatch.setattr(FileRecorder, "output", crashing)
    with pytest.raises(_Crash):
        _sim("leapfrog", 1 * u.day, monitor_every=10).run(
            until=400 * u.day, outputs=21, output=cut, progress=False, checkpoint_interval=0)
    monkeypatch.setattr(FileRecorder, "output", real)
    r_cut = orbits.Simulation.from_file(cut, functions={"drag": drag}).resume(progress=False)
    a, b = orbits.load(whole), orbits.load(cut)
    assert np.array_equal(a.work.value, b.work.value) and a.work.value[-1] > 0
    assert np.array_equal(a.energy_error, b.energy_error)
    assert r_cut.max_energy_error() == r_whole.max_energy_error()


def test_state_record_carries_the_work():
    sim = _sim("leapfrog", 1 * u.day)
    start = sim.state
    assert list(start.workspace["work"]) == [0.0, 0.0]
    sim.run(until=100 * u.day, outputs=2, progress=False)
    w = sim.work
    assert w.value > 0
    sim.set_state(start)
    assert sim.work.value == 0.0
    sim.run(until=100 * u.day, outputs=2, progress=False)
    assert sim.work == w


def test_non_finite_state_leaves_the_work_of_the_last_good_step():
    # the driver finds the failing step by running a copy of the state and the
    # workspace again; W, kept in the workspace, is that of the last good state
    sim = _sim("leapfrog", 1 * u.day)
    with pytest.raises(NonFiniteState):
        sim.run(until=30000 * u.day, outputs=2, progress=False)
    good = _sim("leapfrog", 1 * u.day)
    good.run(until=sim.time, outputs=2, progress=False)
    assert sim.steps == good.steps and sim.time.value == pytest.approx(BLOW_UP, abs=1.0)
    assert np.array_equal(sim.state.x, good.state.x)
    assert sim.work == good.work and math.isfinite(sim.work.value)


def test_in_loop_monitor_rows_record_the_work():
    sim = _sim("rk4", 1 * u.day, monitor_every=1)
    r = sim.run(until=10 * u.yr, outputs=11, progress=False)
    mon = r.monitor
    assert np.array_equal(mon["work"].value[-1:], r.work.value[-1:])
    assert mon["energy_error"].max() < 1e-6       # E + W, not E (2.2e-2)


def test_scipy_references_integrate_the_work():
    # radau carries W as one more component of its ODE, under its tolerance
    pytest.importorskip("scipy")
    integ = orbits.integrators.get("radau", rtol=1e-10, atol=1e-13)
    # a quarter of the orbit (scipy's Radau evaluates the force some 2500
    # times, each a call from Python)
    free = _sim(integ, drag_on=False).run(until=0.25 * u.yr, outputs=11, progress=False)
    dragged = _sim(integ).run(until=0.25 * u.yr, outputs=11, progress=False)
    e = dragged.energy.value
    # measured: E + W off by 1.1e-13 against 1.3e-13 without the drag, which
    # took 6.1e-4 of the energy out (over the whole orbit 4.9e-13 against
    # 4.4e-13, with 2.2e-3 out)
    assert abs(e[-1] - e[0]) / abs(e[0]) > 1e-4
    assert dragged.energy_error.max() < 3 * free.energy_error.max()


def test_wisdom_holman_refuses_a_term_without_potential():
    with pytest.raises(IntegratorOptionError, match="has no potential|velocities"):
        _sim("wh", 1 * u.day)


# -- nothing changes without non-conservative terms ------------------------------------------

#: largest energy errors of the conservative Kepler runs below, measured with
#: the loops as they were before the work was integrated (the same bits now)
BEFORE = {"leapfrog": 0.00019720598130213365, "ias15": 1.0734175421859677e-15}


@pytest.mark.parametrize("name", ["leapfrog", "ias15"])
def test_without_non_conservative_terms_the_work_is_zero_and_errors_unchanged(name):
    sim = _sim(name, 1 * u.day if name == "leapfrog" else None, drag_on=False)
    r = sim.run(until=10 * u.yr, outputs=101, progress=False)
    assert sim.work.value == 0.0 and r.work is None
    assert "work" not in sim.state.workspace
    e = r.energy.value
    assert np.array_equal(r.energy_error, np.abs(e - e[0]) / abs(e[0]))
    assert r.energy_error.max() == pytest.approx(BEFORE[name], rel=1e-12)


def test_conservative_terms_do_no_work():
    # a term with a potential is in the energy, not in W
    sim = orbits.Simulation(orbits.scenes.kepler(e=0.5), "leapfrog", dt=1 * u.day,
                            forces=[orbits.forces.GRPotential("Star")])
    r = sim.run(until=1 * u.yr, outputs=3, progress=False)
    assert r.work is None and sim.work.value == 0.0
