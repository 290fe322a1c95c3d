"""The Kepler drift: a body advanced on its two-body orbit by a time step, in
universal variables.

:func:`kepler_drift` advances one row of a state in place, for ellipses,
parabolae and hyperbolae and a step of any size and sign (see its notes: a
short-step path from a Taylor starter for the steps of a planetary
integration, a bracketed solver for every other step).  Its short-step
arithmetic is written once in the inlined helpers below (:func:`short_start`,
:func:`quartic_step`, :func:`f_and_g`, :func:`advanced_state`), which the
planets' lanes (:mod:`.wh_lanes`) and the systems' lanes (:mod:`.wh_batch`)
share, so that all three agree bit for bit; :func:`bracketed_anomaly` gives
the bracketed solver's anomaly to the drift's tangent
(:mod:`.kepler_tangent`) and to the encounter search (:mod:`.encounters`).
Status codes are two-body codes of :class:`~.status.Status`.

References
----------
Danby, J. M. A. 1988, *Fundamentals of Celestial Mechanics*, 2nd ed.,
Willmann-Bell, sect. 6.9 and 6.10; Danby, J. M. A. 1987, "The solution of
Kepler's equation. III", Celest. Mech. 40, 303.
"""

import math

import numpy as np

from ._jit import fma, njit
from .status import Status
from .stumpff import _SIXTH, _stumpff_short, stumpff

__all__ = [
    "DRIFT_MAX_ITER",
    "kepler_drift",
    "kepler_drift_bracketed",
    "short_step_anomaly",
    "short_start",
    "quartic_step",
    "f_and_g",
    "dot3",
    "radius",
    "advanced",
    "advanced_state",
    "advance_by_anomaly",
    "bracketed_anomaly",
    "row_state",
    "straight_drift",
]

_EPS = 2.220446049250313e-16
_TWO_PI = 2.0 * math.pi

# Bounded iterations of the universal Kepler equation: Danby's quartic
# iteration from the starters below needs 2-4 on the steps of a planetary
# integration and at most ~10 at e = 1 +- 1e-12 or 1e6 orbital periods; the
# rest is room for the bisection safeguard.
DRIFT_MAX_ITER = 200

# stop when a correction is below this many ulps of the iterate
_DRIFT_STEP_TOL = 2.0 * _EPS

# The short-step path of the drift (the steps of a planetary integration, up
# to a sixth of an orbit): taken when |dt| |v0| < _SHORT_STEP r0 and the
# starter spans |beta s^2| <= _SHORT_STEP_Z (an eccentric anomaly of at most
# 1 rad), else the bracketed solver.  From the fifth-order Taylor starter
# (relative error at most 3e-5 for Mercury at a twentieth of its orbit,
# 6e-7 for Jupiter, 1e-4 for Mercury at a fifteenth) Danby's quartic
# iteration runs without a bracket; a correction d with |d| <=
# _SHORT_STEP_TOL |s| leaves an error ~(d/s)^4 <= 1e-18 relative, below
# rounding, so s + d is taken as the root.  One iteration does up to a
# twentieth of an orbit of the solar system's planets, two at a sixth;
# after _SHORT_STEP_ITER iterations without that the bracketed solver
# starts again from the beginning.
# Kepler's equation is increasing in s (its derivative is r > 0), so a small
# correction means a nearby root.
_SHORT_STEP = 1.0
_SHORT_STEP_Z = 1.0
_TWENTYFOURTH = 1.0 / 24.0
_ONE_HUNDRED_TWENTIETH = 1.0 / 120.0
_SHORT_STEP_TOL = 3e-5
_SHORT_STEP_ITER = 3


@njit(inline="always")
def dot3(a0, a1, a2, b0, b1, b2):
    """``a . b`` as the short-step drift computes it, with fused
    multiply-adds: ``((a0 b0) + a1 b1) + a2 b2``, each sum rounded once with
    its product."""
    return fma(a2, b2, fma(a1, b1, a0 * b0))


@njit(inline="always")
def radius(r0, sig, zeta, G1, G2):
    """``r = r0 + sigma G1 + zeta G2``, the radius after a step by the
    anomaly whose ``G1 = s c1``, ``G2 = s^2 c2`` (``sigma = x0 . v0``), with
    fused multiply-adds; the quartic iteration's derivative and the f and g
    functions share it."""
    return fma(zeta, G2, fma(sig, G1, r0))


