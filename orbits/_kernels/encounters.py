"""Closest approach of two bodies inside one integration step.

A step-based integrator knows the relative position ``dx = x_i - x_j`` and
velocity ``dv = v_i - v_j`` of a pair only at the ends of a step; the
closest approach can fall between them.  The kernels here find it, for a
collision detector and an encounter log:

* :func:`hermite_closest`: on the cubic Hermite interpolant of the relative
  position through both ends (exact for motion that is a cubic in time);
* :func:`kepler_closest`: on the two-body orbit of the pair through one
  state, inside a time window (exact for an isolated pair);
* :func:`kepler_contact`: on that orbit, the first time the pair comes
  within a given separation (where a step cannot be finished, as two bodies
  meet head-on);
* :func:`closest_approach`: the estimate for one step of an N-body
  integration, from both ends: two-body motion in a tidal field fitted to
  the step during an encounter, the Hermite interpolant when the pair barely
  interacts.

Every function takes plain float64 scalars and length-3 arrays in the
caller's units, with ``G`` folded into ``mu = G (m_i + m_j)``, and
returns a tuple; none allocates but the tidal fit of ``closest_approach``
during an encounter (six arrays of at most 30 numbers a fit).  Invalid input (non-finite values,
``mu < 0``, an empty window) gives NaNs, never an exception.

References
----------
.. [1] Danby, J. M. A. 1988, *Fundamentals of Celestial Mechanics*, 2nd ed.,
   Willmann-Bell, sect. 6.9 (universal variables, the time of pericentre
   passage).
.. [2] Burden, R. L. & Faires, J. D. 2011, *Numerical Analysis*, 9th ed.,
   Brooks/Cole, sect. 3.5 (cubic Hermite interpolation).
.. [3] Wisdom, J. & Holman, M. 1991, AJ 102, 1528 (Kepler drifts between
   kicks of a weak perturbation).
.. [4] Murray, C. D. & Dermott, S. F. 1999, *Solar System Dynamics*,
   Cambridge University Press, sect. 3.13 and 4.9 (Hill radius; the tidal
   term of a distant mass).
.. [5] Dennis, J. E. & Schnabel, R. B. 1996, *Numerical Methods for
   Unconstrained Optimization and Nonlinear Equations*, SIAM, ch. 8 and 10
   (Broyden's update, Gauss-Newton).
"""

import math

import numpy as np

from ._jit import njit
from .kepler import bracketed_anomaly, short_step_anomaly
from .stumpff import stumpff

__all__ = [
    "ROOT_MAX_ITER",
    "hermite_closest",
    "kepler_closest",
    "kepler_contact",
    "closest_approach",
]

_EPS = 2.220446049250313e-16
_TWO_PI = 2.0 * math.pi
_NAN = math.nan

# Safeguarded Newton on a polynomial monotone on its bracket: Newton
# converges quadratically once close, bisection halves the bracket
# otherwise, and [0, 1] is resolved to an ulp in at most 55 halvings.
ROOT_MAX_ITER = 100

# closest_approach treats the step as two-body motion in a tidal field when
# the two-body orbit from the start misses the end of the step by less than
# this fraction of what a straight line misses it by, and otherwise (the
# pair barely interacts) takes the Hermite interpolant.  Beside a
# Jupiter-mass planet at 5 au (Hill radius 0.35 au) the fraction is 0.01-0.1
# for encounters inside 0.6 Hill radii, 0.25-0.3 at 0.9, 0.7-0.9 at 1.4.
_WEAK_INTERACTION = 0.5

# Kick-drift-kick steps on each side of the junction when the orbits in the
# fitted field are followed.  8, 16, 32 and 64 give the same separations to
# 2e-8 at steps of P/600 and finer (the field model, not the splitting,
# limits the accuracy); 16 leaves a margin.
_HALF_SUBSTEPS = 16

# Weight of the velocity mismatch at the junction against the position
# mismatch, in units of the step (1/3 and 1/10 gave the same errors within
# a factor 2).
_VELOCITY_WEIGHT = 0.1

# Forward-difference step of the fit's Jacobian, as |T| h^2 (dimensionless):
# the mismatch changes by ~1e-6 of the orbit, so rounding costs ~1e-10 of the
# derivative and the curvature in T ~1e-6.
_FD_STEP = 1e-6

# The fit has converged when its correction is below _FIT_TOL of the field
# (the field moves the separation by <= 1e-2 of itself on the steps served,
# so this leaves < 1e-8), when the correction, as |dT| h^2, is below
# _FIT_ABS (a field at rounding level), or when the mismatch itself is below
# _FIT_NOISE of the states (two-body data: the mismatch is the rounding of
# the drifts).  The Jacobian is computed again where a correction misses its
# linear prediction by more than _REFRESH of the mismatch (the pericentre
# passage makes the mismatch nonlinear), and otherwise updated by Broyden's
# formula while the correction exceeds _BROYDEN_MIN of the field (below, the
# secant is rounding noise).  The encounters of closest_approach's notes
# take 2-6 passes, 10 at most; _FIT_MAX_ITER means that no field fits.
_FIT_TOL = 1e-6
_FIT_ABS = 1e-14
_FIT_NOISE = 1e-12
_REFRESH = 0.5
_BROYDEN_MIN = 1e-4
_FIT_MAX_ITER = 12

# An unknown of the fit whose pivot falls below this fraction of the largest
# carries no information (a radial encounter leaves components of the field
# that it cannot feel); it is left at zero.
_PIVOT_TOL = 1e-12

# The orbits are joined at the middle of the step unless the pericentre
# passage lies within this fraction of the step from it (see
# closest_approach).
_JUNCTION_CLEARANCE = 0.125

_INV_SQRT3 = 1.0 / math.sqrt(3.0)


# --------------------------------------------------------------------------
# Real roots of a polynomial on [0, 1]
# --------------------------------------------------------------------------

@njit(inline="always")
def _horner(c, s):
    """``c[0] + c[1] s + ... + c[5] s^5`` for a 6-tuple ``c``."""
    return c[0] + s * (c[1] + s * (c[2] + s * (c[3] + s * (c[4] + s * c[5]))))


