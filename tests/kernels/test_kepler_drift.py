"""The universal-variable Kepler drift and the Stumpff functions, against
high-precision (mpmath) evaluations of the same formulas and against the
two-body invariants."""

import math

import numpy as np
import pytest

from orbits._kernels import kepler as K
from orbits._kernels.elements import elements_to_state
from orbits._kernels.status import Status
from orbits._kernels.stumpff import _stumpff_short, stumpff

mpmath = pytest.importorskip("mpmath")


def mp_stumpff(z):
    with mpmath.workdps(60):
        z = mpmath.mpf(z)
        if z > 0:
            sz = mpmath.sqrt(z)
            c0, c1 = mpmath.cos(sz), mpmath.sin(sz) / sz
        else:
            sz = mpmath.sqrt(-z)
            c0, c1 = mpmath.cosh(sz), mpmath.sinh(sz) / sz
        return c0, c1, (1 - c0) / z, (1 - c1) / z


def mp_drift(mu, x, v, dt):
    """The drift in 50 digits: bisection on the universal Kepler equation."""
    with mpmath.workdps(50):
        mu, dt = mpmath.mpf(mu), mpmath.mpf(dt)
        x = [mpmath.mpf(float(c)) for c in x]
        v = [mpmath.mpf(float(c)) for c in v]
        r0 = mpmath.sqrt(sum(c * c for c in x))
        eta = sum(a * b for a, b in zip(x, v))
        beta = 2 * mu / r0 - sum(c * c for c in v)
        zeta = mu - beta * r0

        def G(s):
            if s == 0:
                return 1, 0, 0, 0
            c0, c1, c2, c3 = mp_stumpff(beta * s * s)
            return c0, s * c1, s * s * c2, s ** 3 * c3

        def F(s):
            g = G(s)
            return r0 * s + eta * g[2] + zeta * g[3] - dt
        lo, hi = (mpmath.mpf(0), dt / r0) if dt > 0 else (dt / r0, mpmath.mpf(0))
        while (F(hi) < 0) if dt > 0 else (F(lo) > 0):
            if dt > 0:
                lo, hi = hi, 2 * hi
            else:
                lo, hi = 2 * lo, lo
        for _ in range(300):
            mid = (lo + hi) / 2
            if F(mid) < 0:
                lo = mid
            else:
                hi = mid
        s = (lo + hi) / 2
        _, G1, G2, _ = G(s)
        r = r0 + eta * G1 + zeta * G2
        f, g = 1 - mu * G2 / r0, r0 * G1 + eta * G2
        fd, gd = -mu * G1 / (r * r0), 1 - mu * G2 / r
        return (np.array([float(f * a + g * b) for a, b in zip(x, v)]),
                np.array([float(fd * a + gd * b) for a, b in zip(x, v)]))


def test_stumpff_against_mpmath():
    # absolute error relative to the functions' scale (1, 1, 1/2, 1/6 near 0):
    # series and quarter-argument doubling lose a few ulps (measured 2e-16);
    # for |z| large the hyperbolic ones are compared relatively
    for z in np.r_[np.linspace(-40, 40, 401), np.logspace(-14, 1, 30),
                   -np.logspace(-14, 1, 30)]:
        if z == 0:
            assert stumpff(0.0) == (1.0, 1.0, 0.5, 1.0 / 6.0)
            continue
        got = stumpff(z)
        ref = mp_stumpff(z)
        for g, r in zip(got, ref):
            scale = max(1.0, abs(float(r)))
            assert abs(g - float(r)) <= 2e-15 * scale, (z, got, ref)


def test_the_short_step_stumpff_series_against_mpmath():
    # the drift's four-term (|z| <= 2e-3) and nine-term (|z| <= 1) series:
    # within 2 ulps of each function at every z measured (truncation below
    # 1e-18, rounding of the Estrin sums), as the general form (1-2 ulps)
    for z in np.r_[np.linspace(-1, 1, 401), np.logspace(-8, 0, 60), -np.logspace(-8, 0, 60)]:
        if z == 0:
            continue
        got = _stumpff_short(z)
        ref = mp_stumpff(z)
        for g, r in zip(got, ref):
            assert abs(g - float(r)) <= 2 * math.ulp(float(r)), (z, got, ref)


