"""Kepler's equation: the mean, eccentric, hyperbolic and true anomalies of a
conic from one another.

Every function works on plain float64 scalars; angles are in radians.

Mean anomaly
------------
* elliptic: ``M = E - e sin E`` (eccentric anomaly ``E``);
* hyperbolic: ``M = e sinh F - F`` (hyperbolic anomaly ``F``);
* parabolic (``e == 1`` exactly): Barker's equation ``M = D + D^3 / 3`` with
  ``D = tan(f / 2)``, so that ``M = sqrt(mu / (2 q^3)) (t - tau)`` for
  pericentre distance ``q`` and time of pericentre passage ``tau``.

For ellipses and hyperbolae ``M = n (t - tau)`` with mean motion
``n = sqrt(mu / |a|^3)``, so a caller advances an orbit by adding ``n dt`` to
``M``.

References
----------
.. [1] Murray, C. D. & Dermott, S. F. 1999, *Solar System Dynamics*,
   Cambridge University Press, ch. 2.
.. [2] Danby, J. M. A. 1988, *Fundamentals of Celestial Mechanics*, 2nd ed.,
   Willmann-Bell, ch. 6 (the two-body problem).
.. [3] Battin, R. H. 1999, *An Introduction to the Mathematics and Methods of
   Astrodynamics*, rev. ed., AIAA, ch. 4 (Barker's equation, hyperbolic
   Kepler equation).
.. [4] Fukushima, T. 1997, "A method solving Kepler's equation for hyperbolic
   case", *Celest. Mech. Dyn. Astron.* 68, 121 (solving it robustly near
   the parabolic limit and for large mean anomalies).
"""

import math

import numpy as np

from ._jit import njit, value

__all__ = [
    "KEPLER_MAX_ITER",
    "mean_to_eccentric",
    "eccentric_to_mean",
    "mean_to_hyperbolic",
    "hyperbolic_to_mean",
    "mean_to_parabolic",
    "true_from_mean",
    "mean_from_true",
]

# Bounded iteration count for the Kepler solvers.  The starters below need at
# most 6 iterations over e in [0, 1 - 1e-6] and e in (1, 1e8]; the rest is
# headroom for the bisection safeguard, which halves the bracket each time.
KEPLER_MAX_ITER = 100

# Switch from the starter E0 = M + e sin M (error O(e^2)) to the cubic
# starter, which is exact in the limit e -> 1, M -> 0: either side of 0.5
# takes at most 5 Newton steps.
_CUBIC_STARTER_E = 0.5

# Up to this eccentricity 1 + e cos f is evaluated in half angles (see
# _one_plus_e_cos); it is the root of (e^2 - 1) / e = 1.
_HALF_ANGLE_MAX_E = 0.5 * (1.0 + math.sqrt(5.0))

_EPS = 2.220446049250313e-16
_PI = math.pi
_TWO_PI = 2.0 * math.pi

# Stop the Newton iteration when a step is this many ulps of the iterate: the
# residual itself is only known to a few ulps of M, so smaller steps are noise.
_STEP_TOL = 4.0 * _EPS


# --------------------------------------------------------------------------
# Accurate pieces of the Kepler equations
# --------------------------------------------------------------------------

@njit
def _x_minus_sin(x):
    """``x - sin(x)`` without cancellation for small ``x``."""
    if abs(x) >= 1.0:
        return x - math.sin(x)
    # Taylor series: near x = 0 the difference is O(x^3) and the direct form
    # would lose all digits; for |x| < 1 the terms fall by >= 20x each.
    x2 = x * x
    term = x * x2 / 6.0
    total = term
    k = 2
    while abs(term) > 0.5 * _EPS * abs(total):
        term *= -x2 / ((2 * k) * (2 * k + 1))
        total += term
        k += 1
    return total


@njit
def _sinh_minus_x(x):
    """``sinh(x) - x`` without cancellation for small ``x``."""
    if abs(x) >= 1.0:
        return math.sinh(x) - x
    x2 = x * x
    term = x * x2 / 6.0
    total = term
    k = 2
    while abs(term) > 0.5 * _EPS * abs(total):
        term *= x2 / ((2 * k) * (2 * k + 1))
        total += term
        k += 1
    return total


@njit
def _cubic_root(p, q):
    """Real root of ``t^3 + 3 p t - 2 q = 0`` for ``p >= 0, q >= 0``.

    Cardano's ``t = w - p / w`` with ``w^3 = q + sqrt(q^2 + p^3)`` cancels when
    ``q`` is small; multiplying through by ``w^3 - p^3 / w^3 = 2 q`` gives a
    form with positive terms only.
    """
    if q == 0.0:
        return 0.0
    s = math.hypot(q, p * math.sqrt(p))
    w = (q + s) ** (1.0 / 3.0)
    w2 = w * w
    return 2.0 * q / (w2 + p + p * p / w2)