@njit(inline="always")
def _derivative(c):
    """Coefficients of the derivative, padded to six."""
    return (c[1], 2.0 * c[2], 3.0 * c[3], 4.0 * c[4], 5.0 * c[5], 0.0)


@njit(inline="always")
def _put(t, k, value):
    """The 5-tuple ``t`` with entry ``k`` replaced (numba tuples are immutable;
    this keeps the root lists off the heap)."""
    return (value if k == 0 else t[0], value if k == 1 else t[1],
            value if k == 2 else t[2], value if k == 3 else t[3],
            value if k == 4 else t[4])


@njit(inline="always")
def _value(c, dc, A, s, vector):
    """The polynomial ``c`` and its derivative ``dc`` at ``s``; with
    ``vector``, ``c`` is ``p . p'`` of the cubic ``p`` whose coefficient
    vectors are ``A = (a0, a1, a2, a3)`` (12 numbers), and it is evaluated
    from ``p`` and its derivatives instead (see :func:`hermite_closest`)."""
    if not vector:
        return _horner(c, s), _horner(dc, s)
    px = A[0] + s * (A[3] + s * (A[6] + s * A[9]))
    py = A[1] + s * (A[4] + s * (A[7] + s * A[10]))
    pz = A[2] + s * (A[5] + s * (A[8] + s * A[11]))
    qx = A[3] + s * (2.0 * A[6] + 3.0 * s * A[9])
    qy = A[4] + s * (2.0 * A[7] + 3.0 * s * A[10])
    qz = A[5] + s * (2.0 * A[8] + 3.0 * s * A[11])
    rx = 2.0 * A[6] + 6.0 * s * A[9]
    ry = 2.0 * A[7] + 6.0 * s * A[10]
    rz = 2.0 * A[8] + 6.0 * s * A[11]
    return (px * qx + py * qy + pz * qz,
            qx * qx + qy * qy + qz * qz + px * rx + py * ry + pz * rz)


@njit
def _root_in(c, dc, A, vector, lo, hi, flo, fhi):
    """A root in ``(lo, hi)`` of the polynomial ``c`` (see :func:`_value`),
    whose values ``flo``, ``fhi`` at the ends have opposite signs."""
    s = lo - flo * (hi - lo) / (fhi - flo)     # regula falsi starter
    if not (lo < s < hi):
        s = 0.5 * (lo + hi)
    neg_lo = flo < 0.0
    for _ in range(ROOT_MAX_ITER):
        f, d = _value(c, dc, A, s, vector)
        if f == 0.0:
            return s
        if (f < 0.0) == neg_lo:
            lo = s
        else:
            hi = s
        s_new = s - f / d
        if not (lo < s_new < hi):
            s_new = 0.5 * (lo + hi)
        # s lies in [0, 1]: an absolute tolerance of a few ulps of 1 resolves
        # the root as well as the values determine it.
        if abs(s_new - s) <= 2.0 * _EPS or hi - lo <= 2.0 * _EPS:
            return s_new
        s = s_new
    return s


@njit
def _roots_between(c, A, vector, crit, m):
    """Roots in ``(0, 1)`` of the polynomial ``c`` (see :func:`_value`),
    monotone between ``0``, the ``m`` sorted points ``crit`` and ``1`` (the
    roots of its derivative).

    Each monotone piece holds at most one root: one inside where the values at
    its ends have opposite signs, or its right end where the value is exactly
    zero there.  Returns a 5-tuple (NaN-padded, sorted) and the count.
    """
    dc = _derivative(c)
    roots = (_NAN, _NAN, _NAN, _NAN, _NAN)
    n = 0
    lo = 0.0
    flo, _ = _value(c, dc, A, lo, vector)
    for k in range(m + 1):
        hi = crit[k] if k < m else 1.0
        fhi, _ = _value(c, dc, A, hi, vector)
        if fhi == 0.0:
            if hi < 1.0 and n < 5:
                roots = _put(roots, n, hi)
                n += 1
        elif ((flo < 0.0 and fhi > 0.0) or (flo > 0.0 and fhi < 0.0)) and n < 5:
            roots = _put(roots, n, _root_in(c, dc, A, vector, lo, hi, flo, fhi))
            n += 1
        lo = hi
        flo = fhi
    return roots, n


@njit
def _unit_roots(c, A):
    """All real roots in ``(0, 1)`` of ``p . p'``, the quintic ``c``, for the
    cubic ``p`` with coefficient vectors ``A``.

    The roots of each derivative split ``[0, 1]`` into pieces on which the
    polynomial above it is monotone (Rolle), starting from the fourth
    derivative, which is linear: no root can be missed, however close two
    roots are, and no companion matrix or heap array is needed.  The
    derivatives are evaluated from their coefficients; the quintic itself
    from ``p`` and ``p'``, whose components carry absolute errors of a few
    ``eps max|a_k|``: a sign change of ``p . p'`` then follows one of ``p``'s
    components through zero to that accuracy even where the coefficients of
    the quintic, dot products of the ``a_k``, would leave its value at
    rounding level over a wide interval (a flat minimum).
    """
    d1 = _derivative(c)
    d2 = _derivative(d1)
    d3 = _derivative(d2)
    d4 = _derivative(d3)
    crit = (_NAN, _NAN, _NAN, _NAN, _NAN)
    # from the fourth derivative down to the quintic, in a loop so that the
    # count and the flag are variables: passed as constants, numba would
    # compile _roots_between (and _root_in) once for each value
    pieces = (d4, d3, d2, d1, c)
    m = np.int64(0)
    for k in range(5):
        crit, m = _roots_between(pieces[k], A, k == 4, crit, m)
    return crit, m


# --------------------------------------------------------------------------
# Hermite interpolant
# --------------------------------------------------------------------------

@njit(inline="always")
def _ends(dx0, dv0, dx1, dv1):
    # the twelve numbers of a step's two ends
    return (dx0[0], dx0[1], dx0[2], dv0[0], dv0[1], dv0[2],
            dx1[0], dx1[1], dx1[2], dv1[0], dv1[1], dv1[2])


