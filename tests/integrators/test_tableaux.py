"""Algebra of the coefficient tables (Hairer, Nørsett & Wanner 1993, II.1)."""

import numpy as np
import pytest

from orbits import integrators
from orbits.integrators.base import ExplicitRungeKutta, SplittingMethod

RK = [c for c in integrators._classes() if issubclass(c, ExplicitRungeKutta)]
SPLIT = [c for c in integrators._classes() if issubclass(c, SplittingMethod)]


@pytest.mark.parametrize("cls", RK, ids=lambda c: c.name)
def test_butcher_consistency(cls):
    A, B, C = cls.A, cls.B, cls.C
    s = len(B)
    assert A.shape == (s, s) and C.shape == (s,)
    # explicit: strictly lower triangular
    assert np.all(np.triu(A) == 0)
    # consistency: weights sum to 1 and row sums equal the nodes (exact in binary
    # for these tables up to one rounding of 1/3 and 1/6)
    assert abs(B.sum() - 1.0) < 4e-16
    np.testing.assert_allclose(A.sum(axis=1), C, rtol=0, atol=1e-16)


@pytest.mark.parametrize("cls", RK, ids=lambda c: c.name)
def test_butcher_order_conditions(cls):
    """The classical order conditions up to the declared order (trees up to order 4)."""
    A, b, c = cls.A, cls.B, cls.C
    conditions = {
        1: [(b.sum(), 1.0)],
        2: [(b @ c, 1 / 2)],
        3: [(b @ c ** 2, 1 / 3), (b @ A @ c, 1 / 6)],
        4: [(b @ c ** 3, 1 / 4), (b @ (c * (A @ c)), 1 / 8), (b @ A @ c ** 2, 1 / 12),
            (b @ A @ A @ c, 1 / 24)],
    }
    for order in range(1, cls.order + 1):
        for value, expected in conditions[order]:
            assert abs(value - expected) < 1e-15, (cls.name, order)
    # and the next order fails, so the declared order is not an understatement
    if cls.order + 1 in conditions:
        assert any(abs(v - e) > 1e-3 for v, e in conditions[cls.order + 1])


@pytest.mark.parametrize("cls", SPLIT, ids=lambda c: c.name)
def test_splitting_coefficients_sum_to_one(cls):
    drift = sum(c for k, c in cls.operators if k == "drift")
    kick = sum(c for k, c in cls.operators if k == "kick")
    assert drift == 1.0 and kick == 1.0


@pytest.mark.parametrize("cls", SPLIT, ids=lambda c: c.name)
def test_symmetric_splittings_are_palindromes(cls):
    ops = list(cls.operators)
    assert (ops == ops[::-1]) == cls.time_symmetric
