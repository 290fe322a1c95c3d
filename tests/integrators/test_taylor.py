"""Taylor's method (``taylor``): its series, its step, its accuracy and its refusals."""

import math

import astropy.units as u
import numpy as np
import pytest

import orbits
from orbits import forces
from orbits._kernels import taylor as tk
from orbits._kernels.gravity import gravity_args
from orbits._kernels.kepler import kepler_drift
from orbits._kernels.stepping import gravity_force
from orbits.errors import IntegratorOptionError, NonFiniteState, StepSizeUnderflow

from ..helpers import kepler_bodies


def _series(x, v, gm, n_active, order, eps2=0.0):
    # the kernel's series of (x, v), through the arrays bind allocates
    integ = orbits.integrators.get("taylor", order=order)
    ws = integ.workspace(len(x))
    integ.bind(ws, gravity_force("small"), gravity_args(1.0, gm, n_active, eps2))
    X, V, D, R2, S, W, IR, A, PI, PJ = ws["series"]
    npair = tk.pairs_and_padding(len(x), n_active, PI, PJ, D)
    ok = tk.expand(x, v, X, V, D, R2, S, W, IR, A, PI, PJ, npair, gm, eps2, order)
    return ok, X, V


def test_order_from_tolerance():
    # Jorba & Zou's rule p = ceil(-ln(tol) / 2 + 1); heyoka.py reports the
    # same orders for these tolerances (benchmarks/bench_ias15.py: 13 at 1e-10,
    # 20 at double's epsilon)
    assert tk.order_for(1e-10) == 13
    assert tk.order_for(float(np.finfo(float).eps)) == 20
    assert tk.order_for(1e-5) == 7
    assert tk.order_for(0.5) == 2
    assert orbits.integrators.get("taylor", tol=1e-10, order=9).order_used == 9


