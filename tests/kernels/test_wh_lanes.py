"""The Kepler drift of one system with its planets in vector lanes
(orbits._kernels.wh_lanes) against the scalar drift of the Wisdom-Holman
loop (orbits._kernels.wisdom_holman.kepler_drift_all).

Every comparison here is exact (``np.array_equal``, tolerance zero), not a
tolerance: a column the lanes take is computed by the same floating-point
operations in the same order as the scalar short-step path (fastmath is off,
so LLVM neither reorders nor fuses them, and a vector instruction rounds each
lane as its scalar form does), and a column outside the lanes' domain is
drifted by the scalar ``kepler_drift`` itself.  So any difference, even of
one ulp, is a bug.  Each test also checks which path its columns took, so
that the fallbacks it means to test are exercised.
"""

import math

import numpy as np
import pytest

from orbits._kernels.elements import elements_to_state
from orbits._kernels import wh_lanes as L
from orbits._kernels import wisdom_holman as W


def system(orbits_, mu=1.0):
    """Jacobi arrays (N, 3) of a centre of mass (row 0, drifting) and one row
    per ``(a, e, f)`` about ``mu``, and each row's mu."""
    n = len(orbits_) + 1
    xj, vj = np.zeros((n, 3)), np.zeros((n, 3))
    xj[0], vj[0] = (0.1, -0.2, 0.05), (1e-3, 2e-3, -1e-3)
    for i, (a, e, f) in enumerate(orbits_, start=1):
        x, v = np.zeros(3), np.zeros(3)
        assert elements_to_state(mu, a, e, 0.2 + 0.1 * i, 1.0 + i, 2.0 - 0.3 * i, f,
                                   x, v) == 0
        xj[i], vj[i] = x, v
    return xj, vj, np.full(n, mu)


def both(xj, vj, mu, h, steps=1):
    """``steps`` drifts of ``h`` by the scalar drift, by the lanes, and by the
    lanes on the state kept in them (written back after each drift), compared
    after every drift; returns the lanes' scratch after the last and the
    number of planets the lanes declined in it."""
    a, b = xj.copy(), vj.copy()
    c, d = xj.copy(), vj.copy()
    e, f = xj.copy(), vj.copy()
    w1, w2 = np.zeros_like(xj), np.zeros_like(xj)
    S = L.lanes_scratch(len(xj))
    R = L.lanes_scratch(len(xj))
    L.resident_load(e, f, mu, mu, R)
    for k in range(steps):
        W.kepler_drift_all(a, b, mu, h, w1, w2)
        declined = L.kepler_drift_lanes(c, d, mu, h, S)
        kept = L.resident_drift(e, f, mu, h, R)
        L.resident_store(R, e, f)
        for p, q in ((a, c), (b, d), (a, e), (b, f)):
            assert np.array_equal(p, q, equal_nan=True), k
        assert kept == declined
    assert declined == np.sum(~lanes_took(S, len(xj)))
    return S, declined


def lanes_took(S, n):
    return S[L._TAKE, :n - 1] != 0.0


CIRCULAR = [(1.0, 0.0, 0.3), (1.6, 0.01, 2.0), (5.2, 0.05, -1.0), (9.5, 0.0, 4.0)]


def test_circular_planets_take_the_lanes_bit_for_bit():
    # steps of a planetary integration (1/200 of the innermost period)
    xj, vj, mu = system(CIRCULAR)
    S, declined = both(xj, vj, mu, 2 * math.pi / 200, steps=50)
    assert declined == 0


@pytest.mark.parametrize("f", [0.0, 0.05, math.pi])
def test_eccentric_and_hyperbolic_orbits_beside_circular_ones(f):
    # e = 0.99 at pericentre (r = 0.01, where the step is long against the
    # orbit: the scalar drift's bracketed solver), near it and at
    # apocentre, and two hyperbolae, in the same system as circular orbits
    orbits_ = CIRCULAR[:2] + [(1.0, 0.99, f), (-1.0, 1.5, f / 2), (-0.5, 5.0, -f / 3)] \
        + CIRCULAR[2:]
    xj, vj, mu = system(orbits_)
    both(xj, vj, mu, 2 * math.pi / 200, steps=30)
    both(xj, vj, mu, -2 * math.pi / 200, steps=30)
    S, _ = both(xj, vj, mu, 2 * math.pi / 200)
    took = lanes_took(S, len(xj))
    assert took[[0, 1, 5, 6]].all()
    if f == 0.0:
        # at pericentre the e = 0.99 orbit is outside the lanes' domain: it
        # went to the scalar drift
        assert not took[2]