@njit(inline="always")
def _norm3(x, y, z):
    return math.sqrt(x * x + y * y + z * z)


@njit
def hermite_closest(dx0, dv0, dx1, dv1, h):
    """Closest approach on the cubic Hermite interpolant of a step.

    Parameters
    ----------
    dx0, dv0 : ndarray, shape (3,)
        Relative position ``x_i - x_j`` [length] and velocity [length / time]
        at the start of the step.
    dx1, dv1 : ndarray, shape (3,)
        The same at the end of the step.
    h : float
        The step [time], either sign.

    Returns
    -------
    s_min : float
        Fraction of the step in ``[0, 1]`` at which the interpolant is
        closest to the origin (the earliest, if several points are equally
        close).
    d_min : float
        That distance [length].
    speed : float
        ``|p'(s_min)| / |h|``, the relative speed there [length / time].

    All three are NaN for non-finite input.  For ``h = 0`` the step is a
    point: ``(0, |dx0|, |dv0|)``.

    Notes
    -----
    With ``s = t / h`` the interpolant matching both positions and both
    velocities is ``p(s) = a0 + a1 s + a2 s^2 + a3 s^3`` with ::

        a0 = dx0,  a1 = h dv0,
        a2 = 3 (dx1 - dx0) - h (2 dv0 + dv1),
        a3 = 2 (dx0 - dx1) + h (dv0 + dv1).

    The extrema of ``|p|^2`` are the roots of ``p . p'``, a quintic whose
    coefficients are dot products of the ``a_k``.  Its roots in ``(0, 1)``
    are isolated by the roots of its derivatives, found the same way from
    the linear fourth derivative up (each polynomial is monotone between the
    roots of its derivative, so none is missed however close two are), and
    polished by Newton's method kept inside the bracket, with ``p . p'``
    itself evaluated from ``p`` and ``p'`` (see ``_unit_roots``).  The
    smallest of ``|p|`` at these roots and at both ends is returned.  A cubic
    (in particular a straight line) is reproduced exactly, so for such
    motion the result is exact up to rounding: ``d_min`` carries an absolute
    error of a few ``eps max|a_k|`` (1.7 on random cubics), of the order of
    the rounding of the data themselves.

    References
    ----------
    Burden & Faires (2011), sect. 3.5.
    """
    x0, y0, z0, u0, v0, w0, x1, y1, z1, u1, v1, w1 = _ends(dx0, dv0, dx1, dv1)
    total = x0 + y0 + z0 + u0 + v0 + w0 + x1 + y1 + z1 + u1 + v1 + w1
    if not math.isfinite(total * 0.0 + h):
        return _NAN, _NAN, _NAN
    if h == 0.0:
        return 0.0, _norm3(x0, y0, z0), _norm3(u0, v0, w0)
    a1x = h * u0
    a1y = h * v0
    a1z = h * w0
    a2x = 3.0 * (x1 - x0) - h * (2.0 * u0 + u1)
    a2y = 3.0 * (y1 - y0) - h * (2.0 * v0 + v1)
    a2z = 3.0 * (z1 - z0) - h * (2.0 * w0 + w1)
    a3x = 2.0 * (x0 - x1) + h * (u0 + u1)
    a3y = 2.0 * (y0 - y1) + h * (v0 + v1)
    a3z = 2.0 * (z0 - z1) + h * (w0 + w1)
    # p . p' = sum_m ((m + 1) / 2) sum_{k + l = m + 1} a_k . a_l s^m
    a01 = x0 * a1x + y0 * a1y + z0 * a1z
    a11 = a1x * a1x + a1y * a1y + a1z * a1z
    a02 = x0 * a2x + y0 * a2y + z0 * a2z
    a03 = x0 * a3x + y0 * a3y + z0 * a3z
    a12 = a1x * a2x + a1y * a2y + a1z * a2z
    a13 = a1x * a3x + a1y * a3y + a1z * a3z
    a22 = a2x * a2x + a2y * a2y + a2z * a2z
    a23 = a2x * a3x + a2y * a3y + a2z * a3z
    a33 = a3x * a3x + a3y * a3y + a3z * a3z
    c = (a01, a11 + 2.0 * a02, 3.0 * (a03 + a12), 4.0 * a13 + 2.0 * a22,
         5.0 * a23, 3.0 * a33)
    A = (x0, y0, z0, a1x, a1y, a1z, a2x, a2y, a2z, a3x, a3y, a3z)
    roots, n = _unit_roots(c, A)

    s_best = 0.0
    d2_best = x0 * x0 + y0 * y0 + z0 * z0
    for k in range(n + 1):
        s = roots[k] if k < n else 1.0
        px = x0 + s * (a1x + s * (a2x + s * a3x))
        py = y0 + s * (a1y + s * (a2y + s * a3y))
        pz = z0 + s * (a1z + s * (a2z + s * a3z))
        d2 = px * px + py * py + pz * pz
        if d2 < d2_best:
            d2_best = d2
            s_best = s
    s = s_best
    qx = a1x + s * (2.0 * a2x + 3.0 * s * a3x)
    qy = a1y + s * (2.0 * a2y + 3.0 * s * a3y)
    qz = a1z + s * (2.0 * a2z + 3.0 * s * a3z)
    return s_best, math.sqrt(d2_best), _norm3(qx, qy, qz) / abs(h)


# --------------------------------------------------------------------------
# Two-body orbit
# --------------------------------------------------------------------------

@njit
def _line_closest(x, y, z, vx, vy, vz, t_lo, t_hi):
    """Closest approach to the origin of ``x + v t`` for ``t`` in the window."""
    v2 = vx * vx + vy * vy + vz * vz
    if v2 == 0.0:
        t = min(max(0.0, t_lo), t_hi)
        return t, _norm3(x, y, z), 0.0
    t_star = -(x * vx + y * vy + z * vz) / v2
    speed = math.sqrt(v2)
    if t_lo <= t_star <= t_hi:
        # the distance of the line from the origin, |x cross v| / |v|, which
        # does not cancel as x + v t_star does
        hx = y * vz - z * vy
        hy = z * vx - x * vz
        hz = x * vy - y * vx
        return t_star, _norm3(hx, hy, hz) / speed, speed
    t = t_lo if t_star < t_lo else t_hi
    return t, _norm3(x + vx * t, y + vy * t, z + vz * t), speed


