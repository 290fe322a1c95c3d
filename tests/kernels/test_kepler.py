"""Tests of orbits._kernels.anomalies and .elements: Kepler's equation and elements <-> state.

Layers: (a) Kepler-equation residuals, in float64 and exactly (mpmath);
(b) anomaly conversions inverse to each other; (c) elements -> state ->
elements and state -> elements -> state round trips over hypothesis-drawn
orbits; (d) an independent oracle (REBOUND); (e) the degenerate conventions
and status codes; (f) the array helpers against the scalar kernels.
"""

import math

import numpy as np
import pytest
import rebound
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from orbits._kernels.anomalies import (mean_from_true, mean_to_eccentric, mean_to_hyperbolic,
                                       mean_to_parabolic, true_from_mean)
from orbits._kernels.elements import (CIRCULAR_TOL, elements_to_state, elements_to_state_many,
                                      state_to_elements, state_to_elements_many)
from orbits._kernels.status import Status, describe_status

EPS = np.finfo(float).eps
TWO_PI = 2.0 * math.pi

ELLIPTIC_E = [0.0, 0.5, 0.9, 0.99, 0.999, 0.999999]
HYPERBOLIC_E = [1.0001, 1.5, 10.0]

_small = np.logspace(-15, 0, 31)
ELLIPTIC_M = np.unique(np.concatenate([
    np.linspace(-4 * math.pi, 4 * math.pi, 401),
    _small, -_small,
    [0.0, math.pi, -math.pi, TWO_PI, 10.0, 123.456, 1e3, -1e4, 1e6, -1e6, 1e9],
]))
_wide = np.logspace(-15, 8, 47)
HYPERBOLIC_M = np.unique(np.concatenate([np.linspace(-20.0, 20.0, 201), _wide, -_wide]))


def wrap(angle):
    """Angle difference reduced to [-pi, pi)."""
    return (angle + math.pi) % TWO_PI - math.pi


# ---------------------------------------------------------------------------
# (a) Kepler's equation
# ---------------------------------------------------------------------------

@pytest.mark.parametrize("e", ELLIPTIC_E)
def test_elliptic_residual_float64(e):
    for M in ELLIPTIC_M:
        E = mean_to_eccentric(M, e)
        residual = E - e * math.sin(E) - M
        # Evaluating the residual in float64 costs ~3 roundings of the
        # largest term (sin, product, difference) and a correctly rounded E
        # adds |1 - e cos E| ulp(E) / 2 <= eps |E|: 4 eps max(|E|, |M|).
        # Measured worst: 1.9 eps max(|E|, |M|).
        assert abs(residual) <= 4 * EPS * max(abs(E), abs(M)), (M, E, residual)
        # Same revolution as M: |E - M| = e |sin E| <= e, up to rounding of E.
        assert abs(E - M) <= e + 4 * EPS * max(abs(M), 1.0)


@pytest.mark.parametrize("e", ELLIPTIC_E)
def test_elliptic_backward_error_exact(e):
    import mpmath
    mpmath.mp.dps = 40
    for M in ELLIPTIC_M:
        E = mean_to_eccentric(M, e)
        exact = mpmath.mpf(E) - e * mpmath.sin(mpmath.mpf(E)) - M
        # Backward error: E solves the equation for a mean anomaly this far
        # from M.  The best float E leaves |g'(E)| ulp(E) / 2, and M itself is
        # known to ulp(M) / 2; reducing M with a rounded 2 pi adds
        # 4e-17 |M|.  Measured worst: 0.47 of this bound (e = 0.999).
        bound = 2 * EPS * (abs(M) + abs(E * (1.0 - e * math.cos(E))))
        assert abs(float(exact)) <= bound, (M, E, float(exact), bound)


