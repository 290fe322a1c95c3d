"""dopri5 and dop853: tables, orders with fixed steps, tolerance control, outputs."""

import math

import numpy as np
import pytest

import orbits
from orbits.errors import IntegratorOptionError

from helpers import adaptive_fixed_steps_error, kepler_bodies

PAIRS = ["dopri5", "dop853"]


@pytest.mark.parametrize("name", PAIRS)
def test_table_algebra(name):
    cls = type(orbits.integrators.get(name))
    A, B, C, E = cls.A, cls.B, cls.C, cls.E
    # row sums equal the nodes, weights sum to one (rounding of ~20 terms)
    np.testing.assert_allclose(A.sum(axis=1), C, atol=2e-15)
    assert abs(B.sum() - 1) < 4e-15
    # an error estimate is a difference of two consistent weight sets: sums to 0
    assert abs(E.sum()) < 4e-15
    assert np.all(np.triu(A) == 0)


@pytest.mark.parametrize("name, steps", [("dopri5", (100, 200, 400)),
                                         ("dop853", (20, 40, 80))])
def test_fixed_step_order(name, steps):
    # e = 0.2 and these step counts: in the asymptotic regime (measured
    # successive orders 5.22, 5.16 and 7.91, 7.99) and far above rounding
    # (smallest errors 8e-10 and 1e-12; at e = 0.5 the asymptotic range is
    # reached only just above the rounding floor)
    declared = orbits.integrators.get(name).order
    errs = [adaptive_fixed_steps_error(name, n, e=0.2) for n in steps]
    orders = [math.log2(errs[i] / errs[i + 1]) for i in range(len(errs) - 1)]
    assert all(abs(p - declared) < 0.3 for p in orders), (orders, errs)


@pytest.mark.parametrize("name", PAIRS)
def test_error_falls_with_tolerance(name):
    errors, steps = [], []
    for rtol in (1e-6, 1e-9, 1e-12):
        integ = orbits.integrators.get(name, rtol=rtol, atol=rtol * 1e-3)
        r = orbits.Simulation(kepler_bodies(e=0.5), integrator=integ).run(
            until=20 * math.pi, outputs=2, progress=False)
        errors.append(np.abs(r.positions.value[-1, 1] - kepler_bodies(e=0.5).positions.value[1]).max())
        steps.append(r.steps)
    # each 1000-fold tightening cuts the error by at least 100 and costs more steps
    assert errors[0] > 100 * errors[1] > 1e4 * errors[2] / 100
    assert steps[0] < steps[1] < steps[2]


def test_outputs_hit_exactly_and_counts_recorded():
    integ = orbits.integrators.get("dop853", rtol=1e-10, atol=1e-13)
    r = orbits.Simulation(kepler_bodies(e=0.7), integrator=integ).run(
        until=10.0, outputs=37, progress=False)
    # the documented output times: t0 + k (until - t0) / (outputs - 1), the last exactly until
    expected = [k * 10.0 / 36 for k in range(36)] + [10.0]
    np.testing.assert_array_equal(r.times.value, expected)
    assert r.steps > 0 and r.force_evaluations >= 12 * r.steps and r.steps_rejected >= 0
    assert "rejected" in r.summary()


@pytest.mark.parametrize("options, match", [
    (dict(rtol=0.0), "'rtol' must be a positive"), (dict(atol=-1.0), "'atol'"),
    (dict(epsilon=1e-9), "no option 'epsilon'; valid options: atol, rtol"),
])
def test_bad_options(options, match):
    with pytest.raises(IntegratorOptionError, match=match):
        orbits.integrators.get("dopri5", **options)