@njit(inline="always")
def advanced(a, b, p, q):
    """One component after a short step, as an increment of its start ``a``
    so that no digit of it is lost: ``a + (p a + q b)`` with ``q b`` the
    larger term (``g v0`` for a position, ``fdot x0`` for a velocity; ``p``
    is ``f - 1`` or ``gdot - 1``), rounded once with ``p a``."""
    return a + fma(q, b, p * a)


@njit(inline="always")
def advanced_state(x0, y0, z0, vx0, vy0, vz0, fm1, g, fdot, gdm1):
    """The state after a short step from ``(x0, v0)`` with the Lagrange
    coefficients ``f - 1``, ``g``, ``fdot``, ``gdot - 1``: each component
    :func:`advanced`, ``x = x0 + ((f - 1) x0 + g v0)``, ``v = v0 + (fdot x0 +
    (gdot - 1) v0)``.  The scalar drift, the planets' lanes and the systems'
    lanes all write their end state from it."""
    return (advanced(x0, vx0, fm1, g), advanced(y0, vy0, fm1, g), advanced(z0, vz0, fm1, g),
            advanced(vx0, x0, gdm1, fdot), advanced(vy0, y0, gdm1, fdot),
            advanced(vz0, z0, gdm1, fdot))


@njit(inline="always")
def short_start(mu, x0, y0, z0, vx0, vy0, vz0, dt):
    """The start's invariants and the fifth-order Taylor starter of the
    universal anomaly for a step ``dt``: ``(r2, v2, r0, 1 / r0, eta = x0 . v0,
    beta, zeta, s)``.  The one arithmetic of :func:`short_step_anomaly`, of
    the planets' lanes (:mod:`.wh_lanes`) and of the systems' lanes
    (:mod:`.wh_batch`), which must agree bit for bit."""
    r2 = dot3(x0, y0, z0, x0, y0, z0)
    v2 = dot3(vx0, vy0, vz0, vx0, vy0, vz0)
    r0 = math.sqrt(r2)
    ir0 = 1.0 / r0
    eta = dot3(x0, y0, z0, vx0, vy0, vz0)
    beta = fma(2.0 * mu, ir0, -v2)
    zeta = fma(-beta, r0, mu)
    # s = w (1 + a1 w + a2 w^2 + a3 w^3 + a4 w^4), w = dt / r0: the series of
    # Kepler's equation t = r0 s + eta G2 + zeta G3 inverted, with e = eta /
    # r0 and q = zeta / r0 = v^2 - G M / r0 (its form without zeta, a
    # multiplication sooner): a1 = -e / 2, a2 = (3 e^2 - q) / 6, a3 = e (beta
    # - 15 e^2 + 10 q) / 24, a4 = (e^2 (105 (e^2 - q) - 15 beta) + q (10 q +
    # beta)) / 120.  Each coefficient is a few operations from 1 / r0 and the
    # polynomial is summed in pairs of powers (a2 + a3 w, then w^2), so that
    # the starter is as few operations deep as the third-order one was
    w = dt * ir0
    e = eta * ir0
    q = fma(-mu, ir0, v2)
    e2 = e * e
    bq = fma(10.0, q, beta)
    a2 = fma(0.5 * e, e, q * -_SIXTH)
    a3 = (e * _TWENTYFOURTH) * fma(-15.0 * e, e, bq)
    a4 = fma(e2, fma(0.875, e2 - q, -0.125 * beta), (q * _ONE_HUNDRED_TWENTIETH) * bq)
    w2 = w * w
    ws = fma(w2, fma(w2, a4, fma(a3, w, a2)), -0.5 * e * w)
    s = fma(w, ws, w)
    return r2, v2, r0, ir0, eta, beta, zeta, s