@njit
def _one_plus_e_cos(e, f):
    """``1 + e cos f``, with the smaller rounding error of two forms.

    Where ``1 + e cos f`` is small, ``e cos f`` is near -1 and the direct form
    carries an absolute error ~eps.  The half-angle form
    ``(1 + e) cos^2(f/2) + (1 - e) sin^2(f/2)`` has positive terms for an
    ellipse (relative error ~eps, also at apocentre as e -> 1), and for a
    hyperbola its terms are ~(e^2 - 1) / (2 e) where they cancel, so it is
    the better form while (e^2 - 1) / e < 1.
    """
    if e > _HALF_ANGLE_MAX_E:
        return 1.0 + e * math.cos(f)
    c = math.cos(0.5 * f)
    s = math.sin(0.5 * f)
    return (1.0 + e) * (c * c) + (1.0 - e) * (s * s)


@njit
def _reduce_angle(x):
    """``(x_reduced, x - x_reduced)`` with ``x_reduced`` in ``[-pi, pi]``.

    ``fmod`` is exact, so the reduced angle carries no error from the number
    of revolutions, however large.
    """
    r = np.fmod(x, _TWO_PI)
    if r > _PI:
        r -= _TWO_PI
    elif r < -_PI:
        r += _TWO_PI
    return r, x - r


# --------------------------------------------------------------------------
# Kepler's equation
# --------------------------------------------------------------------------

@njit
def _newton_in_bracket(x, lo, hi, M, e, c, hyperbolic):
    """The root of ``c x + e (x - sin x) - M`` (``c = 1 - e``, an ellipse) or,
    with ``hyperbolic``, of ``c x + e (sinh x - x) - M`` (``c = e - 1``): a
    residual increasing and convex on the bracket ``[lo, hi]`` that holds the
    root, written so that both terms are positive (the direct forms cancel
    near 0 for ``e`` near 1).  Newton's method from ``x``, each step kept
    inside the bracket that the residual's sign narrows first: a step past
    ``hi`` stops there, one below ``lo`` bisects.  It stops when a step or
    the bracket is within :data:`_STEP_TOL` relative."""
    for _ in range(KEPLER_MAX_ITER):
        if hyperbolic:
            g = c * x + e * _sinh_minus_x(x) - M
        else:
            g = c * x + e * _x_minus_sin(x) - M
        if g == 0.0:
            break
        if g > 0.0:
            hi = x
        else:
            lo = x
        # the slope, 1 - e cos x or e cosh x - 1, without cancellation at x = 0
        if hyperbolic:
            s = math.sinh(0.5 * x)
        else:
            s = math.sin(0.5 * x)
        dg = c + 2.0 * e * s * s
        x_new = x - g / dg
        if x_new > hi:
            x_new = hi
        elif x_new < lo:
            x_new = 0.5 * (lo + hi)
        if abs(x_new - x) <= _STEP_TOL * x or hi - lo <= _STEP_TOL * hi:
            x = x_new
            break
        x = x_new
    return x


@njit
def _solve_elliptic_reduced(M, e):
    """Root of ``E - e sin E = M`` for ``0 <= M <= pi, 0 < e < 1``."""
    # On [0, pi] the residual g(E) is increasing and convex, and the root lies
    # in [M, M + e].  A Newton step from the left of the root lands to its
    # right, and from there the steps decrease monotonically to the root, so
    # clipping to the bracket keeps the iteration global.
    lo = M
    hi = min(M + e, _PI)
    if e < _CUBIC_STARTER_E:
        E = M + e * math.sin(M)
    else:
        # E - sin E <= E^3 / 6, so the root of (1 - e) E + e E^3 / 6 = M is a
        # lower bound, and exact as e -> 1 and M -> 0 where Newton from a
        # generic starter needs many steps.
        E = _cubic_root(2.0 * (1.0 - e) / e, 3.0 * M / e)
        lo = max(lo, E)
    E = min(max(E, lo), hi)
    return _newton_in_bracket(E, lo, hi, M, e, 1.0 - e, value(False))