def cases():
    rng = np.random.default_rng(7)
    out = []
    kinds = [("ellipse", lambda: rng.uniform(0, 0.95)),
             ("near-parabolic ellipse", lambda: 1 - 10 ** rng.uniform(-10, -4)),
             ("near-parabolic hyperbola", lambda: 1 + 10 ** rng.uniform(-10, -4)),
             ("hyperbola", lambda: rng.uniform(1.1, 20))]
    for label, ecc in kinds:
        for _ in range(6):
            e = ecc()
            q = 10 ** rng.uniform(-2, 0.5)
            a = q / (1 - e)
            x, v = np.zeros(3), np.zeros(3)
            f = rng.uniform(-2, 2)
            if e > 1:
                f = rng.uniform(-0.8, 0.8) * math.acos(-1 / e)
            assert elements_to_state(1.0, a, e, 0.4, 1.0, 2.0, f, x, v) == 0
            dt = 10 ** rng.uniform(-3, 2.5) * rng.choice([-1, 1])
            out.append((label, x, v, dt))
    return out


@pytest.mark.parametrize("case", cases(), ids=lambda c: f"{c[0]}-{c[3]:.3g}")
def test_drift_against_mpmath(case):
    label, x, v, dt = case
    xs, vs = x[None].copy(), v[None].copy()
    assert K.kepler_drift(1.0, xs, vs, 0, dt) == Status.OK
    xr, vr = mp_drift(1.0, x, v, dt)
    # a step that ends near pericentre cancels |f| x0 + g v0 to |x|: the
    # error is ~eps times the largest term over the result (measured below
    # 1e-13 on these cases); multi-period ellipse steps add ~eps per period
    r0 = np.linalg.norm(x)
    beta = 2 / r0 - v @ v
    periods = abs(dt) * beta ** 1.5 / (2 * math.pi) if beta > 0 else 0.0
    tol = 1e-13 * (1 + periods) * max(1.0, r0 / np.linalg.norm(xr))
    assert np.linalg.norm(xs[0] - xr) <= tol * np.linalg.norm(xr)
    assert np.linalg.norm(vs[0] - vr) <= tol * max(np.linalg.norm(vr), np.linalg.norm(v))


def test_long_elliptic_step_costs_no_accuracy():
    # 1e4 periods in one call equals the same drift reduced modulo the period
    x, v = np.zeros((1, 3)), np.zeros((1, 3))
    elements_to_state(1.0, 1.0, 0.3, 0.1, 0.2, 0.3, 0.4, x[0], v[0])
    period = 2 * math.pi
    a, b = (x.copy(), v.copy()), (x.copy(), v.copy())
    K.kepler_drift(1.0, *a, 0, 1e4 * period + 0.5)
    K.kepler_drift(1.0, *b, 0, 0.5)
    # the period comes from the state's energy, known to a few eps; 1e4
    # periods shift the phase by ~2 pi 1e4 * 4 eps ~ 6e-11 (measured 7e-11)
    np.testing.assert_allclose(a[0], b[0], rtol=0, atol=3e-10)


def test_drift_composes_and_reverses():
    x, v = np.zeros((1, 3)), np.zeros((1, 3))
    elements_to_state(1.0, 2.0, 0.9, 0.1, 0.2, 0.3, 2.5, x[0], v[0])
    a = (x.copy(), v.copy())
    b = (x.copy(), v.copy())
    K.kepler_drift(1.0, *a, 0, 0.7)
    K.kepler_drift(1.0, *a, 0, 1.1)
    K.kepler_drift(1.0, *b, 0, 1.8)
    np.testing.assert_allclose(a[0], b[0], rtol=1e-14, atol=0)
    K.kepler_drift(1.0, *b, 0, -1.8)
    np.testing.assert_allclose(b[0], x, rtol=1e-14, atol=0)
    np.testing.assert_allclose(b[1], v, rtol=1e-14, atol=0)


