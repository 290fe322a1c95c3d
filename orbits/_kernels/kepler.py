"""Two-body orbits: Kepler's equation and elements <-> Cartesian state.

Every function works on plain float64 scalars and C-contiguous float64 arrays
in one consistent unit system; the gravitational parameter ``mu = G (m1 + m2)``
is passed in.  Angles are in radians.

Element set
-----------
``a, e, inc, Omega, omega, f``: semi-major axis, eccentricity, inclination,
longitude of the ascending node, argument of pericentre and true anomaly.
Elliptic orbits have ``0 <= e < 1`` and ``a > 0``; hyperbolic orbits have
``e > 1`` and ``a < 0``, so that the semi-latus rectum ``p = a (1 - e^2)`` is
positive for both.  A parabola (``e == 1``) has no finite ``a`` and cannot be
built from this element set; it can be read from a state (see
:func:`state_to_elements`).

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

Status codes
------------
Kernels that can fail return one of the ``STATUS_*`` integers below and fill
their outputs with NaN (except for :data:`STATUS_PARABOLIC_ORBIT`, which is a
warning: the outputs are filled).  :func:`describe_status` turns a code into a
sentence for the exception the Python layer raises.

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

from ._jit import fma, njit

__all__ = [
    "STATUS_OK",
    "STATUS_BEYOND_ASYMPTOTE",
    "STATUS_INVALID_ELEMENTS",
    "STATUS_INVALID_STATE",
    "STATUS_RADIAL_ORBIT",
    "STATUS_PARABOLIC_ORBIT",
    "STATUS_BAD_SHAPE",
    "KEPLER_MAX_ITER",
    "CIRCULAR_TOL",
    "PLANAR_TOL",
    "RADIAL_TOL",
    "describe_status",
    "mean_to_eccentric",
    "eccentric_to_mean",
    "mean_to_hyperbolic",
    "hyperbolic_to_mean",
    "mean_to_parabolic",
    "true_from_mean",
    "mean_from_true",
    "elements_to_state",
    "state_to_elements",
    "elements_to_state_many",
    "state_to_elements_many",
    "stumpff",
    "stumpff_lane",
    "kepler_drift",
    "short_step_anomaly",
    "short_start",
    "quartic_step",
    "f_and_g",
    "dot3",
    "radius",
    "advanced",
    "advanced_state",
    "advance_by_anomaly",
    "DRIFT_MAX_ITER",
    "bracketed_anomaly",
    "kepler_drift_tangent",
]

STATUS_OK = 0
STATUS_BEYOND_ASYMPTOTE = 1   # hyperbola with 1 + e cos f <= 0: no such point
STATUS_INVALID_ELEMENTS = 2   # non-finite, mu <= 0, e < 0, e == 1, or sign(a) wrong for e
STATUS_INVALID_STATE = 3      # non-finite, mu <= 0, or body at the primary (r == 0)
STATUS_RADIAL_ORBIT = 4       # zero angular momentum: no orbital plane
STATUS_PARABOLIC_ORBIT = 5    # energy zero (or of the wrong sign for e) within rounding
STATUS_BAD_SHAPE = 6          # an array argument is too short

_MESSAGES = {
    STATUS_OK: "ok",
    STATUS_BEYOND_ASYMPTOTE: "the true anomaly lies beyond the asymptote of the "
                             "hyperbola (1 + e cos f <= 0)",
    STATUS_INVALID_ELEMENTS: "invalid orbital elements: they must be finite with mu > 0, "
                             "e >= 0, e != 1, a > 0 for e < 1 and a < 0 for e > 1",
    STATUS_INVALID_STATE: "invalid state: it must be finite with mu > 0 and the body "
                          "away from its primary",
    STATUS_RADIAL_ORBIT: "the orbit is radial (zero angular momentum), so its plane "
                         "and orientation are undefined",
    STATUS_PARABOLIC_ORBIT: "the orbit is parabolic to within rounding (zero energy); "
                            "its semi-major axis is infinite or meaningless",
    STATUS_BAD_SHAPE: "an array argument is too short",
}

# Bounded iteration count for the Kepler solvers.  The starters below need at
# most 6 iterations over e in [0, 1 - 1e-6] and e in (1, 1e8]; the rest is
# headroom for the bisection safeguard, which halves the bracket each time.
KEPLER_MAX_ITER = 100

# Below this eccentricity the pericentre is not a usable reference: the
# eccentricity vector is a difference of unit-size vectors carrying absolute
# rounding errors of a few 1e-16, so its direction is uncertain by > 1e-2 rad.
CIRCULAR_TOL = 1e-14

# An orbit is planar when the node vector (the x, y part of the angular
# momentum) is at the rounding level of the cross product r x v, whose
# components carry absolute errors of a few eps * |r| |v|.  inc = pi stored in
# floating point gives sin(inc) ~ 1.2e-16, below this.
PLANAR_TOL = 8.0 * 2.220446049250313e-16

# Likewise an angular momentum at the rounding level of |r| |v| has no
# direction: the orbit is radial.
RADIAL_TOL = 8.0 * 2.220446049250313e-16

# Switch from the starter E0 = M + e sin M (error O(e^2)) to the cubic
# starter, which is exact in the limit e -> 1, M -> 0.  Measured: at most
# 5 Newton steps on either side of 0.5.
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


def describe_status(status):
    """Sentence describing a status code returned by the kernels in this module.

    Parameters
    ----------
    status : int

    Returns
    -------
    str
    """
    return _MESSAGES.get(int(status), f"unknown status code {int(status)}")


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
    one_minus_e = 1.0 - e
    for _ in range(KEPLER_MAX_ITER):
        # Split E - e sin E = (1 - e) E + e (E - sin E) so that both terms are
        # positive: the direct form cancels near E = 0, e = 1.
        g = one_minus_e * E + e * _x_minus_sin(E) - M
        if g == 0.0:
            break
        if g > 0.0:
            hi = E
        else:
            lo = E
        # 1 - e cos E written without cancellation at E = 0, e = 1.
        s = math.sin(0.5 * E)
        dg = one_minus_e + 2.0 * e * s * s
        E_new = E - g / dg
        if E_new > hi:
            E_new = hi
        elif E_new < lo:
            E_new = 0.5 * (lo + hi)
        if abs(E_new - E) <= _STEP_TOL * E or hi - lo <= _STEP_TOL * hi:
            E = E_new
            break
        E = E_new
    return E


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
    for _ in range(KEPLER_MAX_ITER):
        g = em1 * F + e * _sinh_minus_x(F) - M
        if g == 0.0:
            break
        if g > 0.0:
            hi = F
        else:
            lo = F
        s = math.sinh(0.5 * F)
        dg = em1 + 2.0 * e * s * s          # e cosh F - 1 without cancellation
        F_new = F - g / dg
        if F_new > hi:
            F_new = hi
        elif F_new < lo:
            F_new = 0.5 * (lo + hi)
        if abs(F_new - F) <= _STEP_TOL * F or hi - lo <= _STEP_TOL * hi:
            F = F_new
            break
        F = F_new
    return F


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


# --------------------------------------------------------------------------
# Elements <-> state
# --------------------------------------------------------------------------

@njit
def _fill_nan(arr, n):
    for k in range(n):
        arr[k] = math.nan


@njit
def elements_to_state(mu, a, e, inc, Omega, omega, f, out_pos, out_vel):
    """Position and velocity of a body relative to its primary, from elements.

    Parameters
    ----------
    mu : float
        ``G (m1 + m2)`` [length^3 / time^2], > 0.
    a : float
        Semi-major axis [length]; > 0 for ``e < 1``, < 0 for ``e > 1``.
    e : float
        Eccentricity, ``>= 0`` and ``!= 1``.
    inc, Omega, omega : float
        Inclination, longitude of the ascending node, argument of pericentre
        [rad].
    f : float
        True anomaly [rad].
    out_pos : ndarray, shape (3,)
        Written: relative position [length].
    out_vel : ndarray, shape (3,)
        Written: relative velocity [length / time].

    Returns
    -------
    status : int
        :data:`STATUS_OK`; :data:`STATUS_BEYOND_ASYMPTOTE` if
        ``1 + e cos f <= 0`` on a hyperbola; :data:`STATUS_INVALID_ELEMENTS`
        for non-finite values, ``mu <= 0``, ``e < 0``, ``e == 1`` or a sign of
        ``a`` that does not match ``e``; :data:`STATUS_BAD_SHAPE`.  The
        outputs are NaN unless the status is OK.

    Notes
    -----
    With ``p = a (1 - e^2)`` and ``r = p / (1 + e cos f)``, the perifocal
    state is ``r (cos f, sin f)`` and ``sqrt(mu / p) (-sin f, e + cos f)``; it
    is rotated by ``R_z(Omega) R_x(inc) R_z(omega)``, whose first two columns
    are the unit vectors P (to pericentre) and Q (90 degrees ahead in the
    direction of motion).

    References
    ----------
    Murray & Dermott (1999); Danby (1988).
    """
    if out_pos.shape[0] < 3 or out_vel.shape[0] < 3:
        return STATUS_BAD_SHAPE
    finite = (math.isfinite(mu) and math.isfinite(a) and math.isfinite(e)
              and math.isfinite(inc) and math.isfinite(Omega)
              and math.isfinite(omega) and math.isfinite(f))
    if (not finite or not (mu > 0.0) or not (e >= 0.0) or e == 1.0
            or (e < 1.0 and not (a > 0.0)) or (e > 1.0 and not (a < 0.0))):
        _fill_nan(out_pos, 3)
        _fill_nan(out_vel, 3)
        return STATUS_INVALID_ELEMENTS
    cf = math.cos(f)
    sf = math.sin(f)
    denom = _one_plus_e_cos(e, f)
    if not (denom > 0.0):
        _fill_nan(out_pos, 3)
        _fill_nan(out_vel, 3)
        return STATUS_BEYOND_ASYMPTOTE
    # (1 - e)(1 + e) rather than 1 - e^2: exact for e near 1.
    p = a * ((1.0 - e) * (1.0 + e))
    r = p / denom
    vfac = math.sqrt(mu / p)
    xp = r * cf
    yp = r * sf
    vxp = -vfac * sf
    vyp = vfac * (e + cf)

    cO = math.cos(Omega)
    sO = math.sin(Omega)
    co = math.cos(omega)
    so = math.sin(omega)
    ci = math.cos(inc)
    si = math.sin(inc)
    Px = cO * co - sO * so * ci
    Py = sO * co + cO * so * ci
    Pz = so * si
    Qx = -cO * so - sO * co * ci
    Qy = -sO * so + cO * co * ci
    Qz = co * si

    out_pos[0] = xp * Px + yp * Qx
    out_pos[1] = xp * Py + yp * Qy
    out_pos[2] = xp * Pz + yp * Qz
    out_vel[0] = vxp * Px + vyp * Qx
    out_vel[1] = vxp * Py + vyp * Qy
    out_vel[2] = vxp * Pz + vyp * Qz
    return STATUS_OK


@njit
def _wrap_positive(x):
    """Angle in ``[0, 2 pi)``."""
    y = np.fmod(x, _TWO_PI)
    if y < 0.0:
        y += _TWO_PI
    # fmod of a tiny negative number plus 2 pi can round up to 2 pi.
    if y >= _TWO_PI:
        y = 0.0
    return y


@njit
def state_to_elements(mu, pos, vel, out):
    """Osculating elements of a body about its primary, from its relative state.

    Parameters
    ----------
    mu : float
        ``G (m1 + m2)`` [length^3 / time^2], > 0.
    pos : ndarray, shape (3,)
        Relative position [length].
    vel : ndarray, shape (3,)
        Relative velocity [length / time].
    out : ndarray, shape (7,) (or longer; only the first 7 are written)
        Written: ``a, e, inc, Omega, omega, f, M``.

        * ``a`` [length]: ``1 / (2/r - v^2/mu)``; negative for hyperbolae.
        * ``e``: length of the eccentricity vector.
        * ``inc`` in ``[0, pi]``; ``inc > pi/2`` is a retrograde orbit.
        * ``Omega``, ``omega`` in ``[0, 2 pi)``.
        * ``f``, ``M`` in ``[-pi, pi]`` (negative before pericentre); ``M`` is
          the mean anomaly of :func:`mean_from_true` (hyperbolic
          ``e sinh F - F``; Barker's form when the status is
          :data:`STATUS_PARABOLIC_ORBIT`).

    Returns
    -------
    status : int
        :data:`STATUS_OK`; :data:`STATUS_INVALID_STATE` (non-finite input,
        ``mu <= 0`` or ``r == 0``: all outputs NaN); :data:`STATUS_RADIAL_ORBIT`
        (angular momentum at rounding level: ``a`` is written, ``e = 1``, the
        angles are NaN); :data:`STATUS_PARABOLIC_ORBIT` (the energy is zero or
        its sign disagrees with ``e < 1`` within rounding: all outputs are
        written, ``a`` is ``+-inf`` or meaningless and ``M`` is Barker's
        ``D + D^3/3``); :data:`STATUS_BAD_SHAPE`.

    Notes
    -----
    Degenerate conventions, chosen so that :func:`elements_to_state`
    reproduces the state:

    * planar (``sin inc`` at rounding level, :data:`PLANAR_TOL`):
      ``Omega = 0``, the node line is the x axis and ``omega`` is measured
      from it in the direction of motion (so ``omega`` is the longitude of
      pericentre for prograde orbits and minus it for retrograde ones);
    * circular (``e <= CIRCULAR_TOL``): ``omega = 0`` and ``f`` is the
      argument of latitude, measured from the ascending node (from the x axis
      if also planar);
    * all angles come from ``atan2`` of two orthogonal projections, never
      ``acos``, so they keep full accuracy near 0 and pi.

    The eccentricity vector is ``(v x h) / mu - r / |r|``; the true anomaly is
    ``atan2(|h| (r . v), |h|^2 - mu |r|)`` (from ``e cos f = p/r - 1`` and
    ``e sin f = |h| (r . v) / (mu r)``); the argument of latitude ``u`` is the
    angle from the node to ``r`` in the orbital plane, and ``omega = u - f``.

    References
    ----------
    Murray & Dermott (1999); Danby (1988).
    """
    if pos.shape[0] < 3 or vel.shape[0] < 3 or out.shape[0] < 7:
        return STATUS_BAD_SHAPE
    x = pos[0]
    y = pos[1]
    z = pos[2]
    vx = vel[0]
    vy = vel[1]
    vz = vel[2]
    r = math.sqrt(x * x + y * y + z * z)
    v2 = vx * vx + vy * vy + vz * vz
    if (not (mu > 0.0) or not math.isfinite(mu) or not math.isfinite(r)
            or not math.isfinite(v2) or r == 0.0):
        _fill_nan(out, 7)
        return STATUS_INVALID_STATE
    v = math.sqrt(v2)
    alpha = 2.0 / r - v2 / mu          # 1 / a (vis-viva)

    hx = y * vz - z * vy
    hy = z * vx - x * vz
    hz = x * vy - y * vx
    h = math.sqrt(hx * hx + hy * hy + hz * hz)
    if h <= RADIAL_TOL * r * v:
        _fill_nan(out, 7)
        out[0] = 1.0 / alpha
        out[1] = 1.0
        return STATUS_RADIAL_ORBIT

    ex = (vy * hz - vz * hy) / mu - x / r
    ey = (vz * hx - vx * hz) / mu - y / r
    ez = (vx * hy - vy * hx) / mu - z / r
    e = math.sqrt(ex * ex + ey * ey + ez * ez)

    node = math.hypot(hx, hy)
    inc = math.atan2(node, hz)
    if node <= PLANAR_TOL * r * v:
        Omega = 0.0
        nx = 1.0
        ny = 0.0
    else:
        Omega = _wrap_positive(math.atan2(hx, -hy))
        nx = -hy / node
        ny = hx / node
    # m = h_hat x n_hat: in the orbital plane, 90 degrees ahead of the node
    # in the direction of motion.
    mx = -hz * ny / h
    my = hz * nx / h
    mz = (hx * ny - hy * nx) / h
    u = math.atan2(x * mx + y * my + z * mz, x * nx + y * ny)

    rv = x * vx + y * vy + z * vz
    if e <= CIRCULAR_TOL:
        f = u
        omega = 0.0
    else:
        f = math.atan2(h * rv, h * h - mu * r)
        omega = _wrap_positive(u - f)

    status = STATUS_OK
    if alpha == 0.0 or (alpha > 0.0) != (e < 1.0):
        status = STATUS_PARABOLIC_ORBIT
        D = math.tan(0.5 * f)
        M = D + D * D * D / 3.0
    else:
        M = mean_from_true(f, e)

    out[0] = 1.0 / alpha
    out[1] = e
    out[2] = inc
    out[3] = Omega
    out[4] = omega
    out[5] = f
    out[6] = M
    return status


@njit
def elements_to_state_many(mu, elems, pos, vel, status):
    """:func:`elements_to_state` over many bodies.

    Parameters
    ----------
    mu : ndarray, shape (n,)
        ``G (m_primary + m_i)`` for each body.
    elems : ndarray, shape (n, 6)
        Rows ``a, e, inc, Omega, omega, f``.
    pos, vel : ndarray, shape (n, 3)
        Written: relative positions and velocities.
    status : ndarray of int64, shape (n,)
        Written: each body's status.

    Returns
    -------
    int
        :data:`STATUS_OK` if every body succeeded, otherwise the first
        non-zero status (``status`` says which rows failed).
    """
    n = mu.shape[0]
    if (elems.shape[0] < n or elems.shape[1] < 6 or pos.shape[0] < n
            or vel.shape[0] < n or status.shape[0] < n):
        return STATUS_BAD_SHAPE
    first = STATUS_OK
    for i in range(n):
        s = elements_to_state(mu[i], elems[i, 0], elems[i, 1], elems[i, 2],
                              elems[i, 3], elems[i, 4], elems[i, 5],
                              pos[i], vel[i])
        status[i] = s
        if first == STATUS_OK:
            first = s
    return first


@njit
def state_to_elements_many(mu, pos, vel, out, status):
    """:func:`state_to_elements` over many bodies.

    Parameters
    ----------
    mu : ndarray, shape (n,)
        ``G (m_primary + m_i)`` for each body.
    pos, vel : ndarray, shape (n, 3)
        Relative positions and velocities.
    out : ndarray, shape (n, 7)
        Written: rows ``a, e, inc, Omega, omega, f, M``.
    status : ndarray of int64, shape (n,)
        Written: each body's status.

    Returns
    -------
    int
        :data:`STATUS_OK` if every body succeeded, otherwise the first
        non-zero status.
    """
    n = mu.shape[0]
    if (pos.shape[0] < n or vel.shape[0] < n or out.shape[0] < n
            or status.shape[0] < n):
        return STATUS_BAD_SHAPE
    first = STATUS_OK
    for i in range(n):
        s = state_to_elements(mu[i], pos[i], vel[i], out[i])
        status[i] = s
        if first == STATUS_OK:
            first = s
    return first


# --------------------------------------------------------------------------
# Kepler drift in universal variables
# --------------------------------------------------------------------------

# Stumpff functions: |z| above this is evaluated from cos/sin (cosh/sinh)
# directly, where 1 - cos sqrt(z) and 1 - sin sqrt(z) / sqrt(z) lose at most
# a bit to cancellation; below it from the series after quartering z to below
# _STUMPFF_SERIES_Z and doubling back.
_STUMPFF_DIRECT_Z = 4.0
# |z| < 0.1: the series below to z^6 is exact to 0.1^7 / 17! ~ 3e-22.
_STUMPFF_SERIES_Z = 0.1
# |z| < 2e-3 (a step of up to 0.045 rad of eccentric anomaly: the steps of a
# planetary integration): four terms suffice, the first omitted one being
# (2e-3)^4 / 10! ~ 4e-18 against c2 = 1/2.
_STUMPFF_SHORT_Z = 2e-3
_SIXTH = 1.0 / 6.0

# Bounded iterations of the universal Kepler equation: Danby's quartic
# iteration from the starters below needs 2-4 on the steps of a planetary
# integration and at most ~10 at e = 1 +- 1e-12 or 1e6 orbital periods; the
# rest is room for the bisection safeguard.
DRIFT_MAX_ITER = 200

# stop when a correction is below this many ulps of the iterate
_DRIFT_STEP_TOL = 2.0 * _EPS

# The short-step path of the drift (the steps of a planetary integration):
# taken when |dt| |v0| < _SHORT_STEP r0 and the starter spans |beta s^2| <=
# _SHORT_STEP_Z (an eccentric anomaly of at most 1 rad), else the bracketed
# solver.  From the third-order Taylor starter Danby's quartic iteration runs
# without a bracket; a correction d with |d| <= _SHORT_STEP_TOL |s| leaves an
# error ~(d/s)^4 <= 1e-18 relative, below rounding, so s + d is taken as the
# root.  After _SHORT_STEP_ITER iterations without that the bracketed solver
# starts again from the beginning (it has never been needed on the
# benchmark scenes, where the starter is good to 1e-6 and one iteration does).
_SHORT_STEP = 0.5
_SHORT_STEP_Z = 1.0
_SHORT_STEP_TOL = 3e-5
_SHORT_STEP_ITER = 3


@njit(inline="always")
def _stumpff_series(z):
    """Stumpff functions from their series, for ``|z| <= _STUMPFF_SERIES_Z``."""
    # c2 = 1/2! - z/4! + z^2/6! - ..., c3 = 1/3! - z/5! + z^2/7! - ... (Horner)
    c2 = (1.0 / 2 - z * (1.0 / 24 - z * (1.0 / 720 - z * (1.0 / 40320 - z * (
        1.0 / 3628800 - z * (1.0 / 479001600 - z * (1.0 / 87178291200)))))))
    c3 = (1.0 / 6 - z * (1.0 / 120 - z * (1.0 / 5040 - z * (1.0 / 362880 - z * (
        1.0 / 39916800 - z * (1.0 / 6227020800 - z * (1.0 / 1307674368000)))))))
    return 1.0 - z * c2, 1.0 - z * c3, c2, c3


@njit(inline="always")
def _stumpff_inline(z):
    """:func:`stumpff`, with its most common case (``|z|`` small) inlined."""
    if -_STUMPFF_SERIES_Z <= z <= _STUMPFF_SERIES_Z:
        return _stumpff_series(z)
    return stumpff(z)


@njit(inline="always")
def _stumpff_short(z):
    """:func:`stumpff` for the short steps of a planetary integration: for
    ``|z| <= _STUMPFF_SHORT_Z`` four terms of each series, in Estrin's form
    (two independent halves, for a shorter chain of dependent operations)."""
    if -_STUMPFF_SHORT_Z <= z <= _STUMPFF_SHORT_Z:
        return _estrin(z)
    return _stumpff_inline(z)


@njit
def stumpff(z):
    """Stumpff functions ``c0(z), c1(z), c2(z), c3(z)``.

    Parameters
    ----------
    z : float
        Argument (``beta s^2`` in the universal Kepler equation); any sign.

    Returns
    -------
    c0, c1, c2, c3 : float
        ``c0 = cos sqrt(z)``, ``c1 = sin sqrt(z) / sqrt(z)``,
        ``c2 = (1 - c0) / z``, ``c3 = (1 - c1) / z`` (hyperbolic functions of
        ``sqrt(-z)`` for ``z < 0``), continuous through ``z = 0`` where they
        are ``1, 1, 1/2, 1/6``.

    Notes
    -----
    For ``|z| <= 4`` the argument is quartered until it is below 0.1, ``c2``
    and ``c3`` are summed from their series ``c_k(z) = sum_j (-z)^j /
    (k + 2j)!``, and the quarter-argument identities
    ``c2(4z) = c1(z)^2 / 2``, ``c3(4z) = (c2(z) + c0(z) c3(z)) / 4`` bring
    them back, with ``c0 = 1 - z c2`` and ``c1 = 1 - z c3`` at every level.

    References
    ----------
    Stumpff, K. 1959, *Himmelsmechanik*, Band I, VEB Deutscher Verlag der
    Wissenschaften; Danby, J. M. A. 1988, *Fundamentals of Celestial
    Mechanics*, 2nd ed., sect. 6.9.
    """
    if z > _STUMPFF_DIRECT_Z:
        sz = math.sqrt(z)
        c0 = math.cos(sz)
        c1 = math.sin(sz) / sz
        return c0, c1, (1.0 - c0) / z, (1.0 - c1) / z
    if z < -_STUMPFF_DIRECT_Z:
        sz = math.sqrt(-z)
        c0 = math.cosh(sz)
        c1 = math.sinh(sz) / sz
        return c0, c1, (1.0 - c0) / z, (1.0 - c1) / z
    n = 0
    while abs(z) > _STUMPFF_SERIES_Z:
        z *= 0.25
        n += 1
    c0, c1, c2, c3 = _stumpff_series(z)
    for _ in range(n):
        c3 = 0.25 * (c2 + c0 * c3)
        c2 = 0.5 * c1 * c1
        z *= 4.0
        c0 = 1.0 - z * c2
        c1 = 1.0 - z * c3
    return c0, c1, c2, c3


# quarterings of a Stumpff argument that stumpff_lane takes: |z| <= 4 (above
# it stumpff uses the trigonometric form directly) needs at most 3, as
# 4 / 4^3 < _STUMPFF_SERIES_Z
_LANE_QUARTERINGS = 3


@njit(inline="always")
def _estrin(z):
    # _stumpff_short's four terms of each series, in Estrin's form with fused
    # multiply-adds: c2 = (1/2 - z/4!) + z^2 (1/6! - z/8!), c3 = (1/3! -
    # z/5!) + z^2 (1/7! - z/9!), c0 = 1 - z c2, c1 = 1 - z c3
    z2 = z * z
    c2 = fma(z2, fma(-z, 1.0 / 40320, 1.0 / 720), fma(-z, 1.0 / 24, 0.5))
    c3 = fma(z2, fma(-z, 1.0 / 362880, 1.0 / 5040), fma(-z, 1.0 / 120, 1.0 / 6))
    return fma(-z, c2, 1.0), fma(-z, c3, 1.0), c2, c3


@njit(inline="always")
def stumpff_lane(z, general):
    """:func:`_stumpff_short` without a branch, for loops that LLVM turns into
    vector instructions (one orbit per lane), and whether ``z`` is in its
    domain (``|z| <= 4``; beyond it the caller must take the scalar path).
    ``general`` (the same for every lane) False: only the four-term series,
    valid when every lane has ``|z| <= _STUMPFF_SHORT_Z``.  Bit for bit
    :func:`_stumpff_short` inside the domain: the same operations, the
    branches of :func:`stumpff` taken as masked selects."""
    e0, e1, e2, e3 = _estrin(z)
    if not general:
        return e0, e1, e2, e3, True
    # stumpff: quarter until |z| <= 0.1 (masked), the seven-term series
    # there, and the quarter-argument identities back
    zq = z
    n = 0
    for _ in range(_LANE_QUARTERINGS):
        big = abs(zq) > _STUMPFF_SERIES_Z
        zq = zq * 0.25 if big else zq
        n += 1 if big else 0
    c2 = (1.0 / 2 - zq * (1.0 / 24 - zq * (1.0 / 720 - zq * (1.0 / 40320 - zq * (
        1.0 / 3628800 - zq * (1.0 / 479001600 - zq * (1.0 / 87178291200)))))))
    c3 = (1.0 / 6 - zq * (1.0 / 120 - zq * (1.0 / 5040 - zq * (1.0 / 362880 - zq * (
        1.0 / 39916800 - zq * (1.0 / 6227020800 - zq * (1.0 / 1307674368000)))))))
    c0 = 1.0 - zq * c2
    c1 = 1.0 - zq * c3
    for k in range(_LANE_QUARTERINGS):
        up = k < n
        d3 = 0.25 * (c2 + c0 * c3)
        d2 = 0.5 * c1 * c1
        zu = zq * 4.0
        c3 = d3 if up else c3
        c2 = d2 if up else c2
        zq = zu if up else zq
        d0 = 1.0 - zq * c2
        d1 = 1.0 - zq * c3
        c0 = d0 if up else c0
        c1 = d1 if up else c1
    short = -_STUMPFF_SHORT_Z <= z <= _STUMPFF_SHORT_Z
    ok = not (z > _STUMPFF_DIRECT_Z or z < -_STUMPFF_DIRECT_Z)
    if short:
        return e0, e1, e2, e3, ok
    return c0, c1, c2, c3, ok


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
    """The start's invariants and the third-order Taylor starter of the
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
    w = dt * ir0
    e = eta * ir0
    # s = w (1 + w (-e / 2 + w (3 e^2 - zeta / r0) / 6))
    s = w * fma(w, fma(w, fma(3.0 * e, e, -zeta * ir0) * _SIXTH, -0.5 * e), 1.0)
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
    < r0 / 2`` and less than a radian of eccentric anomaly, the root ``s``
    of the universal Kepler equation from the third-order Taylor starter
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
def _advance_row(mu, x, v, i, s, r0, ir0, beta, zeta):
    # advance_by_anomaly, returning besides whether it advanced the row's
    # start and what the drift's tangent reuses (_short_coefficients')
    x0 = x[i, 0]
    y0 = x[i, 1]
    z0 = x[i, 2]
    vx0 = v[i, 0]
    vy0 = v[i, 1]
    vz0 = v[i, 2]
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
        :data:`STATUS_OK`, or :data:`STATUS_INVALID_STATE` (non-finite input,
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
    derivatives).  A step short against the orbit (``|dt| |v0| < r0 / 2``
    and less than a radian of eccentric anomaly) starts from the Taylor
    series ::

        s = w (1 - w eta / (2 r0) + w^2 (3 eta^2 / r0^2 - zeta / r0) / 6),  w = dt / r0

    (``ds/dt = 1/r``, ``d^2s/dt^2 = -eta / r^3``, ``d^3s/dt^3 = 3 eta^2 /
    r^5 - zeta / r^4``), whose error is of fourth order in the step, and
    stops as soon as a correction is below ``3e-5`` of ``s``, which leaves
    ``(3e-5)^4`` after it: one iteration and two evaluations of the
    Stumpff functions on the steps of a planetary integration.  Any other
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
        return STATUS_OK
    return _kepler_drift_bracketed(mu, x, v, i, dt)