@pytest.mark.parametrize("ratio", [1 / 50, 1 / 20, 1 / 15, 1 / 10])
def test_the_steps_people_take_stay_in_the_lanes(ratio):
    # a fiftieth to a tenth of the innermost period, with an eccentric orbit
    # at its pericentre: Stumpff arguments beyond the four-term series, which
    # the short-step passes decline, and within the nine-term one, converged
    # after one iteration (a fiftieth) or two: the medium passes take every
    # planet, and after the first drift go first (the memo counts down)
    xj, vj, mu = system(CIRCULAR + [(1.0, 0.2, 0.0)])
    S, declined = both(xj, vj, mu, ratio * 2 * math.pi, steps=20)
    assert declined == 0
    assert S[L.MEMO, 1] == L.RETRY - 19


def test_the_medium_passes_return_to_the_short_ones_bit_for_bit():
    # a step long enough for the medium passes, then short ones: the medium
    # passes take those first (their four-term series where the short passes
    # would take it), for RETRY drifts, then the short passes again
    xj, vj, mu = system(CIRCULAR)
    a, b = xj.copy(), vj.copy()
    c, d = xj.copy(), vj.copy()
    w1, w2 = np.zeros_like(xj), np.zeros_like(xj)
    S = L.lanes_scratch(len(xj))
    for k in range(L.RETRY + 5):
        h = 2 * math.pi / (20 if k == 0 else 400)
        W.kepler_drift_all(a, b, mu, h, w1, w2)
        assert L.kepler_drift_lanes(c, d, mu, h, S) == 0
        assert np.array_equal(a, c) and np.array_equal(b, d), k
        assert S[L.MEMO, 1] == max(L.RETRY - k, 0), k


@pytest.mark.parametrize("inner", [None, 0.08])
def test_the_second_iteration_only_where_a_column_needs_it(inner):
    # the steps' drift (resident_drift, the medium passes) at a short step
    # of the outer planets: every column converges after the first iteration
    # (row _T: 1.0 for a Stumpff argument within the series, plus 2.0 for
    # converged), and the second pass is left out; with an inner planet whose
    # step is long against its orbit, that column needs the second, which
    # is then made in every lane, the converged ones keeping the first's
    # anomaly.  The scalar drift's bits either way
    planets = CIRCULAR + ([(inner, 0.1, 1.0)] if inner else [])
    xj, vj, mu = system(planets)
    a, b = xj.copy(), vj.copy()
    e, f = xj.copy(), vj.copy()
    w1, w2 = np.zeros_like(xj), np.zeros_like(xj)
    R = L.lanes_scratch(len(xj))
    L.resident_load(e, f, mu, mu, R)
    needed = 0
    for k in range(30):
        h = 2 * math.pi / 400
        W.kepler_drift_all(a, b, mu, h, w1, w2)
        assert L.resident_drift(e, f, mu, h, R) == 0
        L.resident_store(R, e, f)
        assert np.array_equal(a, e) and np.array_equal(b, f), k
        flags = R[L._T, :len(planets)]
        assert (flags[:len(CIRCULAR)] == 3.0).all(), k
        if inner:
            needed += flags[-1] == 1.0
    if inner:
        # the inner planet (a ninth of its orbit a step, beyond the reach of
        # the fifth-order starter's one iteration) needs the second iteration
        # on most drifts
        assert needed >= 10


@pytest.mark.parametrize("ratio", [1 / 5, 1.0, 7.3])
def test_longer_steps_are_left_to_the_scalar_drift(ratio):
    # a fifth of the innermost period and beyond: more than a radian of its
    # orbit, outside the lanes' domain (the bracketed solver, with the period
    # reduced for the longest)
    xj, vj, mu = system(CIRCULAR + [(0.7, 0.3, 1.0)])
    S, declined = both(xj, vj, mu, ratio * 2 * math.pi, steps=20)
    assert not lanes_took(S, len(xj))[0]
    assert declined >= 1


@pytest.mark.parametrize("planets", [1, 2, 3, 4, 5, 8, 9])
def test_every_number_of_planets_and_the_padding(planets):
    orbits_ = [(1.0 + 0.37 * k, 0.02 * (k % 3), 0.5 * k) for k in range(planets)]
    xj, vj, mu = system(orbits_)
    mu = mu * np.linspace(1.0, 1.01, len(mu))     # each row its own mu (Jacobi)
    assert L.lanes_scratch(len(xj)).shape[1] % L.LANE_WIDTH == 0
    both(xj, vj, mu, 0.01, steps=20)