@njit(inline="always")
def quartic_step(s, r0, eta, beta, zeta, c0, c1, c2, c3, dt):
    """Danby's quartic correction of the universal anomaly ``s`` (Stumpff
    functions ``c0 .. c3`` of ``beta s^2``), as a series in the Newton step
    ``d1``: ``d + a d^2 + b d^3 = d1`` with ``a = f2 / (2 r)``, ``b = f3 / (6
    r)``, ``fk`` the k-th derivative of Kepler's equation ``f``.  Shared as
    :func:`short_start` is."""
    G1 = s * c1
    ss = s * s
    G2 = ss * c2
    G3 = ss * s * c3
    # f = r0 s + eta G2 + zeta G3 - dt, from the difference r0 s - dt rounded once
    f = fma(zeta, G3, fma(eta, G2, fma(r0, s, -dt)))
    ir = 1.0 / radius(r0, eta, zeta, G1, G2)
    d1 = -f * ir
    a = 0.5 * fma(eta, c0, zeta * G1) * ir
    b = fma(zeta, c0, -(beta * eta) * G1) * ir * _SIXTH
    # d1 (1 + d1 (-a + d1 (2 a^2 - b)))
    return d1 * fma(d1, fma(d1, fma(2.0 * a, a, -b), -a), 1.0)


@njit(inline="always")
def f_and_g(mu, s, r0, ir0, sig, zeta, c1, c2):
    """The Lagrange coefficients of a step by the anomaly ``s`` (Stumpff
    functions ``c1``, ``c2`` of ``beta s^2``; ``sig = x0 . v0``): ``(G1, G2,
    r, 1 / r, f - 1, g, fdot, gdot - 1)``.  Shared as :func:`short_start` is."""
    G1 = s * c1
    G2 = s * s * c2
    r = radius(r0, sig, zeta, G1, G2)
    ir = 1.0 / r
    fm1 = -mu * G2 * ir0
    g = fma(sig, G2, r0 * G1)
    fdot = -mu * G1 * ir0 * ir
    gdm1 = -mu * G2 * ir
    return G1, G2, r, ir, fm1, g, fdot, gdm1


@njit(inline="always")
def short_step_anomaly(mu, x0, y0, z0, vx0, vy0, vz0, dt):
    """The universal anomaly of a step short against the orbit, or NaN.

    The first half of :func:`kepler_drift`'s short-step path (see there):
    for the relative state ``x0 .. vz0`` and a step ``dt`` with ``|dt| |v0|
    < r0`` and less than a radian of eccentric anomaly, the root ``s``
    of the universal Kepler equation from the fifth-order Taylor starter
    and at most three unbracketed quartic iterations; with it ``r0``, ``1 /
    r0``, ``beta`` and ``zeta`` for :func:`advance_by_anomaly`.  ``s`` is
    NaN where this does not apply or has not converged (and for
    non-finite input, ``r0 = 0``, ``mu <= 0`` or ``dt = 0``): then the
    bracketed solver must be used.
    """
    r2, v2, r0, ir0, eta, beta, zeta, s = short_start(mu, x0, y0, z0, vx0, vy0, vz0, dt)
    # NaN, r0 = 0 and dt = 0 fail these tests
    if not (dt * dt * v2 < (_SHORT_STEP * _SHORT_STEP) * r2 and mu > 0.0 and dt != 0.0):
        return math.nan, r0, ir0, beta, zeta
    if not (abs(beta * s * s) <= _SHORT_STEP_Z):
        return math.nan, r0, ir0, beta, zeta
    for _ in range(_SHORT_STEP_ITER):
        c0, c1, c2, c3 = _stumpff_short(beta * s * s)
        d = quartic_step(s, r0, eta, beta, zeta, c0, c1, c2, c3, dt)
        s += d
        if abs(d) <= _SHORT_STEP_TOL * abs(s):
            return s, r0, ir0, beta, zeta
    return math.nan, r0, ir0, beta, zeta


@njit(inline="always")
def _apply_f_and_g(x, v, i, x0, y0, z0, vx0, vy0, vz0, fm1, g, fdot, gdm1):
    """Row ``i`` of ``x``, ``v`` from its start ``(x0, v0)`` and the Lagrange
    coefficients, written as increments (``f - 1``, ``g dot - 1``) so that a
    short step loses no digits of the start: ``x = x0 + ((f - 1) x0 + g v0)``,
    ``v = v0 + (f dot x0 + (g dot - 1) v0)``."""
    (x[i, 0], x[i, 1], x[i, 2], v[i, 0], v[i, 1], v[i, 2]) = advanced_state(
        x0, y0, z0, vx0, vy0, vz0, fm1, g, fdot, gdm1)