@njit
def _kepler_drift_bracketed(mu, x, v, i, dt):
    """:func:`kepler_drift` by the bracketed solver, for any step: the anomaly
    from :func:`bracketed_anomaly`, then f and g from the universal functions
    there (the same values its last iteration tested)."""
    x0 = x[i, 0]
    y0 = x[i, 1]
    z0 = x[i, 2]
    vx0 = v[i, 0]
    vy0 = v[i, 1]
    vz0 = v[i, 2]
    s, turns = bracketed_anomaly(mu, x0, y0, z0, vx0, vy0, vz0, dt)
    if not (s == s):
        for d in range(3):
            x[i, d] = math.nan
            v[i, d] = math.nan
        return STATUS_INVALID_STATE
    if dt == 0.0:
        return STATUS_OK
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
    return STATUS_OK


# --------------------------------------------------------------------------
# The tangent of the Kepler drift (variational equations)
# --------------------------------------------------------------------------

# |z| below this: c4 and c5 from their series (to the z^8 term, whose
# successor is below 1e-17 of the sum for |z| < 1); above it from c2, c3,
# where (1/2 - c2) / z and (1/6 - c3) / z lose at most log2(12) bits.
_STUMPFF45_SERIES_Z = 1.0


@njit(inline="always")
def _stumpff45(z):
    """The next two Stumpff functions ``c4 = (1/2 - c2) / z``, ``c5 = (1/6 - c3) / z``
    (``1/24``, ``1/120`` at ``z = 0``), which the derivatives of ``G_2`` and
    ``G_3`` in ``beta`` need."""
    if -_STUMPFF45_SERIES_Z < z < _STUMPFF45_SERIES_Z:
        # c_k = sum_j (-z)^j / (k + 2j)!  (Horner)
        c4 = (1.0 / 24 - z * (1.0 / 720 - z * (1.0 / 40320 - z * (1.0 / 3628800 - z * (
            1.0 / 479001600 - z * (1.0 / 87178291200 - z * (1.0 / 20922789888000 - z * (
                1.0 / 6402373705728000 - z * (1.0 / 2432902008176640000)))))))))
        c5 = (1.0 / 120 - z * (1.0 / 5040 - z * (1.0 / 362880 - z * (1.0 / 39916800 - z * (
            1.0 / 6227020800 - z * (1.0 / 1307674368000 - z * (1.0 / 355687428096000 - z * (
                1.0 / 121645100408832000 - z * (1.0 / 51090942171709440000)))))))))
        return c4, c5
    c0, c1, c2, c3 = stumpff(z)
    return (0.5 - c2) / z, (_SIXTH - c3) / z


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