@pytest.mark.parametrize("e", HYPERBOLIC_E)
def test_hyperbolic_residual(e):
    import mpmath
    mpmath.mp.dps = 40
    for M in HYPERBOLIC_M:
        F = mean_to_hyperbolic(M, e)
        assert math.copysign(1.0, F) == math.copysign(1.0, M)
        exact = e * mpmath.sinh(mpmath.mpf(F)) - F - M
        # As in the elliptic case: |g'(F)| ulp(F) / 2 from rounding F (for
        # large M this is |M| F eps / 2, the resolution of float F), plus
        # ulp(M) / 2.  Measured worst: 0.55 of this bound for e from 1 + 1e-7
        # to 1e4.
        bound = 2 * EPS * (abs(M) + abs(F * (e * math.cosh(F) - 1.0)))
        assert abs(float(exact)) <= bound, (M, F, float(exact), bound)


def test_parabolic_residual():
    import mpmath
    mpmath.mp.dps = 40
    for M in HYPERBOLIC_M:
        D = mean_to_parabolic(M)
        exact = mpmath.mpf(D) + mpmath.mpf(D) ** 3 / 3 - M
        # Same form of bound with g'(D) = 1 + D^2; measured worst 0.23 of it.
        bound = 2 * EPS * (abs(M) + abs(D) * (1.0 + D * D))
        assert abs(float(exact)) <= bound, (M, D, float(exact), bound)
        assert true_from_mean(M, 1.0) == pytest.approx(2 * math.atan(D), abs=0, rel=4 * EPS)


@pytest.mark.parametrize("e", [0.3, 0.999999])
def test_elliptic_solver_matches_scipy_brentq(e):
    # An independent root finder on the textbook residual, as a sanity check
    # of the whole branch structure (reduction, symmetry, revolutions).
    from scipy.optimize import brentq
    for M in np.linspace(-7.0, 7.0, 57):
        k = round(M / TWO_PI)
        ref = brentq(lambda E: E - e * math.sin(E) - M,
                     k * TWO_PI - math.pi, k * TWO_PI + math.pi, xtol=1e-15, rtol=4 * EPS)
        # Condition number 1 / (1 - e cos E) reaches 1e6 near pericentre
        # for e = 1 - 1e-6, where brentq's own residual ~1e-16 maps to ~1e-10.
        tol = 1e-15 / (1.0 - e * math.cos(ref)) + 4 * EPS * abs(ref)
        assert abs(mean_to_eccentric(M, e) - ref) <= tol


def test_invalid_kepler_inputs_give_nan():
    assert math.isnan(mean_to_eccentric(1.0, 1.0))
    assert math.isnan(mean_to_eccentric(1.0, -0.1))
    assert math.isnan(mean_to_eccentric(math.inf, 0.5))
    assert math.isnan(mean_to_hyperbolic(1.0, 1.0))
    assert math.isnan(mean_to_hyperbolic(math.nan, 2.0))
    assert math.isnan(true_from_mean(1.0, -1.0))
    assert math.isnan(mean_from_true(2.5, 2.0))     # beyond the asymptote
    assert math.isnan(mean_from_true(math.nan, 1.0))


# ---------------------------------------------------------------------------
# (b) anomalies and radius
# ---------------------------------------------------------------------------

def _dM_df(f, e):
    """|dM/df| for the conventions of the module (Barker's form at e = 1)."""
    denom = 1.0 + e * math.cos(f)
    if e == 1.0:
        return 0.5 * (1.0 + math.tan(0.5 * f) ** 2) ** 2
    return abs(1.0 - e * e) ** 1.5 / denom ** 2


@pytest.mark.parametrize("e", ELLIPTIC_E + [1.0] + HYPERBOLIC_E)
def test_true_and_mean_anomaly_are_inverse(e):
    f_max = math.pi if e < 1.0 else math.acos(-1.0 / e)
    fs = np.linspace(-0.999 * f_max, 0.999 * f_max, 301)
    if e < 1.0:
        fs = np.concatenate([fs, fs + 6 * math.pi])     # revolutions are kept
    for f in fs:
        M = mean_from_true(f, e)
        f2 = true_from_mean(M, e)
        # f -> M -> f: each direction is accurate to a few ulps of its
        # output, and an error dM in M moves f by dM / (dM/df).  Measured
        # worst: 2 eps (|f| + |M| / (dM/df)) (e = 10).
        tol = 8 * EPS * (abs(f) + abs(M) / _dM_df(f, e))
        assert abs(f2 - f) <= tol, (f, M, f2, tol)