@njit(inline="always")
def _short_coefficients(mu, x0, y0, z0, vx0, vy0, vz0, s, r0, ir0, beta, zeta):
    # the f and g coefficients of a short step by the anomaly s (see
    # advance_by_anomaly), with what the drift's tangent reuses: (c0 .. c3,
    # sigma = x0 . v0, r, 1 / r, f - 1, g, fdot, gdot - 1); r <= 0 (or NaN)
    # where the step must go to the bracketed solver
    sig = dot3(x0, y0, z0, vx0, vy0, vz0)
    c0, c1, c2, c3 = _stumpff_short(beta * s * s)
    _, _, r, ir, fm1, g, fdot, gdm1 = f_and_g(mu, s, r0, ir0, sig, zeta, c1, c2)
    return c0, c1, c2, c3, sig, r, ir, fm1, g, fdot, gdm1


@njit(inline="always")
def straight_drift(xj, vj, i, h):
    """Row ``i`` of ``xj`` moved by ``h`` times its velocity (the centre of
    mass's drift)."""
    xj[i, 0] += h * vj[i, 0]
    xj[i, 1] += h * vj[i, 1]
    xj[i, 2] += h * vj[i, 2]


@njit(inline="always")
def row_state(x, v, i):
    """Row ``i`` of the positions ``x`` and velocities ``v`` as six numbers,
    ``(x0, y0, z0, vx0, vy0, vz0)``."""
    return x[i, 0], x[i, 1], x[i, 2], v[i, 0], v[i, 1], v[i, 2]


@njit(inline="always")
def _advance_row(mu, x, v, i, s, r0, ir0, beta, zeta):
    # advance_by_anomaly, returning besides whether it advanced the row's
    # start and what the drift's tangent reuses (_short_coefficients')
    x0, y0, z0, vx0, vy0, vz0 = row_state(x, v, i)
    c0, c1, c2, c3, sig, r, ir, fm1, g, fdot, gdm1 = _short_coefficients(
        mu, x0, y0, z0, vx0, vy0, vz0, s, r0, ir0, beta, zeta)
    ok = r > 0.0
    if ok:
        _apply_f_and_g(x, v, i, x0, y0, z0, vx0, vy0, vz0, fm1, g, fdot, gdm1)
    return (ok, (x0, y0, z0, vx0, vy0, vz0), (c0, c1, c2, c3), sig, ir,
            (fm1, g, fdot, gdm1))


@njit(inline="always")
def advance_by_anomaly(mu, x, v, i, s, r0, ir0, beta, zeta):
    """Advance row ``i`` of ``x``, ``v`` by the universal anomaly ``s`` (the
    f and g functions of :func:`kepler_drift`); the other arguments from
    :func:`short_step_anomaly`.  False, and nothing written, if the radius
    at the end is not positive."""
    return _advance_row(mu, x, v, i, s, r0, ir0, beta, zeta)[0]