@njit(inline="always")
def _stumpff45_short(z):
    """:func:`_stumpff45` for the short steps of a planetary integration:
    four terms of each series for ``|z| <= _STUMPFF_SHORT_Z`` (the first
    omitted, ``z^4 / 12!``, below 1e-18 of ``c4``), in Estrin's form."""
    if -_STUMPFF_SHORT_Z <= z <= _STUMPFF_SHORT_Z:
        z2 = z * z
        c4 = (1.0 / 24 - z * (1.0 / 720)) + z2 * ((1.0 / 40320) - z * (1.0 / 3628800))
        c5 = (1.0 / 120 - z * (1.0 / 5040)) + z2 * ((1.0 / 362880) - z * (1.0 / 39916800))
        return c4, c5
    return _stumpff45(z)


@njit(inline="always")
def _tangent_rows(mu, x, v, i, n, dmu, k, x0, y0, z0, vx0, vy0, vz0, s, r0, ir0, sig, beta,
                  zeta, G0, G1, G2, G3, G4, G5, ir, fm1, g, fdot, gdm1):
    # the tangent rows i + n (1 + j) of body i, whose drift started at
    # (x0, v0) and took the (whole) universal anomaly s with the universal
    # functions G0 .. G5 and the coefficients f - 1, g, fdot, gdot - 1:
    # implicit differentiation of Kepler's equation (see kepler_drift_tangent)
    # dG_k / dbeta = (k G_(k+2) - s G_(k+1)) / 2
    b1 = 0.5 * (G3 - s * G2)
    b2 = G4 - 0.5 * s * G3
    b3 = 0.5 * (3.0 * G5 - s * G4)
    sb = sig * b2 + zeta * b3
    for j in range(k):
        o = i + n * (1 + j)
        dx0 = x[o, 0]
        dy0 = x[o, 1]
        dz0 = x[o, 2]
        dvx0 = v[o, 0]
        dvy0 = v[o, 1]
        dvz0 = v[o, 2]
        dm = dmu[j, i]
        dr0 = (x0 * dx0 + y0 * dy0 + z0 * dz0) * ir0
        dsig = x0 * dvx0 + y0 * dvy0 + z0 * dvz0 + vx0 * dx0 + vy0 * dy0 + vz0 * dz0
        dbeta = (2.0 * dm - 2.0 * mu * dr0 * ir0) * ir0 - 2.0 * (
            vx0 * dvx0 + vy0 * dvy0 + vz0 * dvz0)
        dzeta = dm - r0 * dbeta - beta * dr0
        ds = -(s * dr0 + G2 * dsig + G3 * dzeta + sb * dbeta) * ir
        dG1 = G0 * ds + b1 * dbeta
        dG2 = G1 * ds + b2 * dbeta
        dr = dr0 + dsig * G1 + sig * dG1 + dzeta * G2 + zeta * dG2
        df = -(dm * G2 + mu * dG2) * ir0 - fm1 * dr0 * ir0
        dg = dr0 * G1 + r0 * dG1 + dsig * G2 + sig * dG2
        dfdot = -(dm * G1 + mu * dG1) * ir * ir0 - fdot * (dr * ir + dr0 * ir0)
        dgd = -(dm * G2 + mu * dG2) * ir - gdm1 * dr * ir
        x[o, 0] = dx0 + (fm1 * dx0 + g * dvx0) + (df * x0 + dg * vx0)
        x[o, 1] = dy0 + (fm1 * dy0 + g * dvy0) + (df * y0 + dg * vy0)
        x[o, 2] = dz0 + (fm1 * dz0 + g * dvz0) + (df * z0 + dg * vz0)
        v[o, 0] = dvx0 + (fdot * dx0 + gdm1 * dvx0) + (dfdot * x0 + dgd * vx0)
        v[o, 1] = dvy0 + (fdot * dy0 + gdm1 * dvy0) + (dfdot * y0 + dgd * vy0)
        v[o, 2] = dvz0 + (fdot * dz0 + gdm1 * dvz0) + (dfdot * z0 + dgd * vz0)