@pytest.mark.parametrize("e", [0.0, 0.5, 0.99, 0.999999, 1.0001, 1.01, 1.5, 10.0])
def test_radius_is_accurate_to_its_conditioning(e):
    import mpmath
    mpmath.mp.dps = 40
    a = 1.0 if e < 1.0 else -1.0
    f_max = math.pi if e < 1.0 else math.acos(-1.0 / e)
    fs = np.concatenate([np.linspace(-0.999 * f_max, 0.999 * f_max, 301),
                         f_max * (1.0 - np.logspace(-8, -3, 11))])
    pos = np.empty(3)
    vel = np.empty(3)
    for f in fs:
        assert elements_to_state(1.0, a, e, 0.3, 0.2, 0.1, f, pos, vel) == Status.OK
        r = mpmath.sqrt(mpmath.fsum([mpmath.mpf(x) ** 2 for x in pos]))
        denom = 1 + mpmath.mpf(e) * mpmath.cos(mpmath.mpf(f))
        exact = mpmath.mpf(a) * (1 - mpmath.mpf(e) ** 2) / denom
        # The relative condition number of r(f) is |e f sin f| / (1 + e cos f):
        # the rounding of f-dependent terms is amplified by that much and no
        # more.  Near apocentre as e -> 1 and near the asymptotes of a
        # hyperbola with e < 1.6, cos f ~ -1 rounded in the direct form
        # 1 + e cos f would add eps / (1 + e cos f), 2e5 eps at e = 1 - 1e-6.
        # Measured worst: 2.7 eps (1 + cond).
        cond = abs(e * f * math.sin(f)) / float(denom)
        assert abs(float(r / exact - 1)) <= 4 * EPS * (1.0 + cond), (f, float(r / exact - 1))


# ---------------------------------------------------------------------------
# (c) round trips
# ---------------------------------------------------------------------------

def log_uniform(lo, hi):
    return st.floats(math.log10(lo), math.log10(hi)).map(lambda x: 10.0 ** x)


angles = st.floats(0.0, TWO_PI, exclude_max=True)
inclinations = st.floats(0.01, math.pi - 0.01)
mus = log_uniform(1e-3, 1e3)


def _check_round_trip(mu, a, e, inc, Omega, omega, f):
    pos = np.empty(3)
    vel = np.empty(3)
    assert elements_to_state(mu, a, e, inc, Omega, omega, f, pos, vel) == Status.OK
    out = np.empty(7)
    assert state_to_elements(mu, pos, vel, out) == Status.OK
    a2, e2, inc2, Omega2, omega2, f2, M2 = out
    # Each conversion is ~50 flops on O(1) quantities; vis-viva loses
    # 2 a / r <= 2 / |1 - e| (<= 200 here) in a.  Measured worst over 2e5
    # elliptic and 1e5 hyperbolic orbits: a 2.1e-13, e 6.8e-14 (hyperbola
    # near its asymptote), inc 5e-15, Omega 1.5e-14 (cond 1 / sin(inc)).
    assert abs(a2 - a) <= 1e-12 * abs(a)
    assert abs(e2 - e) <= 1e-12
    assert abs(wrap(inc2 - inc)) <= 1e-12
    assert abs(wrap(Omega2 - Omega)) <= 1e-12
    # The pericentre direction comes from the eccentricity vector, whose
    # components carry absolute errors of a few eps, so omega and f alone are
    # uncertain by ~eps / e: measured worst 7.3 eps / e over 2e5 orbits
    # (1.6e-12 at e = 0.001).  1e-12 holds for e >= 0.0022; below, the bound
    # is 10 eps / e.  Their sum, the argument of latitude, does not depend
    # on the pericentre and is held to 1e-12 everywhere (measured 1.5e-14).
    angle_tol = max(1e-12, 10 * EPS / e)
    assert abs(wrap(omega2 - omega)) <= angle_tol
    assert abs(wrap(f2 - f)) <= angle_tol
    assert abs(wrap(omega2 + f2 - omega - f)) <= 1e-12
    assert abs(wrap(M2 - mean_from_true(f, e))) <= 1e-12 + angle_tol * _dM_df(f, e)
    # Ranges promised by the docstring.
    assert 0.0 <= inc2 <= math.pi
    assert 0.0 <= Omega2 < TWO_PI and 0.0 <= omega2 < TWO_PI
    assert -math.pi <= f2 <= math.pi

    pos2 = np.empty(3)
    vel2 = np.empty(3)
    assert elements_to_state(mu, a2, e2, inc2, Omega2, omega2, f2, pos2, vel2) == Status.OK
    # Back to the state: the element errors above map back with the same
    # factors; measured worst 6.6e-14 (position), 3.3e-14 (velocity).
    assert np.linalg.norm(pos2 - pos) <= 1e-12 * np.linalg.norm(pos)
    assert np.linalg.norm(vel2 - vel) <= 1e-12 * np.linalg.norm(vel)


