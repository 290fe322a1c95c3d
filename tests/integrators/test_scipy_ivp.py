"""radau and lsoda: scipy's solvers behind the integrator contract."""

import math

import numpy as np
import pytest

import orbits

from helpers import kepler_bodies


@pytest.mark.parametrize("name", ["radau", "lsoda"])
def test_agree_with_the_exact_orbit(name):
    # after exactly one period the orbit is back at its start; at rtol 1e-10
    # the global error over one orbit is ~1e-8 (measured 1e-9 .. 1e-8)
    b = kepler_bodies(e=0.3)
    integ = orbits.integrators.get(name, rtol=1e-10, atol=1e-12)
    r = orbits.Simulation(b, integrator=integ).run(until=2 * math.pi, outputs=5,
                                                   progress=False)
    err = np.abs(r.positions.value[-1, 1] - b.positions.value[1]).max()
    assert err < 1e-7
    assert r.steps > 10 and r.force_evaluations > r.steps
    np.testing.assert_array_equal(r.times.value, [k * 2 * math.pi / 4 for k in range(4)]
                                  + [2 * math.pi])


def test_tighter_tolerance_is_more_accurate():
    b = kepler_bodies(e=0.3)
    errs = []
    for rtol in (1e-6, 1e-10):
        integ = orbits.integrators.get("radau", rtol=rtol, atol=rtol * 1e-2)
        r = orbits.Simulation(b, integrator=integ).run(until=2 * math.pi, outputs=2,
                                                       progress=False)
        errs.append(np.abs(r.positions.value[-1, 1] - b.positions.value[1]).max())
    assert errs[0] > 100 * errs[1]


def test_options_and_unsupported_features():
    with pytest.raises(orbits.IntegratorOptionError, match="rtol"):
        orbits.integrators.get("lsoda", rtol=0)
    with pytest.raises(orbits.IntegratorOptionError, match="stopping conditions"):
        orbits.Simulation(kepler_bodies(), integrator="radau", escape_distance=10.0)
    sim = orbits.Simulation(kepler_bodies(), integrator="radau", monitor_every=5)
    with pytest.raises(orbits.IntegratorOptionError, match="monitor_every"):
        sim.run(until=1.0, outputs=2, progress=False)


@pytest.mark.parametrize("method", ["lsoda", "radau"])
def test_user_state_padding_stays_zero(method):
    # a scalar state fills one of the three entries of its row; the other two
    # must have zero derivatives, or the solver's error control sees whatever
    # memory was there (lsoda then failed at random with StepSizeUnderflow)
    import numba

    @numba.njit
    def spring(x, v, t):
        return -100.0 * x

    runs = [orbits.integrate(spring, 1.0, 0.0, method=method, until=2.0, outputs=3)
            for _ in range(3)]
    for tr in runs[1:]:
        assert np.array_equal(tr.x, runs[0].x) and tr.steps == runs[0].steps
    # rtol 1e-9 on an oscillation of amplitude 1 over 3 periods: ~1e-7 at worst
    assert abs(runs[0].x[-1] - np.cos(20.0)) < 1e-6
