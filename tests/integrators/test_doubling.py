"""rk4-doubling: fourth order, error control by step doubling."""

import math

import numpy as np
import pytest

import orbits
from orbits._kernels import stepping
from orbits._kernels.gravity import pair_workspace

from helpers import kepler_bodies


def one_orbit(n, e=0.2):
    # loose tolerances: every step accepted, so the steps are exactly 2 pi / n
    integ = orbits.integrators.get("rk4-doubling", rtol=1e6, atol=1e6)
    b = kepler_bodies(e=e)
    x, v = b.positions.value.copy(), b.velocities.value.copy()
    x0, v0 = x.copy(), v.copy()
    m = b.masses.value
    ws = integ.workspace(2, 2 * math.pi / n)
    fargs = (m.copy(), 1, 0.0, pair_workspace(2, 1))
    force = stepping.gravity_force("small")
    mon = (0, 0, m, 1.0, 1, 0.0)
    t = 0.0
    for k in range(n):
        status, t, acc, rej, fev, _ = integ.advance_to(
            ws, x, v, t, (k + 1) * 2 * math.pi / n, force, fargs, mon, k, np.empty(0),
            np.zeros((0, 10)), None, 10)
        assert status == 0 and acc == 1 and rej == 0 and fev in (11, 12)
    return np.abs(x - x0).max() + np.abs(v - v0).max()


def test_order_four_with_fixed_steps():
    # the kept result is two RK4 half steps: fourth order (no extrapolation);
    # 100..400 steps per orbit at e = 0.2 are in the asymptotic range
    errs = [one_orbit(n) for n in (100, 200, 400)]
    orders = [math.log2(errs[i] / errs[i + 1]) for i in range(2)]
    assert all(abs(p - 4) < 0.2 for p in orders), (orders, errs)


def test_tolerance_controls_the_error_and_costs_steps():
    errs, steps = [], []
    start = kepler_bodies(e=0.5).positions.value[1]
    for rtol in (1e-6, 1e-9):
        integ = orbits.integrators.get("rk4-doubling", rtol=rtol, atol=rtol * 1e-3)
        r = orbits.Simulation(kepler_bodies(e=0.5), integrator=integ).run(
            until=20 * math.pi, outputs=2, progress=False)
        errs.append(np.abs(r.positions.value[-1, 1] - start).max())
        steps.append(r.steps)
        assert r.force_evaluations >= 11 * r.steps
    # 1000 times tighter: the global error falls by at least 100 (theory:
    # 1000^(4/5) = 250 for a per-step criterion of order 4)
    assert errs[0] > 100 * errs[1] and steps[1] > steps[0]


def test_bad_options():
    with pytest.raises(orbits.IntegratorOptionError, match="rtol"):
        orbits.integrators.get("rk4-doubling", rtol=-1)