@njit
def kepler_drift(mu, x, v, i, dt):
    """Advance body ``i`` on its two-body orbit by ``dt``, in place.

    Parameters
    ----------
    mu : float
        Gravitational parameter of the orbit [length^3 / time^2], > 0.
    x, v : ndarray, shape (N, 3)
        Positions and velocities relative to the centre of attraction; row
        ``i`` is advanced.
    i : int
        The row.
    dt : float
        Time step, either sign, any size.

    Returns
    -------
    status : int
        ``Status.OK``, or ``Status.INVALID_STATE`` (non-finite input,
        ``mu <= 0``, ``r = 0`` or no convergence); then row ``i`` is NaN.

    Notes
    -----
    With ``r0 = |x0|``, ``eta = x0 . v0``, ``beta = 2 mu / r0 - v0^2``
    (``mu / a``), ``zeta = mu - beta r0`` and the universal functions
    ``G_k(s) = s^k c_k(beta s^2)``, the universal anomaly ``s`` (with
    ``ds/dt = 1/r``) solves Kepler's equation ::

        r0 s + eta G_2(s) + zeta G_3(s) = dt

    whose derivative in ``s`` is the radius ``r = r0 + eta G_1 + zeta G_2 > 0``;
    the state follows from the f and g functions ::

        x = x0 + (f - 1) x0 + g v0,   v = v0 + fdot x0 + (gdot - 1) v0
        f - 1 = -mu G_2 / r0,  g = r0 G_1 + eta G_2,
        fdot = -mu G_1 / (r r0),  gdot - 1 = -mu G_2 / r

    written as increments so that a short step loses nothing to
    cancellation.  The same formulas hold for ellipses, parabolae and
    hyperbolae.  On an ellipse ``dt`` is first reduced modulo the period, so
    that a step of many periods costs no more than one.  The equation is
    solved by Danby's quartic iteration (Newton with the second and third
    derivatives).  A step short against the orbit (``|dt| |v0| < r0`` and
    less than a radian of eccentric anomaly) starts from the Taylor series ::

        s = w (1 - w eta / (2 r0) + w^2 (3 eta^2 / r0^2 - zeta / r0) / 6),  w = dt / r0

    (``ds/dt = 1/r``, ``d^2s/dt^2 = -eta / r^3``, ``d^3s/dt^3 = 3 eta^2 /
    r^5 - zeta / r^4``), whose error is of fourth order in the step, and
    stops as soon as a correction is below ``3e-5`` of ``s``, which leaves
    ``(3e-5)^4`` after it: one or two iterations on the steps of a
    planetary integration, with the Stumpff functions from four or nine
    terms of their series.  Any other
    step, or a short one that has not converged in three iterations, is
    solved inside a bracket that shrinks with every residual evaluated, with
    bisection when an iterate would leave it; ``f`` is increasing in ``s``,
    so the bracket always holds the root.  Its starters: the second-order
    Taylor series, the mean anomaly for long elliptic steps and the
    asymptotic growth of ``G_3`` for long hyperbolic ones.

    References
    ----------
    Danby, J. M. A. 1988, *Fundamentals of Celestial Mechanics*, 2nd ed.,
    Willmann-Bell, sect. 6.9 and 6.10; Danby, J. M. A. 1987, "The solution of
    Kepler's equation. III", Celest. Mech. 40, 303; Stumpff (1959);
    Wisdom, J. & Holman, M. 1991, AJ 102, 1528 (its use in mixed-variable
    symplectic maps).
    """
    s, r0, ir0, beta, zeta = short_step_anomaly(mu, x[i, 0], x[i, 1], x[i, 2],
                                                v[i, 0], v[i, 1], v[i, 2], dt)
    if s == s and advance_by_anomaly(mu, x, v, i, s, r0, ir0, beta, zeta):
        return Status.OK
    return kepler_drift_bracketed(mu, x, v, i, dt)


@njit
def kepler_drift_bracketed(mu, x, v, i, dt):
    """:func:`kepler_drift` by the bracketed solver, for any step: the anomaly
    from :func:`bracketed_anomaly`, then f and g from the universal functions
    there (the same values its last iteration tested)."""
    x0, y0, z0, vx0, vy0, vz0 = row_state(x, v, i)
    s, turns = bracketed_anomaly(mu, x0, y0, z0, vx0, vy0, vz0, dt)
    if not (s == s):
        for d in range(3):
            x[i, d] = math.nan
            v[i, d] = math.nan
        return Status.INVALID_STATE
    if dt == 0.0:
        return Status.OK
    r0 = math.sqrt(x0 * x0 + y0 * y0 + z0 * z0)
    eta = x0 * vx0 + y0 * vy0 + z0 * vz0
    beta = 2.0 * mu / r0 - (vx0 * vx0 + vy0 * vy0 + vz0 * vz0)
    zeta = mu - beta * r0
    c0, c1, c2, c3 = stumpff(beta * s * s)
    G1 = s * c1
    G2 = s * s * c2
    r = r0 + eta * G1 + zeta * G2
    fm1 = -mu * G2 / r0
    g = r0 * G1 + eta * G2
    fdot = -mu * G1 / (r * r0)
    gdm1 = -mu * G2 / r
    _apply_f_and_g(x, v, i, x0, y0, z0, vx0, vy0, vz0, fm1, g, fdot, gdm1)
    return Status.OK