@njit
def mean_to_eccentric(M, e):
    """Eccentric anomaly from mean anomaly: solve ``E - e sin E = M``.

    Parameters
    ----------
    M : float
        Mean anomaly [rad], any value; whole revolutions are kept.
    e : float
        Eccentricity, ``0 <= e < 1``.

    Returns
    -------
    E : float
        Eccentric anomaly [rad], in the same revolution as ``M``:
        ``|E - M| <= e``.  NaN if ``e`` is outside ``[0, 1)`` or ``M`` is not
        finite.

    Notes
    -----
    ``M`` is reduced exactly to ``[-pi, pi]`` with ``fmod``; by symmetry the
    equation is solved for ``|M|`` on ``[0, pi]``, where its residual is
    increasing and convex and the root lies in ``[M, M + e]``.  Newton's method
    starts from ``M + e sin M`` for ``e < 0.5`` and otherwise from the root of
    the cubic ``(1 - e) E + e E^3 / 6 = M`` (a lower bound that is exact in the
    singular corner ``e -> 1, M -> 0``), and its iterates are kept inside the
    bracket, with bisection as the last resort.  The residual is evaluated as
    ``(1 - e) E + e (E - sin E) - M`` with a series for ``E - sin E``, so the
    relative accuracy of ``E`` stays at a few ulps for ``e`` up to
    ``1 - 1e-6`` and beyond, also for tiny ``M``.

    References
    ----------
    Murray & Dermott (1999); Danby (1988).
    """
    if not (0.0 <= e < 1.0) or not math.isfinite(M):
        return math.nan
    Mr, turns = _reduce_angle(M)
    if e == 0.0:
        return M
    E = _solve_elliptic_reduced(abs(Mr), e)
    if Mr < 0.0:
        E = -E
    return turns + E


@njit
def eccentric_to_mean(E, e):
    """Mean anomaly ``M = E - e sin E`` [rad], without cancellation near ``E = 0``.

    Parameters
    ----------
    E : float
        Eccentric anomaly [rad].
    e : float
        Eccentricity, ``0 <= e < 1``.

    Returns
    -------
    M : float
        Mean anomaly [rad], same revolution as ``E``.
    """
    Er, turns = _reduce_angle(E)
    return turns + (1.0 - e) * Er + e * _x_minus_sin(Er)


@njit
def _solve_hyperbolic_positive(M, e):
    """Root of ``e sinh F - F = M`` for ``M >= 0, e > 1``."""
    # For F >= 0 the residual is increasing and convex; the same argument as
    # in the elliptic case makes clipped Newton global.  Bounds:
    #   e sinh F - F <= e sinh F               ->  F >= asinh(M / e)
    #   e sinh F - F >= (e - 1) sinh F         ->  F <= asinh(M / (e - 1))
    #   e sinh F - F >= (e - 1) F + e F^3 / 6  ->  F <= cubic root
    em1 = e - 1.0
    lo = math.asinh(M / e)
    # One fixed-point pass F = asinh((M + F) / e) from a lower bound stays a
    # lower bound and is within O(log M / M) of the root for large M.
    lo = math.asinh((M + lo) / e)
    F_cubic = _cubic_root(2.0 * em1 / e, 3.0 * M / e)
    hi = min(math.asinh(M / em1), F_cubic)
    # The cubic is exact for small F (e -> 1, M -> 0), the asinh pass for
    # large F.
    F = F_cubic if F_cubic < 1.0 else lo
    F = min(max(F, lo), hi)
    return _newton_in_bracket(F, lo, hi, M, e, em1, value(True))


@njit
def mean_to_hyperbolic(M, e):
    """Hyperbolic anomaly from mean anomaly: solve ``e sinh F - F = M``.

    Parameters
    ----------
    M : float
        Hyperbolic mean anomaly [rad], any finite value.
    e : float
        Eccentricity, ``e > 1``.

    Returns
    -------
    F : float
        Hyperbolic anomaly, with the sign of ``M``.  NaN if ``e <= 1`` or ``M``
        is not finite.

    Notes
    -----
    Solved for ``|M|``, where the residual is increasing and convex.  The
    root is bracketed by ``asinh((M + asinh(M/e)) / e)`` below and by
    ``min(asinh(M / (e - 1)), cubic)`` above, where the cubic is the root of
    ``(e - 1) F + e F^3 / 6 = M``.  Newton starts from the cubic when that is
    below 1 (near-parabolic, small ``M``) and from the lower asinh bound
    otherwise (large ``|M|``), and is kept inside the bracket.  The residual is
    evaluated as ``(e - 1) F + e (sinh F - F) - M``, accurate for ``e`` close
    to 1.

    References
    ----------
    Danby (1988); Battin (1999); Fukushima (1997).
    """
    if not (e > 1.0) or not math.isfinite(M) or not math.isfinite(e):
        return math.nan
    F = _solve_hyperbolic_positive(abs(M), e)
    return -F if M < 0.0 else F


