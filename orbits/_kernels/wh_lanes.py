"""The Wisdom-Holman step of one system with its planets in vector lanes.

:mod:`orbits._kernels.wh_batch` puts many systems in the lanes of the
vector registers; this module puts the planets of one system there
(structure of arrays, as WHFast512 does, Javaheri, Rein & Tamayo 2023),
for the compiled loop of :mod:`orbits._kernels.wisdom_holman`.  The state
stays in that loop's arrays of shape (N, 3) (its epilogue, synchronisation
and outputs read them); an operator copies what it needs into rows of a
scratch array (:func:`lanes_scratch`), one row per quantity and one column
per planet, runs its arithmetic as loops over the columns that LLVM turns
into vector instructions (four planets in an AVX2 register), and writes the
result back.

:func:`kepler_drift_lanes` drifts every planet, bit for bit as
:func:`~orbits._kernels.wisdom_holman.kepler_drift_all` does, in one pass
over the columns: the scalar drift's short-step path
(:func:`~orbits._kernels.kepler.kepler_drift`: the third-order starter of
the universal anomaly, one of Danby's quartic iterations, the f and g
functions) with the four-term Stumpff series
(:func:`~orbits._kernels.kepler.stumpff_lane`).  This is the whole drift of
a planetary step (a few hundredths of a radian of anomaly, where the
starter is good to 1e-6 and one iteration converges), and one pass lets the
processor overlap the planets' long chains of dependent operations: the
eight planets' drift took 0.19 µs against 0.39 µs for the scalar drift
(0.27 µs as three passes, starter, iteration and f and g, each a loop).  A
lane is taken where the scalar path would have done exactly this
(converged after one iteration, both Stumpff arguments within the
four-term series, a positive radius at the end).  Every other planet (a
step long against its orbit, more than 0.045 rad of eccentric anomaly, a
high eccentricity near pericentre, a hyperbola close in) is drifted by the
scalar :func:`~orbits._kernels.kepler.kepler_drift` from the same start,
which is what the scalar loop does for it too.  So no accuracy is lost, and
the results are those of the scalar loop bit for bit: fastmath is off, so
LLVM neither reorders nor fuses the operations, and a vector instruction
rounds each lane as its scalar form does.

A masked form of the whole short-step path in the lanes (the iteration
repeated until every lane has converged, the general Stumpff form with a
masked number of quarterings, as :mod:`orbits._kernels.wh_batch` does) was
measured and dropped: where a step is long for some planets (the Sun and
eight planets at 1 or 4 days) it was slower than the scalar drift
(1.06-1.19 times the scalar loop's step), as the general Stumpff form then
costs every lane; the lanes' single pass with the declined planets left to
the scalar drift is faster there.  Where more than a quarter of the
planets are declined the loop leaves the drift to the scalar code for
:data:`RETRY` drifts before trying the lanes again (:data:`MEMO`;
``_lanes_drift`` in :mod:`orbits._kernels.wisdom_holman`).

The interaction kick stays the scalar one.  Its pair loop and its two sums
along the bodies are sequential in the scalar code's order, which a
bit-for-bit vector form must keep: measured on the eight planets, the
pairs' separations gathered in that order into columns, their inverse cubes
in vector instructions and the sums back in order (0.34 µs), or a column of
pairs per body with the sums in vector lanes (0.54 µs), or only the mass
ratios and Kepler terms in lanes (0.33 µs) were all slower than the scalar
kick (0.31 µs); a step is a chain of dependent operations, drift, kick,
drift, and the kick's critical path is in its sums, not its arithmetic.

What keeps LLVM from vectorising a loop, learnt here and in
:mod:`orbits._kernels.wh_batch`: a branch per element (``and`` between
comparisons is one: Python's short circuit; ``&`` of the booleans is not),
an index numba cannot prove non-negative (unsigned indices), and indexed
loads from an array the loop also writes (it cannot check them for
overlap).  The columns are padded to a multiple of :data:`LANE_WIDTH` with
copies of the first planet, so that no loop has a scalar remainder; the
copies' results are never used.

References
----------
Javaheri, P., Rein, H. & Tamayo, D. 2023, "WHFast512: a symplectic N-body
integrator for planetary systems optimized with AVX512 instructions", Open
J. Astrophys. 6 (planets in vector lanes, a Kepler solver without branches).
Rein, H. & Tamayo, D. 2015, MNRAS 452, 376 (WHFast).  Danby, J. M. A. 1988,
*Fundamentals of Celestial Mechanics*, 2nd ed., sect. 6.9.
"""