@settings(max_examples=400, deadline=None)
@given(mu=mus, a=log_uniform(1e-2, 1e3), e=st.floats(0.001, 0.99), inc=inclinations,
       Omega=angles, omega=angles, f=st.floats(-math.pi, math.pi))
def test_round_trip_elliptic(mu, a, e, inc, Omega, omega, f):
    _check_round_trip(mu, a, e, inc, Omega, omega, f)


@settings(max_examples=400, deadline=None)
@given(mu=mus, a=log_uniform(1e-2, 1e3), e=st.floats(1.01, 10.0), inc=inclinations,
       Omega=angles, omega=angles, s=st.floats(-0.99, 0.99))
def test_round_trip_hyperbolic(mu, a, e, inc, Omega, omega, s):
    # Up to 99% of the asymptote angle, where 1 + e cos f is ~0.004 for
    # e = 1.01 and e = 10 loses ~e eps in it; measured worst 6.8e-14 in e
    # and 1.6e-14 in the angles (at 99.9%: 4.6e-13 and 9.5e-14).
    f = s * math.acos(-1.0 / e)
    _check_round_trip(mu, -a, e, inc, Omega, omega, f)


vectors = st.tuples(*[st.floats(-1.0, 1.0)] * 3)


@settings(max_examples=400, deadline=None)
@given(mu=mus, r=vectors, v=vectors, r_scale=log_uniform(1e-2, 1e2),
       v_scale=log_uniform(1e-2, 1e2))
def test_round_trip_state(mu, r, v, r_scale, v_scale):
    pos = np.array(r) * r_scale
    vel = np.array(v) * v_scale
    rn, vn = np.linalg.norm(pos), np.linalg.norm(vel)
    assume(rn > 1e-2 * r_scale and vn > 1e-2 * v_scale)
    out = np.empty(7)
    status = state_to_elements(mu, pos, vel, out)
    # Near-radial states (|h| < 1e-3 |r| |v|) and near-parabolic ones are
    # ill-conditioned in (a, e): the state comes back with relative error
    # ~3.6 eps / |1 - e| (measured 8e-13 at |1 - e| = 1e-3, 1e-10 at 1e-5),
    # so they are left out.
    assume(np.linalg.norm(np.cross(pos, vel)) > 1e-3 * rn * vn)
    assume(status == Status.OK and abs(out[1] - 1.0) > 0.01)
    pos2 = np.empty(3)
    vel2 = np.empty(3)
    assert elements_to_state(mu, *out[:6], pos2, vel2) == Status.OK
    # Measured worst over 1.5e5 accepted random states: 1.2e-13 (position).
    assert np.linalg.norm(pos2 - pos) <= 1e-12 * rn
    assert np.linalg.norm(vel2 - vel) <= 1e-12 * vn


# ---------------------------------------------------------------------------
# (d) oracle: REBOUND (G = 1, primary of unit mass, test particle: mu = 1)
# ---------------------------------------------------------------------------

ORACLE_CASES = [
    # a, e, inc, Omega, omega, f
    (1.3, 0.2, 0.4, 1.1, 2.3, -0.7),
    (1.0, 0.01, 1.2, 4.0, 0.3, 2.9),
    (5.0, 0.95, 2.6, 0.5, 5.5, 0.1),       # retrograde, eccentric
    (-2.0, 1.5, 0.3, 0.2, 0.4, 0.5),
    (-0.3, 5.0, 1.9, 3.0, 1.0, -1.2),      # retrograde hyperbola
    (-10.0, 1.05, 0.7, 6.0, 2.0, 2.5),     # near-parabolic, near the asymptote
]