@njit(inline="always")
def _drift_tangent_rows(mu, x, v, i, n, dmu, k, x0, y0, z0, vx0, vy0, vz0, s, turns,
                        c0, c1, c2, c3):
    # the tangent rows of body i after the bracketed solver took the universal
    # anomaly s (of a step reduced by `turns` periods) with the Stumpff
    # functions c0..c3 of beta s^2
    r2 = x0 * x0 + y0 * y0 + z0 * z0
    r0 = math.sqrt(r2)
    sig = x0 * vx0 + y0 * vy0 + z0 * vz0
    beta = 2.0 * mu / r0 - (vx0 * vx0 + vy0 * vy0 + vz0 * vz0)
    zeta = mu - beta * r0
    G0 = c0
    G1 = s * c1
    G2 = s * s * c2
    G3 = s * s * s * c3
    c4, c5 = _stumpff45(beta * s * s)
    G4 = s * s * s * s * c4
    G5 = s * s * s * s * s * c5
    if turns != 0.0:
        # many periods: G0, G1, G2 are periodic in s, the others are not, and
        # the derivatives belong to the whole anomaly (the period depends on
        # the state: that is the secular part of the tangent)
        sf = s + turns * (_TWO_PI / math.sqrt(beta))
        G3 = (sf - G1) / beta
        G4 = (0.5 * sf * sf - G2) / beta
        G5 = (sf * sf * sf * _SIXTH - G3) / beta
        s = sf
    r = r0 + sig * G1 + zeta * G2
    ir = 1.0 / r
    _tangent_rows(mu, x, v, i, n, dmu, k, x0, y0, z0, vx0, vy0, vz0, s, r0, 1.0 / r0, sig, beta,
                  zeta, G0, G1, G2, G3, G4, G5, ir, -mu * G2 / r0, r0 * G1 + sig * G2,
                  -mu * G1 / (r * r0), -mu * G2 * ir)


