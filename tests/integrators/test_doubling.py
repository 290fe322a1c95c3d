"""rk4-doubling: fourth order, error control by step doubling."""

import math

import numpy as np
import pytest

import orbits

from helpers import adaptive_fixed_steps_error, kepler_bodies


def test_order_four_with_fixed_steps():
    # the kept result is two RK4 half steps: fourth order (no extrapolation);
    # 100..400 steps per orbit at e = 0.2 are in the asymptotic range
    errs = [adaptive_fixed_steps_error("rk4-doubling", n) for n in (100, 200, 400)]
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
