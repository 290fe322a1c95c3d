"""Long-run behaviour of the invariants (STYLE layer d)."""

import math

import numpy as np
import pytest

import orbits

from helpers import kepler_bodies

ORBITS = 10_000
SYMPLECTIC = ["symplectic-euler", "verlet", "leapfrog"]


def energy_series(name, steps_per_orbit, orbits_=ORBITS, outputs=4001):
    b = kepler_bodies(e=0.3, m_orbiter=1e-3)
    sim = orbits.Simulation(b, integrator=name, dt=2 * math.pi / steps_per_orbit,
                            monitors=("energy",))
    r = sim.run(until=2 * math.pi * orbits_, outputs=outputs, progress=False)
    return r.energy_error


@pytest.mark.parametrize("name", SYMPLECTIC)
def test_symplectic_energy_error_is_bounded(name):
    # a symplectic method conserves a modified energy exactly (backward error
    # analysis, HLW IX.8): the error oscillates with a fixed amplitude, so the
    # largest error in the last tenth of 10,000 orbits matches the first tenth.
    # A factor 1.5 leaves room for sampling different phases; secular growth
    # over 10,000 orbits would give a factor ~10.
    err = energy_series(name, 500)
    tenth = len(err) // 10
    early = err[1:tenth].max()
    late = err[-tenth:].max()
    assert late < 1.5 * early, (early, late)
    assert early > 0


def test_explicit_euler_energy_grows():
    # the negative control: explicit Euler expands phase space, so its energy
    # error grows secularly; the same criterion must fail for it
    err = energy_series("euler", 20000, orbits_=100, outputs=1001)
    tenth = len(err) // 10
    assert err[-tenth:].max() > 5 * err[1:tenth].max()


def test_rk4_energy_drifts_linearly():
    # rk4 is not symplectic: over 10,000 orbits its energy error keeps growing
    err = energy_series("rk4", 100, orbits_=2000, outputs=2001)
    tenth = len(err) // 10
    assert err[-tenth:].max() > 5 * err[1:tenth].max()


@pytest.mark.parametrize("name", SYMPLECTIC)
def test_splittings_keep_angular_momentum_to_roundoff(name):
    # drifts leave x cross v unchanged and kicks are along the line joining
    # pairs, so angular momentum is conserved up to rounding: after n steps at
    # most ~n * eps in the worst case (1e5 steps: 2e-11); in practice a random
    # walk of ~sqrt(n) eps.  rk4 on the same run errs by ~1e-7 (below).
    b = orbits.scenes.outer_solar_system()
    sim = orbits.Simulation(b, integrator=name, dt=50.0, monitors=("angular_momentum",))
    r = sim.run(until=50.0 * 100_000, outputs=101, progress=False)
    assert r.angular_momentum_error.max() < 2e-11


def test_rk4_does_not_keep_angular_momentum_exactly():
    b = orbits.scenes.outer_solar_system()
    sim = orbits.Simulation(b, integrator="rk4", dt=200.0, monitors=("angular_momentum",))
    r = sim.run(until=200.0 * 25_000, outputs=11, progress=False)
    assert r.angular_momentum_error.max() > 1e-10


@pytest.mark.parametrize("name", ["verlet", "leapfrog"])
def test_time_reversibility(name):
    # symmetric methods retrace their steps with -dt up to rounding
    # (error ~ n eps |x|: 1000 steps -> ~1e-13; allow 1e-12)
    b = kepler_bodies(e=0.6)
    x0 = b.positions.value.copy()
    tr = orbits.integrators.get(name)
    sim = orbits.Simulation(b, integrator=tr, dt=0.01, monitors=())
    sim.run(until=10.0, outputs=2, progress=False)
    back = orbits.Simulation(sim.bodies, integrator=name, dt=0.01, monitors=())
    # integrate backward by reversing velocities (time reversal symmetry)
    bb = back.bodies
    rev = orbits.BodySet.from_arrays(bb.masses.value, bb.positions.value,
                                     -bb.velocities.value, names=bb.names, units=bb.units)
    r = orbits.Simulation(rev, integrator=name, dt=0.01, monitors=()).run(
        until=10.0, outputs=2, progress=False)
    np.testing.assert_allclose(r.positions.value[-1], x0, rtol=0, atol=1e-12)