@njit
def _radius_and_speed(mu, x, y, z, vx, vy, vz, dt):
    """Distance and speed on the two-body orbit ``dt`` after the state."""
    px, py, pz, qx, qy, qz = _drift(mu, x, y, z, vx, vy, vz, dt)
    return _norm3(px, py, pz), _norm3(qx, qy, qz)


@njit
def _kepler_closest(mu, x, y, z, vx, vy, vz, t_lo, t_hi):
    """:func:`kepler_closest` on scalars."""
    total = x + y + z + vx + vy + vz + t_lo + t_hi + mu
    if not math.isfinite(total) or not (mu >= 0.0) or not (t_lo <= t_hi):
        return _NAN, _NAN, _NAN
    if mu == 0.0:
        return _line_closest(x, y, z, vx, vy, vz, t_lo, t_hi)
    r0 = _norm3(x, y, z)
    if r0 == 0.0:
        return _NAN, _NAN, _NAN
    v2 = vx * vx + vy * vy + vz * vz
    eta = x * vx + y * vy + z * vz
    beta = 2.0 * mu / r0 - v2
    hx = y * vz - z * vy
    hy = z * vx - x * vz
    hz = x * vy - y * vx
    p = (hx * hx + hy * hy + hz * hz) / mu
    # eccentricity vector ((v^2 - mu / r) dx - (dx . dv) dv) / mu: absolute
    # error of a few eps, where sqrt(1 - p / a) would have sqrt(eps) near e = 0
    k = v2 - mu / r0
    ex = (k * x - eta * vx) / mu
    ey = (k * y - eta * vy) / mu
    ez = (k * z - eta * vz) / mu
    e = _norm3(ex, ey, ez)
    q = p / (1.0 + e)

    if beta > 0.0:
        sb = math.sqrt(beta)
        E = math.atan2(eta * sb / mu, 1.0 - r0 * beta / mu)
        s = E / sb
    elif beta < 0.0:
        sb = math.sqrt(-beta)
        s = math.asinh(eta * sb / (mu * e)) / sb
    else:
        s = eta / mu
    c3 = stumpff(beta * s * s)[3]
    since = s * (q + mu * e * s * s * c3)      # time since pericentre

    if beta > 0.0:
        period = _TWO_PI * mu / (beta * sb)
        tau0 = -since
        tau = tau0 + math.ceil((t_lo - tau0) / period) * period
        if tau <= t_hi:
            return max(tau, t_lo), q, math.sqrt(mu * (1.0 + e) / q)
        # no passage in the window: it lies between two, (tau - P, tau)
        u_lo = t_lo - (tau - period)
        u_hi = tau - t_hi
        if min(u_lo, period - u_lo) <= min(u_hi, period - u_hi):
            t_end = t_lo
        else:
            t_end = t_hi
    else:
        tau = -since
        if t_lo <= tau <= t_hi:
            return tau, q, math.sqrt(mu * (1.0 + e) / q)
        t_end = t_hi if tau > t_hi else t_lo
    d, speed = _radius_and_speed(mu, x, y, z, vx, vy, vz, t_end)
    return t_end, d, speed


@njit
def kepler_closest(mu, dx, dv, t_lo, t_hi):
    """Closest approach on the two-body orbit of a pair, inside a time window.

    Parameters
    ----------
    mu : float
        ``G (m_i + m_j)`` [length^3 / time^2], ``>= 0``; 0 gives straight-line
        motion.
    dx, dv : ndarray, shape (3,)
        Relative position [length] and velocity [length / time] at time 0.
    t_lo, t_hi : float
        The window [time], ``t_lo <= t_hi``; it need not contain 0.

    Returns
    -------
    t_min : float
        Time in ``[t_lo, t_hi]`` at which the separation is smallest [time].
    d_min : float
        That separation [length].
    speed : float
        The relative speed there [length / time].

    All NaN for non-finite input, ``mu < 0``, ``t_lo > t_hi``, or ``dx = 0``
    with ``mu > 0`` (the pair at collision has no orbit).

    Notes
    -----
    The separation on a conic is smallest at pericentre and grows
    monotonically with the time from the nearest pericentre passage
    (``r(tau + u) = r(tau - u)``).  So: if a pericentre passage lies in the
    window, the minimum is the pericentre distance ``q = p / (1 + e)``
    (``p = |dx x dv|^2 / mu``, ``e`` the length of the eccentricity vector),
    reached with speed ``sqrt(mu (1 + e) / q)`` (vis-viva with
    ``2/q - 1/a = (1 + e) / q``, which does not cancel near ``e = 1``); on an
    ellipse that spans several periods the earliest passage in the window is
    returned.  Otherwise it is at the end of the window nearer in time to a
    pericentre passage, where the orbit is propagated with the f and g
    functions of :func:`orbits._kernels.kepler.bracketed_anomaly`'s
    universal anomaly.

    The time since pericentre comes from the universal anomaly ``s``
    measured from pericentre, where ``r dr/dt = mu e G_1(s)`` and
    ``r = q + mu e G_2(s)``: with ``beta = 2 mu / r - v^2`` this gives
    ``e sin E = (dx . dv) sqrt(beta) / mu``, ``e cos E = 1 - r beta / mu``,
    ``s = E / sqrt(beta)`` (ellipse), ``sinh F = (dx . dv) sqrt(-beta) /
    (mu e)``, ``s = F / sqrt(-beta)`` (hyperbola) and ``s = (dx . dv) / mu``
    (parabola), all continuous through ``beta = 0``, and Kepler's equation
    from pericentre ::

        t - tau = s (q + mu e s^2 c_3(beta s^2))

    whose two terms have the same sign, so that the time keeps its relative
    accuracy near the parabolic limit where ``E - e sin E`` would cancel.

    A radial orbit (zero angular momentum) is the limit ``q = 0``: the
    bodies meet at the pericentre time, with infinite speed, and that is
    what is returned when the meeting falls in the window.

    References
    ----------
    Danby (1988), sect. 6.9.
    """
    return _kepler_closest(mu, dx[0], dx[1], dx[2], dv[0], dv[1], dv[2], t_lo, t_hi)


