"""Yoshida's compositions of the leapfrog: their weights and measured orders.

The registry-wide convergence test (test_convergence.py) measures every
fixed-step method on a Kepler orbit; here the orders are measured again on a
problem with no special structure (the Hénon-Heiles potential), so that a
cancellation peculiar to the Kepler problem cannot hide a wrong coefficient.
"""

import math

import numba
import numpy as np
import pytest

import orbits
from orbits.integrators import tableaux

COMPOSITIONS = {"yoshida4": (4, tableaux.YOSHIDA4_WEIGHTS),
                "yoshida6": (6, tableaux.YOSHIDA6_WEIGHTS),
                "yoshida8": (8, tableaux.YOSHIDA8_WEIGHTS)}


def full_weights(outer):
    w0 = 1.0 - 2.0 * math.fsum(outer)
    return np.array(list(outer) + [w0] + list(outer)[::-1])


@pytest.mark.parametrize("name", COMPOSITIONS)
def test_weights_satisfy_the_odd_power_conditions(name):
    # a symmetric composition of a symmetric second-order method has order
    # >= 2k + 2 only if sum w^(2j+1) = 0 for j = 1..k (Yoshida 1990, sect. 4);
    # these are necessary, not sufficient (the orders are measured below).
    # The weights are printed to 15 digits and |w| < 2, so a power sum of
    # degree 7 over 15 weights carries up to ~15 * 7 * 2^6 * 1e-15 = 7e-12 from
    # the last printed digit (measured for yoshida8: 2.7e-12).
    order, outer = COMPOSITIONS[name]
    w = full_weights(outer)
    assert math.fsum(w) == 1.0
    for p in range(3, order, 2):
        assert abs(math.fsum(w ** p)) < 1e-11, (name, p)
    # the next odd power does not vanish: the declared order is not an understatement
    assert abs(math.fsum(w ** (order + 1))) > 1e-3


@pytest.mark.parametrize("name", COMPOSITIONS)
def test_table_is_the_composition(name):
    # kicks are the weights; drifts the means of neighbouring weights
    _, outer = COMPOSITIONS[name]
    w = full_weights(outer)
    ops = orbits.integrators.get(name).operators
    kicks = np.array([c for k, c in ops if k == "kick"])
    drifts = np.array([c for k, c in ops if k == "drift"])
    mid = 0.5 * (w[:-1] + w[1:])
    np.testing.assert_allclose(kicks, w, rtol=0, atol=1e-15)
    np.testing.assert_allclose(drifts, np.r_[0.5 * w[0], mid, 0.5 * w[-1]], rtol=0,
                               atol=1e-15)
    assert [k for k, _ in ops] == ["drift", "kick"] * len(w) + ["drift"]


@numba.njit(cache=True)
def henon_heiles(x, v, t):
    a = np.empty(2)
    a[0] = -x[0] - 2.0 * x[0] * x[1]
    a[1] = -x[1] - x[0] * x[0] + x[1] * x[1]
    return a


X0 = np.array([0.1, -0.2])
V0 = np.array([0.3, 0.15])   # energy 0.097 < 1/6: bounded, chaotic layer avoided
T_END = 10.0


def final_state(name, steps):
    tr = orbits.integrate(henon_heiles, X0, V0, dt=T_END / steps, steps=steps,
                          method=name, every=steps)
    return np.r_[tr.x[-1], tr.v[-1]]


# Steps over T_END: coarse enough that the error stays far above round-off
# (yoshida8 at 240 steps: error 8e-14, against round-off ~5e-15), fine enough
# to be asymptotic (measured: 4.03, 4.01; 6.00, 6.00; 7.85, 7.87; at coarser
# steps yoshida8's higher terms still show, e.g. 7.63 from 40 to 80 steps).
STEPS = {"yoshida4": (40, 80, 160), "yoshida6": (40, 80, 160), "yoshida8": (60, 120, 240)}


@pytest.mark.parametrize("name", COMPOSITIONS)
def test_measured_order_on_henon_heiles(name):
    order, _ = COMPOSITIONS[name]
    # reference: the eighth-order method at a step 16 times below the finest used
    ref = final_state("yoshida8", 16 * STEPS[name][-1])
    errs = [np.linalg.norm(final_state(name, n) - ref) for n in STEPS[name]]
    measured = [math.log2(errs[i] / errs[i + 1]) for i in range(len(errs) - 1)]
    # the same criterion as the registry-wide test: within 0.2 of the declared order
    assert all(abs(p - order) < 0.2 for p in measured), (name, measured, errs)


@pytest.mark.parametrize("name", COMPOSITIONS)
def test_time_reversible(name):
    # symmetric: n steps with h then n steps with -h return to the start, up
    # to round-off (one ulp of the state per sub-step, ~1e-16 * 100 steps * 15)
    n = 100
    fwd = orbits.integrate(henon_heiles, X0, V0, dt=0.05, steps=n, method=name, every=n)
    back = orbits.integrate(henon_heiles, fwd.x[-1], fwd.v[-1], dt=-0.05, steps=n,
                            method=name, every=n)
    np.testing.assert_allclose(back.x[-1], X0, rtol=0, atol=1e-13)
    np.testing.assert_allclose(back.v[-1], V0, rtol=0, atol=1e-13)