def test_drift_conserves_energy_and_angular_momentum():
    rng = np.random.default_rng(3)
    for e in (0.1, 0.7, 1.5):
        a = 1.0 if e < 1 else -1.0
        x, v = np.zeros((1, 3)), np.zeros((1, 3))
        elements_to_state(1.0, a, e, 0.5, 0.6, 0.7, 0.3, x[0], v[0])
        E0 = 0.5 * v[0] @ v[0] - 1 / np.linalg.norm(x[0])
        L0 = np.cross(x[0], v[0])
        for dt in rng.uniform(-3, 3, 50):
            K.kepler_drift(1.0, x, v, 0, dt)
        E = 0.5 * v[0] @ v[0] - 1 / np.linalg.norm(x[0])
        # 50 drifts, each correct to a few ulps (measured 1e-15)
        assert abs(E / E0 - 1) < 1e-13
        np.testing.assert_allclose(np.cross(x[0], v[0]), L0, rtol=0, atol=1e-13)


def test_invalid_input_gives_status_and_nan():
    x, v = np.zeros((1, 3)), np.ones((1, 3))
    assert K.kepler_drift(1.0, x, v, 0, 0.1) == Status.INVALID_STATE
    assert np.all(np.isnan(x)) and np.all(np.isnan(v))
    x, v = np.ones((1, 3)), np.ones((1, 3))
    assert K.kepler_drift(-1.0, x, v, 0, 0.1) == Status.INVALID_STATE


def short_cases():
    # steps short against the orbit, |dt| |v| / r0 from 1e-4 to 0.45, where
    # kepler_drift takes its unbracketed short-step path: ellipses, near-
    # parabolic orbits on both sides and hyperbolae, anywhere on the orbit
    rng = np.random.default_rng(11)
    out = []
    for e in (0.0, 0.3, 0.9, 1 - 1e-9, 1 + 1e-9, 1.5, 30.0):
        for _ in range(5):
            q = 10 ** rng.uniform(-2, 0.5)
            a = q / (1 - e) if e != 1 else q
            f = rng.uniform(-2.5, 2.5)
            if e > 1:
                f = rng.uniform(-0.9, 0.9) * math.acos(-1 / e)
            x, v = np.zeros(3), np.zeros(3)
            assert elements_to_state(1.0, a, e, 0.4, 1.0, 2.0, f, x, v) == 0
            dt = 10 ** rng.uniform(-4, math.log10(0.45)) * np.linalg.norm(x) \
                / np.linalg.norm(v) * rng.choice([-1, 1])
            out.append((f"e={e:g}", x, v, dt))
    return out


@pytest.mark.parametrize("case", short_cases(), ids=lambda c: f"{c[0]}-{c[3]:.3g}")
def test_short_step_path_against_mpmath_and_the_bracketed_solver(case):
    label, x, v, dt = case
    xs, vs = x[None].copy(), v[None].copy()
    assert K.kepler_drift(1.0, xs, vs, 0, dt) == Status.OK
    xr, vr = mp_drift(1.0, x, v, dt)
    # as in test_drift_against_mpmath (a single period at most here)
    tol = 1e-13 * max(1.0, np.linalg.norm(x) / np.linalg.norm(xr))
    assert np.linalg.norm(xs[0] - xr) <= tol * np.linalg.norm(xr)
    assert np.linalg.norm(vs[0] - vr) <= tol * max(np.linalg.norm(vr), np.linalg.norm(v))
    # the two solvers find the same root: a few ulps (measured 2e-16)
    xb, vb = x[None].copy(), v[None].copy()
    assert K.kepler_drift_bracketed(1.0, xb, vb, 0, dt) == Status.OK
    np.testing.assert_allclose(xs, xb, rtol=0, atol=2e-15 * np.linalg.norm(xb))
    np.testing.assert_allclose(vs, vb, rtol=0, atol=2e-15 * max(np.linalg.norm(vb),
                                                                np.linalg.norm(v)))