import math

import numpy as np

from ._jit import njit
from .kepler import (_SHORT_STEP, _SHORT_STEP_ITER, _SHORT_STEP_TOL, _SHORT_STEP_Z, _SIXTH,
                     _STUMPFF45_SERIES_Z, _STUMPFF_SERIES_Z, _STUMPFF_SHORT_Z, _estrin,
                     _estrin45, _stumpff45_series, _stumpff_series, kepler_drift,
                     kepler_drift_tangent, stumpff_lane)

__all__ = ["LANE_WIDTH", "DRIFT_ROWS", "MEMO", "RETRY", "lane_columns", "lanes_scratch",
           "kepler_drift_lanes", "TW", "TANGENT_ROWS", "TANGENT_MEMO", "tangent_lanes_scratch",
           "kepler_drift_tangent_lanes"]

#: doubles in a vector register of the machines this is tuned for (AVX2); the
#: planets' columns are padded to a multiple of it
LANE_WIDTH = 4

#: rows of the drift's scratch: the start (6) and mu, the end state (6),
#: the verdict, and a memo for the caller (:data:`MEMO`)
DRIFT_ROWS = 15
_X, _MU, _Y, _TAKE = 0, 6, 7, 13
#: the scratch's row whose column 0 the loop keeps from drift to drift (see
#: orbits._kernels.wisdom_holman._lanes_drift): the drifts left before the
#: lanes are tried again after they declined too many planets
MEMO = 14

#: drifts that the loop leaves to the scalar drift after the lanes have
#: declined more than a quarter of the planets (a scene whose steps are long
#: against several orbits, where the lanes would be wasted every time),
#: before it tries them again
RETRY = 64


