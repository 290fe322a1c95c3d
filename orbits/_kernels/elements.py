"""Orbital elements <-> Cartesian state of a body relative to its primary.

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
:func:`state_to_elements`).  The mean anomaly is that of
:mod:`.anomalies`.

Status codes
------------
Kernels that can fail return one of the two-body codes of
:class:`~.status.Status` and fill their outputs with NaN (except for
``Status.PARABOLIC_ORBIT``, which is a warning: the outputs are filled).
:func:`~.status.describe_status` turns a code into a sentence for the
exception the Python layer raises.

References
----------
Murray & Dermott (1999), ch. 2, and Danby (1988), ch. 6 (the two-body
problem), cited in full in :mod:`.anomalies`.
"""

import math

import numpy as np

from ._jit import njit, value
from .anomalies import _TWO_PI, _one_plus_e_cos, mean_from_true
from .status import Status

__all__ = [
    "CIRCULAR_TOL",
    "PLANAR_TOL",
    "RADIAL_TOL",
    "elements_to_state",
    "state_to_elements",
    "elements_to_state_many",
    "state_to_elements_many",
]

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
        ``Status.OK``; ``Status.BEYOND_ASYMPTOTE`` if
        ``1 + e cos f <= 0`` on a hyperbola; ``Status.INVALID_ELEMENTS``
        for non-finite values, ``mu <= 0``, ``e < 0``, ``e == 1`` or a sign of
        ``a`` that does not match ``e``; ``Status.BAD_SHAPE``.  The
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
        return Status.BAD_SHAPE
    finite = (math.isfinite(mu) and math.isfinite(a) and math.isfinite(e)
              and math.isfinite(inc) and math.isfinite(Omega)
              and math.isfinite(omega) and math.isfinite(f))
    if (not finite or not (mu > 0.0) or not (e >= 0.0) or e == 1.0
            or (e < 1.0 and not (a > 0.0)) or (e > 1.0 and not (a < 0.0))):
        _fill_nan(out_pos, value(3))
        _fill_nan(out_vel, value(3))
        return Status.INVALID_ELEMENTS
    cf = math.cos(f)
    sf = math.sin(f)
    denom = _one_plus_e_cos(e, f)
    if not (denom > 0.0):
        _fill_nan(out_pos, value(3))
        _fill_nan(out_vel, value(3))
        return Status.BEYOND_ASYMPTOTE
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
    return Status.OK


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
          the mean anomaly of :func:`~.anomalies.mean_from_true` (hyperbolic
          ``e sinh F - F``; Barker's form when the status is
          ``Status.PARABOLIC_ORBIT``).

    Returns
    -------
    status : int
        ``Status.OK``; ``Status.INVALID_STATE`` (non-finite input,
        ``mu <= 0`` or ``r == 0``: all outputs NaN); ``Status.RADIAL_ORBIT``
        (angular momentum at rounding level: ``a`` is written, ``e = 1``, the
        angles are NaN); ``Status.PARABOLIC_ORBIT`` (the energy is zero or
        its sign disagrees with ``e < 1`` within rounding: all outputs are
        written, ``a`` is ``+-inf`` or meaningless and ``M`` is Barker's
        ``D + D^3/3``); ``Status.BAD_SHAPE``.

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
        return Status.BAD_SHAPE
    x, y, z = pos[0], pos[1], pos[2]
    vx, vy, vz = vel[0], vel[1], vel[2]
    r = math.sqrt(x * x + y * y + z * z)
    v2 = vx * vx + vy * vy + vz * vz
    if (not (mu > 0.0) or not math.isfinite(mu) or not math.isfinite(r)
            or not math.isfinite(v2) or r == 0.0):
        _fill_nan(out, value(7))
        return Status.INVALID_STATE
    v = math.sqrt(v2)
    alpha = 2.0 / r - v2 / mu          # 1 / a (vis-viva)

    hx = y * vz - z * vy
    hy = z * vx - x * vz
    hz = x * vy - y * vx
    h = math.sqrt(hx * hx + hy * hy + hz * hz)
    if h <= RADIAL_TOL * r * v:
        _fill_nan(out, value(7))
        out[0] = 1.0 / alpha
        out[1] = 1.0
        return Status.RADIAL_ORBIT

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

    status = Status.OK
    if alpha == 0.0 or (alpha > 0.0) != (e < 1.0):
        status = Status.PARABOLIC_ORBIT
        D = math.tan(0.5 * f)
        M = D + D * D * D / 3.0
    else:
        M = mean_from_true(f, e)

    out[0], out[1], out[2], out[3] = 1.0 / alpha, e, inc, Omega
    out[4], out[5], out[6] = omega, f, M
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
        ``Status.OK`` if every body succeeded, otherwise the first
        non-zero status (``status`` says which rows failed).
    """
    n = mu.shape[0]
    if (elems.shape[0] < n or elems.shape[1] < 6 or pos.shape[0] < n
            or vel.shape[0] < n or status.shape[0] < n):
        return Status.BAD_SHAPE
    first = Status.OK
    for i in range(n):
        s = elements_to_state(mu[i], elems[i, 0], elems[i, 1], elems[i, 2],
                              elems[i, 3], elems[i, 4], elems[i, 5],
                              pos[i], vel[i])
        status[i] = s
        if first == Status.OK:
            first = s
    return first


@njit
def state_to_elements_many(mu, pos, vel, out, status):
    """:func:`state_to_elements` over many bodies, the other way from
    :func:`elements_to_state_many`: ``mu``, ``status`` and the result as
    there; ``pos``, ``vel`` (shape (n, 3)) the relative positions and
    velocities, and ``out`` (shape (n, 7)) written, rows ``a, e, inc,
    Omega, omega, f, M``."""
    n = mu.shape[0]
    if (pos.shape[0] < n or vel.shape[0] < n or out.shape[0] < n
            or status.shape[0] < n):
        return Status.BAD_SHAPE
    first = Status.OK
    for i in range(n):
        s = state_to_elements(mu[i], pos[i], vel[i], out[i])
        status[i] = s
        if first == Status.OK:
            first = s
    return first