def test_short_step_anomaly_declines_what_it_cannot_do():
    # long steps, dt = 0, r = 0, mu <= 0 and NaN: NaN, the bracketed solver's case
    x, v = np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])
    ok = K.short_step_anomaly(1.0, *x, *v, 0.1)[0]
    assert math.isfinite(ok)
    for mu, xx, dt in [(1.0, x, 2.0), (1.0, x, 0.0), (1.0, 0 * x, 0.1), (0.0, x, 0.1),
                       (-1.0, x, 0.1), (1.0, x * math.nan, 0.1), (1.0, x, math.nan)]:
        assert math.isnan(K.short_step_anomaly(mu, *xx, *v, dt)[0]), (mu, xx, dt)


@pytest.mark.parametrize("dt", [1e-3, 0.3, 3.0, 40.0, -7.0])
def test_every_planets_drift_is_kepler_drift_bit_for_bit(dt):
    # The Wisdom-Holman loop drifts every row in two passes and sends a step
    # that is not short straight to the bracketed solver: kepler_drift would
    # try the same short step on the same numbers first, so the rows must
    # equal kepler_drift's exactly (tolerance zero), short steps and long
    # ones, ellipses (e up to 0.99) and a hyperbola alike
    from orbits._kernels.wisdom_holman import kepler_drift_all
    orbits_ = [(1.0, 0.0, 0.3), (1.6, 0.2, 2.0), (0.5, 0.99, 0.0), (-3.0, 1.5, 0.4),
               (9.5, 0.05, 4.0)]
    n = len(orbits_) + 1
    x, v = np.zeros((n, 3)), np.zeros((n, 3))
    x[0], v[0] = (0.1, -0.2, 0.05), (1e-3, 2e-3, -1e-3)
    for i, (a, e, f) in enumerate(orbits_, start=1):
        assert elements_to_state(1.0, a, e, 0.3, 1.0 + i, 2.0 - 0.3 * i, f, x[i], v[i]) == 0
    mu = np.full(n, 1.0)
    xa, va = x.copy(), v.copy()
    kepler_drift_all(xa, va, mu, dt, np.zeros_like(x), np.zeros_like(x))
    for i in range(1, n):
        xb, vb = x.copy(), v.copy()
        assert K.kepler_drift(1.0, xb, vb, i, dt) == Status.OK
        assert np.array_equal(xa[i], xb[i]) and np.array_equal(va[i], vb[i]), i
    # the centre of mass moves in a straight line
    assert np.array_equal(xa[0], x[0] + dt * v[0])


def _starter_error(e, f, dt):
    # the relative error of short_start's anomaly against the converged root
    x, v = np.zeros(3), np.zeros(3)
    assert elements_to_state(1.0, 1.0, e, 0.3, 0.5, 1.0, f, x, v) == 0
    s0 = K.short_start(1.0, *x, *v, dt)[-1]
    s = K.short_step_anomaly(1.0, *x, *v, dt)[0]
    return abs(s0 - s) / abs(s)


def test_the_starter_is_fifth_order_and_one_iteration_does_at_a_twentieth_of_an_orbit():
    # short_start's series of the anomaly in the step has its terms to the
    # fifth power, so its relative error falls as dt^5: 32 times for half
    # the step once the step is short enough for the leading term to rule
    # (measured 29-32 from a fiftieth of an orbit; a fourth-order starter
    # would give 16, the third-order one 8; at least 24 asked).  At a
    # twentieth of an orbit of e <= 0.2 (Mercury's steps in a solar system
    # run at the usual step), anywhere on the orbit, the error is within
    # the tolerance at which one quartic iteration is taken as converged
    # (K._SHORT_STEP_TOL; measured at most 2.6e-5), so the drift makes one
    period = 2 * math.pi
    for e in (0.0, 0.1, 0.2):
        for f in np.linspace(-math.pi, math.pi, 24, endpoint=False):
            err = _starter_error(e, f, period / 20)
            assert err < K._SHORT_STEP_TOL, (e, f, err)
            err = _starter_error(e, f, period / 50)
            if err > 1e-12:
                # (below that, rounding decides the ratio; e = 0 is exact)
                assert err / _starter_error(e, f, period / 100) > 24.0, (e, f)