def test_zero_step_and_non_finite_states():
    xj, vj, mu = system(CIRCULAR)
    both(xj, vj, mu, 0.0)
    xj[2, 1] = np.nan
    vj[3, 0] = np.inf
    both(xj, vj, mu, 0.01)


@pytest.mark.parametrize("f", [0.0, 0.05])
def test_two_drifts_in_one_pass_are_each_the_scalar_drift(f):
    # the Wisdom-Holman loop's output: the next step's drift h of the state
    # kept in the lanes and the owed drift h2 of a copy into arrays (N, 3),
    # in one pass over the lanes; each must
    # be the scalar drift bit for bit, also for planets the lanes decline
    # (e = 0.99 at pericentre, a hyperbola), whose start the copy must keep
    orbits_ = CIRCULAR[:2] + [(1.0, 0.99, f), (-1.0, 1.5, f / 2)] + CIRCULAR[2:]
    xj, vj, mu = system(orbits_)
    h, h2 = 2 * math.pi / 200, math.pi / 200
    w1, w2 = np.zeros_like(xj), np.zeros_like(xj)
    a, b = xj.copy(), vj.copy()
    W.kepler_drift_all(a, b, mu, h, w1, w2)
    c, d = xj.copy(), vj.copy()
    W.kepler_drift_all(c, d, mu, h2, w1, w2)
    S = L.lanes_scratch(len(xj))
    L.resident_load(xj, vj, mu, mu, S)
    xs, vs = np.full_like(xj, np.nan), np.full_like(xj, np.nan)
    declined = L.resident_drift_twice(xj, vj, mu, h, xs, vs, h2, S)
    L.resident_store(S, xj, vj)
    assert np.array_equal(xj, a) and np.array_equal(vj, b)
    assert np.array_equal(xs, c) and np.array_equal(vs, d)
    m, c = len(xj) - 1, L.lane_columns(len(xj))   # the copy after the state's padding
    took, took2 = S[L._RTAKE, :m] != 0.0, S[L._RTAKE, c:c + m] != 0.0
    assert declined == np.sum(~took) and 1 <= declined < len(xj) - 1
    assert np.sum(~took2) >= 1            # the copy had declined planets too


@pytest.mark.parametrize("owed", [0.0, math.pi / 170])
def test_the_outputs_drift_of_the_loop_with_and_without_a_drift_owed(owed):
    # the lanes' loop's output drift (as wh_loop binds it): the state
    # drifted by h in the lanes, and the output's copy, drifted by what it
    # owes, in xs, vs, in the same passes; with nothing owed
    # the copy is the state itself.  Each bit for bit the scalar drift, with
    # declined planets among them
    drift = W.called(W.specialize(W._resident_output_drift, "lanes", inline=True, nrt=False),
                     False)
    xj, vj, mu = system(CIRCULAR[:2] + [(1.0, 0.99, 0.0)] + CIRCULAR[2:])
    h = 2 * math.pi / 160
    w1, w2 = np.zeros_like(xj), np.zeros_like(xj)
    a, b = xj.copy(), vj.copy()
    W.kepler_drift_all(a, b, mu, h, w1, w2)
    c, d = xj.copy(), vj.copy()
    if owed:
        W.kepler_drift_all(c, d, mu, owed, w1, w2)
    S = L.lanes_scratch(len(xj))
    L.resident_load(xj, vj, mu, mu, S)
    xs, vs = np.full_like(xj, np.nan), np.full_like(xj, np.nan)
    S[W.PENDING, 0] = 1.0
    x, acc = np.zeros_like(xj), np.zeros_like(xj)
    drift(xj, vj, mu, h, xs, vs, owed, x, acc, (S,))
    assert S[W.PENDING, 0] == 0.0
    L.resident_store(S, xj, vj)
    assert np.array_equal(xj, a) and np.array_equal(vj, b)
    assert np.array_equal(xs, c) and np.array_equal(vs, d)
    # the e = 0.99 planet declined, in the state and (with a drift owed) in
    # the copy: the verdicts of the pass over both
    m, c = len(xj) - 1, L.lane_columns(len(xj))   # the copy after the state's padding
    assert np.sum(S[L._RTAKE, :m] == 0.0) == 1
    if owed:
        assert np.sum(S[L._RTAKE, c:c + m] == 0.0) == 1