def test_series_of_a_circular_orbit_are_those_of_cos_and_sin():
    # a test particle on the unit circle about a unit mass (G = 1): x = cos t,
    # y = sin t, so x[k] = cos^(k)(0) / k! exactly; the recurrences give them to
    # a few roundings of the largest term (1, at k = 0), measured 2e-19
    order = 20
    x = np.array([[0.0, 0, 0], [1.0, 0, 0]])
    v = np.array([[0.0, 0, 0], [0.0, 1.0, 0]])
    ok, X, V = _series(x, v, np.array([1.0, 0.0]), 1, order)
    assert ok
    k = np.arange(order + 1)
    fact = np.array([math.factorial(i) for i in k], dtype=float)
    cos_k = np.where(k % 2 == 0, (-1.0) ** (k // 2), 0.0) / fact
    sin_k = np.where(k % 2 == 1, (-1.0) ** ((k - 1) // 2), 0.0) / fact
    np.testing.assert_allclose(X[:, 0, 1], cos_k, rtol=0, atol=1e-15)
    np.testing.assert_allclose(X[:, 1, 1], sin_k, rtol=0, atol=1e-15)
    # velocities: the derivative series, v[k] = (k + 1) x[k + 1]
    np.testing.assert_allclose(V[:-1, 0, 1], k[:-1] * 0 + (k[1:] * cos_k[1:]), atol=1e-15)
    # the central body, massive and pulled by nothing massive, stays put
    assert np.all(X[:, :, 0] == 0.0)


def test_series_of_an_eccentric_orbit_match_the_kepler_solution():
    # the series summed at a small h is the exact two-body motion
    # (orbits._kernels.kepler.kepler_drift) to the truncation and a few
    # roundings: near the pericentre (r = 0.3) the series' radius is about
    # 0.17, so at h = 0.02 and order 20 the truncation is (0.02 / 0.17)^21,
    # 3e-20, and only the roundings (1e-16 of the terms) remain
    b = kepler_bodies(e=0.7, f=0.3)
    x, v = b.positions.value.copy(), b.velocities.value.copy()
    order, h = 20, 0.02
    ok, X, V = _series(x, v, b.masses.value.copy(), 1, order)
    xs = sum(X[k, :, 1] * h ** k for k in range(order + 1))
    vs = sum(V[k, :, 1] * h ** k for k in range(order + 1))
    xe = (x[1:] - x[:1]).copy()
    ve = (v[1:] - v[:1]).copy()
    kepler_drift(1.0, xe, ve, 0, h)
    np.testing.assert_allclose(xs, xe[0], rtol=0, atol=1e-14)
    np.testing.assert_allclose(vs, ve[0], rtol=0, atol=1e-14)


def test_two_massive_bodies_move_about_their_barycentre():
    # a pair of equal masses: each is pulled by the other alone, so the
    # barycentre's series stops at order 1 (its velocity) exactly
    x = np.array([[-0.5, 0.0, 0.0], [0.5, 0.0, 0.0]])
    v = np.array([[0.0, -0.5, 0.01], [0.0, 0.5, 0.01]])
    ok, X, V = _series(x, v, np.array([0.5, 0.5]), 2, 12)
    assert ok
    np.testing.assert_allclose(X[2:, :, 0] + X[2:, :, 1], 0.0, atol=1e-16)


@pytest.mark.parametrize("e, bound", [(0.0, 2e-12), (0.5, 2e-12), (0.9, 2e-11),
                                      (0.99, 1.5e-9)])
def test_kepler_orbits_to_round_off(e, bound):
    # a test particle after 20 periods, against the exact two-body solution:
    # measured 1.6e-13, 1.4e-13, 1.7e-12 and 1.2e-10 of a (ias15 at its
    # default epsilon: 5e-14, 4e-14, 4e-13, 4.5e-11 with 4 to 6 times the
    # steps); the bounds leave a factor of ten
    b = kepler_bodies(e=e)
    x0, v0 = b.positions.value.copy(), b.velocities.value.copy()
    sim = orbits.Simulation(b, "taylor", monitors=())
    sim.run(until=20 * 2 * math.pi, outputs=2, progress=False)
    xe = (x0[1:] - x0[:1]).copy()
    ve = (v0[1:] - v0[:1]).copy()
    kepler_drift(1.0, xe, ve, 0, 20 * 2 * math.pi)
    x = sim.bodies.positions.value
    assert np.abs((x[1] - x[0]) - xe[0]).max() < bound


def test_outer_solar_system_matches_ias15_and_conserves_energy():
    # 1000 years: our ias15 (epsilon 1e-9) and taylor at its default tol agree
    # to 3e-10 au, the error level both reach at 10^4 years against an
    # extended-precision reference (benchmarks/RESULTS.md, bench_ias15),
    # measured 5e-12 here; the energy error measured 1e-15 to 1.9e-15
    b = orbits.scenes.outer_solar_system()
    sim = orbits.Simulation(b, "taylor", monitors=["energy", "angular_momentum"])
    res = sim.run(until=1000 * u.yr, outputs=3, progress=False)
    ref = orbits.Simulation(b, "ias15", monitors=()).run(until=1000 * u.yr, outputs=3,
                                                           progress=False)
    diff = np.abs(res.positions[-1] - ref.positions[-1]).to_value(u.au).max()
    assert diff < 3e-10
    assert abs(res.energy_error[-1]) < 2e-14
    assert sim.steps < 2000      # 1254 measured: about 15 steps a Jupiter orbit
    assert sim.force_evaluations == 20 * sim.steps


def test_looser_tolerance_takes_a_lower_order_and_a_larger_error():
    # the truncation is near tol of the largest coordinate a step (30 au
    # here), so the error grows as tol does
    b = orbits.scenes.outer_solar_system()
    errs = []
    ref = orbits.Simulation(b, "taylor", monitors=()).run(until=300 * u.yr, outputs=2,
                                                            progress=False)
    for tol in (1e-6, 1e-9):
        integ = orbits.integrators.get("taylor", tol=tol)
        r = orbits.Simulation(b, integ, monitors=()).run(until=300 * u.yr, outputs=2,
                                                         progress=False)
        errs.append(np.abs(r.positions[-1] - ref.positions[-1]).to_value(u.au).max())
    assert errs[0] > 30 * errs[1] > 0.0


def test_test_particles_and_softening_as_ias15():
    # massless bodies are pulled and pull nothing; softened gravity: the two
    # methods agree to their own errors (measured 5e-14 and 2e-14 au over 30
    # years; the bound leaves a factor of twenty)
    b = orbits.scenes.outer_solar_system()
    b.add("tp1", mass=0.0, primary="Sun", a=5.6 * u.au, e=0.1)
    b.add("tp2", mass=0.0, primary="Sun", a=12.0 * u.au, e=0.2, inc=10 * u.deg)
    for kw in ({}, {"softening": 0.01 * u.au}):
        r = [orbits.Simulation(b, name, monitors=(), **kw).run(
            until=30 * u.yr, outputs=2, progress=False).positions[-1].to_value(u.au)
            for name in ("taylor", "ias15")]
        assert np.abs(r[0] - r[1]).max() < 1e-12


def test_outputs_in_the_loop_equal_runs_that_stop_there():
    # the loop lands on each output time as a run ending there does: the same
    # steps, so the same numbers, bit for bit
    b = kepler_bodies(e=0.6)
    times = np.linspace(0.0, 10.0, 6)
    res = orbits.Simulation(b, "taylor", monitors=()).run(until=10.0, outputs=6,
                                                          progress=False)
    sim = orbits.Simulation(b, "taylor", monitors=())
    for k, t in enumerate(times[1:], start=1):
        sim.run(until=t, outputs=2, progress=False)
        assert np.array_equal(sim.bodies.positions.value, res.positions[k].value)


def test_backwards_returns_to_the_start():
    # the loop integrates towards an earlier t_end too: forward five periods
    # and back lands on the start to round-off (measured 5e-14 at e = 0.8)
    integ = orbits.integrators.get("taylor")
    b = kepler_bodies(e=0.8)
    x, v = b.positions.value.copy(), b.velocities.value.copy()
    m = b.masses.value.copy()
    force, fargs = gravity_force("small"), gravity_args(1.0, m, 1, 0.0)
    ws = integ.workspace(2)
    integ.bind(ws, force, fargs)
    mon = (0, 0, m, 1.0, 1, 0.0)
    t = 0.0
    for t_end in (10 * math.pi, 0.0):
        status, t, acc, rej, fev, _ = integ.advance_to(
            ws, x, v, t, t_end, force, fargs, mon, 0, np.empty(0), np.zeros((0, 11)), None,
            10**6)
        assert status.name == "OK" and t == t_end and acc > 50 and rej == 0
    assert np.abs(x - b.positions.value).max() < 1e-12


def test_bad_options_are_named():
    for opts, what in (({"tol": 0.0}, "tol"), ({"tol": "small"}, "tol"),
                       ({"order": 1}, "order"), ({"order": 2.5}, "order"),
                       ({"order": -3}, "order"), ({"min_dt": -1.0}, "min_dt"),
                       ({"epsilon": 1e-9}, "epsilon")):
        with pytest.raises(IntegratorOptionError, match=what):
            orbits.integrators.get("taylor", **opts)


def test_refuses_what_its_recurrences_do_not_cover():
    b = orbits.scenes.outer_solar_system()
    with pytest.raises(IntegratorOptionError, match="taylor cannot take the force term"):
        orbits.Simulation(b, "taylor", forces=[forces.GRPotential("Sun")])
    with pytest.raises(IntegratorOptionError, match="variational equations"):
        orbits.Simulation(b, "taylor", variations=1)
    with pytest.raises(IntegratorOptionError, match="a user's force function"):
        orbits.integrate(lambda x, v, t: -x, np.ones(3), np.zeros(3), until=1.0,
                         method="taylor")


def test_a_collision_stops_with_the_last_good_state():
    # two bodies falling straight onto each other from rest: the series' radius
    # shrinks with the distance, the steps with it, and the run stops with
    # StepSizeUnderflow or NonFiniteState at the time it reached, the state
    # there finite and kept
    b = orbits.BodySet(units=orbits.UnitSystem.nbody())
    b.add("a", mass=0.5, position=[-0.5, 0, 0], velocity=[0, 0, 0])
    b.add("b", mass=0.5, position=[0.5, 0, 0], velocity=[0, 0, 0])
    sim = orbits.Simulation(b, "taylor", monitors=())
    with pytest.raises((StepSizeUnderflow, NonFiniteState)) as info:
        sim.run(until=10.0, outputs=2, progress=False)
    # free fall from rest at separation 1 under G (m_a + m_b) = 1 takes pi / 2^1.5
    assert 0.0 < float(sim.time.value) <= math.pi / 2 ** 1.5 + 1e-9
    assert np.isfinite(sim.bodies.positions.value).all()
    assert "from t = " in str(info.value)


def test_min_dt_stops_the_run():
    b = kepler_bodies(e=0.5)
    sim = orbits.Simulation(b, orbits.integrators.get("taylor", min_dt=10.0), monitors=())
    with pytest.raises(StepSizeUnderflow):
        sim.run(until=100.0, outputs=2, progress=False)