@njit
def _separation_at(mu, x, y, z, vx, vy, vz, dt):
    """Separation and speed on the two-body orbit (a line for ``mu = 0``)
    ``dt`` after the state."""
    if mu == 0.0:
        return (_norm3(x + vx * dt, y + vy * dt, z + vz * dt), _norm3(vx, vy, vz))
    return _radius_and_speed(mu, x, y, z, vx, vy, vz, dt)


@njit
def kepler_contact(mu, dx, dv, r, t_hi):
    """The first time in ``[0, t_hi]`` at which the two-body orbit of a pair
    comes within ``r``.

    Parameters
    ----------
    mu : float
        ``G (m_i + m_j)`` [length^3 / time^2], ``>= 0`` (0: a straight line).
    dx, dv : ndarray, shape (3,)
        Relative position [length] and velocity [length / time] at time 0.
    r : float
        The separation of contact [length], ``> 0``.
    t_hi : float
        The end of the window [time], ``>= 0``.

    Returns
    -------
    t_c : float
        The time the separation falls to ``r`` (0 if it is below ``r``
        already) [time].
    d : float
        The separation there (``r`` up to the bisection's resolution)
        [length].
    speed : float
        The relative speed there [length / time].

    All NaN where the orbit stays beyond ``r`` in the window (or for invalid
    input, as :func:`kepler_closest`).

    Notes
    -----
    The closest approach in the window is :func:`kepler_closest`'s, at
    ``t_min``.  Before it the separation decreases from the last apocentre
    passage on, and is larger than at time 0 before that, so it crosses
    ``r`` exactly once in ``[0, t_min]``: bisection on the two-body drift
    (the f and g functions of :func:`kepler_closest`) finds it to a few ulps
    of ``t_min`` in :data:`ROOT_MAX_ITER` halvings at most.  A radial orbit
    (``q = 0``, the bodies meeting head-on) is resolved as any other: the
    contact lies before the meeting, where the drift is regular.

    Examples
    --------
    >>> import numpy as np
    >>> from orbits._kernels.encounters import kepler_contact
    >>> t, d, s = kepler_contact(0.0, np.array([3.0, 0, 0]), np.array([-1.0, 0, 0]),
    ...                          2.0, 10.0)
    >>> round(t, 12), round(d, 12), s
    (1.0, 2.0, 1.0)
    """
    x, y, z = dx[0], dx[1], dx[2]
    vx, vy, vz = dv[0], dv[1], dv[2]
    t_min, q, _ = _kepler_closest(mu, x, y, z, vx, vy, vz, 0.0, t_hi)
    if not (q < r) or not (r > 0.0):
        return _NAN, _NAN, _NAN
    d0 = _norm3(x, y, z)
    if d0 <= r:
        return 0.0, d0, _norm3(vx, vy, vz)
    lo = 0.0
    hi = t_min
    for _ in range(ROOT_MAX_ITER):
        mid = 0.5 * (lo + hi)
        if not (lo < mid < hi):
            break
        if _separation_at(mu, x, y, z, vx, vy, vz, mid)[0] > r:
            lo = mid
        else:
            hi = mid
    # hi: the first time found inside r (lo, just before it, is still beyond)
    d, speed = _separation_at(mu, x, y, z, vx, vy, vz, hi)
    return hi, d, speed


# --------------------------------------------------------------------------
# Two-body motion in a fitted tidal field
# --------------------------------------------------------------------------

@njit
def _drift(mu, x, y, z, vx, vy, vz, dt):
    """The two-body state ``dt`` after ``(x, v)`` (``mu > 0``), as six floats;
    NaN where the drift fails.  The f and g functions of
    :func:`orbits._kernels.kepler.kepler_drift` on scalars, from its
    short-step anomaly where that applies and its bracketed one otherwise
    (an elliptic step of many periods is reduced modulo the period there,
    and f and g depend on the reduced anomaly only)."""
    s, r0, ir0, beta, zeta = short_step_anomaly(mu, x, y, z, vx, vy, vz, dt)
    if not (s == s):
        if dt == 0.0:
            return x, y, z, vx, vy, vz
        # a long step, or one through a close pericentre
        s = bracketed_anomaly(mu, x, y, z, vx, vy, vz, dt)[0]
        if not (s == s):
            return _NAN, _NAN, _NAN, _NAN, _NAN, _NAN
    eta = x * vx + y * vy + z * vz
    _, c1, c2, _ = stumpff(beta * s * s)
    G1 = s * c1
    G2 = s * s * c2
    r = r0 + eta * G1 + zeta * G2
    fm1 = -mu * G2 * ir0
    g = r0 * G1 + eta * G2
    fdot = -mu * G1 * ir0 / r
    gdm1 = -mu * G2 / r
    return (x + (fm1 * x + g * vx), y + (fm1 * y + g * vy), z + (fm1 * z + g * vz),
            vx + (fdot * x + gdm1 * vx), vy + (fdot * y + gdm1 * vy),
            vz + (fdot * z + gdm1 * vz))


@njit(inline="always")
def _tidal_tensor(c):
    """``(Txx, Tyy, Tzz, Txy, Txz, Tyz)`` of ``sum_k c_k B_k`` over the
    orthogonal basis of symmetric traceless 3x3 matrices (each of Frobenius
    norm sqrt(2)): the off-diagonal pairs xy, xz, yz, ``diag(1, -1, 0)`` and
    ``diag(1, 1, -2) / sqrt(3)``."""
    d = c[4] * _INV_SQRT3
    return c[3] + d, d - c[3], -2.0 * d, c[0], c[1], c[2]


@njit(inline="always")
def _tidal_field(T, x, y, z):
    """The acceleration ``T (x, y, z)`` of the tidal field ``T`` (:func:`_tidal_tensor`)."""
    txx, tyy, tzz, txy, txz, tyz = T
    return txx * x + txy * y + txz * z, txy * x + tyy * y + tyz * z, txz * x + tyz * y + tzz * z