@njit
def hyperbolic_to_mean(F, e):
    """Mean anomaly ``M = e sinh F - F``, without cancellation near ``F = 0``.

    Parameters
    ----------
    F : float
        Hyperbolic anomaly.
    e : float
        Eccentricity, ``e > 1``.

    Returns
    -------
    M : float
    """
    return (e - 1.0) * F + e * _sinh_minus_x(F)


@njit
def mean_to_parabolic(M):
    """``D = tan(f / 2)`` from Barker's equation ``D + D^3 / 3 = M``.

    Parameters
    ----------
    M : float
        Parabolic mean anomaly ``sqrt(mu / (2 q^3)) (t - tau)``.

    Returns
    -------
    D : float

    References
    ----------
    Battin (1999); Danby (1988).
    """
    if not math.isfinite(M):
        return math.nan
    # D^3 + 3 D - 3 M = 0 in closed form, then one Newton step to remove the
    # few ulps lost in the cube root.
    D = _cubic_root(1.0, 1.5 * abs(M))
    D -= (D + D * D * D / 3.0 - abs(M)) / (1.0 + D * D)
    return -D if M < 0.0 else D


@njit
def true_from_mean(M, e):
    """True anomaly from mean anomaly, for any conic.

    Parameters
    ----------
    M : float
        Mean anomaly [rad]: elliptic ``E - e sin E``, hyperbolic
        ``e sinh F - F``, parabolic (``e == 1`` exactly) Barker's
        ``D + D^3 / 3`` (see the module notes).
    e : float
        Eccentricity, ``e >= 0``.

    Returns
    -------
    f : float
        True anomaly [rad].  Elliptic: in the same revolution as ``M``
        (``|f - M| < pi``), so that the map is continuous and
        :func:`mean_from_true` inverts it.  Hyperbolic and parabolic: in
        ``(-f_inf, f_inf)`` with ``f_inf = arccos(-1/e)``.  NaN for ``e < 0`` or
        non-finite input.

    References
    ----------
    Murray & Dermott (1999); Danby (1988).
    """
    if not (e >= 0.0) or not math.isfinite(M) or not math.isfinite(e):
        return math.nan
    if e < 1.0:
        Mr, turns = _reduce_angle(M)
        E = mean_to_eccentric(Mr, e)
        # Half-angle form: well conditioned for all E and e < 1.
        f = 2.0 * math.atan2(math.sqrt(1.0 + e) * math.sin(0.5 * E),
                             math.sqrt(1.0 - e) * math.cos(0.5 * E))
        return turns + f
    if e > 1.0:
        F = mean_to_hyperbolic(M, e)
        return 2.0 * math.atan(math.sqrt((e + 1.0) / (e - 1.0)) * math.tanh(0.5 * F))
    return 2.0 * math.atan(mean_to_parabolic(M))


@njit
def mean_from_true(f, e):
    """Mean anomaly from true anomaly, for any conic.

    Parameters
    ----------
    f : float
        True anomaly [rad].
    e : float
        Eccentricity, ``e >= 0``.

    Returns
    -------
    M : float
        Mean anomaly [rad] in the convention of :func:`true_from_mean`.
        Elliptic: in the same revolution as ``f``.  Hyperbolic and parabolic:
        ``f`` is first reduced to ``[-pi, pi]``; NaN if it lies on or beyond
        the asymptote (``1 + e cos f <= 0``).

    References
    ----------
    Murray & Dermott (1999); Danby (1988).
    """
    if not (e >= 0.0) or not math.isfinite(f) or not math.isfinite(e):
        return math.nan
    fr, turns = _reduce_angle(f)
    if e < 1.0:
        E = 2.0 * math.atan2(math.sqrt(1.0 - e) * math.sin(0.5 * fr),
                             math.sqrt(1.0 + e) * math.cos(0.5 * fr))
        return turns + (1.0 - e) * E + e * _x_minus_sin(E)
    denom = _one_plus_e_cos(e, fr)
    if not (denom > 0.0):
        return math.nan
    if e > 1.0:
        # sinh F = sqrt(e^2 - 1) sin f / (1 + e cos f); finite everywhere
        # inside the asymptotes, unlike the tan(f/2) form.
        F = math.asinh(math.sqrt((e - 1.0) * (e + 1.0)) * math.sin(fr) / denom)
        return hyperbolic_to_mean(F, e)
    D = math.tan(0.5 * fr)
    return D + D * D * D / 3.0
