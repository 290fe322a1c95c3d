"""Exactness with REBOUND's leapfrog (issue 4, part 4).

REBOUND's ``leapfrog`` step is drift(h/2), basic gravity, kick(h), drift(h/2)
with ``x += (h/2) v`` and ``v += h a``; its serial pair loop visits j < i and
rounds as :func:`orbits._kernels.gravity.accelerate_pairwise_rebound` does.
With the same initial floats and G (``BodySet.to_rebound``), a loop over that
kernel reproduces REBOUND bit for bit.  The public ``leapfrog`` does not yet:
its force receives ``G m`` only (``Simulation._fargs``), and ``(G / r^3) m``
cannot be formed from ``G m``; see ``test_public_leapfrog_is_bit_identical``.
"""

import math

import astropy.units as u
import numba
import numpy as np
import pytest

import orbits
from orbits._kernels.gravity import accelerate_pairwise_rebound, accelerate_pairwise_small

DT = 10.0  # days


@numba.njit(error_model="numpy")
def dkd_steps(x, v, G, m, n_active, h, nsteps, acc):
    n = x.shape[0]
    half = h * 0.5
    for _ in range(nsteps):
        for i in range(n):
            x[i, 0] += half * v[i, 0]
            x[i, 1] += half * v[i, 1]
            x[i, 2] += half * v[i, 2]
        accelerate_pairwise_rebound(x, G, m, n_active, 0.0, acc)
        for i in range(n):
            v[i, 0] += h * acc[i, 0]
            v[i, 1] += h * acc[i, 1]
            v[i, 2] += h * acc[i, 2]
        for i in range(n):
            x[i, 0] += half * v[i, 0]
            x[i, 1] += half * v[i, 1]
            x[i, 2] += half * v[i, 2]


def state(reb):
    return (np.array([p.xyz for p in reb.particles]),
            np.array([p.vxyz for p in reb.particles]))


def both(nsteps, bodies=None):
    rebound = pytest.importorskip("rebound")  # noqa: F841
    bodies = bodies or orbits.scenes.outer_solar_system()
    reb = bodies.to_rebound()
    reb.integrator = "leapfrog"
    reb.dt = DT
    x, v = state(reb)
    m = np.array([p.m for p in reb.particles])
    dkd_steps(x, v, reb.G, m, len(m), DT, nsteps, np.zeros_like(x))
    reb.steps(nsteps)
    return (x, v), state(reb)


@pytest.mark.parametrize("nsteps", [1, 10_000, 1_000_000])
def test_rebound_arithmetic_is_bit_identical(nsteps):
    # 1e6 steps: 0.1 s here, 0.2 s in REBOUND
    (x, v), (xr, vr) = both(nsteps)
    assert np.array_equal(x, xr) and np.array_equal(v, vr)


def test_rebound_kernel_agrees_with_ours_to_rounding():
    b = orbits.scenes.solar_system(moon=False)
    sim = orbits.Simulation(b, integrator="leapfrog", dt=1 * u.day)
    x, m, G = sim._x, sim._m, sim.units.G
    a1, a2 = np.zeros_like(x), np.zeros_like(x)
    accelerate_pairwise_rebound(x, G, m, len(m), 0.0, a1)
    accelerate_pairwise_small(x, G * m, len(m), 0.0, a2, np.zeros((4, 1)))
    scale = np.abs(a2).max(axis=1, keepdims=True)
    # a few ulps per row (measured 2e-16 relative)
    assert (np.abs(a1 - a2) / scale).max() < 1e-14
    assert not np.array_equal(a1, a2)   # the roundings do differ


def test_no_fused_multiply_add_in_the_exact_loop():
    # fastmath is off, so LLVM must not contract a * b + c into one rounding
    asm = "\n".join(dkd_steps.inspect_asm().values())
    assert "vfmadd" not in asm and "vfmsub" not in asm and "vfnmadd" not in asm


def test_public_leapfrog_is_bit_identical():
    b = orbits.scenes.outer_solar_system()
    reb = b.to_rebound()
    reb.integrator = "leapfrog"
    reb.dt = DT
    reb.steps(10_000)
    sim = orbits.Simulation(b, integrator="leapfrog", dt=DT * u.day, monitors=(),
                            rebound_arithmetic=True)
    sim.run(until=10_000 * DT * u.day, outputs=2, progress=False)
    xr, vr = state(reb)
    assert np.array_equal(sim._x, xr) and np.array_equal(sim._v, vr)


def test_public_leapfrog_is_bit_identical_after_a_million_steps():
    # the criterion: 1,000,000 steps of the outer solar system
    b = orbits.scenes.outer_solar_system()
    reb = b.to_rebound()
    reb.integrator = "leapfrog"
    reb.dt = DT
    reb.steps(1_000_000)
    sim = orbits.Simulation(b, integrator="leapfrog", dt=DT * u.day, monitors=(),
                            rebound_arithmetic=True)
    sim.run(until=1_000_000 * DT * u.day, outputs=2, progress=False)
    xr, vr = state(reb)
    assert np.array_equal(sim._x, xr) and np.array_equal(sim._v, vr)