@njit(inline="always")
def _tidal_kick(T, half, x, y, z, vx, vy, vz):
    """The velocity after a kick of ``half`` by the tidal field ``T`` at ``(x, y, z)``."""
    ax, ay, az = _tidal_field(T, x, y, z)
    return vx + half * ax, vy + half * ay, vz + half * az


@njit
def _tidal_orbit(mu, S, c, h, n):
    """The state after ``n`` kick-drift-kick steps of ``h / n`` from ``S``
    under ``mu`` and the tidal field ``c``."""
    T = _tidal_tensor(c)
    dt = h / n
    x, y, z, vx, vy, vz = S
    half = 0.5 * dt
    for k in range(n):
        vx, vy, vz = _tidal_kick(T, half, x, y, z, vx, vy, vz)
        x, y, z, vx, vy, vz = _drift(mu, x, y, z, vx, vy, vz, dt)
        vx, vy, vz = _tidal_kick(T, half, x, y, z, vx, vy, vz)
    return x, y, z, vx, vy, vz


@njit
def _mismatch(mu, S0, S1, c, h, wv, n, tm):
    """Where the tidal orbits from both ends of the step meet at ``tm``:
    the difference of their states, velocities weighted by ``wv``."""
    xa, ya, za, ua, va, wa = _tidal_orbit(mu, S0, c, tm, n)
    xb, yb, zb, ub, vb, wb = _tidal_orbit(mu, S1, c, tm - h, n)
    return (xa - xb, ya - yb, za - zb, wv * (ua - ub), wv * (va - vb), wv * (wa - wb))


@njit(inline="always")
def _dot6(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] + a[4] * b[4] + a[5] * b[5]


@njit(inline="always")
def _shift5(c, k, step):
    return (c[0] + (step if k == 0 else 0.0), c[1] + (step if k == 1 else 0.0),
            c[2] + (step if k == 2 else 0.0), c[3] + (step if k == 3 else 0.0),
            c[4] + (step if k == 4 else 0.0))


@njit(inline="always")
def _store6(out, k, a, b, scale):
    """Row ``k`` of ``out`` := ``(a - b) * scale`` for the 6-tuple ``a`` and
    the 6-array ``b``."""
    out[k, 0] = (a[0] - b[0]) * scale
    out[k, 1] = (a[1] - b[1]) * scale
    out[k, 2] = (a[2] - b[2]) * scale
    out[k, 3] = (a[3] - b[3]) * scale
    out[k, 4] = (a[4] - b[4]) * scale
    out[k, 5] = (a[5] - b[5]) * scale


@njit(inline="always")
def _copy6(out, a):
    """``out[:] = a`` for the 6-tuple ``a``."""
    out[0] = a[0]
    out[1] = a[1]
    out[2] = a[2]
    out[3] = a[3]
    out[4] = a[4]
    out[5] = a[5]


@njit
def _solve5(A, b, c):
    """Solve the symmetric positive semi-definite 5x5 system ``A c = b`` by
    elimination without pivoting, into ``c`` (``A`` and ``b`` are
    overwritten); an unknown whose pivot is below ``_PIVOT_TOL`` of the
    largest diagonal entry carries no information and is set to 0 (the
    least-squares solution that leaves it alone)."""
    big = max(A[0, 0], A[1, 1], A[2, 2], A[3, 3], A[4, 4])
    dropped = 0     # a bit for each unknown left at 0
    for k in range(5):
        piv = A[k, k]
        if not (piv > _PIVOT_TOL * big):
            dropped |= 1 << k
            continue
        for i in range(k + 1, 5):
            f = A[i, k] / piv
            for j in range(5):
                A[i, j] = A[i, j] + -f * A[k, j]
            b[i] = b[i] - f * b[k]
    for k in range(5):
        c[k] = 0.0
    for k in range(4, -1, -1):
        if not (dropped >> k) & 1:
            t = b[k]
            for j in range(k + 1, 5):
                t -= A[k, j] * c[j]
            c[k] = t / A[k, k]


@njit
def _jacobian(mu, S0, S1, c, r, h, wv, n, tm, J):
    """Rows ``J[k]``: the mismatch's derivative in field coefficient ``k`` at
    ``c`` (where the mismatch is ``r``), by forward differences."""
    step = _FD_STEP / (h * h)
    inv = 1.0 / step
    for k in range(5):
        _store6(J, k, _mismatch(mu, S0, S1, _shift5(c, k, step), h, wv, n, tm), r, inv)