def _rebound_pair(**kwargs):
    sim = rebound.Simulation()
    sim.G = 1.0
    sim.add(m=1.0)
    sim.add(primary=sim.particles[0], m=0.0, **kwargs)
    return sim


@pytest.mark.parametrize("a, e, inc, Omega, omega, f", ORACLE_CASES)
def test_elements_to_state_matches_rebound(a, e, inc, Omega, omega, f):
    sim = _rebound_pair(a=a, e=e, inc=inc, Omega=Omega, omega=omega, f=f)
    pos = np.empty(3)
    vel = np.empty(3)
    assert elements_to_state(1.0, a, e, inc, Omega, omega, f, pos, vel) == Status.OK
    ref_pos = np.array(sim.particles[1].xyz)
    ref_vel = np.array(sim.particles[1].vxyz)
    # Two ~50-flop evaluations of the same formulas in different orders;
    # 1e-12 is the accuracy asked of the kernels, measured worst 8e-16.
    assert np.linalg.norm(pos - ref_pos) <= 1e-12 * np.linalg.norm(ref_pos)
    assert np.linalg.norm(vel - ref_vel) <= 1e-12 * np.linalg.norm(ref_vel)


@pytest.mark.parametrize("a, e, inc, Omega, omega, f", ORACLE_CASES)
def test_state_to_elements_matches_rebound(a, e, inc, Omega, omega, f):
    sim = _rebound_pair(a=a, e=e, inc=inc, Omega=Omega, omega=omega, f=f)
    p = sim.particles[1]
    orbit = p.orbit(primary=sim.particles[0])
    out = np.empty(7)
    assert state_to_elements(1.0, np.array(p.xyz), np.array(p.vxyz), out) == Status.OK
    # Same state, independent formulas: the round-trip figures apply (these
    # cases stay away from e ~ 0, inc ~ 0 and pi, where either code could
    # use acos-based angles that lose digits).  Measured worst 4.4e-15
    # (omega and M at e = 0.01, cond ~1 / e).
    assert out[0] == pytest.approx(orbit.a, rel=1e-12)
    assert out[1] == pytest.approx(orbit.e, abs=1e-12)
    for mine, theirs in zip(out[2:7], (orbit.inc, orbit.Omega, orbit.omega, orbit.f, orbit.M)):
        assert abs(wrap(mine - theirs)) <= 1e-12


@pytest.mark.parametrize("e, M", [(0.3, 2.0), (0.9, -0.05), (0.999, 0.001),
                                  (1.5, 3.0), (3.0, -40.0), (1.01, 0.02)])
def test_true_from_mean_matches_rebound(e, M):
    a = 1.0 if e < 1.0 else -1.0
    sim = _rebound_pair(a=a, e=e, M=M)
    f_ref = sim.particles[1].orbit(primary=sim.particles[0]).f
    # REBOUND solves Kepler's equation to ~1e-15 and then converts through
    # the state.  df/dM reaches (1 + e)^2 / (1 - e^2)^1.5 = 4.5e4 at
    # (0.999, 0.001), which amplifies its last-digit residual: measured
    # 6.1e-14 there, <= 2.7e-15 elsewhere.
    assert abs(wrap(true_from_mean(M, e) - f_ref)) <= 1e-12


# ---------------------------------------------------------------------------
# (e) degenerate conventions and status codes
# ---------------------------------------------------------------------------

def _elements_of(mu, a, e, inc, Omega, omega, f):
    pos = np.empty(3)
    vel = np.empty(3)
    assert elements_to_state(mu, a, e, inc, Omega, omega, f, pos, vel) == Status.OK
    out = np.empty(7)
    status = state_to_elements(mu, pos, vel, out)
    pos2 = np.empty(3)
    vel2 = np.empty(3)
    assert elements_to_state(mu, *out[:6], pos2, vel2) == Status.OK
    # Whatever the convention, the state must come back (~50 flops).
    assert np.linalg.norm(pos2 - pos) <= 1e-13 * np.linalg.norm(pos)
    assert np.linalg.norm(vel2 - vel) <= 1e-13 * np.linalg.norm(vel)
    return status, out


