"""Measured convergence order equals the declared order (STYLE layer b).

Oracle: a Kepler orbit returns exactly to its initial state after one
period, so the error after one period is the integrator's global error.
"""

import math

import numpy as np
import pytest

import orbits
from orbits import integrators

from helpers import kepler_bodies

# Methods that split the motion into exact Kepler drifts and kicks (wh, saba*)
# are exact on this oracle, whose only force is the central one; their orders
# are measured on a perturbed problem in test_wisdom_holman.py.
FIXED = [info.name for info in integrators.available()
         if not info.adaptive and not integrators.get(info.name).needs_central_body]

# Steps per orbit.  Coarse enough that the error is far above round-off
# (rk4 at 1600 steps has error ~1e-9), fine enough to be in the asymptotic
# regime for e = 0.5 (checked: successive ratios agree to a few percent).
# yoshida8 at 400 steps has error 9e-12, still far above round-off.
STEPS_PER_ORBIT = {1: (4000, 8000, 16000), 2: (400, 800, 1600), 4: (200, 400, 800),
                   6: (100, 200, 400), 8: (100, 200, 400)}


def one_orbit_error(name, n):
    b = kepler_bodies(e=0.5)
    x0 = b.positions.value[1].copy()
    v0 = b.velocities.value[1].copy()
    sim = orbits.Simulation(b, integrator=name, dt=2 * math.pi / n, monitors=())
    r = sim.run(until=2 * math.pi, outputs=2, progress=False)
    assert r.steps == n
    dx = np.linalg.norm(r.positions.value[-1, 1] - x0)
    dv = np.linalg.norm(r.velocities.value[-1, 1] - v0)
    return dx + dv


@pytest.mark.parametrize("name", FIXED)
def test_measured_order(name):
    declared = integrators.get(name).order
    errs = [one_orbit_error(name, n) for n in STEPS_PER_ORBIT[declared]]
    orders = [math.log2(errs[i] / errs[i + 1]) for i in range(len(errs) - 1)]
    # the criterion: measured order within 0.2 of the declared one
    assert all(abs(p - declared) < 0.2 for p in orders), (name, orders, errs)