@njit
def _fit_tidal_field(mu, S0, S1, h, n, tm):
    """The symmetric traceless tidal tensor (5 coefficients) whose orbits
    from both ends of the step (``n`` kick-drift-kick steps each way) meet
    best at ``tm``; whether the fit converged; the passes it took.

    Gauss-Newton on the 6 x 5 least-squares problem.  The mismatch is linear
    in the field except through the pericentre passage, which shears the
    orbit that crosses it; so the Jacobian (forward differences, 5
    evaluations of the mismatch) is computed again only where the last
    correction missed its prediction by more than _REFRESH of the mismatch,
    and otherwise brought up to date by Broyden's rank-one update.  The
    Jacobian, the normal equations and the residuals are small arrays made
    once a fit (loops over them compile to a fraction of the code that
    tuples unrolled into).
    """
    wv = _VELOCITY_WEIGHT * abs(h)
    # a mismatch at the rounding level of the states needs no field
    noise = _FIT_NOISE * (_norm3(S0[0], S0[1], S0[2]) + _norm3(S1[0], S1[1], S1[2])
                          + wv * (_norm3(S0[3], S0[4], S0[5]) + _norm3(S1[3], S1[4], S1[5])))
    c = (0.0, 0.0, 0.0, 0.0, 0.0)
    R = _mismatch(mu, S0, S1, c, h, wv, n, tm)
    if _dot6(R, R) <= noise * noise:
        return c, True, 0
    J = np.empty((5, 6))    # row k: the mismatch's derivative in coefficient k
    A = np.empty((5, 5))
    b = np.empty(5)
    dc = np.empty(5)
    r = np.empty(6)         # the mismatch at c
    u = np.empty(6)
    _copy6(r, R)
    _jacobian(mu, S0, S1, c, r, h, wv, n, tm, J)
    for it in range(_FIT_MAX_ITER):
        for i in range(5):
            for k in range(5):
                A[i, k] = _dot6(J[i], J[k])
            b[i] = -_dot6(J[i], r)
        _solve5(A, b, dc)
        c = (c[0] + dc[0], c[1] + dc[1], c[2] + dc[2], c[3] + dc[3], c[4] + dc[4])
        size = abs(c[0]) + abs(c[1]) + abs(c[2]) + abs(c[3]) + abs(c[4])
        change = abs(dc[0]) + abs(dc[1]) + abs(dc[2]) + abs(dc[3]) + abs(dc[4])
        if not math.isfinite(size):
            return c, False, it + 1
        if change <= _FIT_TOL * size or change * (h * h) <= _FIT_ABS:
            return c, True, it + 1
        R_new = _mismatch(mu, S0, S1, c, h, wv, n, tm)
        if _dot6(R_new, R_new) <= noise * noise:
            return c, True, it + 1
        # u = R_new - (R + J dc): what the linear model did not predict
        _copy6(u, R_new)
        for m in range(6):
            u[m] = u[m] - r[m]
        for k in range(5):
            for m in range(6):
                u[m] = u[m] - J[k, m] * dc[k]
        _copy6(r, R_new)
        if _dot6(u, u) > (_REFRESH * _REFRESH) * _dot6(R_new, R_new):
            _jacobian(mu, S0, S1, c, r, h, wv, n, tm, J)
        elif change > _BROYDEN_MIN * size:
            # below _BROYDEN_MIN of the field the secant is rounding noise
            norm2 = (dc[0] * dc[0] + dc[1] * dc[1] + dc[2] * dc[2] + dc[3] * dc[3]
                     + dc[4] * dc[4])
            for k in range(5):
                dck = dc[k] / norm2
                for m in range(6):
                    J[k, m] = J[k, m] + u[m] * dck
    return c, False, _FIT_MAX_ITER


@njit
def _closest_on_tidal_orbits(mu, S0, S1, c, h, n, tm):
    """Closest approach along the fitted orbits: the two-body arc of each
    drift, from the start up to ``tm`` and from the end back to it."""
    T = _tidal_tensor(c)
    d_best = math.inf
    t_best = _NAN
    tau_best = 0.0
    dt_best = 0.0
    B = S0
    for side in range(2):
        S = S0 if side == 0 else S1
        span = tm if side == 0 else tm - h
        origin = 0.0 if side == 0 else h
        dt = span / n
        lo = min(dt, 0.0)
        hi = max(dt, 0.0)
        x, y, z, vx, vy, vz = S
        half = 0.5 * dt
        for k in range(n):
            vx, vy, vz = _tidal_kick(T, half, x, y, z, vx, vy, vz)
            tau, d, v = _kepler_closest(mu, x, y, z, vx, vy, vz, lo, hi)
            if d < d_best:
                d_best = d
                t_best = origin + k * dt + tau
                tau_best = tau
                dt_best = dt
                B = (x, y, z, vx, vy, vz)
            x, y, z, vx, vy, vz = _drift(mu, x, y, z, vx, vy, vz, dt)
            vx, vy, vz = _tidal_kick(T, half, x, y, z, vx, vy, vz)
    if not math.isfinite(d_best):
        return _NAN, _NAN, _NAN
    # A drift carries the velocity after the half-kick of its start, dt / 2
    # of the field ahead of the motion it stands for; at tau into the drift
    # the motion has taken tau of it:
    #   v = v_drift + (tau - dt / 2) a,  x = x_drift + (tau^2 / 2 - tau dt / 2) a
    # with a = T x, which removes the O(dt |T| |x|) error of the speed.
    x, y, z, vx, vy, vz = _drift(mu, B[0], B[1], B[2], B[3], B[4], B[5], tau_best)
    ax, ay, az = _tidal_field(T, x, y, z)
    kv = tau_best - 0.5 * dt_best
    kx = 0.5 * tau_best * kv
    speed = _norm3(vx + kv * ax, vy + kv * ay, vz + kv * az)
    # the distance from the arc's own minimum (no cancellation at a close
    # pericentre), moved along the radius by the position correction
    r = _norm3(x, y, z)
    d = d_best + kx * (x * ax + y * ay + z * az) / r
    if not (speed == speed) or not (d == d):
        return _NAN, _NAN, _NAN
    return t_best, d, speed


# --------------------------------------------------------------------------
# The estimate a step-based integrator calls
# --------------------------------------------------------------------------