def test_circular_orbit_measures_f_from_the_node():
    status, (a, e, inc, Omega, omega, f, M) = _elements_of(2.0, 3.0, 0.0, 0.7, 1.0, 2.0, 0.5)
    assert status == Status.OK
    assert e <= CIRCULAR_TOL
    assert omega == 0.0
    # f is the argument of latitude omega + f; tolerances: a few ulps of 2 pi.
    assert abs(wrap(f - 2.5)) <= 1e-14
    assert abs(wrap(Omega - 1.0)) <= 1e-14 and abs(inc - 0.7) <= 1e-14
    assert abs(wrap(M - f)) <= 1e-14


def test_planar_prograde_orbit_puts_the_longitude_of_pericentre_in_omega():
    status, (a, e, inc, Omega, omega, f, M) = _elements_of(1.0, 1.0, 0.3, 0.0, 1.0, 2.0, -0.4)
    assert status == Status.OK
    assert inc == 0.0 and Omega == 0.0
    assert abs(wrap(omega - 3.0)) <= 1e-14          # Omega + omega
    assert abs(wrap(f + 0.4)) <= 1e-14


def test_planar_retrograde_orbit():
    # inc = pi: R_z(Omega) R_x(pi) R_z(omega) = R_x(pi) R_z(omega - Omega),
    # so with the node on the x axis the argument of pericentre is
    # omega - Omega.
    status, (a, e, inc, Omega, omega, f, M) = _elements_of(1.0, 1.0, 0.3, math.pi, 1.0, 2.0, -0.4)
    assert status == Status.OK
    assert abs(inc - math.pi) <= 1e-15 and Omega == 0.0
    assert abs(wrap(omega - 1.0)) <= 1e-14
    assert abs(wrap(f + 0.4)) <= 1e-14


def test_circular_planar_orbit_measures_f_from_the_x_axis():
    status, (a, e, inc, Omega, omega, f, M) = _elements_of(1.0, 1.0, 0.0, 0.0, 1.0, 2.0, 0.5)
    assert status == Status.OK
    assert Omega == 0.0 and omega == 0.0 and inc == 0.0
    assert abs(wrap(f - 3.5)) <= 1e-14              # true longitude


def test_retrograde_orbit_has_inclination_above_right_angle():
    pos = np.empty(3)
    vel = np.empty(3)
    assert elements_to_state(1.0, 2.0, 0.1, 2.5, 1.0, 2.0, 0.3, pos, vel) == Status.OK
    assert np.cross(pos, vel)[2] < 0.0
    out = np.empty(7)
    assert state_to_elements(1.0, pos, vel, out) == Status.OK
    assert abs(out[2] - 2.5) <= 1e-14


def test_hyperbola_beyond_asymptote_is_an_error():
    pos = np.zeros(3)
    vel = np.zeros(3)
    # e = 2: asymptote at f = arccos(-1/2) = 2.094; 1 + 2 cos 2.5 = -0.60.
    status = elements_to_state(1.0, -1.0, 2.0, 0.1, 0.2, 0.3, 2.5, pos, vel)
    assert status == Status.BEYOND_ASYMPTOTE
    assert np.isnan(pos).all() and np.isnan(vel).all()
    assert elements_to_state(1.0, -1.0, 2.0, 0.1, 0.2, 0.3, 2.0, pos, vel) == Status.OK


@pytest.mark.parametrize("mu, a, e", [
    (1.0, 1.0, 1.0),        # parabola: no finite a
    (1.0, -1.0, 0.5),       # a < 0 with e < 1
    (1.0, 1.0, 1.5),        # a > 0 with e > 1
    (1.0, 1.0, -0.1),
    (0.0, 1.0, 0.5),
    (1.0, math.nan, 0.5),
    (1.0, 1.0, math.inf),
])
def test_invalid_elements(mu, a, e):
    pos = np.zeros(3)
    vel = np.zeros(3)
    assert elements_to_state(mu, a, e, 0.1, 0.2, 0.3, 0.4, pos, vel) == Status.INVALID_ELEMENTS
    assert np.isnan(pos).all() and np.isnan(vel).all()