def lane_columns(n):
    """Columns of the scratch for ``n`` bodies: one per planet (``n - 1``),
    padded to a multiple of :data:`LANE_WIDTH`."""
    return LANE_WIDTH * max(1, (n - 1 + LANE_WIDTH - 1) // LANE_WIDTH)


def lanes_scratch(n):
    """The scratch of :func:`kepler_drift_lanes` for ``n`` bodies, shape
    (:data:`DRIFT_ROWS`, :func:`lane_columns` ``(n)``)."""
    return np.zeros((DRIFT_ROWS, lane_columns(n)))


@njit(inline="always")
def _single_pass(S, h, P):
    # the usual planetary step in one pass over the columns: the starter,
    # one quartic iteration and the f and g functions, all with the
    # four-term Stumpff series; a column is right (its verdict 1) where the
    # scalar path would have done exactly this: in the short-step domain,
    # both Stumpff arguments within the four-term series, converged after
    # one iteration, a positive radius at the end.  Every operation is the
    # one kepler.short_step_anomaly and kepler._short_coefficients do, in
    # their order, so that a right column is bit for bit the scalar drift.
    # Returns how many columns are not right.
    X0 = S[_X]
    X1 = S[_X + 1]
    X2 = S[_X + 2]
    V0 = S[_X + 3]
    V1 = S[_X + 4]
    V2 = S[_X + 5]
    MU = S[_MU]
    Y0 = S[_Y]
    Y1 = S[_Y + 1]
    Y2 = S[_Y + 2]
    U0 = S[_Y + 3]
    U1 = S[_Y + 4]
    U2 = S[_Y + 5]
    tk_ = S[_TAKE]
    rejected = 0
    for k in range(P):
        mu = MU[k]
        x0 = X0[k]
        y0 = X1[k]
        z0 = X2[k]
        vx0 = V0[k]
        vy0 = V1[k]
        vz0 = V2[k]
        r2 = x0 * x0 + y0 * y0 + z0 * z0
        v2 = vx0 * vx0 + vy0 * vy0 + vz0 * vz0
        r0 = math.sqrt(r2)
        ir0 = 1.0 / r0
        et = x0 * vx0 + y0 * vy0 + z0 * vz0
        beta = 2.0 * mu * ir0 - v2
        zeta = mu - beta * r0
        w = h * ir0
        s = w * (1.0 + w * (-0.5 * et * ir0
                            + w * ((3.0 * et * et * ir0 * ir0 - zeta * ir0) * _SIXTH)))
        z = beta * s * s
        good = ((h * h * v2 < (_SHORT_STEP * _SHORT_STEP) * r2) & (mu > 0.0) & (h != 0.0)
                & (abs(z) <= _STUMPFF_SHORT_Z))
        c0, c1, c2, c3, _ = stumpff_lane(z, False)
        G1 = s * c1
        G2 = s * s * c2
        G3 = s * s * s * c3
        f = r0 * s + et * G2 + zeta * G3 - h
        ir = 1.0 / (r0 + et * G1 + zeta * G2)
        d1 = -f * ir
        a = 0.5 * (et * c0 + zeta * G1) * ir
        b = (zeta * c0 - beta * et * G1) * ir * _SIXTH
        d = d1 * (1.0 + d1 * (-a + d1 * (2.0 * a * a - b)))
        s = s + d
        done = abs(d) <= _SHORT_STEP_TOL * abs(s)
        z = beta * s * s
        c0, c1, c2, c3, _ = stumpff_lane(z, False)
        G1 = s * c1
        G2 = s * s * c2
        # (_advance's sigma is this et: the same expression of the start)
        r = r0 + et * G1 + zeta * G2
        ir = 1.0 / r
        fm1 = -mu * G2 * ir0
        g = r0 * G1 + et * G2
        fdot = -mu * G1 * ir0 * ir
        gdm1 = -mu * G2 * ir
        Y0[k] = x0 + (fm1 * x0 + g * vx0)
        Y1[k] = y0 + (fm1 * y0 + g * vy0)
        Y2[k] = z0 + (fm1 * z0 + g * vz0)
        U0[k] = vx0 + (fdot * x0 + gdm1 * vx0)
        U1[k] = vy0 + (fdot * y0 + gdm1 * vy0)
        U2[k] = vz0 + (fdot * z0 + gdm1 * vz0)
        take = good & done & (abs(z) <= _STUMPFF_SHORT_Z) & (r > 0.0)
        tk_[k] = 1.0 if take else 0.0
        rejected += not take
    return rejected


@njit
def kepler_drift_lanes(xj, vj, mu, h, S):
    """:func:`~orbits._kernels.wisdom_holman.kepler_drift_all` with the
    planets in vector lanes, bit for bit.

    Parameters
    ----------
    xj, vj : ndarray, shape (N, 3)
        Positions and velocities: row 0 drifts in a straight line, row
        ``i >= 1`` on its orbit about ``mu[i]``.  In place.
    mu : ndarray, shape (N,)
        Each row's Kepler ``G M``.
    h : float
        The step.
    S : ndarray, shape (DRIFT_ROWS, P)
        Scratch (:func:`lanes_scratch`), ``P >= N - 1`` a multiple of
        :data:`LANE_WIDTH`.

    Returns
    -------
    declined : int
        The planets the lanes declined (drifted by the scalar drift).

    Notes
    -----
    See the module notes.
    """
    xj[0, 0] += h * vj[0, 0]
    xj[0, 1] += h * vj[0, 1]
    xj[0, 2] += h * vj[0, 2]
    n = xj.shape[0]
    P = np.uint64(S.shape[1])
    # the columns; the padding repeats planet 1, whose copies are never read
    for k in range(S.shape[1]):
        i = k + 1 if k + 1 < n else 1
        S[_X, k] = xj[i, 0]
        S[_X + 1, k] = xj[i, 1]
        S[_X + 2, k] = xj[i, 2]
        S[_X + 3, k] = vj[i, 0]
        S[_X + 4, k] = vj[i, 1]
        S[_X + 5, k] = vj[i, 2]
        S[_MU, k] = mu[i]
    _single_pass(S, h, P)
    declined = 0
    for i in range(1, n):
        k = i - 1
        if S[_TAKE, k] != 0.0:
            xj[i, 0] = S[_Y, k]
            xj[i, 1] = S[_Y + 1, k]
            xj[i, 2] = S[_Y + 2, k]
            vj[i, 0] = S[_Y + 3, k]
            vj[i, 1] = S[_Y + 4, k]
            vj[i, 2] = S[_Y + 5, k]
        else:
            # declined: the scalar drift from the same start, still in xj,
            # vj (its short-step path first, as the scalar loop takes it,
            # then the bracketed solver)
            kepler_drift(mu[i], xj, vj, i, h)
            declined += 1
    return declined



# -- the drift with its tangent ------------------------------------------------------------
#
# kepler_drift_tangent_lanes is orbits._kernels.wh_tangent.drift_tangent with
# the planets in lanes, bit for bit.  The variational runs that use it (chaos
# maps of a test planet beside the giant planets, at a few per cent of the
# innermost period) take steps of 0.1 to 0.3 rad of eccentric anomaly, where
# the single pass above declines every planet: the short-step solver there
# needs two iterations and the seven-term Stumpff series.  So this drift runs
# the scalar short-step path (kepler.short_step_anomaly, then
# kepler.advance_tangent_by_anomaly) as masked passes over the columns: the
# starter, each quartic iteration while a column has not converged (at most
# kepler._SHORT_STEP_ITER), then the f and g functions with the universal
# functions that the tangent takes, then the tangent of each vector.  A pass
# takes the Stumpff functions from their series where every column it needs
# has |z| <= 0.1 (the scalar path's own branch there), from stumpff_lane's
# general form (quarterings and doublings, whose chain of dependent
# operations is twice as long) otherwise.  A column that the scalar path
# would not finish this way (outside its domain, not converged, |z| > 4, a
# non-positive radius) is drifted by kepler.kepler_drift_tangent from the
# same start, as the scalar drift does.

#: the most planets the tangent drift takes in lanes (its scratch's columns);
#: a larger system drifts with the scalar code
TW = 16

# The scratch is a flat array of rows of TW columns, each row at a fixed
# offset (below, the row's index times TW), so that LLVM sees every two rows
# a constant distance apart and vectorises a pass without checking them for
# overlap at run time: with the rows of a 2-d array (a run-time row stride)
# it gives up beyond about twenty rows in a loop, as the f and g functions
# and the tangent need.  The rows: the start (6) and mu; a tangent vector's
# mass variation; the anomaly s, r0, 1 / r0, sigma, beta, zeta; whether the
# column still iterates, whether it converged; the universal functions G0 ..
# G5, 1 / r, f - 1, g, fdot, gdot - 1; whether it is taken; the end (6); a
# tangent vector's start (6) and end (6).
_OX, _OMU, _ODM, _OS, _OR0, _OIR0, _OSIG, _OBETA, _OZETA, _OACT, _OCONV = (
    r * TW for r in (0, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15))
_OG, _OIR, _OFM1, _OGF, _OFDOT, _OGDM1, _OTAKE, _OY, _OD, _ODY = (
    r * TW for r in (16, 22, 23, 24, 25, 26, 27, 28, 34, 40))
#: rows of the scratch
TANGENT_ROWS = 46
# after the rows: the columns in use, then the caller's memo (TANGENT_MEMO)
_OCOLUMNS = TANGENT_ROWS * TW
#: the element of the tangent drift's scratch that the caller keeps from
#: drift to drift (:func:`orbits._kernels.wh_tangent.drift_tangent`): the
#: drifts left to the scalar code, as :data:`MEMO`
TANGENT_MEMO = _OCOLUMNS + 1


def tangent_lanes_scratch(n):
    """The scratch of :func:`kepler_drift_tangent_lanes` for ``n`` bodies, at
    most ``TW + 1``."""
    if not 2 <= n <= TW + 1:
        raise ValueError(f"tangent lanes: {n - 1} planets, from 1 to {TW}")
    S = np.zeros(_OCOLUMNS + 2)
    S[_OCOLUMNS] = lane_columns(n)
    return S


@njit(inline="always")
def _series_lane(z):
    # kepler._stumpff_short for |z| <= _STUMPFF_SERIES_Z (the four-term
    # series to 2e-3, the seven-term one beyond), without a branch
    e0, e1, e2, e3 = _estrin(z)
    s0, s1, s2, s3 = _stumpff_series(z)
    short = (-_STUMPFF_SHORT_Z <= z) & (z <= _STUMPFF_SHORT_Z)
    if short:
        return e0, e1, e2, e3
    return s0, s1, s2, s3


@njit(inline="always")
def _stumpff_columns(z, general):
    # the Stumpff functions of a pass, and whether z is in their domain
    if general:
        return stumpff_lane(z, True)
    c0, c1, c2, c3 = _series_lane(z)
    return c0, c1, c2, c3, True


@njit(inline="always")
def _stumpff45_lane(z, c2, c3):
    # kepler._stumpff45_short without a branch, given the c2, c3 of the same
    # z that kepler.stumpff gives beyond |z| = _STUMPFF45_SERIES_Z
    e4, e5 = _estrin45(z)
    h4, h5 = _stumpff45_series(z)
    d4 = (0.5 - c2) / z
    d5 = (_SIXTH - c3) / z
    short = (-_STUMPFF_SHORT_Z <= z) & (z <= _STUMPFF_SHORT_Z)
    series = (-_STUMPFF45_SERIES_Z < z) & (z < _STUMPFF45_SERIES_Z)
    c4 = e4 if short else (h4 if series else d4)
    c5 = e5 if short else (h5 if series else d5)
    return c4, c5


@njit(inline="always")
def _tangent_starter(S, h, P):
    # short_step_anomaly up to its iterations: the start's invariants and the
    # third-order starter, and whether the column is in the short-step domain
    # (then it iterates); returns how many of those have |z| beyond the
    # series
    big = 0
    for k in range(P):
        mu = S[_OMU + k]
        x0 = S[_OX + k]
        y0 = S[_OX + TW + k]
        z0 = S[_OX + 2 * TW + k]
        vx0 = S[_OX + 3 * TW + k]
        vy0 = S[_OX + 4 * TW + k]
        vz0 = S[_OX + 5 * TW + k]
        r2 = x0 * x0 + y0 * y0 + z0 * z0
        v2 = vx0 * vx0 + vy0 * vy0 + vz0 * vz0
        r0 = math.sqrt(r2)
        ir0 = 1.0 / r0
        et = x0 * vx0 + y0 * vy0 + z0 * vz0
        beta = 2.0 * mu * ir0 - v2
        zeta = mu - beta * r0
        w = h * ir0
        s = w * (1.0 + w * (-0.5 * et * ir0
                            + w * ((3.0 * et * et * ir0 * ir0 - zeta * ir0) * _SIXTH)))
        z = beta * s * s
        good = ((h * h * v2 < (_SHORT_STEP * _SHORT_STEP) * r2) & (mu > 0.0) & (h != 0.0)
                & (abs(z) <= _SHORT_STEP_Z))
        S[_OS + k] = s
        S[_OR0 + k] = r0
        S[_OIR0 + k] = ir0
        S[_OSIG + k] = et
        S[_OBETA + k] = beta
        S[_OZETA + k] = zeta
        S[_OACT + k] = 1.0 if good else 0.0
        S[_OCONV + k] = 0.0
        big += good & (abs(z) > _STUMPFF_SERIES_Z)
    return big


@njit(inline="always")
def _tangent_iteration(S, h, P, general):
    # one of short_step_anomaly's quartic iterations in every column still
    # iterating (a column whose Stumpff argument is beyond stumpff_lane's
    # domain stops, not converged); returns how many columns still iterate
    # and how many of those, or of the converged ones, have |z| beyond the
    # series
    left = 0
    big = 0
    for k in range(P):
        s = S[_OS + k]
        r0 = S[_OR0 + k]
        et = S[_OSIG + k]
        beta = S[_OBETA + k]
        zeta = S[_OZETA + k]
        act = S[_OACT + k] != 0.0
        c0, c1, c2, c3, ok = _stumpff_columns(beta * s * s, general)
        G1 = s * c1
        G2 = s * s * c2
        G3 = s * s * s * c3
        f = r0 * s + et * G2 + zeta * G3 - h
        ir = 1.0 / (r0 + et * G1 + zeta * G2)
        d1 = -f * ir
        a = 0.5 * (et * c0 + zeta * G1) * ir
        b = (zeta * c0 - beta * et * G1) * ir * _SIXTH
        d = d1 * (1.0 + d1 * (-a + d1 * (2.0 * a * a - b)))
        sn = s + d
        done = abs(d) <= _SHORT_STEP_TOL * abs(sn)
        go = act & ok
        s = sn if go else s
        conv = (go & done) | (S[_OCONV + k] != 0.0)
        still = go & (not done)
        S[_OS + k] = s
        S[_OCONV + k] = 1.0 if conv else 0.0
        S[_OACT + k] = 1.0 if still else 0.0
        left += still
        big += (still | conv) & (abs(beta * s * s) > _STUMPFF_SERIES_Z)
    return left, big


@njit(inline="always")
def _tangent_advance(S, P, general):
    # kepler._short_coefficients and the universal functions G0 .. G5 that
    # the tangent takes (advance_tangent_by_anomaly's), the end state, and
    # whether the column is taken (converged, |z| <= 4, a positive radius)
    for k in range(P):
        mu = S[_OMU + k]
        x0 = S[_OX + k]
        y0 = S[_OX + TW + k]
        z0 = S[_OX + 2 * TW + k]
        vx0 = S[_OX + 3 * TW + k]
        vy0 = S[_OX + 4 * TW + k]
        vz0 = S[_OX + 5 * TW + k]
        s = S[_OS + k]
        r0 = S[_OR0 + k]
        ir0 = S[_OIR0 + k]
        beta = S[_OBETA + k]
        zeta = S[_OZETA + k]
        sig = x0 * vx0 + y0 * vy0 + z0 * vz0
        z = beta * s * s
        c0, c1, c2, c3, ok = _stumpff_columns(z, general)
        G1 = s * c1
        G2 = s * s * c2
        r = r0 + sig * G1 + zeta * G2
        ir = 1.0 / r
        fm1 = -mu * G2 * ir0
        g = r0 * G1 + sig * G2
        fdot = -mu * G1 * ir0 * ir
        gdm1 = -mu * G2 * ir
        c4, c5 = _stumpff45_lane(z, c2, c3)
        s2 = s * s
        s3 = s2 * s
        S[_OY + k] = x0 + (fm1 * x0 + g * vx0)
        S[_OY + TW + k] = y0 + (fm1 * y0 + g * vy0)
        S[_OY + 2 * TW + k] = z0 + (fm1 * z0 + g * vz0)
        S[_OY + 3 * TW + k] = vx0 + (fdot * x0 + gdm1 * vx0)
        S[_OY + 4 * TW + k] = vy0 + (fdot * y0 + gdm1 * vy0)
        S[_OY + 5 * TW + k] = vz0 + (fdot * z0 + gdm1 * vz0)
        S[_OSIG + k] = sig
        S[_OG + k] = c0
        S[_OG + TW + k] = G1
        S[_OG + 2 * TW + k] = s2 * c2
        S[_OG + 3 * TW + k] = s3 * c3
        S[_OG + 4 * TW + k] = s2 * s2 * c4
        S[_OG + 5 * TW + k] = s3 * s2 * c5
        S[_OIR + k] = ir
        S[_OFM1 + k] = fm1
        S[_OGF + k] = g
        S[_OFDOT + k] = fdot
        S[_OGDM1 + k] = gdm1
        take = (S[_OCONV + k] != 0.0) & ok & (r > 0.0)
        S[_OTAKE + k] = 1.0 if take else 0.0


@njit(inline="always")
def _tangent_vector(S, P):
    # kepler._tangent_rows of one tangent vector in every column: its start
    # in rows _OD, its mass variation in _ODM, the result into rows _ODY
    for k in range(P):
        mu = S[_OMU + k]
        x0 = S[_OX + k]
        y0 = S[_OX + TW + k]
        z0 = S[_OX + 2 * TW + k]
        vx0 = S[_OX + 3 * TW + k]
        vy0 = S[_OX + 4 * TW + k]
        vz0 = S[_OX + 5 * TW + k]
        s = S[_OS + k]
        r0 = S[_OR0 + k]
        ir0 = S[_OIR0 + k]
        sig = S[_OSIG + k]
        beta = S[_OBETA + k]
        zeta = S[_OZETA + k]
        G0 = S[_OG + k]
        G1 = S[_OG + TW + k]
        G2 = S[_OG + 2 * TW + k]
        G3 = S[_OG + 3 * TW + k]
        G4 = S[_OG + 4 * TW + k]
        G5 = S[_OG + 5 * TW + k]
        ir = S[_OIR + k]
        fm1 = S[_OFM1 + k]
        g = S[_OGF + k]
        fdot = S[_OFDOT + k]
        gdm1 = S[_OGDM1 + k]
        b1 = 0.5 * (G3 - s * G2)
        b2 = G4 - 0.5 * s * G3
        b3 = 0.5 * (3.0 * G5 - s * G4)
        sb = sig * b2 + zeta * b3
        dx0 = S[_OD + k]
        dy0 = S[_OD + TW + k]
        dz0 = S[_OD + 2 * TW + k]
        dvx0 = S[_OD + 3 * TW + k]
        dvy0 = S[_OD + 4 * TW + k]
        dvz0 = S[_OD + 5 * TW + k]
        dm = S[_ODM + k]
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
        S[_ODY + k] = dx0 + (fm1 * dx0 + g * dvx0) + (df * x0 + dg * vx0)
        S[_ODY + TW + k] = dy0 + (fm1 * dy0 + g * dvy0) + (df * y0 + dg * vy0)
        S[_ODY + 2 * TW + k] = dz0 + (fm1 * dz0 + g * dvz0) + (df * z0 + dg * vz0)
        S[_ODY + 3 * TW + k] = dvx0 + (fdot * dx0 + gdm1 * dvx0) + (dfdot * x0 + dgd * vx0)
        S[_ODY + 4 * TW + k] = dvy0 + (fdot * dy0 + gdm1 * dvy0) + (dfdot * y0 + dgd * vy0)
        S[_ODY + 5 * TW + k] = dvz0 + (fdot * dz0 + gdm1 * dvz0) + (dfdot * z0 + dgd * vz0)


@njit(inline="always")
def _columns_in(S, o, x, v, first, n, P):
    # rows first + 1 .. first + n - 1 of x, v into the six scratch rows from
    # offset o, one per column; the padding repeats the first of them
    for c in range(P):
        i = first + (c + 1 if c + 1 < n else 1)
        S[o + c] = x[i, 0]
        S[o + TW + c] = x[i, 1]
        S[o + 2 * TW + c] = x[i, 2]
        S[o + 3 * TW + c] = v[i, 0]
        S[o + 4 * TW + c] = v[i, 1]
        S[o + 5 * TW + c] = v[i, 2]


@njit(inline="always")
def _columns_out(S, o, x, v, first, n):
    # the taken columns of the six scratch rows from offset o back into rows
    # first + 1 .. first + n - 1 of x, v
    for c in range(n - 1):
        if S[_OTAKE + c] != 0.0:
            i = first + c + 1
            x[i, 0] = S[o + c]
            x[i, 1] = S[o + TW + c]
            x[i, 2] = S[o + 2 * TW + c]
            v[i, 0] = S[o + 3 * TW + c]
            v[i, 1] = S[o + 4 * TW + c]
            v[i, 2] = S[o + 5 * TW + c]


@njit
def kepler_drift_tangent_lanes(xj, vj, mu, h, dmu, k, S):
    """:func:`~orbits._kernels.wh_tangent.drift_tangent` with the planets in
    vector lanes, bit for bit.

    Parameters
    ----------
    xj, vj : ndarray, shape (n (1 + K), 3)
        The bodies' Jacobi rows ``[0, n)`` (row 0 drifts in a straight line,
        row ``i >= 1`` on its orbit about ``mu[i]``), then tangent vector
        ``j``'s in rows ``[n (1 + j), n (2 + j))``.  In place.
    mu : ndarray, shape (n,)
        Each row's Kepler ``G M``.
    h : float
        The step.
    dmu : ndarray, shape (K, n)
        The variation of ``mu`` each tangent vector carries.
    k : int
        The tangent vectors carried, the first ``k <= K``.
    S : ndarray
        Scratch (:func:`tangent_lanes_scratch` for ``n`` bodies).

    Returns
    -------
    declined : int
        The planets drifted by the scalar
        :func:`~orbits._kernels.kepler.kepler_drift_tangent` instead.
    """
    n = mu.shape[0]
    xj[0, 0] += h * vj[0, 0]
    xj[0, 1] += h * vj[0, 1]
    xj[0, 2] += h * vj[0, 2]
    for j in range(k):
        o = n * (1 + j)
        xj[o, 0] += h * vj[o, 0]
        xj[o, 1] += h * vj[o, 1]
        xj[o, 2] += h * vj[o, 2]
    P = np.uint64(S[_OCOLUMNS])
    _columns_in(S, _OX, xj, vj, 0, n, P)
    for c in range(P):
        S[_OMU + c] = mu[c + 1 if c + 1 < n else 1]
    big = _tangent_starter(S, h, P)
    for _ in range(_SHORT_STEP_ITER):
        left, big = _tangent_iteration(S, h, P, big > 0)
        if left == 0:
            break
    _tangent_advance(S, P, big > 0)
    for j in range(k):
        o = n * (1 + j)
        _columns_in(S, _OD, xj, vj, o, n, P)
        for c in range(P):
            S[_ODM + c] = dmu[j, c + 1 if c + 1 < n else 1]
        _tangent_vector(S, P)
        _columns_out(S, _ODY, xj, vj, o, n)
    _columns_out(S, _OY, xj, vj, 0, n)
    declined = 0
    for i in range(1, n):
        if S[_OTAKE + i - 1] == 0.0:
            # from the same start, still in xj, vj and their tangent rows
            kepler_drift_tangent(mu[i], xj, vj, i, h, dmu, k)
            declined += 1
    return declined