@njit
def closest_approach(mu, dx0, dv0, dx1, dv1, h):
    """Closest approach of a pair inside one step of an N-body integration.

    Parameters
    ----------
    mu : float
        ``G (m_i + m_j)`` [length^3 / time^2], ``>= 0``.
    dx0, dv0, dx1, dv1, h
        The relative states at the step's two ends and the step, as
        :func:`hermite_closest` takes them.

    Returns
    -------
    t_min : float
        Time of the closest approach, from the start of the step (between 0
        and ``h``) [time].
    d_min : float
        The separation there [length].
    speed : float
        The relative speed there [length / time].

    All NaN for non-finite input or ``mu < 0``.

    Notes
    -----
    *Which estimate.*  If the two-body orbit from the start misses the end
    state by at least half of what a straight line misses it by
    (``_WEAK_INTERACTION``), the pair's own gravity explains little of its
    motion and :func:`hermite_closest` is returned: at 1.4 and 2.9 Hill
    radii from a Jupiter-mass planet its error is below 7e-7 and 3e-9 of the
    separation at a step of P/200 (P the planet's period), 9e-9 and 4e-11
    at P/600.  Otherwise the pair is in an encounter, and neither simple
    estimate will do, nor their minimum: on the encounters below, the cubic
    cannot turn with a close encounter, and its minimum ranged
    from 0.13 to 800 times the true separation at P/200 (so a minimum of the
    estimates would take it when it undershoots); and the two-body orbit
    through either end carries the perturbation of the other bodies
    accumulated from that end to the encounter: errors up to 0.18 of the
    separation at P/200 and 1.7e-4 at P/2000 (the better of the two: 1.2e-2
    and 1.7e-5).

    *Two-body motion in a fitted tidal field.*  Inside a few Hill radii the
    other bodies act on the pair through the difference of their pulls,
    whose first term is linear in the separation: ``dx'' = -mu dx / |dx|^3
    + T dx`` with ``T`` symmetric and traceless (the Hessian of a potential
    that is harmonic at the pair), five numbers, taken constant over the
    step.  The orbits in this field from the start and from the end are
    followed to a junction by kick-drift-kick steps whose drifts are exact
    two-body arcs (so a close pericentre passage costs nothing), and ``T``
    is fitted by Gauss-Newton so that the two meet: six conditions, five
    unknowns, least squares.  The junction is the middle of the step, or a
    quarter step from the end farther from the pericentre passage when that
    is within an eighth of the step of the middle (a junction inside the
    passage makes the mismatch turn with it).  The closest approach is then
    the smallest of :func:`kepler_closest` over each drift arc, corrected
    for the half kick that the drift's velocity runs ahead of the motion.
    Pure two-body data give ``T = 0`` and the two-body answer.  Where no
    field fits (the fit does not converge, or an orbit crosses the origin)
    the smaller of the two one-sided two-body estimates is returned.

    *Accuracy*, against DOP853 at ``rtol = 1e-13`` for a massless
    body passing a Jupiter-mass planet on a circular orbit at 5 au around a
    solar-mass star (P = 11.2 yr), at pericentre distances 1e-4 to 0.1 au,
    speeds at infinity 0.5 to 6 au/yr, two inclinations and the encounter
    at 0.1 to 0.9 of the step; worst relative errors of the separation and
    the speed:

    ======  ========  ========
    step    d_min     speed
    ======  ========  ========
    P/200   1.3e-4    2.8e-5
    P/300   1.0e-5    5.9e-6
    P/400   3.8e-6    2.6e-6
    P/600   7.6e-7    8.5e-7
    P/1000  1.8e-7    2.2e-7
    P/2000  3.3e-8    2.9e-8
    ======  ========  ========

    and ``t_min`` within 4e-5 of the step.  The error is what the model
    leaves out: the field turns with the planet's orbit, by ``2 pi h / P``
    over the step, and its next term grows as the separation over the
    planet's distance from the star; both shrink with the step, roughly as
    its cube.  A caller that needs 1e-6 of the separation should subdivide
    to steps of P/600 or less around an encounter.  An Earth-mass body in
    place of the massless one gives the same figures.

    Cost: the Hermite estimate alone outside encounters; in an encounter,
    the fit's passes (32 drifts each) and the arcs, some thirty times more,
    and up to a thousand times more where no field fits (end states that
    no orbit joins, or a bound pair drifted over many of its periods in one
    step); the figures are in benchmarks/RESULTS.md.
    """
    x0, y0, z0, u0, v0, w0, x1, y1, z1, u1, v1, w1 = _ends(dx0, dv0, dx1, dv1)
    total = x0 + y0 + z0 + u0 + v0 + w0 + x1 + y1 + z1 + u1 + v1 + w1
    if not math.isfinite(total * 0.0 + h + mu) or not (mu >= 0.0):
        return _NAN, _NAN, _NAN
    s, d_h, v_h = hermite_closest(dx0, dv0, dx1, dv1, h)
    if mu == 0.0 or h == 0.0:
        return s * h, d_h, v_h
    # How much of the departure from a straight line the pair's own gravity
    # explains: the two-body orbit from the start misses the end by the
    # effect of the other bodies alone, the straight line by everything.
    xk, yk, zk, uk, vk, wk = _drift(mu, x0, y0, z0, u0, v0, w0, h)
    ah = abs(h)
    miss_kepler = _norm3(x1 - xk, y1 - yk, z1 - zk) + ah * _norm3(u1 - uk, v1 - vk, w1 - wk)
    miss_line = (_norm3(x1 - x0 - h * u0, y1 - y0 - h * v0, z1 - z0 - h * w0)
                 + ah * _norm3(u1 - u0, v1 - v0, w1 - w0))
    if miss_kepler >= _WEAK_INTERACTION * miss_line:
        return s * h, d_h, v_h
    if miss_kepler == miss_kepler:
        S0 = (x0, y0, z0, u0, v0, w0)
        S1 = (x1, y1, z1, u1, v1, w1)
        # The orbits are joined in the middle of the step unless the
        # pericentre passage is near it: there the mismatch turns with the
        # passage and the fit is no longer nearly linear, so they are joined
        # a quarter step from the end farther from the passage instead.
        t_peri = _kepler_closest(mu, x0, y0, z0, u0, v0, w0, min(h, 0.0), max(h, 0.0))[0]
        tm = 0.5 * h
        if abs(t_peri - tm) < _JUNCTION_CLEARANCE * abs(h):
            tm = 0.25 * h if t_peri / h > 0.5 else 0.75 * h
        c, converged, _ = _fit_tidal_field(mu, S0, S1, h, _HALF_SUBSTEPS, tm)
        if converged:
            t, d, v = _closest_on_tidal_orbits(mu, S0, S1, c, h, _HALF_SUBSTEPS, tm)
            if d == d:
                return t, d, v
    # No field joins the ends (or the two-body orbit from the start meets
    # the origin): the two-body estimates from each end
    lo = min(h, 0.0)
    hi = max(h, 0.0)
    t_best, d_best, v_best = _kepler_closest(mu, x0, y0, z0, u0, v0, w0, lo, hi)
    t, d, v = _kepler_closest(mu, x1, y1, z1, u1, v1, w1, lo - h, hi - h)
    if d < d_best or not (d_best == d_best):
        t_best, d_best, v_best = t + h, d, v
    return t_best, d_best, v_best