@njit
def bracketed_anomaly(mu, x0, y0, z0, vx0, vy0, vz0, dt):
    """The universal anomaly of :func:`kepler_drift`'s bracketed solver.

    The same iteration as the drift's bracketed path, stopped where it
    stops, for the derivatives of the drift (:func:`kepler_drift_tangent`),
    which need ``s`` and not only the state.  Returns ``(s, turns)``: on a
    long elliptic step ``dt`` is first reduced modulo the period ``P`` and
    ``s`` belongs to the reduced step ``dt - turns P`` (``turns`` a whole
    number, 0.0 otherwise).  ``s`` is NaN where the drift fails (invalid
    state, no convergence or a non-positive radius); ``s = 0`` for ``dt = 0``.
    """
    r0 = math.sqrt(x0 * x0 + y0 * y0 + z0 * z0)
    v2 = vx0 * vx0 + vy0 * vy0 + vz0 * vz0
    if not (mu > 0.0) or not (r0 > 0.0) or not math.isfinite(r0 + v2 + dt + mu):
        return math.nan, 0.0
    if dt == 0.0:
        return 0.0, 0.0
    eta = x0 * vx0 + y0 * vy0 + z0 * vz0
    beta = 2.0 * mu / r0 - v2
    zeta = mu - beta * r0
    hx = y0 * vz0 - z0 * vy0
    hy = z0 * vx0 - x0 * vz0
    hz = x0 * vy0 - y0 * vx0
    p = (hx * hx + hy * hy + hz * hz) / mu
    e2 = 1.0 - p * beta / mu
    q = p / (1.0 + math.sqrt(e2 if e2 > 0.0 else 0.0))
    turns = 0.0
    if beta > 0.0:
        period = _TWO_PI * mu / (beta * math.sqrt(beta))
        if abs(dt) > period:
            reduced = np.fmod(dt, period)
            turns = float(round((dt - reduced) / period))
            dt = reduced
    if dt > 0.0:
        lo = 0.0
        hi = dt / q if q > 0.0 else math.inf
    else:
        lo = dt / q if q > 0.0 else -math.inf
        hi = 0.0
    s = dt / r0 - 0.5 * eta * dt * dt / (r0 * r0 * r0)
    if abs(dt) * math.sqrt(v2) > 0.2 * r0 or not (lo < s < hi):
        if beta > 0.0:
            s = dt * beta / mu
        else:
            b = -beta
            sb = math.sqrt(b) if b > 0.0 else 0.0
            scale = zeta + sb * (abs(eta) + sb * r0)
            if sb > 0.0 and scale > 0.0:
                s = math.log(1.0 + 2.0 * b * sb * abs(dt) / scale) / sb
                s = s if dt > 0.0 else -s
        if not (lo < s < hi):
            s = 0.5 * (lo + hi) if math.isfinite(hi - lo) else dt / r0
    r = r0
    it = 0
    width = hi - lo
    for _ in range(DRIFT_MAX_ITER):
        c0, c1, c2, c3 = stumpff(beta * s * s)
        G0 = c0
        G1 = s * c1
        G2 = s * s * c2
        G3 = s * s * s * c3
        f = r0 * s + eta * G2 + zeta * G3 - dt
        r = r0 + eta * G1 + zeta * G2
        if f == 0.0:
            return (s, turns) if r > 0.0 else (math.nan, 0.0)
        if f < 0.0:
            lo = s
        else:
            hi = s
        fpp = eta * G0 + zeta * G1
        fppp = zeta * G0 - beta * eta * G1
        d1 = -f / r
        d2 = -f / (r + 0.5 * d1 * fpp)
        s_new = s - f / (r + 0.5 * d2 * fpp + d2 * d2 * fppp / 6.0)
        it += 1
        if it % 4 == 0:
            slow = (hi - lo) > 0.5 * width
            width = hi - lo
        else:
            slow = False
        if slow or not (lo < s_new < hi):
            if math.isfinite(lo) and math.isfinite(hi):
                if lo > 0.0 and hi > 4.0 * lo:
                    s_new = math.sqrt(lo * hi)
                elif hi < 0.0 and lo < 4.0 * hi:
                    s_new = -math.sqrt(lo * hi)
                else:
                    s_new = 0.5 * (lo + hi)
            elif math.isfinite(lo):
                s_new = 2.0 * lo + dt / r0
            else:
                s_new = 2.0 * hi + dt / r0
        if abs(s_new - s) <= _DRIFT_STEP_TOL * abs(s):
            return (s, turns) if r > 0.0 else (math.nan, 0.0)
        s = s_new
    return math.nan, 0.0