@njit(inline="always")
def advance_tangent_by_anomaly(mu, x, v, i, n, dmu, k, s, r0, ir0, beta, zeta):
    """:func:`advance_by_anomaly` of row ``i`` (bit for bit) and of its first
    ``k`` tangent vectors (``n`` rows apart, ``dmu`` as
    :func:`kepler_drift_tangent`'s), from the same universal functions.
    False, and nothing written, if the radius at the end is not positive."""
    ok, start, c, sig, ir, coef = _advance_row(mu, x, v, i, s, r0, ir0, beta, zeta)
    if not ok:
        return False
    x0, y0, z0, vx0, vy0, vz0 = start
    c0, c1, c2, c3 = c
    fm1, g, fdot, gdm1 = coef
    z = beta * s * s
    c4, c5 = _stumpff45_short(z)
    s2 = s * s
    s3 = s2 * s
    _tangent_rows(mu, x, v, i, n, dmu, k, x0, y0, z0, vx0, vy0, vz0, s, r0, ir0, sig, beta,
                  zeta, c0, s * c1, s2 * c2, s3 * c3, s2 * s2 * c4, s3 * s2 * c5, ir, fm1, g,
                  fdot, gdm1)
    return True


@njit
def kepler_drift_tangent(mu, x, v, i, dt, dmu, k):
    """:func:`kepler_drift` of row ``i`` by ``dt``, and its tangent vectors carried
    through the drift's exact derivative, in place.

    Parameters
    ----------
    mu : float
        Gravitational parameter of the orbit, > 0.
    x, v : ndarray, shape (n (1 + k), 3)
        Row ``i`` is the relative state that drifts; rows ``i + n (1 + j)``
        (``j < K``) are its tangent vectors ``(dx, dv)``, ``n =
        dmu.shape[1]`` rows apart (the bodies of a system, then ``k``
        blocks of their tangent vectors).
    i : int
        The row.
    dt : float
        Time step, either sign, any size.
    dmu : ndarray, shape (K, n)
        The variation of ``mu`` that tangent vector ``j`` carries is
        ``dmu[j, i]`` (zeros for none).
    k : int
        The tangent vectors carried: the first ``k <= K``.

    Returns
    -------
    status : int
        :data:`STATUS_OK`, or :data:`STATUS_INVALID_STATE` as
        :func:`kepler_drift`; then row ``i`` and its tangent rows are NaN.

    Notes
    -----
    Row ``i`` is advanced by :func:`kepler_drift`'s own arithmetic (its
    short-step path, or its bracketed solver), so that it is bit for bit
    the drift's.  The tangent differentiates the solution: with ``sigma =
    x0 . v0``, ``beta = 2 mu / r0 - v0^2``, ``zeta = mu - beta r0`` and the
    universal functions ``G_k = s^k c_k(beta s^2)`` (``dG_k/ds = G_(k-1)``,
    ``dG_k/dbeta = (k G_(k+2) - s G_(k+1)) / 2``), Kepler's equation
    ``r0 s + sigma G_2 + zeta G_3 = dt`` at fixed ``dt`` gives ::

        r ds = -(s dr0 + G_2 dsigma + G_3 dzeta
                 + (sigma dG_2/dbeta + zeta dG_3/dbeta) dbeta)

    (``r`` the radius at the end), and the derivatives of ``f - 1 = -mu G_2
    / r0``, ``g = r0 G_1 + sigma G_2``, ``fdot = -mu G_1 / (r r0)``, ``gdot - 1
    = -mu G_2 / r`` give ``dx = df x0 + f dx0 + dg v0 + g dv0``, ``dv =
    dfdot x0 + fdot dx0 + dgdot v0 + gdot dv0``.  ``dmu`` enters through
    ``dbeta = 2 dmu / r0 - ...``, ``dzeta`` and the ``mu`` in ``f``, ``g``.
    A long elliptic step, solved modulo the period, is differentiated at the
    whole anomaly (the period depends on the state).

    References
    ----------
    Danby, J. M. A. 1988, *Fundamentals of Celestial Mechanics*, 2nd ed.,
    sect. 6.9 (universal variables); Rein, H. & Tamayo, D. 2016, MNRAS 459,
    2275 (the tangent of the Wisdom-Holman map).
    """
    n = dmu.shape[1]
    x0 = x[i, 0]
    y0 = x[i, 1]
    z0 = x[i, 2]
    vx0 = v[i, 0]
    vy0 = v[i, 1]
    vz0 = v[i, 2]
    s, r0, ir0, beta, zeta = short_step_anomaly(mu, x0, y0, z0, vx0, vy0, vz0, dt)
    if s == s and advance_tangent_by_anomaly(mu, x, v, i, n, dmu, k, s, r0, ir0, beta, zeta):
        return STATUS_OK
    status = kepler_drift(mu, x, v, i, dt)
    s, turns = bracketed_anomaly(mu, x0, y0, z0, vx0, vy0, vz0, dt)
    if status != STATUS_OK or not (s == s):
        for j in range(k):
            for d in range(3):
                x[i + n * (1 + j), d] = math.nan
                v[i + n * (1 + j), d] = math.nan
        return STATUS_INVALID_STATE
    r0 = math.sqrt(x0 * x0 + y0 * y0 + z0 * z0)
    beta = 2.0 * mu / r0 - (vx0 * vx0 + vy0 * vy0 + vz0 * vz0)
    c0, c1, c2, c3 = stumpff(beta * s * s)
    _drift_tangent_rows(mu, x, v, i, n, dmu, k, x0, y0, z0, vx0, vy0, vz0, s, turns,
                        c0, c1, c2, c3)
    return STATUS_OK