def test_radial_orbit_is_reported_not_nan():
    out = np.zeros(7)
    status = state_to_elements(1.0, np.array([1.0, 0.0, 0.0]), np.array([0.5, 0.0, 0.0]), out)
    assert status == Status.RADIAL_ORBIT
    assert out[0] == 1.0 / (2.0 - 0.25) and out[1] == 1.0
    assert np.isnan(out[2:]).all()
    # At rest: also radial.
    status = state_to_elements(1.0, np.array([0.0, 2.0, 0.0]), np.zeros(3), out)
    assert status == Status.RADIAL_ORBIT


def test_invalid_states():
    out = np.zeros(7)
    assert state_to_elements(1.0, np.zeros(3), np.ones(3), out) == Status.INVALID_STATE
    assert np.isnan(out).all()
    assert state_to_elements(0.0, np.ones(3), np.ones(3), out) == Status.INVALID_STATE
    assert state_to_elements(1.0, np.array([1.0, math.nan, 0.0]), np.ones(3),
                               out) == Status.INVALID_STATE
    assert state_to_elements(1.0, np.ones(3), np.ones(3), np.zeros(6)) == Status.BAD_SHAPE


def test_exactly_parabolic_state():
    # r = 1, v = 2, mu = 2: 2/r - v^2/mu = 0 and e = 1 exactly, at pericentre.
    out = np.zeros(7)
    status = state_to_elements(2.0, np.array([1.0, 0.0, 0.0]), np.array([0.0, 2.0, 0.0]), out)
    assert status == Status.PARABOLIC_ORBIT
    assert out[0] == math.inf and out[1] == 1.0
    assert out[2] == 0.0 and out[5] == 0.0 and out[6] == 0.0


def test_status_codes_are_distinct_and_described():
    # one set of codes for the loops and the two-body kernels: no value has two
    # names (an alias would be a second meaning), and every code its own sentence
    members = Status.__members__
    assert len(set(members.values())) == len(members)
    run = {s for s in Status if s <= Status.LOG_FULL}
    two_body = set(Status) - run
    assert len(two_body) == 6 and min(two_body) > max(run)
    messages = {describe_status(c) for c in Status}
    assert len(messages) == len(Status)
    assert "unknown" in describe_status(99)


# ---------------------------------------------------------------------------
# (f) array helpers against the scalar kernels
# ---------------------------------------------------------------------------

def test_many_match_scalar_kernels():
    rng = np.random.default_rng(7)
    n = 50
    mu = rng.uniform(0.5, 2.0, n)
    elems = np.column_stack([
        rng.uniform(0.5, 5.0, n), rng.uniform(0.0, 0.9, n), rng.uniform(0.0, math.pi, n),
        rng.uniform(0.0, TWO_PI, n), rng.uniform(0.0, TWO_PI, n), rng.uniform(-3.0, 3.0, n)])
    elems[10] = (-1.0, 2.0, 0.1, 0.2, 0.3, 2.5)          # beyond the asymptote
    pos = np.empty((n, 3))
    vel = np.empty((n, 3))
    status = np.empty(n, dtype=np.int64)
    assert elements_to_state_many(mu, elems, pos, vel, status) == Status.BEYOND_ASYMPTOTE
    assert status[10] == Status.BEYOND_ASYMPTOTE and (np.delete(status, 10) == 0).all()
    p = np.empty(3)
    v = np.empty(3)
    for i in range(n):
        assert elements_to_state(mu[i], *elems[i], p, v) == status[i]
        np.testing.assert_array_equal(p, pos[i])
        np.testing.assert_array_equal(v, vel[i])

    out = np.empty((n, 7))
    assert state_to_elements_many(mu, pos, vel, out, status) == Status.INVALID_STATE
    o = np.empty(7)
    for i in range(n):
        assert state_to_elements(mu[i], pos[i], vel[i], o) == status[i]
        np.testing.assert_array_equal(o, out[i])
