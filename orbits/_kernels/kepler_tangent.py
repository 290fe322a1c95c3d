"""The tangent of the Kepler drift: :func:`~.kepler.kepler_drift` and its exact
derivative carried to tangent vectors, for the variational equations of the
Wisdom-Holman family (:mod:`.wh_tangent`).

The drift's row is advanced by the drift's own arithmetic, bit for bit; the
tangent rows by implicit differentiation of the universal Kepler equation
(see :func:`kepler_drift_tangent`).

References
----------
Danby, J. M. A. 1988, *Fundamentals of Celestial Mechanics*, 2nd ed.,
sect. 6.9 (universal variables); Rein, H. & Tamayo, D. 2016, MNRAS 459,
2275 (the tangent of the Wisdom-Holman map).
"""

import math

from ._jit import njit
from .kepler import _advance_row, bracketed_anomaly, kepler_drift, row_state, short_step_anomaly
from .status import Status
from .stumpff import _SIXTH, _stumpff45, _stumpff45_short, stumpff

__all__ = ["advance_tangent_by_anomaly", "kepler_drift_tangent"]

_TWO_PI = 2.0 * math.pi


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
        dx0, dy0, dz0, dvx0, dvy0, dvz0 = row_state(x, v, o)
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
        ``Status.OK``, or ``Status.INVALID_STATE`` as
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
    x0, y0, z0, vx0, vy0, vz0 = row_state(x, v, i)
    s, r0, ir0, beta, zeta = short_step_anomaly(mu, x0, y0, z0, vx0, vy0, vz0, dt)
    if s == s and advance_tangent_by_anomaly(mu, x, v, i, n, dmu, k, s, r0, ir0, beta, zeta):
        return Status.OK
    status = kepler_drift(mu, x, v, i, dt)
    s, turns = bracketed_anomaly(mu, x0, y0, z0, vx0, vy0, vz0, dt)
    if status != Status.OK or not (s == s):
        for j in range(k):
            for d in range(3):
                x[i + n * (1 + j), d] = math.nan
                v[i + n * (1 + j), d] = math.nan
        return Status.INVALID_STATE
    r0 = math.sqrt(x0 * x0 + y0 * y0 + z0 * z0)
    beta = 2.0 * mu / r0 - (vx0 * vx0 + vy0 * vy0 + vz0 * vz0)
    c0, c1, c2, c3 = stumpff(beta * s * s)
    _drift_tangent_rows(mu, x, v, i, n, dmu, k, x0, y0, z0, vx0, vy0, vz0, s, turns,
                        c0, c1, c2, c3)
    return Status.OK