@pytest.mark.parametrize("planets", [1, 3, 4, 5, 8, 9])
def test_two_drifts_side_by_side_for_every_size(planets):
    # the copy's columns after the state's padding, for every number of
    # planets: each column bit for bit the scalar drift, over repeated
    # outputs, and the state's padding left a copy of its first planet, as
    # resident_load makes it
    orbits_ = [(1.0 + 0.45 * k, 0.03 * (k % 4), 0.7 * k) for k in range(planets)]
    xj, vj, mu = system(orbits_)
    w1, w2 = np.zeros_like(xj), np.zeros_like(xj)
    a, b = xj.copy(), vj.copy()
    S = L.lanes_scratch(len(xj))
    L.resident_load(xj, vj, mu, mu, S)
    P = L.lane_columns(len(xj))
    for k in range(5):
        h, h2 = 2 * math.pi / (150 + k), math.pi / (170 - k)
        c, d = a.copy(), b.copy()
        W.kepler_drift_all(c, d, mu, h2, w1, w2)
        W.kepler_drift_all(a, b, mu, h, w1, w2)
        xs, vs = np.full_like(xj, np.nan), np.full_like(xj, np.nan)
        assert L.resident_drift_twice(xj, vj, mu, h, xs, vs, h2, S) == 0
        assert np.array_equal(xs, c) and np.array_equal(vs, d)
        L.resident_store(S, xj, vj)
        assert np.array_equal(xj, a) and np.array_equal(vj, b)
        rows = S[L._RX:L._RX + 6, :P]
        assert np.array_equal(rows[:, planets:], np.repeat(rows[:, :1], P - planets, axis=1))


@pytest.mark.parametrize("n, passive", [(5, 0), (9, 0), (9, 2), (12, 3)])
@pytest.mark.parametrize("coordinates", ["jacobi", "democratic-heliocentric"])
def test_the_kick_in_lanes_is_the_scalar_kick_bit_for_bit(coordinates, n, passive):
    # the lanes' loop's perturbation step on the state kept in the lanes
    # (Jacobi: the interaction kick; democratic heliocentric: jump, kick,
    # jump) against the scalar one, over repeated kicks: padded columns (5
    # and 12 bodies), full ones (9), and massless bodies after the massive
    # ones (n_active = n - passive), which feel the pulls but exert none
    rng = np.random.default_rng(7 + n)
    x = rng.standard_normal((n, 3)) * 10 ** rng.uniform(-0.5, 1.5, (n, 1))
    gm = 10 ** rng.uniform(-9, -3, n)
    gm[0] = 1.0
    gm[n - passive:] = 0.0
    na = n - passive
    v = np.random.default_rng(8).standard_normal((n, 3)) * 0.1
    step = W.COORDINATE_SYSTEMS[coordinates][2]
    eta = np.cumsum(gm) if coordinates == "jacobi" else np.full(n, gm[0])
    kick = L.resident_kick if coordinates == "jacobi" else L.resident_jump_kick
    a, b, c, d = x.copy(), v.copy(), x.copy(), v.copy()
    w, acc = np.zeros_like(x), np.zeros_like(x)
    S = L.lanes_scratch(n)
    L.resident_load(c, d, gm, eta, S)
    for k in range(10):
        step(a, b, w, acc, gm, eta, na, 0.01)
        kick(c, d, gm, na, 0.01, S)
        L.resident_store(S, c, d)
        assert np.array_equal(a, c) and np.array_equal(b, d), k
    assert not np.array_equal(b, v)


@pytest.mark.parametrize("n", [5, 9, 12])
def test_the_finite_check_in_lanes_is_the_scalar_check(n):
    # stepping.state_is_finite of the state written back, for a non-finite
    # value in every place of a real row (row 0 stays in the arrays), and a
    # NaN in the padding, which is not part of the state
    from orbits._kernels.stepping import state_is_finite
    rng = np.random.default_rng(n)
    xj, vj = rng.standard_normal((n, 3)), rng.standard_normal((n, 3))
    mu = np.ones(n)
    S = L.lanes_scratch(n)
    L.resident_load(xj, vj, mu, mu, S)
    assert L.resident_finite(xj, vj, S) and state_is_finite(xj, vj)
    P = L.lane_columns(n)
    if P > n - 1:
        S[L._RX + 1, P - 1] = np.nan
        assert L.resident_finite(xj, vj, S)
    for bad in (np.nan, np.inf, -np.inf):
        for i in range(n):
            for arr in (0, 1):
                for dim in range(3):
                    a, b = xj.copy(), vj.copy()
                    (a, b)[arr][i, dim] = bad
                    L.resident_load(a, b, mu, mu, S)
                    assert not L.resident_finite(a, b, S)
                    assert not state_is_finite(a, b)
    # a sum that overflows is not finite for either
    a, b = xj.copy(), vj.copy()
    a[1, 0] = a[2, 0] = 1.7e308
    L.resident_load(a, b, mu, mu, S)
    assert L.resident_finite(a, b, S) == state_is_finite(a, b)
