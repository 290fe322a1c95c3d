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
:func:`~orbits._kernels.wisdom_holman.kepler_drift_all` does, in three
passes over the columns: the scalar drift's short-step path
(:func:`~orbits._kernels.kepler.kepler_drift`: the fifth-order starter of
the universal anomaly, Danby's quartic iterations, the f and g functions),
and passes over all the planets let the processor overlap their long chains
of dependent operations, which the scalar drift, one planet after another,
cannot (see "three passes" below).  The passes come in two forms:

* the short-step passes (:func:`drift_columns`): one iteration and the
  four-term Stumpff series (:func:`~orbits._kernels.stumpff.stumpff_lane`),
  the whole drift of a short step (a few hundredths of a radian of anomaly,
  where the starter is good to a few 1e-9 and one iteration converges);
* the medium passes (:func:`medium_columns`), for the steps people take
  with Wisdom-Holman (a twentieth of the innermost period, up to a radian of
  an orbit): up to two iterations, each lane with the four- or the nine-term
  series (:func:`~orbits._kernels.stumpff.stumpff_medium_lane`), the
  scalar path's taken by a select; the second iteration is a pass of its
  own, made in every lane where any column has not converged after the
  first (up to a twentieth of an orbit of e <= 0.2 none has: the starter is
  of fifth order).  The steps' drift of the state kept in the lanes
  (:func:`resident_drift`) takes them always: a lane whose step is short
  takes the four-term series and keeps the first iteration's anomaly, as
  the short passes would, and where no column needs it the second pass is
  left out, so the loop compiles one drift instead of two (5 s less on a
  first run) and the drift of a short step costs a pass less
  (benchmarks/RESULTS.md).
  The outputs' drifts
  (:func:`kepler_drift_lanes`, :func:`resident_drift_twice`) take the short
  passes, and the medium ones, compiled once, where those declined a planet,
  then first for the next :data:`RETRY` drifts (row :data:`MEMO`, column
  1).

A lane is taken where the scalar path would have done exactly what its
passes did (converged after the iterations they make, every Stumpff
argument within their series, a positive radius at the end).  Every other
planet (a step of more than a radian of its orbit, a high eccentricity near
pericentre, a hyperbola close in) is drifted by the scalar
:func:`~orbits._kernels.kepler.kepler_drift` from the same start, which is
what the scalar loop does for it too.  So no accuracy is lost, and the
results are those of the scalar loop bit for bit: fastmath is off, so LLVM
neither reorders nor fuses the operations, and a vector instruction rounds
each lane as its scalar form does.  The fused multiply-adds of the shared
Kepler helpers (:func:`orbits._kernels._jit.fma`, correctly rounded on
every machine) are written out, so the scalar drift has them too; with
them the drift's chains are shorter.

A masked form of the whole path (the iteration repeated until every lane
has converged, the general Stumpff form with a masked number of
quarterings, as :mod:`orbits._kernels.wh_batch` does) is slower than the
scalar drift where a step is long for some planets, as the general Stumpff
form then costs every lane (benchmarks/RESULTS.md); the medium passes'
fixed polynomial and two iterations cover the planetary steps without it.
Where more than a quarter of the planets are declined, an output's
synchronising drift leaves the drift to the scalar code for :data:`RETRY`
drifts before trying the lanes again (row :data:`MEMO`, column 0;
``_lanes_drift`` in :mod:`orbits._kernels.wisdom_holman`); the steps'
drift of the state kept in the lanes always tries them.

The interaction kick's pulls
(:func:`orbits._kernels.gravity.pull_rows`) go to the lanes as well: one
vector pass per source body over all the lanes, each lane's pulls summed
over the sources in ascending order, which is the scalar pair loop's order,
so the kick too is bit for bit the scalar one.  It evaluates each pair
twice (once per body); the forms that evaluate it once (the separations
gathered into columns, a column of pairs per body, each pair's factor by
diagonals of rotated lanes as WHFast512 does) are no quicker, as the step's
chains of dependent sums, not the divider alone, set its pace
(benchmarks/RESULTS.md).  Two things decide the speed of a lanes pass: its
sums must not go through masked stores (a masked store cannot be forwarded
to the next pass's load; the lane a source skips adds an exact zero
instead), and the pass must store nothing but its sums (LLVM keeps the
scalar form of a pass that writes a further row).

The loop keeps its state in the lanes between outputs (see "the state kept
in the lanes" below): copies in and out of the (N, 3) arrays on every
operator would cost more than the lanes save below seven bodies.

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

from ._jit import njit, slots, specialize
# the planets' columns, padded to a multiple of the lane width (shared with the
# gravity kernels' lanes)
from .gravity import (LANE_WIDTH, aligned_zeros, lane_columns, pull_factors, pull_rows,
                      pull_rows_factored)
from .kepler import (_SHORT_STEP, _SHORT_STEP_TOL, advanced_state, f_and_g, kepler_drift,
                     quartic_step, short_start, straight_drift)
from .stumpff import _STUMPFF_MEDIUM_Z, _STUMPFF_SHORT_Z, stumpff_lane, stumpff_medium_lane

# the names the templates below are written against, bound by specialize
step_of, short_passes = slots("step_of", "short_passes")

__all__ = ["LANE_WIDTH", "DRIFT_ROWS", "MEMO", "PENDING", "RETRY", "lane_columns",
           "lanes_scratch", "kepler_drift_lanes",
           "drift_columns", "column_start", "SCRATCH_ROWS", "lanes_scratch_shape", "resident_load",
           "resident_store", "resident_drift_twice", "resident_drift", "resident_finite",
           "resident_kick", "resident_jump_kick", "resident_jump", "resident_pulls",
           "resident_velocity_kick", "resident_drift_into", "jump_shift", "jump_rows", "kick_rows",
           "pulls_rows", "zero_sums", "medium_rows", "STATE", "SUMS"]


#: rows of the drift's scratch: the start (6) and mu, the end state (6),
#: the verdict, memos (:data:`MEMO`), each column's step, and
#: an output the loop has yet to finish (:data:`PENDING`)
DRIFT_ROWS = 17
_X, _MU, _Y, _TAKE = 0, 6, 7, 13
#: the scratch's row whose first columns are kept from drift to drift:
#: column 0 (orbits._kernels.wisdom_holman._lanes_drift) the drifts left
#: before the lanes are tried again after they declined too many planets,
#: column 1 the drifts left that go straight to the medium passes
MEMO = 14
_H = 15
#: the scratch's row where the loop notes an output due at the end of a step
#: (1, its row, its time), whose synchronising drift it then makes in the same
#: pass as the next step's first drift (:func:`resident_drift_twice`)
PENDING = 16

#: drifts that the loop leaves to the scalar drift after the lanes have
#: declined more than a quarter of the planets (a scene whose steps are long
#: against several orbits, where the lanes would be wasted every time),
#: before it tries them again; and drifts that go straight to the medium
#: passes after the short ones declined a planet
RETRY = 64


def lanes_scratch(n):
    """The scratch of :func:`kepler_drift_lanes` and of the lanes' state
    (``resident_*``)
    for ``n`` bodies, shape (:data:`SCRATCH_ROWS`, 2 :func:`lane_columns`
    ``(n)``)."""
    return aligned_zeros(lanes_scratch_shape(n))


@njit(inline="always")
def _load(S, xj, vj, mu, h, off, P):
    # columns off .. off + P - 1: the planets' start and mu, and the step h;
    # the padding repeats planet 1, whose copies are never read
    n = xj.shape[0]
    for k in range(P):
        i = k + 1 if k + 1 < n else 1
        c = off + k
        S[_X, c] = xj[i, 0]
        S[_X + 1, c] = xj[i, 1]
        S[_X + 2, c] = xj[i, 2]
        S[_X + 3, c] = vj[i, 0]
        S[_X + 4, c] = vj[i, 1]
        S[_X + 5, c] = vj[i, 2]
        S[_MU, c] = mu[i]
        S[_H, c] = h


@njit(inline="always")
def _store(S, xj, vj, mu, off):
    # the planets from columns off ..: those the lanes took, and the others
    # drifted by the scalar drift from their start (still in xj, vj) by
    # their column's step; returns how many the lanes declined
    declined = 0
    for i in range(1, xj.shape[0]):
        k = off + i - 1
        if S[_TAKE, k] != 0.0:
            xj[i, 0] = S[_Y, k]
            xj[i, 1] = S[_Y + 1, k]
            xj[i, 2] = S[_Y + 2, k]
            vj[i, 0] = S[_Y + 3, k]
            vj[i, 1] = S[_Y + 4, k]
            vj[i, 2] = S[_Y + 5, k]
        else:
            # declined: the scalar drift from the same start (its
            # short-step path first, as the scalar loop takes it, then the
            # bracketed solver)
            kepler_drift(mu[i], xj, vj, i, S[_H, k])
            declined += 1
    return declined


@njit(inline="always")
def column_start(X0, X1, X2, V0, V1, V2, MU, k):
    """Column ``k``'s Kepler ``G M`` and start ``(x, y, z, vx, vy, vz)``, from
    rows laid out as :func:`drift_columns` reads them."""
    return MU[k], X0[k], X1[k], X2[k], V0[k], V1[k], V2[k]


@njit(inline="always")
def _start_column(X0, X1, X2, V0, V1, V2, MU, T, t, k, h, zmax=_STUMPFF_SHORT_Z):
    # the first pass of column k's drift by h (see _pass_rows): the start's
    # invariants and the starter of the anomaly, into rows t .. t + 6 of T
    # (s, r0, 1 / r0, eta, beta, zeta, and 1.0 where the column is in the
    # short-step domain with its starter's Stumpff argument within zmax: the
    # four-term series, or the medium passes' nine-term one)
    mu, x0, y0, z0, vx0, vy0, vz0 = column_start(X0, X1, X2, V0, V1, V2, MU, k)
    r2, v2, r0, ir0, et, beta, zeta, s = short_start(mu, x0, y0, z0, vx0, vy0, vz0, h)
    z = beta * s * s
    good = ((h * h * v2 < (_SHORT_STEP * _SHORT_STEP) * r2) & (mu > 0.0) & (h != 0.0)
            & (abs(z) <= zmax))
    T[t, k] = s
    T[t + 1, k] = r0
    T[t + 2, k] = ir0
    T[t + 3, k] = et
    T[t + 4, k] = beta
    T[t + 5, k] = zeta
    T[t + 6, k] = 1.0 if good else 0.0


@njit(inline="always")
def _started(T, t, k):
    # what the first pass kept of column k for the iterations: (s, r0, eta,
    # beta, zeta)
    return T[t, k], T[t + 1, k], T[t + 3, k], T[t + 4, k], T[t + 5, k]


@njit(inline="always")
def _iterate_column(T, t, k, h):
    # the second pass of column k's drift by h: one quartic iteration from
    # the first pass's rows, the new anomaly into row t + 7 of T and 1.0 where
    # it has converged into row t + 8
    s, r0, et, beta, zeta = _started(T, t, k)
    z = beta * s * s
    c0, c1, c2, c3, _ = stumpff_lane(z, False)
    d = quartic_step(s, r0, et, beta, zeta, c0, c1, c2, c3, h)
    s = s + d
    done = abs(d) <= _SHORT_STEP_TOL * abs(s)
    T[t + 7, k] = s
    T[t + 8, k] = 1.0 if done else 0.0


@njit(inline="always")
def _finish_column(X0, X1, X2, V0, V1, V2, MU, Y0, Y1, Y2, U0, U1, U2, tk_, T, t, k,
                   medium=False):
    # the third pass of column k's drift: the f and g functions of the
    # iterated anomaly, with the four-term Stumpff series (the medium passes:
    # _stumpff_short's four- or nine-term); 1 if the column is not right,
    # else 0
    mu, x0, y0, z0, vx0, vy0, vz0 = column_start(X0, X1, X2, V0, V1, V2, MU, k)
    s = T[t + 7, k]
    r0 = T[t + 1, k]
    ir0 = T[t + 2, k]
    et = T[t + 3, k]
    beta = T[t + 4, k]
    zeta = T[t + 5, k]
    z = beta * s * s
    if medium:
        c0, c1, c2, c3, inside = stumpff_medium_lane(z)
    else:
        c0, c1, c2, c3, _ = stumpff_lane(z, False)
        inside = abs(z) <= _STUMPFF_SHORT_Z
    # (_advance's sigma is this et: the same expression of the start)
    _, _, r, ir, fm1, g, fdot, gdm1 = f_and_g(mu, s, r0, ir0, et, zeta, c1, c2)
    Y0[k], Y1[k], Y2[k], U0[k], U1[k], U2[k] = advanced_state(x0, y0, z0, vx0, vy0, vz0, fm1,
                                                              g, fdot, gdm1)
    take = (T[t + 6, k] != 0.0) & (T[t + 8, k] != 0.0) & inside & (r > 0.0)
    tk_[k] = 1.0 if take else 0.0
    return 0 if take else 1


@njit(inline="always")
def _iterate_column_medium(T, t, k, h):
    # the medium passes' second: the first quartic iteration, as the scalar
    # path (kepler.short_step_anomaly) takes it, with _stumpff_short's four-
    # or nine-term series.  Row t + 7: the anomaly; row t + 8: 1.0 where it
    # has converged with its Stumpff argument within the series (the scalar
    # path stops there); row t (the starter, no longer read): 1.0 where that
    # argument is within the series, plus 2.0 where the iteration converged
    s, r0, et, beta, zeta = _started(T, t, k)
    c0, c1, c2, c3, in0 = stumpff_medium_lane(beta * s * s)
    d = quartic_step(s, r0, et, beta, zeta, c0, c1, c2, c3, h)
    s1 = s + d
    done1 = abs(d) <= _SHORT_STEP_TOL * abs(s1)
    T[t + 7, k] = s1
    T[t + 8, k] = 1.0 if in0 & done1 else 0.0
    T[t, k] = (1.0 if in0 else 0.0) + (2.0 if done1 else 0.0)


@njit(inline="always")
def _iterate_again_medium(T, t, k, h):
    # the medium passes' second iteration, where a column has not converged
    # after the first (the scalar path's second): row t + 7 gets the anomaly
    # the scalar path stops at, row t + 8 1.0 where it has converged with
    # every Stumpff argument it used within the series
    _, r0, et, beta, zeta = _started(T, t, k)
    s1 = T[t + 7, k]
    flags = T[t, k]
    in0 = (flags == 1.0) | (flags == 3.0)
    done1 = flags >= 2.0
    c0, c1, c2, c3, in1 = stumpff_medium_lane(beta * s1 * s1)
    d = quartic_step(s1, r0, et, beta, zeta, c0, c1, c2, c3, h)
    s2 = s1 + d
    done2 = abs(d) <= _SHORT_STEP_TOL * abs(s2)
    T[t + 7, k] = s1 if done1 else s2
    ok = in0 & (done1 | (in1 & done2))
    T[t + 8, k] = 1.0 if ok else 0.0


@njit(inline="always")
def medium_columns(S, src, mu, dst, take, t, h, column_steps, P):
    """:func:`drift_columns` for the steps people take with Wisdom-Holman (a
    twentieth to a sixth of an orbit, up to a radian of eccentric anomaly),
    which the short-step passes decline: the same three passes with up to
    two quartic iterations and the nine-term Stumpff series where the
    four-term one does not hold, each lane bit for bit the scalar drift's
    short-step path (:func:`~orbits._kernels.kepler.short_step_anomaly`),
    which takes the same series and stops at the same iteration.  The rows
    of the scratch ``S``: the start ``src .. src + 5`` with ``mu``, the end
    ``dst .. dst + 5``, the verdict ``take``, the passes' ``t .. t + 8``;
    each column's step is row :data:`_H`'s where ``column_steps``, else
    ``h``.  The second iteration is a pass of its own, made only where a
    column has not converged after the first: at short steps every column
    has, and the drift is a pass shorter.  Returns how many of the ``P``
    columns are left to the scalar drift."""
    return medium_rows(S[src], S[src + 1], S[src + 2], S[src + 3], S[src + 4], S[src + 5],
                       S[mu], S[dst], S[dst + 1], S[dst + 2], S[dst + 3], S[dst + 4],
                       S[dst + 5], S[take], S, t, S[_H], column_steps, h, np.uint64(0), P)


@njit(inline="always")
def medium_rows(X0, X1, X2, V0, V1, V2, MU, Y0, Y1, Y2, U0, U1, U2, tk_, T, t, H,
                column_steps, h, k0, P):
    """:func:`medium_columns` of the columns ``k0 .. P - 1`` of rows laid out
    as :func:`drift_columns` has them (the start ``X``, ``V`` with ``MU``,
    the end ``Y``, ``U``, the verdict ``tk_``, the passes' rows ``t .. t +
    8`` of ``T``; each column's step from ``H`` where ``column_steps``);
    the medium drift of :mod:`orbits._kernels.wh_batch`, whose columns are
    the bodies of many systems."""
    for k in range(k0, P):
        hk = H[k] if column_steps else h
        _start_column(X0, X1, X2, V0, V1, V2, MU, T, t, k, hk, _STUMPFF_MEDIUM_Z)
    for k in range(k0, P):
        hk = H[k] if column_steps else h
        _iterate_column_medium(T, t, k, hk)
    # the second iteration, a pass of its own, only where a column has not
    # converged after the first (at short steps every column has)
    V = T[t + 8]
    unsettled = 0
    for k in range(k0, P):
        unsettled += V[k] == 0.0
    if unsettled:
        for k in range(k0, P):
            hk = H[k] if column_steps else h
            _iterate_again_medium(T, t, k, hk)
    rejected = 0
    for k in range(k0, P):
        rejected += _finish_column(X0, X1, X2, V0, V1, V2, MU, Y0, Y1, Y2, U0, U1, U2, tk_, T,
                                   t, k, True)
    return rejected


# Three passes.  The drift of one column is some 250 vector operations whose
# chain of dependent ones (a square root, three divisions, the polynomials
# between them) is several hundred cycles long.  In one loop the processor
# holds about two columns' vectors in flight, so that a pass over many
# columns runs at about the chain's length per two vectors.  Split into
# loops with shorter bodies, more of them overlap: three passes (the
# starter, the iteration, the f and g functions) are the quickest from the
# outer solar system's few columns to many (two are slower from 16 columns
# on, four at 8 columns; benchmarks/RESULTS.md).  The medium passes' second
# iteration is a fourth, only where a column needs it, which costs no time
# at the steps where one does.  The passes keep nine rows
# (the start's s, r0, 1 / r0, eta, beta, zeta and verdict, the iterated s
# and its verdict), the same floats the one pass kept in registers, so the
# drift is the same bit for bit.


def _pass_rows(X0, X1, X2, V0, V1, V2, MU, Y0, Y1, Y2, U0, U1, U2, tk_, T, t, H, h0, k0, P):
    # the usual planetary step over the columns k0 .. P - 1 of the rows
    # (start X, V and mu; end Y, U; verdict tk_; each column's step H where
    # step_of reads it): the starter, one quartic iteration and the f and g
    # functions, all with the four-term Stumpff series; a column is right
    # (its verdict 1) where the scalar path would have done exactly this: in
    # the short-step domain, both Stumpff arguments within the four-term
    # series, converged after one iteration, a positive radius at the end.
    # Every operation is the one kepler.short_step_anomaly and
    # kepler._short_coefficients do, in their order, so that a right column
    # is bit for bit the scalar drift.  Three passes, their results kept in
    # rows t .. t + 8 of T between them (see "three passes" above).
    # Returns how many columns are not right.
    for k in range(k0, P):
        _start_column(X0, X1, X2, V0, V1, V2, MU, T, t, k,
                      step_of(H, k, h0))
    for k in range(k0, P):
        _iterate_column(T, t, k, step_of(H, k, h0))
    rejected = 0
    for k in range(k0, P):
        rejected += _finish_column(X0, X1, X2, V0, V1, V2, MU, Y0, Y1, Y2, U0, U1, U2, tk_, T,
                                   t, k)
    return rejected


@njit(inline="always")
def drift_columns(X0, X1, X2, V0, V1, V2, MU, Y0, Y1, Y2, U0, U1, U2, tk_, T, t, h, k0, P):
    """The lanes' drift (see the module notes) of the columns ``k0 .. P - 1``
    by ``h``: from the start rows ``X``, ``V`` with ``MU``, into the end rows
    ``Y``, ``U``, and into ``tk_`` 1 for a column bit for bit the scalar
    drift, 0 for one to leave to it; returns how many are left.  Rows ``t
    .. t + 8`` of ``T`` (none of the others) keep the passes' results.
    The drift of :mod:`orbits._kernels.wh_batch`, whose columns are the
    bodies of many systems."""
    # _pass_rows's loops with the one step h, written out again: the
    # batch's step is slower as a call of _pass_rows_one (specialised with
    # _one_step), by a quarter at 16 systems and more at 4
    # (benchmarks/RESULTS.md)
    for k in range(k0, P):
        _start_column(X0, X1, X2, V0, V1, V2, MU, T, t, k, h)
    for k in range(k0, P):
        _iterate_column(T, t, k, h)
    rejected = 0
    for k in range(k0, P):
        rejected += _finish_column(X0, X1, X2, V0, V1, V2, MU, Y0, Y1, Y2, U0, U1, U2, tk_, T,
                                   t, k)
    return rejected


@njit(inline="always")
def _one_step(H, k, h):
    # every column takes the step h
    return h


_pass_rows_one = specialize(_pass_rows, "one_step", inline=True, step_of=_one_step)


@njit
def _medium_scratch(S, h0, P):
    # medium_columns over the drift's rows of the scratch (_X .., _MU, _Y ..,
    # _TAKE); not inlined, so that one compilation serves every loop
    return medium_columns(S, _X, _MU, _Y, _TAKE, _T, h0, False, P)


@njit(inline="always")
def _medium_resident(S, h, P, dst):
    # medium_columns from the rows of the state kept in the lanes (_RX ..,
    # _RMU, _RTAKE) into the rows from dst (_RY .., or others), inlined into
    # the steps' drift: called there, it made the outer solar system's step
    # at 216.6 days 0.36 us against 0.23 (benchmarks/RESULTS.md); the
    # synchronisation's and the corrector's drifts (kepler_drift_lanes) call
    # _medium_scratch
    return medium_columns(S, _RX, _RMU, dst, _RTAKE, _T, h, False, P)


@njit(inline="always")
def _medium_first(S):
    # whether the drift goes straight to the medium passes: for RETRY drifts
    # after the short-step passes last declined a planet (a scene whose steps
    # are long for some planet declines one at every step, and the short
    # passes would be wasted there); counts the drift
    if S[MEMO, 1] > 0.0:
        S[MEMO, 1] -= 1.0
        return True
    return False


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
    S : ndarray, shape (SCRATCH_ROWS, 2 P)
        Scratch (:func:`lanes_scratch`), ``P`` (:func:`lane_columns`)
        ``>= N - 1`` a multiple of :data:`LANE_WIDTH`.

    Returns
    -------
    declined : int
        The planets the lanes declined (drifted by the scalar drift).

    Notes
    -----
    See the module notes.
    """
    straight_drift(xj, vj, 0, h)
    P = lane_columns(xj.shape[0])
    _load(S, xj, vj, mu, h, 0, P)
    _single_pass(S, h, np.uint64(P))
    return _store(S, xj, vj, mu, 0)


# -- the state kept in the lanes ----------------------------------------------------
#
# The loop of orbits._kernels.wisdom_holman keeps its state in arrays of
# shape (N, 3), which its epilogue, synchronisation and outputs read.  The
# operators above copy the planets into the lanes and back on every drift
# and kick; the scalar stores and vector loads of those copies cannot be
# forwarded, and they cost a step more than its kick's arithmetic.  Between
# the loop's outputs the state is now kept in the lanes (as WHFast512 keeps
# it in its registers): rows of the scratch after the drift's, one column a
# planet, loaded once when the loop starts (:func:`resident_load`) and
# written back (:func:`resident_store`) only where the state is read: an
# output, a non-finite state, the loop's return.  Row 0 (the centre of mass,
# which only drifts) stays in the (N, 3) arrays.  The drift
# (:func:`resident_drift`) and the perturbation steps (:func:`resident_kick`
# in Jacobi coordinates, :func:`resident_jump_kick` in democratic
# heliocentric ones) work on these rows with the operations of the scalar
# operators in their order, so the state is theirs bit for bit; the finite
# check (:func:`resident_finite`) is stepping.state_is_finite's sum, also
# in its order.  A padded column (a copy of the first planet) feels no
# pull, so it stays an orbit that the drift takes; where the drift declines
# it after all it becomes a copy of the first planet again.

#: the first row of the lanes' state in the scratch (after the drift's rows)
_R = DRIFT_ROWS
#: the state (x, y, z, vx, vy, vz), the drift's end state, each column's
#: Kepler G M, the drift's verdict, the pulls' sums (3), the inertial
#: positions (3, Jacobi), the weight m_i / eta_i (Jacobi), the Kepler terms
#: of the Jacobi kick (3)
_RX, _RY, _RMU, _RTAKE, _RA, _RQ, _RW, _RK = (_R, _R + 6, _R + 12, _R + 13, _R + 14, _R + 17,
                                              _R + 20, _R + 21)
#: the first rows of the lanes' state (x, y, z, vx, vy, vz) and of the
#: pulls' sums (3), for the kernels that work on that state
STATE, SUMS = _RX, _RA
#: the central body's factors 1 / r^3 in the Jacobi kick (the drift's end
#: rows, free during the kick)
_RF = _RY
#: the drift's passes' results (nine rows, see _pass_rows)
_T = _R + 24
#: rows of the scratch of a loop that keeps its state in the lanes
SCRATCH_ROWS = _R + 33


def _scratch_pass(S, h0, P):
    # every column of the scratch by the step h0: the short-step passes
    # (short_passes, the _pass_rows of that step), and the medium ones where
    # those declined a planet (_medium_first); specialised here, after the
    # rows it names (_T)
    if _medium_first(S):
        return _medium_scratch(S, h0, P)
    rejected = short_passes(S[_X], S[_X + 1], S[_X + 2], S[_X + 3], S[_X + 4], S[_X + 5],
                            S[_MU], S[_Y], S[_Y + 1], S[_Y + 2], S[_Y + 3], S[_Y + 4],
                            S[_Y + 5], S[_TAKE], S, _T, S[_H], h0, np.uint64(0), P)
    if rejected:
        S[MEMO, 1] = RETRY
        rejected = _medium_scratch(S, h0, P)
    return rejected


_single_pass = specialize(_scratch_pass, "one_step", inline=True, short_passes=_pass_rows_one)


def lanes_scratch_shape(n):
    """The shape of :func:`lanes_scratch` ``(n)``."""
    return (SCRATCH_ROWS, 2 * lane_columns(n))


@njit(inline="always")
def resident_load(xj, vj, gm, eta, S):
    """The planets of ``xj``, ``vj`` (rows 1 on) into the lanes' state, with
    their Kepler ``G M`` (``eta``) and Jacobi weights ``gm / eta``; the
    padding repeats planet 1."""
    n = xj.shape[0]
    for k in range(lane_columns(n)):
        i = k + 1 if k + 1 < n else 1
        for d in range(3):
            S[_RX + d, k] = xj[i, d]
            S[_RX + 3 + d, k] = vj[i, d]
        S[_RMU, k] = eta[i]
        S[_RW, k] = gm[i] / eta[i]


@njit(inline="always")
def resident_store(S, xj, vj):
    """The lanes' state back into rows 1 on of ``xj``, ``vj``."""
    for i in range(1, xj.shape[0]):
        for d in range(3):
            xj[i, d] = S[_RX + d, i - 1]
            vj[i, d] = S[_RX + 3 + d, i - 1]


@njit(inline="always")
def resident_drift(xj, vj, eta, h, S):
    """:func:`kepler_drift_lanes` of the lanes' state (row 0 of ``xj`` in a
    straight line), by the medium passes alone (see the module notes); a
    declined planet goes to the scalar drift, with its row of ``xj``, ``vj``
    as scratch.  Returns how many planets were declined."""
    declined = resident_drift_into(xj, vj, eta, h, S, _RY)
    P = np.uint64(lane_columns(xj.shape[0]))
    for r in range(6):
        X = S[_RX + r]
        Y = S[_RY + r]
        for k in range(P):
            X[k] = Y[k]
    return declined


@njit(inline="always")
def resident_drift_into(xj, vj, eta, h, S, dst):
    """:func:`resident_drift` of the lanes' state into the six rows from
    ``dst`` (the drift's end rows, or others of the scratch), the state's
    own rows left as they were; row 0 of ``xj`` drifts in place.  Returns
    how many planets were declined."""
    straight_drift(xj, vj, 0, h)
    P = lane_columns(xj.shape[0])
    rejected = _medium_resident(S, h, np.uint64(P), dst)
    declined = 0
    if rejected:
        declined = _resident_declined(xj, vj, eta, h, S, _RX, dst, _RTAKE, P)
    return declined


@njit(inline="always")
def _resident_declined(xj, vj, eta, h, S, src, dst, take, P):
    # the columns of the lanes' state that the drift by h declined (its
    # verdict in row take): the scalar drift from their start (rows src ..
    # src + 5) into rows dst ..; a declined padding column becomes a copy of
    # column 0.  Returns how many planets were declined.
    n = xj.shape[0]
    declined = 0
    for k in range(P):
        if S[take, k] != 0.0:
            continue
        if k < n - 1:
            i = k + 1
            for d in range(3):
                xj[i, d] = S[src + d, k]
                vj[i, d] = S[src + 3 + d, k]
            kepler_drift(eta[i], xj, vj, i, h)
            for d in range(3):
                S[dst + d, k] = xj[i, d]
                S[dst + 3 + d, k] = vj[i, d]
            declined += 1
        else:
            for r in range(6):
                S[dst + r, k] = S[dst + r, 0]
    return declined


@njit(inline="always")
def resident_drift_twice(xj, vj, eta, h, xs, vs, h2, S):
    """:func:`resident_drift` of the lanes' state by ``h``, and a copy of it
    drifted by ``h2`` into ``xs``, ``vs`` (shape (N, 3)), in the same
    passes, each bit for bit the scalar drift (with ``h2 = 0`` the copy is
    the state as it is).  The Wisdom-Holman loop's output: the copy is the
    state synchronised by the owed drift ``h2``, made beside the next
    step's first drift, whose long chains of dependent operations it
    overlaps (an output's drift made on its own added its whole latency to
    the step).  The copy's columns follow the state's padding in the
    state's rows, so that every row is copied and read whole: a vector load
    of columns stored one by one just before waits for those stores, which
    cost the copy packed after the state's planets more than its fewer
    columns saved (benchmarks/RESULTS.md).  Each column's step goes in row
    :data:`_H`.  Returns how many planets of the state were declined."""
    n = xj.shape[0]
    P = lane_columns(n)
    Pu = np.uint64(P)
    copy = h2 != 0.0
    for d in range(3):
        xs[0, d] = xj[0, d] + h2 * vj[0, d] if copy else xj[0, d]
        vs[0, d] = vj[0, d]
    H = S[_H]
    for k in range(Pu):
        H[k] = h
    if copy:
        for r in range(6):
            A = S[_RX + r]
            for k in range(Pu):
                A[Pu + k] = A[k]
        M = S[_RMU]
        for k in range(Pu):
            M[Pu + k] = M[k]
            H[Pu + k] = h2
    else:
        # nothing owed: the copy is the state as it is
        resident_store(S, xs, vs)
    straight_drift(xj, vj, 0, h)
    # (one pass over both, or over the state alone: the loop inlines one)
    rejected = medium_columns(S, _RX, _RMU, _RY, _RTAKE, _T, h, True,
                              Pu + Pu if copy else Pu)
    if copy:
        # the copy: a declined planet by the scalar drift from its start
        for i in range(1, n):
            k = P + i - 1
            row = _RY if S[_RTAKE, k] != 0.0 else _RX
            for d in range(3):
                xs[i, d] = S[row + d, k]
                vs[i, d] = S[row + 3 + d, k]
            if row == _RX:
                kepler_drift(eta[i], xs, vs, i, h2)
    declined = 0
    if rejected:
        declined = _resident_declined(xj, vj, eta, h, S, _RX, _RY, _RTAKE, P)
    for r in range(6):
        X = S[_RX + r]
        Y = S[_RY + r]
        for k in range(Pu):
            X[k] = Y[k]
    return declined


@njit(inline="always")
def resident_finite(xj, vj, S):
    """:func:`orbits._kernels.stepping.state_is_finite` of the state, row 0
    from ``xj``, ``vj`` and the planets from the lanes: the same sum in the
    same order (each row's six components, then the rows in order)."""
    n = xj.shape[0]
    P = lane_columns(n)
    C = S[_RY]
    for k in range(P):
        C[k] = (S[_RX, k] + S[_RX + 1, k] + S[_RX + 2, k] + S[_RX + 3, k] + S[_RX + 4, k]
                + S[_RX + 5, k])
    s = xj[0, 0] + xj[0, 1] + xj[0, 2] + vj[0, 0] + vj[0, 1] + vj[0, 2]
    for k in range(n - 1):
        s += C[k]
    return math.isfinite(s)


@njit(inline="always")
def zero_sums(S, P):
    """The pulls' sums (:data:`SUMS`) of the ``P`` columns set to zero."""
    for r in range(3):
        A = S[_RA + r]
        for k in range(P):
            A[k] = 0.0


@njit(inline="always")
def _resident_jump(S, gm, n_active, h, P):
    # wisdom_holman.jump on the lanes' state: the same sums in the same order
    jump_rows(S, gm, n_active, h, P, _RX, _RX)


@njit(inline="always")
def jump_shift(S, gm, n_active, h, vel):
    """The shift ``(px, py, pz)`` of every position in
    :func:`~orbits._kernels.wisdom_holman.jump` by ``h``, the velocities in
    the three rows from ``vel``: the same sums in the same order."""
    px = 0.0
    py = 0.0
    pz = 0.0
    for i in range(1, n_active):
        px += gm[i] * S[vel, i - 1]
        py += gm[i] * S[vel + 1, i - 1]
        pz += gm[i] * S[vel + 2, i - 1]
    s = h / gm[0]
    px *= s
    py *= s
    pz *= s
    return px, py, pz


@njit(inline="always")
def jump_rows(S, gm, n_active, h, P, src, dst):
    """:func:`~orbits._kernels.wisdom_holman.jump` by ``h`` of the state in
    the six rows from ``dst`` (its velocities there), its positions from
    the three rows from ``src`` (``src = dst``: in place): the same sums in
    the same order, over the ``P`` columns."""
    px, py, pz = jump_shift(S, gm, n_active, h, dst + 3)
    X = S[src]
    Y = S[src + 1]
    Z = S[src + 2]
    U = S[dst]
    V = S[dst + 1]
    W = S[dst + 2]
    for k in range(P):
        U[k] = X[k] + px
        V[k] = Y[k] + py
        W[k] = Z[k] + pz


@njit(inline="always")
def _resident_velocity_kick(S, h, P):
    kick_rows(S, h, P, _RX + 3, _RX + 3)


@njit(inline="always")
def kick_rows(S, h, P, src, dst):
    """The velocities in the three rows from ``src`` kicked by ``h`` times
    the pulls' sums (:data:`SUMS`), into the three rows from ``dst``
    (``src = dst``: in place), over the ``P`` columns."""
    for r in range(3):
        V = S[src + r]
        U = S[dst + r]
        A = S[_RA + r]
        for k in range(P):
            U[k] = V[k] + h * A[k]


@njit(inline="always")
def resident_jump(S, gm, n_active, h, n):
    """:func:`~orbits._kernels.wisdom_holman.jump` of the lanes' state of
    ``n`` bodies by ``h``, bit for bit."""
    _resident_jump(S, gm, n_active, h, np.uint64(lane_columns(n)))


@njit(inline="always")
def resident_pulls(S, gm, n_active, n):
    """The planets' mutual pulls on the lanes' state of ``n`` bodies (the
    central body's left out) into the sums' rows (:data:`SUMS`), summed over
    the sources in ascending order (:func:`~orbits._kernels.gravity.pull_rows`):
    bit for bit :func:`~orbits._kernels.gravity.pair_accelerations` from
    body 1."""
    pulls_rows(S, gm, n_active, n, _RX)


@njit(inline="always")
def pulls_rows(S, gm, n_active, n, src):
    """:func:`resident_pulls` of the positions in the three rows from ``src``."""
    Pu = np.uint64(lane_columns(n))
    zero_sums(S, Pu)
    X = S[src]
    Y = S[src + 1]
    Z = S[src + 2]
    for j in range(1, n_active):
        pull_rows(X, Y, Z, S[_RA], S[_RA + 1], S[_RA + 2], Pu, X[j - 1], Y[j - 1], Z[j - 1],
                  gm[j], np.uint64(j - 1), 0.0, np.uint64(n - 1))


@njit(inline="always")
def resident_velocity_kick(S, h, n):
    """The lanes' velocities of ``n`` bodies kicked by ``h`` times the sums."""
    _resident_velocity_kick(S, h, np.uint64(lane_columns(n)))


@njit(inline="always")
def resident_jump_kick(xj, vj, gm, n_active, h, S):
    """:func:`~orbits._kernels.wisdom_holman.jump_interaction_kick` of the
    lanes' state (democratic heliocentric), bit for bit: the half jump, the
    planets' pulls summed over the sources in ascending order
    (:func:`resident_pulls`, as
    :func:`~orbits._kernels.gravity.pair_accelerations_lanes` does), the
    kick, the half jump."""
    n = xj.shape[0]
    resident_jump(S, gm, n_active, 0.5 * h, n)
    resident_pulls(S, gm, n_active, n)
    resident_velocity_kick(S, h, n)
    resident_jump(S, gm, n_active, 0.5 * h, n)


@njit(inline="always")
def resident_kick(xj, vj, gm, n_active, h, S):
    """:func:`~orbits._kernels.wisdom_holman.interaction_kick` of the lanes'
    state (Jacobi coordinates; row 0, the centre of mass, from ``xj``), bit
    for bit: the inertial positions
    (:func:`~orbits._kernels.coordinates.from_jacobi_one`'s recurrence), the
    pulls of every pair but (0, 1) summed over the sources in ascending
    order, the central body's own sums, and the Jacobi transform of the
    accelerations with the Kepler terms (:func:`~orbits._kernels.
    wisdom_holman.jacobi_velocity_kick`'s recurrence)."""
    n = xj.shape[0]
    if n <= 2:
        return
    P = lane_columns(n)
    Pu = np.uint64(P)
    X = S[_RX]
    Y = S[_RX + 1]
    Z = S[_RX + 2]
    QX = S[_RQ]
    QY = S[_RQ + 1]
    QZ = S[_RQ + 2]
    W = S[_RW]
    # the inertial positions, from the outermost body in
    sx = xj[0, 0]
    sy = xj[0, 1]
    sz = xj[0, 2]
    for i in range(n - 1, 0, -1):
        k = i - 1
        w = W[k]
        sx -= w * X[k]
        sy -= w * Y[k]
        sz -= w * Z[k]
        QX[k] = X[k] + sx
        QY[k] = Y[k] + sy
        QZ[k] = Z[k] + sz
    # the padding: copies of body 1, which feel no pull
    for k in range(n - 1, P):
        QX[k] = QX[0]
        QY[k] = QY[0]
        QZ[k] = QZ[0]
    # the Kepler terms G eta_i x'_i / r'_i^3 of rows i >= 2 (columns 1 on)
    MU = S[_RMU]
    KX = S[_RK]
    KY = S[_RK + 1]
    KZ = S[_RK + 2]
    for k in range(P):
        rx = X[k]
        ry = Y[k]
        rz = Z[k]
        r2 = rx * rx + ry * ry + rz * rz
        s = MU[k] / (r2 * math.sqrt(r2))
        KX[k] = s * rx
        KY[k] = s * ry
        KZ[k] = s * rz
    zero_sums(S, Pu)
    real = np.uint64(n - 1)
    # the central body pulls every lane but body 1's (the pair (0, 1) is left
    # out); its factors 1 / r^3 kept for its own sums below
    F = S[_RF]
    pull_factors(QX, QY, QZ, F, Pu, sx, sy, sz, np.uint64(0), 0.0, real)
    pull_rows_factored(QX, QY, QZ, S[_RA], S[_RA + 1], S[_RA + 2], Pu, sx, sy, sz, gm[0],
                       np.uint64(0), F, real)
    for j in range(1, n_active):
        pull_rows(QX, QY, QZ, S[_RA], S[_RA + 1], S[_RA + 2], Pu, QX[j - 1], QY[j - 1],
                  QZ[j - 1], gm[j], np.uint64(j - 1), 0.0, real)
    # the central body's sums, pulled by the bodies after body 1 in order (a
    # pair's r^2 is the same whichever body its separation starts from)
    ax = 0.0
    ay = 0.0
    az = 0.0
    for i in range(2, n_active):
        dx = QX[i - 1] - sx
        dy = QY[i - 1] - sy
        dz = QZ[i - 1] - sz
        s = gm[i] * F[i - 1]
        ax += s * dx
        ay += s * dy
        az += s * dz
    # to Jacobi components: jacobi_velocity_kick's recurrence
    AX = S[_RA]
    AY = S[_RA + 1]
    AZ = S[_RA + 2]
    VX = S[_RX + 3]
    VY = S[_RX + 4]
    VZ = S[_RX + 5]
    for i in range(1, n):
        k = i - 1
        bx = AX[k] - ax
        by = AY[k] - ay
        bz = AZ[k] - az
        w = W[k]
        ax += w * bx
        ay += w * by
        az += w * bz
        if i >= 2:
            bx += KX[k]
            by += KY[k]
            bz += KZ[k]
        VX[k] += h * bx
        VY[k] += h * by
        VZ[k] += h * bz
