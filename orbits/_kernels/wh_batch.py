"""The Wisdom-Holman map for many systems at once, one system per vector lane.

:func:`advance_lanes` advances ``B`` independent systems of the same number
of bodies by the map ``K(h/2) I(h) K(h/2)`` in Jacobi coordinates (the
``wh`` integrator with its default options; see
:mod:`orbits._kernels.wisdom_holman` for the split), all with the same step.
The state is kept as structure of arrays with the systems in the innermost
axis: Jacobi positions and velocities of shape (N, 3, B), masses of shape
(N, B).  Inside a call the loop works on a copy laid out component first,
``X[c, i B + b]``: the Kepler drifts, independent of each other, are then
loops over all ``(N - 1) B`` rows of all systems at once, and the
interaction kick is a few loops over the B systems per body and per pair
(its sums over bodies run in the scalar kernel's order), or, for systems of
3 to :data:`UNROLLED_KICK_BODIES` bodies, one loop over the systems with
every pair written out for that size (:func:`advance_loop`; see "the kick
unrolled for one size of system" below).  Every such loop
does the same operations for each element, so that LLVM turns it into
vector instructions (four systems in an AVX2 register, eight with AVX-512)
without a line of hand-written vector code.  Two things keep LLVM from doing
so and are avoided: a loop whose index numba cannot prove non-negative (it
then tests for negative indices, which Python allows, element by element:
the loops over the systems use unsigned indices) and a branch inside the
loop on a flag that is the same for every element (the drift's loops are
written out once for each value of it).  The loops pay a fixed cost each
time they start, so that batches of 16 systems or more gain most and a
batch of one is several times slower than ``wh`` on its own
(``benchmarks/bench_batch.py``).

Each system gets, bit for bit, the arithmetic of the scalar kernels of
:mod:`orbits._kernels.wisdom_holman`: the same operations in the same order
(fastmath is off, so LLVM neither reassociates nor fuses them; the Kepler
helpers' fused multiply-adds are explicit, :func:`orbits._kernels._jit.fma`,
in the scalar code too; and a vector instruction rounds each element as its
scalar form does).  Where the
scalar code branches, the lanes compute both sides and keep one with a
select, never a branch per lane:

* The Kepler drift (:func:`kepler_drift_lanes`) is
  :func:`~orbits._kernels.kepler.kepler_drift`'s short-step path.  It first
  runs as the single system's lanes do
  (:func:`orbits._kernels.wh_lanes.drift_columns`: the starter, one
  iteration and the f and g functions in passes over every body of every
  system), which takes the usual planetary step; the elements those passes
  decline go to the scalar drift where they are few (fewer than one in
  :data:`FEW`).  Where they are more (the Sun and eight planets at a day:
  Mercury in every system, one in eight), the medium passes
  (:func:`orbits._kernels.wh_lanes.medium_rows`: the nine-term Stumpff
  series and a second iteration where a column needs it) take them, the
  steps people use, a twentieth of the innermost period, in every element
  at once, and the next :data:`~orbits._kernels.wh_lanes.RETRY` drifts go
  straight to those; what they decline goes to the scalar drift where few,
  else to the masked form below, which takes them all with their
  iterations.  The passes, three loops (starter, iteration, f and g; see
  ``wh_lanes``) inlined into the step, make the usual drift quicker than
  the masked form's iterations (benchmarks/RESULTS.md).  The masked form:
  the fifth-order Taylor starter of the universal anomaly and Danby's quartic
  iteration, repeated until every lane has converged (at most
  ``_SHORT_STEP_ITER`` times; a lane that has converged keeps its anomaly
  while the others go on, as the scalar loop would have stopped there).
  The Stumpff functions take the same branch-free form: the four-term
  series everywhere and, only when some lane's argument is beyond it, the
  nine-term series (``|z| <= 1``) and the seven-term series after a masked
  number of quarterings of the argument (at most three, which covers ``|z|
  <= 4``), each lane taking the scalar form's.
* A lane outside that domain (a step long against its orbit, ``|dt| |v| >=
  r`` or more than a radian of eccentric anomaly; no convergence in
  three iterations; a Stumpff argument beyond 4; a non-positive radius at
  the end) is drifted by the scalar
  :func:`~orbits._kernels.kepler.kepler_drift` on its own, from the same
  start, which is what the scalar map does for it too, so that accuracy is
  never lost: high eccentricities, near-parabolic and hyperbolic orbits are
  solved by its bracketed solver.

A system whose state turns non-finite is frozen at its last good state and
reported (``status``, ``good``); the others go on.  The state is tested,
as the scalar loops test it, every :data:`CHECK_EVERY` steps, and a copy of
all lanes taken at the start of each such block lets a failed lane be
replayed alone, step by step, to the step that failed.

References
----------
Wisdom, J. & Holman, M. 1991, AJ 102, 1528 (the map).  Rein, H. & Tamayo, D.
2015, MNRAS 452, 376 (WHFast: lazy synchronisation, the Kepler solver's
starter and iteration).  Javaheri, P., Rein, H. & Tamayo, D. 2023, "WHFast512:
a symplectic N-body integrator for planetary systems optimized with AVX512
instructions", Open J. Astrophys. 6 (systems in vector lanes, an iteration
count that does not branch per lane).  Danby, J. M. A. 1988, *Fundamentals of
Celestial Mechanics*, 2nd ed., sect. 6.9 (universal variables).
"""

import importlib.util
import math
import os
import sys
import tempfile
from typing import NamedTuple

import numpy as np

from numba import types as nbtypes

from ._jit import KERNEL_STAMP, contiguous_data, njit, pointer, slots, specialize, value
from .coordinates import interior_gm, to_jacobi
from .gravity import aligned_zeros
from .kepler import (_SHORT_STEP, _SHORT_STEP_ITER, _SHORT_STEP_TOL, _SHORT_STEP_Z,
                     advanced_state, dot3, f_and_g, kepler_drift, quartic_step, short_start)
from .stumpff import _STUMPFF_SHORT_Z
# the Stumpff functions without a branch (shared with orbits._kernels.wh_lanes)
from .stumpff import stumpff_lane as _stumpff_lane
from .invariants import MONITOR_WIDTH, monitor_row
from .status import Status
from .wh_lanes import RETRY, column_start, drift_columns, medium_rows
from .wisdom_holman import synchronize

# the names the templates below are written against, bound by specialize
kick, lane_step = slots("kick", "lane_step")

__all__ = ["CHECK_EVERY", "SCRATCH_ROWS", "Lanes", "Scratch", "lanes_workspace", "kepler_drift_lanes",
           "interaction_kick_lanes", "advance_lanes", "advance_loop", "unrolled_kick",
           "UNROLLED_KICK_BODIES", "record_lanes", "to_lanes", "from_lanes", "lane_inertial"]

#: Steps between the tests of the lanes' states for NaN and inf (as the
#: scalar loops' ``check_every``): a block of this many steps is replayed for
#: a lane that failed in it.
CHECK_EVERY = 16

#: The drift's passes (:func:`orbits._kernels.wh_lanes.drift_columns`)
#: leave the elements they decline to the scalar drift while they are fewer
#: than one in FEW of all, and to the medium passes when there are more
#: (what those decline: the scalar drift again, or the masked short-step
#: path with its iterations, :func:`_masked_drift`, when more than one in
#: FEW).
FEW = 8

#: rows of the scratch ``d``: the drift's end state (0-5), the kick's
#: weights (6), the masked drift's lanes (7), the written-out kick's masses
#: (8-9; its positions and live flags in 0-3 between drifts), the rows the
#: drift's passes keep for the next (_DT on, nine), and in column 0 of row
#: _MEMO the drifts left that go straight to the medium passes
_DT = 10
_MEMO = _DT + 9
SCRATCH_ROWS = _MEMO + 1


class Lanes(NamedTuple):
    """The systems a batch advances, lane ``b`` system ``b``: their Jacobi
    positions and velocities ``xj``, ``vj`` (N, 3, B), ``G`` times the
    masses ``gm`` and the interior masses ``eta`` (N, B,
    :func:`orbits._kernels.coordinates.interior_gm` of each column), the
    closing half drift each lane still owes ``owed`` (0 before its first
    step; :func:`orbits._kernels.wisdom_holman.synchronize` applies it),
    ``live`` (1.0 for a system that goes on, 0.0 for one frozen), and per
    lane ``status`` and ``good`` (the steps of a call it completed)."""
    xj: np.ndarray
    vj: np.ndarray
    gm: np.ndarray
    eta: np.ndarray
    owed: np.ndarray
    live: np.ndarray
    status: np.ndarray
    good: np.ndarray


class Scratch(NamedTuple):
    """:func:`advance_lanes`'s scratch (:func:`lanes_workspace`): the state
    in the lanes' layout (``X``, ``V``), the interaction's positions and
    accelerations (``XI``, ``ACC``), the masses (``GM``, ``MU``), the live
    flags ``LF``, the drift's rows ``d`` and flags ``fl``, the kick's sums
    (``s3``, ``a3``, ``t4``), a block's start (``ckx``, ``ckv``), a lane's
    rows (``px``, ``pv``), the central body's kick (``one_x``, ``one_v``)
    and one lane's flags ``lf1``."""
    X: np.ndarray
    V: np.ndarray
    XI: np.ndarray
    ACC: np.ndarray
    GM: np.ndarray
    MU: np.ndarray
    LF: np.ndarray
    d: np.ndarray
    fl: np.ndarray
    s3: np.ndarray
    a3: np.ndarray
    t4: np.ndarray
    ckx: np.ndarray
    ckv: np.ndarray
    px: np.ndarray
    pv: np.ndarray
    one_x: np.ndarray
    one_v: np.ndarray
    lf1: np.ndarray


def lanes_workspace(n, b):
    """The scratch arrays of :func:`advance_lanes` for ``b`` systems of ``n``
    bodies (a :class:`Scratch`).

    Examples
    --------
    >>> from orbits._kernels.wh_batch import lanes_workspace
    >>> ws = lanes_workspace(3, 4)
    >>> ws.X.shape, ws.d.shape[1]
    ((3, 12), 12)
    """
    m = n * b
    z = aligned_zeros   # each array from a cache line on, as the planets' lanes'
    return Scratch(z((3, m)), z((3, m)), z((3, m)), z((3, m)), z(m), z(m), z(m),
                   z((SCRATCH_ROWS, m)), z((3, m)), z((3, b)), z((3, b)), z((4, b)), z((3, m)),
                   z((3, m)), z((n, 3)), z((n, 3)), z((1, 3)), z((1, 3)), z(m))


@njit(inline="always")
def _components(A):
    # the rows 0, 1 and 2 of A (views): a state's x, y and z over the lanes
    return A[0], A[1], A[2]


@njit(inline="always")
def _needs_general(beta, s, ok, live, k0, m):
    # whether some element that iterates has a Stumpff argument beyond the
    # four-term series
    wide = 0
    for k in range(np.uint64(k0), np.uint64(m)):
        z = beta[k] * s[k] * s[k]
        wide += 1 if (ok[k] * live[k] != 0.0 and not (abs(z) <= _STUMPFF_SHORT_Z)) else 0
    return wide > 0


@njit(inline="always")
def _iterate(s_, r0_, et_, be_, ze_, ok_, cv_, LF, h, nb, m, general):
    # one quartic iteration in every element still iterating (see
    # kepler_drift_lanes); returns how many have not converged
    pending = 0
    for k in range(np.uint64(nb), np.uint64(m)):
        s, r0, et, beta, zeta = s_[k], r0_[k], et_[k], be_[k], ze_[k]
        c0, c1, c2, c3, inside = _stumpff_lane(beta * s * s, general)
        dd = quartic_step(s, r0, et, beta, zeta, c0, c1, c2, c3, h)
        sn = s + dd
        done = abs(dd) <= _SHORT_STEP_TOL * abs(sn)
        going = ok_[k] * LF[k] != 0.0 and cv_[k] == 0.0
        s_[k] = sn if going else s
        cv_[k] = (1.0 if done else 0.0) if going else cv_[k]
        ok_[k] = (1.0 if inside else 0.0) if going else ok_[k]
        pending += 1 if (going and inside and not done) else 0
    return pending


@njit(inline="always")
def _advance(X0, X1, X2, V0, V1, V2, MU, s_, r0_, ir0_, be_, ze_, ok_, cv_, LF, alone, nb, m,
             general):
    # every converged element advanced by its anomaly with the f and g
    # functions (see kepler_drift_lanes); returns how many are left to the
    # scalar drift
    n_alone = 0
    for k in range(np.uint64(nb), np.uint64(m)):
        mu, x0, y0, z0, vx0, vy0, vz0 = column_start(X0, X1, X2, V0, V1, V2, MU, k)
        s, r0, ir0, beta, zeta = s_[k], r0_[k], ir0_[k], be_[k], ze_[k]
        sig = dot3(x0, y0, z0, vx0, vy0, vz0)
        c0, c1, c2, c3, inside = _stumpff_lane(beta * s * s, general)
        _, _, r, ir, fm1, g, fdot, gdm1 = f_and_g(mu, s, r0, ir0, sig, zeta, c1, c2)
        live = LF[k] != 0.0
        take = live and ok_[k] != 0.0 and cv_[k] != 0.0 and inside and r > 0.0
        x1, y1, z1, vx1, vy1, vz1 = advanced_state(x0, y0, z0, vx0, vy0, vz0, fm1, g, fdot,
                                                   gdm1)
        X0[k] = x1 if take else x0
        X1[k] = y1 if take else y0
        X2[k] = z1 if take else z0
        V0[k] = vx1 if take else vx0
        V1[k] = vy1 if take else vy0
        V2[k] = vz1 if take else vz0
        leave = live and not take
        alone[k] = 1.0 if leave else 0.0
        n_alone += 1 if leave else 0
    return n_alone


@njit(inline="always")
def _scalar_drifts(X, V, MU, h, alone, nb, one_x, one_v):
    # the elements with alone != 0 drifted one by one by the scalar
    # kepler_drift, from their start (one_x, one_v: its scratch)
    for k in range(np.uint64(nb), np.uint64(X.shape[1])):
        if alone[k] != 0.0:
            for c in range(3):
                one_x[0, c] = X[c, k]
                one_v[0, c] = V[c, k]
            kepler_drift(MU[k], one_x, one_v, value(0), h)
            for c in range(3):
                X[c, k] = one_x[0, c]
                V[c, k] = one_v[0, c]


@njit(inline="always")
def _masked_drift(X, V, MU, h, LF, nb, d, fl, one_x, one_v):
    # kepler_drift's short-step path in every element with LF != 0 at once
    # (the others keep their state): Danby's iteration repeated until every
    # such element has converged, the general Stumpff form where some
    # argument needs it; the elements it declines in fl[2], drifted by the
    # scalar kepler_drift from the same start
    m = X.shape[1]
    X0, X1, X2 = _components(X)
    V0, V1, V2 = _components(V)
    # the passes' rows: the anomaly, the start's radius and its inverse,
    # eta, beta and zeta; the verdicts (in the domain, converged, left alone)
    s_, r0_, ir0_, et_, be_, ze_ = d[0], d[1], d[2], d[3], d[4], d[5]
    ok_, cv_, alone = fl[0], fl[1], fl[2]
    # the starter (orbits._kernels.kepler.short_step_anomaly)
    for k in range(np.uint64(nb), np.uint64(m)):
        mu, x0, y0, z0, vx0, vy0, vz0 = column_start(X0, X1, X2, V0, V1, V2, MU, k)
        r2, v2, r0, ir0, et, beta, zeta, s = short_start(mu, x0, y0, z0, vx0, vy0, vz0, h)
        good = (h * h * v2 < (_SHORT_STEP * _SHORT_STEP) * r2 and mu > 0.0 and h != 0.0
                and abs(beta * s * s) <= _SHORT_STEP_Z)
        s_[k] = s
        r0_[k] = r0
        ir0_[k] = ir0
        et_[k] = et
        be_[k] = beta
        ze_[k] = zeta
        ok_[k] = 1.0 if good else 0.0
        cv_[k] = 0.0
    # Danby's quartic iteration, until every element has converged; the
    # loop is written out twice, with and without the general Stumpff form,
    # so that the usual case carries none of the other's work
    for _ in range(_SHORT_STEP_ITER):
        if _needs_general(be_, s_, ok_, LF, nb, m):
            pending = _iterate(s_, r0_, et_, be_, ze_, ok_, cv_, LF, h, nb, m, True)
        else:
            pending = _iterate(s_, r0_, et_, be_, ze_, ok_, cv_, LF, h, nb, m, False)
        if pending == 0:
            break
    # the f and g functions (orbits._kernels.kepler._short_coefficients)
    if _needs_general(be_, s_, ok_, LF, nb, m):
        n_alone = _advance(X0, X1, X2, V0, V1, V2, MU, s_, r0_, ir0_, be_, ze_, ok_, cv_, LF,
                           alone, nb, m, True)
    else:
        n_alone = _advance(X0, X1, X2, V0, V1, V2, MU, s_, r0_, ir0_, be_, ze_, ok_, cv_, LF,
                           alone, nb, m, False)
    # the elements outside the domain: the scalar drift, from the same start
    if n_alone:
        _scalar_drifts(X, V, MU, h, alone, nb, one_x, one_v)


@njit
def kepler_drift_lanes(X, V, MU, h, LF, nb, d, fl, one_x, one_v):
    """Drift every system's Jacobi rows by ``h``: row ``i >= 1`` on its orbit
    about its ``mu``, the centre of mass (row 0) in a straight line; elements
    with ``LF == 0`` (frozen lanes) are left as they are.

    Parameters
    ----------
    X, V : ndarray, shape (3, N B)
        Jacobi positions and velocities, component first, then body ``i`` of
        system ``b`` at ``i B + b``: every body of every system in one
        contiguous row, so that the drifts (independent of each other) run
        in one loop of ``(N - 1) B`` elements.  In place.
    MU : ndarray, shape (N B,)
        G times the interior masses (each row's Kepler ``mu``), laid out alike.
    h : float
        The step.
    LF : ndarray, shape (N B,)
        1.0 for the elements of the lanes to drift, 0.0 for frozen ones.
    nb : int
        B, the systems.
    d, fl : ndarray, shapes (:data:`SCRATCH_ROWS`, N B) and (3, N B)
        Scratch (the drift uses rows 0 to 5 and 10 to 19 of ``d``).
    one_x, one_v : ndarray, shape (1, 3)
        Scratch for the scalar drift of an element outside the lanes' domain.

    Notes
    -----
    Per element, bit for bit :func:`orbits._kernels.kepler.kepler_drift`
    (see the module notes): its short-step path in every element at once,
    and its own call for an element that path declines.
    """
    _drift_lanes(X, V, MU, h, LF, nb, d, fl, one_x, one_v)


@njit(inline="always")
def _drift_lanes(X, V, MU, h, LF, nb, d, fl, one_x, one_v):
    # kepler_drift_lanes, inlined into the loops that step: its passes are
    # quicker inlined than as a call of its own (benchmarks/RESULTS.md)
    m = X.shape[1]
    X0, X1, X2 = _components(X)
    V0, V1, V2 = _components(V)
    for k in range(nb):
        if LF[k] != 0.0:
            X0[k] += h * V0[k]
            X1[k] += h * V1[k]
            X2[k] += h * V2[k]
    # the usual planetary step of every body of every system in three passes
    # (orbits._kernels.wh_lanes.drift_columns, the scalar short-step path's
    # operations in its order), into rows 0 to 5 of d with the verdicts in
    # fl[0] (the passes' results in rows _DT on); the others, and frozen
    # lanes, keep their start
    Y0, Y1, Y2 = _components(d)
    U0 = d[3]
    U1 = d[4]
    U2 = d[5]
    take = fl[0]
    alone = fl[2]
    # after the short passes declined many elements, the next RETRY drifts
    # go straight to the medium passes (in _declined_drifts): the short
    # passes then run over no column, and every live element is left to them
    medium = d[_MEMO, 0] > 0.0
    k0 = np.uint64(m) if medium else np.uint64(nb)
    declined = drift_columns(X0, X1, X2, V0, V1, V2, MU, Y0, Y1, Y2, U0, U1, U2, take, d, _DT,
                             h, k0, np.uint64(m))
    for k in range(np.uint64(nb), np.uint64(m)):
        keep = (take[k] * LF[k] != 0.0) & (not medium)
        X0[k] = Y0[k] if keep else X0[k]
        X1[k] = Y1[k] if keep else X1[k]
        X2[k] = Y2[k] if keep else X2[k]
        V0[k] = U0[k] if keep else V0[k]
        V1[k] = U1[k] if keep else V1[k]
        V2[k] = U2[k] if keep else V2[k]
        alone[k] = 1.0 if (LF[k] != 0.0) & ((take[k] == 0.0) | medium) else 0.0
    # the live elements the passes declined (a step long against an orbit,
    # more than one iteration), in a function of its own: inlined at both of
    # the loop's steps, with the scalar drift's solver inlined in it twice,
    # they would take most of the batch loop's compilation
    if declined or medium:
        _declined_drifts(X, V, MU, h, LF, nb, d, fl, one_x, one_v, medium)


@njit
def _declined_drifts(X, V, MU, h, LF, nb, d, fl, one_x, one_v, medium):
    # the elements of fl[2] that the passes declined (with medium, every
    # live element: the short passes ran over none).  Where they are one in
    # FEW or more, the medium passes (wh_lanes.medium_rows: the
    # nine-term Stumpff series, a second iteration where a column needs
    # it; the steps people use) take those they can, and the next RETRY
    # drifts go straight to them; the rest: few, the scalar drift from the
    # same start; more, the masked short-step path in every element with
    # its iterations
    m = X.shape[1]
    alone = fl[2]
    n_alone = 0
    for k in range(np.uint64(nb), np.uint64(m)):
        n_alone += 1 if alone[k] != 0.0 else 0
    if medium:
        d[_MEMO, 0] -= 1.0
    elif FEW * n_alone >= m - nb:
        d[_MEMO, 0] = RETRY
        medium = True
    if medium:
        X0, X1, X2 = _components(X)
        V0, V1, V2 = _components(V)
        Y0, Y1, Y2 = _components(d)
        U0 = d[3]
        U1 = d[4]
        U2 = d[5]
        take = fl[0]
        medium_rows(X0, X1, X2, V0, V1, V2, MU, Y0, Y1, Y2, U0, U1, U2, take, d, _DT, MU, False,
                    h, np.uint64(nb), np.uint64(m))
        n_alone = 0
        for k in range(np.uint64(nb), np.uint64(m)):
            keep = (alone[k] != 0.0) & (take[k] != 0.0)
            X0[k] = Y0[k] if keep else X0[k]
            X1[k] = Y1[k] if keep else X1[k]
            X2[k] = Y2[k] if keep else X2[k]
            V0[k] = U0[k] if keep else V0[k]
            V1[k] = U1[k] if keep else V1[k]
            V2[k] = U2[k] if keep else V2[k]
            left = (alone[k] != 0.0) & (take[k] == 0.0)
            alone[k] = 1.0 if left else 0.0
            n_alone += 1 if left else 0
        if n_alone == 0:
            return
    if FEW * n_alone > m - nb:
        mask = d[7]
        for k in range(np.uint64(nb), np.uint64(m)):
            mask[k] = alone[k]
        _masked_drift(X, V, MU, h, mask, nb, d, fl, one_x, one_v)
    else:
        _scalar_drifts(X, V, MU, h, alone, nb, one_x, one_v)


@njit
def interaction_kick_lanes(X, V, XI, ACC, GM, MU, WQ, n_active, h, LF, nb, s3, a3, t4):
    """Kick every system's Jacobi velocities by ``h`` times the interaction
    accelerations (:func:`orbits._kernels.wisdom_holman.interaction_kick`,
    bit for bit, per lane); frozen lanes (``LF == 0``) are left as they are.

    Parameters
    ----------
    X, V : ndarray, shape (3, N B)
        Jacobi positions and velocities, laid out as in
        :func:`kepler_drift_lanes`; ``V`` in place.
    XI, ACC : ndarray, shape (3, N B)
        Scratch: the inertial positions and accelerations.
    GM, MU : ndarray, shape (N B,)
        G times the masses, and the interior masses.
    WQ : ndarray, shape (N B,)
        ``GM / MU``, the weights of the Jacobi transformation.
    n_active : int
        Massive bodies (the first ``n_active`` rows), the same in every system.
    h : float
    LF : ndarray, shape (N B,)
    nb : int
    s3, a3, t4 : ndarray, shapes (3, B), (3, B) and (4, B)
        Scratch.
    """
    m = X.shape[1]
    n = m // nb
    if n <= 2:
        return
    # unsigned indices: numba then adds no test for negative ones, which
    # would keep LLVM from vectorising the loops over the systems
    unb = np.uint64(nb)
    # inertial positions (orbits._kernels.coordinates.from_jacobi_one)
    J0, J1, J2 = _components(X)
    X0, X1, X2 = _components(XI)
    S0, S1, S2 = _components(s3)
    for b in range(unb):
        S0[b] = J0[b]
        S1[b] = J1[b]
        S2[b] = J2[b]
    for i in range(n - 1, 0, -1):
        o = np.uint64(i * nb)
        for b in range(unb):
            k = o + b
            w = WQ[k]
            S0[b] -= w * J0[k]
            X0[k] = J0[k] + S0[b]
            S1[b] -= w * J1[k]
            X1[k] = J1[k] + S1[b]
            S2[b] -= w * J2[k]
            X2[k] = J2[k] + S2[b]
    for b in range(unb):
        X0[b] = S0[b]
        X1[b] = S1[b]
        X2[b] = S2[b]
    # every pair but (0, 1) (orbits._kernels.gravity.pair_accelerations):
    # three short loops over the systems a pair (the separation, the pull on
    # the later body, the reaction on the earlier one), which LLVM vectorises
    # better than one loop with all three
    A0, A1, A2 = _components(ACC)
    for k in range(m):
        A0[k] = 0.0
        A1[k] = 0.0
        A2[k] = 0.0
    p0, p1, p2 = _components(a3)
    t0, t1, t2 = _components(t4)
    q = t4[3]
    for i in range(1, n):
        oi = np.uint64(i * nb)
        for b in range(unb):
            p0[b] = 0.0
            p1[b] = 0.0
            p2[b] = 0.0
        for j in range(1 if i == 1 else 0, min(i, n_active)):
            oj = np.uint64(j * nb)
            for b in range(unb):
                dx = X0[oi + b] - X0[oj + b]
                dy = X1[oi + b] - X1[oj + b]
                dz = X2[oi + b] - X2[oj + b]
                r2 = dx * dx + dy * dy + dz * dz
                t0[b] = dx
                t1[b] = dy
                t2[b] = dz
                q[b] = 1.0 / (r2 * math.sqrt(r2))
            for b in range(unb):
                sj = GM[oj + b] * q[b]
                p0[b] -= sj * t0[b]
                p1[b] -= sj * t1[b]
                p2[b] -= sj * t2[b]
            if i < n_active:
                for b in range(unb):
                    si = GM[oi + b] * q[b]
                    A0[oj + b] += si * t0[b]
                    A1[oj + b] += si * t1[b]
                    A2[oj + b] += si * t2[b]
        for b in range(unb):
            A0[oi + b] += p0[b]
            A1[oi + b] += p1[b]
            A2[oi + b] += p2[b]
    # to Jacobi components, with the Kepler terms of rows i >= 2
    # (orbits._kernels.wisdom_holman.jacobi_velocity_kick)
    for b in range(unb):
        S0[b] = A0[b]
        S1[b] = A1[b]
        S2[b] = A2[b]
    W0, W1, W2 = _components(V)
    for i in range(1, n):
        o = np.uint64(i * nb)
        for b in range(unb):
            k = o + b
            w = WQ[k]
            ax = A0[k] - S0[b]
            ay = A1[k] - S1[b]
            az = A2[k] - S2[b]
            S0[b] += w * ax
            S1[b] += w * ay
            S2[b] += w * az
            if i >= 2:
                rx = J0[k]
                ry = J1[k]
                rz = J2[k]
                r2 = rx * rx + ry * ry + rz * rz
                s = MU[k] / (r2 * math.sqrt(r2))
                ax += s * rx
                ay += s * ry
                az += s * rz
            keep = LF[k] != 0.0
            W0[k] = W0[k] + h * ax if keep else W0[k]
            W1[k] = W1[k] + h * ay if keep else W1[k]
            W2[k] = W2[k] + h * az if keep else W2[k]


def _step(X, V, GM, MU, n_active, dt, owed, LF, nb, XI, ACC, d, fl, s3, a3, t4, one_x,
          one_v, unrolled):
    # one step of K(h/2) I(h) K(h/2) with the closing half drift deferred (as
    # orbits._kernels.wisdom_holman's loop does with the table WH_DKD):
    # returns the drift now owed.  kick: bound by specialize (_any_size_kick,
    # or _pointer_kick, which calls the unrolled kick it is handed)
    _drift_lanes(X, V, MU, 0.5 * dt + owed, LF, nb, d, fl, one_x, one_v)
    kick(X, V, XI, ACC, GM, MU, n_active, 1.0 * dt, LF, nb, d, s3, a3, t4, unrolled)
    return 0.5 * dt


@njit(inline="always")
def _any_size_kick(X, V, XI, ACC, GM, MU, n_active, h, LF, nb, d, s3, a3, t4, unrolled):
    interaction_kick_lanes(X, V, XI, ACC, GM, MU, d[6], n_active, h, LF, nb, s3, a3, t4)


#: the step of advance_lanes, for systems of any size; advance_loop binds
#: the step with an unrolled_kick instead
_any_size_step = specialize(_step, "any_size", inline=True, kick=_any_size_kick)


@njit(inline="always")
def _lane_finite(X, V, nb, b):
    # orbits._kernels.stepping.state_is_finite, of lane b
    s = 0.0
    for i in range(X.shape[1] // nb):
        k = i * nb + b
        s += X[0, k] + X[1, k] + X[2, k] + V[0, k] + V[1, k] + V[2, k]
    return math.isfinite(s)


def _advance_lanes(lanes, n_active, dt, nsteps, scratch, unrolled=None):
    """Advance every live system ``nsteps`` steps of the Wisdom-Holman map.

    Parameters
    ----------
    lanes : Lanes
        The systems, advanced in place: ``xj``, ``vj``, ``owed`` (the live
        lanes owe the same), ``live``, ``status`` and ``good``.  A lane
        that fails here gets ``Status.NON_FINITE`` in ``status``; ``xj``,
        ``vj`` and ``owed`` keep its state after its good steps, and
        ``live`` turns 0.
    n_active : int
        Massive bodies, the first rows (the same in every system).
    dt : float
        The step.
    nsteps : int
    scratch : Scratch
        :func:`lanes_workspace`'s arrays.  The loop works on the state laid
        out as :func:`kepler_drift_lanes` says, copied in at the start of
        the call and out at its end.
    unrolled : Pointer, optional
        The kick written out for these systems' size (:func:`advance_loop`),
        for the loop compiled to call it; the loop of systems of any size
        (:data:`advance_lanes`) takes none.

    Returns
    -------
    failed : int
        Lanes that failed in this call.

    Examples
    --------
    >>> import numpy as np
    >>> from orbits._kernels import wh_batch
    >>> gm = np.array([[1.0, 1.0], [1e-3, 2e-3], [1e-3, 1e-3]])   # (N, B): two systems
    >>> x = np.zeros((3, 3, 2)); v = np.zeros((3, 3, 2))
    >>> x[1, 0], v[1, 1] = 1.0, 1.0                               # circular planets
    >>> x[2, 0], v[2, 1] = 2.0, 0.5 ** 0.5
    >>> xj, vj, eta = wh_batch.to_lanes(x, v, gm)
    >>> lanes = wh_batch.Lanes(xj, vj, gm, eta, owed=np.zeros(2), live=np.ones(2),
    ...                        status=np.zeros(2, dtype=np.int64),
    ...                        good=np.zeros(2, dtype=np.int64))
    >>> wh_batch.advance_lanes(lanes, 3, 0.01, 100, wh_batch.lanes_workspace(3, 2))
    0
    >>> lanes.owed, lanes.good
    (array([0.005, 0.005]), array([100, 100]))
    """
    xj, vj, gm, eta, owed, live, status, good = lanes
    (X, V, XI, ACC, GM, MU, LF, d, fl, s3, a3, t4, ckx, ckv, px, pv, one_x, one_v,
     lf1) = scratch
    n = xj.shape[0]
    nb = xj.shape[2]
    failed = 0
    for b in range(nb):
        if live[b] != 0.0:
            good[b] = 0
    if nsteps <= 0:
        return failed
    for i in range(n):
        for b in range(nb):
            k = i * nb + b
            for c in range(3):
                X[c, k] = xj[i, c, b]
                V[c, k] = vj[i, c, b]
            GM[k] = gm[i, b]
            MU[k] = eta[i, b]
            # the kick's mass ratios, once a call rather than twice a step,
            # and the masses where the unrolled kick reads them
            d[6, k] = gm[i, b] / eta[i, b]
            d[8, k] = gm[i, b]
            d[9, k] = eta[i, b]
            LF[k] = live[b]
    # every live lane owes the same: that of the first live one
    ow = 0.0
    for b in range(nb):
        if live[b] != 0.0:
            ow = owed[b]
            break
    step = 0
    while step < nsteps:
        blk = min(CHECK_EVERY, nsteps - step)
        # the block's start, for a lane that fails in it
        for c in range(3):
            for k in range(n * nb):
                ckx[c, k] = X[c, k]
                ckv[c, k] = V[c, k]
        ow0 = ow
        for _ in range(blk):
            ow = lane_step(X, V, GM, MU, n_active, dt, ow, LF, nb, XI, ACC, d, fl, s3, a3,
                           t4, one_x, one_v, unrolled)
        for b in range(nb):
            if live[b] == 0.0 or _lane_finite(X, V, nb, b):
                continue
            # replay lane b alone from the block's start, to its last good step
            for i in range(n):
                k = i * nb + b
                for c in range(3):
                    X[c, k] = ckx[c, k]
                    V[c, k] = ckv[c, k]
            for k in range(n * nb):
                lf1[k] = 0.0
            for i in range(n):
                lf1[i * nb + b] = 1.0
            owr = ow0
            done = 0
            for _ in range(blk):
                for i in range(n):
                    k = i * nb + b
                    for c in range(3):
                        px[i, c] = X[c, k]
                        pv[i, c] = V[c, k]
                nxt = lane_step(X, V, GM, MU, n_active, dt, owr, lf1, nb, XI, ACC, d, fl, s3,
                                a3, t4, one_x, one_v, unrolled)
                if not _lane_finite(X, V, nb, b):
                    for i in range(n):
                        k = i * nb + b
                        for c in range(3):
                            X[c, k] = px[i, c]
                            V[c, k] = pv[i, c]
                    break
                owr = nxt
                done += 1
            live[b] = 0.0
            for i in range(n):
                LF[i * nb + b] = 0.0
            owed[b] = owr
            status[b] = Status.NON_FINITE
            good[b] = step + done
            failed += 1
        step += blk
    for i in range(n):
        for b in range(nb):
            k = i * nb + b
            for c in range(3):
                xj[i, c, b] = X[c, k]
                vj[i, c, b] = V[c, k]
    for b in range(nb):
        if live[b] != 0.0:
            owed[b] = ow
            good[b] = nsteps
    return failed


#: the batch loop for systems of any size (see :func:`_advance_lanes`)
advance_lanes = specialize(_advance_lanes, "any_size", lane_step=_any_size_step)


# -- the kick unrolled for one size of system ---------------------------------------
#
# interaction_kick_lanes runs a few short loops over the B systems for every
# pair of bodies, and each loop pays its start and its remainder, so that at
# B = 16 the kick costs more than the whole drift.  Written out for one
# number of bodies, one of massive bodies and one of systems, every pair's
# arithmetic is straight-line code inside a single loop over the systems, with
# the bodies' positions and sums in registers; LLVM turns that loop into vector
# instructions only if it can tell that the kick's stores (the velocities)
# never overlap its loads, which it can where every load comes from one flat
# array and every store goes to another at offsets that are constants of the
# code (a row length of B N known when it compiles), and whose loop over the
# systems runs to a bound it is handed (LLVM never vectorises a loop of fewer
# than 16 iterations known when it compiles).  The written-out kick is bit for
# bit the loops' kick, and a fraction of its time (benchmarks/RESULTS.md).
# numba does not unroll loops of a size known only when a function is
# specialised, so the source is generated (unrolled_kick) and compiled from a
# file, so that numba caches it on disk like the package's own kernels.  It is
# compiled as a C callable of one signature, which one compiled batch loop
# calls through its pointer: a new size of system compiles its kick alone
# (a second or two), not a loop of its own.

#: the most bodies for which advance_loop unrolls the kick (the straight-line
#: code grows as N^2, and its compilation faster still: benchmarks/RESULTS.md)
UNROLLED_KICK_BODIES = 10

#: rows of the flat array the unrolled kick reads (rows of d, each B N long):
#: the Jacobi positions and the live flags (copied each step into rows of
#: the drift's scratch), the Jacobi weights, G m and G times the interior
#: masses (rows 6, 8 and 9, filled once a call by advance_lanes)
_KX, _KLF, _KWQ, _KGM, _KMU = 0, 3, 6, 8, 9


def _kick_source(n, n_active, nb):
    """Python source of ``kick(K, OUT, h, nb)``: interaction_kick_lanes for
    ``nb`` systems of ``n`` bodies (``n_active`` massive), every loop over
    the bodies written out; ``K`` is d flattened (rows above), ``OUT`` the
    velocities V flattened.  Its offsets are those of ``nb`` systems: it
    must be called with that ``nb``."""
    m = n * nb
    lines = [f'"""The unrolled kick of orbits._kernels.wh_batch for {nb} systems of {n} bodies',
             f'({n_active} massive), generated by its _kick_source."""', "",
             "import math", "import numpy as np", "from orbits._kernels._jit import njit", "",
             "", "@njit(_nrt=False)", "def kick(K, OUT, h, nb):",
             "    for b in range(np.uint64(nb)):"]
    put = lines.append

    def at(row, i):
        return f"K[{row * m + i * nb} + b]"

    def out(c, i):
        return f"OUT[{c * m + i * nb} + b]"

    # the inertial positions (coordinates.from_jacobi_one), from the outermost body in
    put(f"        s0 = {at(_KX, 0)}; s1 = {at(_KX + 1, 0)}; s2 = {at(_KX + 2, 0)}")
    for i in range(n - 1, 0, -1):
        put(f"        w = {at(_KWQ, i)}")
        for c in range(3):
            put(f"        j{c}_{i} = {at(_KX + c, i)}")
            put(f"        s{c} -= w * j{c}_{i}")
            put(f"        x{c}_{i} = j{c}_{i} + s{c}")
    for c in range(3):
        put(f"        x{c}_0 = s{c}")
        for i in range(n):
            put(f"        a{c}_{i} = 0.0")
    for i in range(n):
        put(f"        g{i} = {at(_KGM, i)}")
    # every pair but (0, 1), as pair_accelerations sums them
    for i in range(1, n):
        put("        p0 = 0.0; p1 = 0.0; p2 = 0.0")
        for j in range(1 if i == 1 else 0, min(i, n_active)):
            put(f"        dx = x0_{i} - x0_{j}; dy = x1_{i} - x1_{j}; dz = x2_{i} - x2_{j}")
            put("        r2 = dx * dx + dy * dy + dz * dz")
            put("        q = 1.0 / (r2 * math.sqrt(r2))")
            put(f"        sj = g{j} * q")
            put("        p0 -= sj * dx; p1 -= sj * dy; p2 -= sj * dz")
            if i < n_active:
                put(f"        si = g{i} * q")
                put(f"        a0_{j} += si * dx; a1_{j} += si * dy; a2_{j} += si * dz")
        put(f"        a0_{i} += p0; a1_{i} += p1; a2_{i} += p2")
    # to Jacobi components with the Kepler terms (jacobi_velocity_kick)
    put("        s0 = a0_0; s1 = a1_0; s2 = a2_0")
    for i in range(1, n):
        put(f"        w = {at(_KWQ, i)}")
        put(f"        ax = a0_{i} - s0; ay = a1_{i} - s1; az = a2_{i} - s2")
        put("        s0 += w * ax; s1 += w * ay; s2 += w * az")
        if i >= 2:
            put(f"        rx = j0_{i}; ry = j1_{i}; rz = j2_{i}")
            put("        r2 = rx * rx + ry * ry + rz * rz")
            put(f"        s = {at(_KMU, i)} / (r2 * math.sqrt(r2))")
            put("        ax += s * rx; ay += s * ry; az += s * rz")
        put(f"        keep = {at(_KLF, i)} != 0.0")
        for c, a in enumerate("xyz"):
            put(f"        {out(c, i)} = {out(c, i)} + h * a{a} if keep else {out(c, i)}")
    return "\n".join(lines) + "\n"


_UNROLLED = {}


def _kernel_dir():
    # where the generated kernels' files (and numba's caches of them) go:
    # ORBITS_KERNEL_DIR, else a folder of the temporary directory named for
    # the kernels' sources
    base = os.environ.get("ORBITS_KERNEL_DIR") or tempfile.gettempdir()
    path = os.path.join(base, f"orbits-kernels-{KERNEL_STAMP}")
    os.makedirs(path, exist_ok=True)
    return path


def unrolled_kick(n, n_active, nb):
    """The ``kick(K, OUT, h, nb)`` of :func:`_kick_source` compiled as a C
    callable of :data:`KICK_SIGNATURE` (a :class:`~._jit.Pointer`), made once
    a process (and cached on disk by numba)."""
    key = (n, n_active, nb)
    if key not in _UNROLLED:
        name = f"wh_batch_kick_{n}_{n_active}_{nb}"
        path = os.path.join(_kernel_dir(), name + ".py")
        source = _kick_source(n, n_active, nb)
        try:
            with open(path) as f:
                same = f.read() == source
        except OSError:
            same = False
        if not same:
            # another process may be writing it too: each writes its own
            # file and moves it into place whole
            fd, tmp = tempfile.mkstemp(suffix=".py", dir=os.path.dirname(path))
            with os.fdopen(fd, "w") as f:
                f.write(source)
            os.replace(tmp, path)
        # registered under its name, which numba records in its cache and
        # imports again when a later process loads the compiled kick
        modname = f"_orbits_{name}_{KERNEL_STAMP}"
        module = sys.modules.get(modname)
        if module is None:
            spec = importlib.util.spec_from_file_location(modname, path)
            module = importlib.util.module_from_spec(spec)
            sys.modules[modname] = module
            spec.loader.exec_module(module)
        _UNROLLED[key] = pointer(module.kick, KICK_SIGNATURE)
    return _UNROLLED[key]


#: the unrolled kick's signature, ``kick(K, OUT, h, nb)`` with ``K`` and
#: ``OUT`` the data of the flat arrays (contiguous rows of d and of the
#: velocities): one loop (:data:`_unrolled_lanes`) calls the kick of every
#: size through it
KICK_SIGNATURE = nbtypes.void(nbtypes.CPointer(nbtypes.float64),
                              nbtypes.CPointer(nbtypes.float64), nbtypes.float64, nbtypes.int64)


@njit(inline="always")
def _pointer_kick(X, V, XI, ACC, GM, MU, n_active, h, LF, nb, d, s3, a3, t4, unrolled):
    # the rows the unrolled kick reads that change from step to step (the
    # positions; the live flags, which are lf1 when a lane is replayed) into
    # rows of d that are the drift's scratch, free until the next drift
    m = X.shape[1]
    for r in range(3):
        A = X[r]
        B = d[_KX + r]
        for k in range(np.uint64(m)):
            B[k] = A[k]
    F = d[_KLF]
    for k in range(np.uint64(m)):
        F[k] = LF[k]
    # the number of systems as a value known only when the kick runs: a loop
    # of a trip count below 16 known when it compiles is never vectorised
    # (at 4 and 8 systems the kick would stay scalar)
    unrolled(contiguous_data(d), contiguous_data(V), h, nb)


#: the batch loop that calls an unrolled kick through its pointer, for
#: systems of every size (see :func:`advance_loop`)
_unrolled_lanes = specialize(
    _advance_lanes, "unrolled",
    lane_step=specialize(_step, "unrolled", inline=True, kick=_pointer_kick))


class _UnrolledLoop:
    # advance_lanes's call for nb systems of one size, with their unrolled kick
    __slots__ = ("nb", "kick")

    def __init__(self, nb, kick):
        self.nb = nb
        self.kick = kick

    def __call__(self, lanes, n_active, dt, nsteps, scratch):
        if lanes.owed.shape[0] != self.nb:
            raise ValueError("wh_batch: a loop of advance_loop takes the number of systems "
                             "it was made for")
        return _unrolled_lanes(lanes, n_active, dt, nsteps, scratch, self.kick)


def advance_loop(n, n_active, nb):
    """:func:`advance_lanes` for ``nb`` systems of ``n`` bodies (``n_active``
    massive), with the kick unrolled for that size (bit for bit the same
    steps) where ``3 <= n <= UNROLLED_KICK_BODIES``; else (or where the
    generated kernel's file cannot be written) advance_lanes itself.  One
    compiled loop serves every size: it calls the size's kick through its
    pointer, so a new size compiles only its kick."""
    if not 3 <= n <= UNROLLED_KICK_BODIES:
        return advance_lanes
    try:
        kick_ = unrolled_kick(n, n_active, nb)
    except OSError:
        # no folder to write the generated kernel to: the loops' kick
        return advance_lanes
    return _UnrolledLoop(nb, kick_)


def to_lanes(x, v, gm):
    """The lanes' Jacobi state of systems given in inertial coordinates.

    Parameters
    ----------
    x, v : ndarray, shape (N, 3, B)
        Inertial positions and velocities of B systems (massive bodies first,
        the central one at row 0).
    gm : ndarray, shape (N, B)
        G times the masses.

    Returns
    -------
    xj, vj : ndarray, shape (N, 3, B)
        Jacobi positions and velocities
        (:func:`orbits._kernels.coordinates.to_jacobi` of each system).
    eta : ndarray, shape (N, B)
        G times the interior masses.
    """
    n, _, nb = x.shape
    xj = np.zeros((n, 3, nb))
    vj = np.zeros((n, 3, nb))
    eta = np.zeros((n, nb))
    for b in range(nb):
        g = np.ascontiguousarray(gm[:, b])
        e = np.zeros(n)
        interior_gm(g, e)
        a = np.zeros((n, 3))
        w = np.zeros((n, 3))
        to_jacobi(np.ascontiguousarray(x[:, :, b]), np.ascontiguousarray(v[:, :, b]), g, e,
                  a, w)
        xj[:, :, b] = a
        vj[:, :, b] = w
        eta[:, b] = e
    return xj, vj, eta


def from_lanes(xj, vj, gm, eta, owed, n_active):
    """Inertial positions and velocities, shape (N, 3, B), of the lanes' state
    (:func:`orbits._kernels.wisdom_holman.synchronize` of each system: its
    owed drift applied to a copy, then back from Jacobi coordinates)."""
    n, _, nb = xj.shape
    x = np.zeros((n, 3, nb))
    v = np.zeros((n, 3, nb))
    for b in range(nb):
        a, w = lane_inertial(xj, vj, gm, eta, owed, n_active, b)
        x[:, :, b] = a
        v[:, :, b] = w
    return x, v


def lane_inertial(xj, vj, gm, eta, owed, n_active, b):
    """Inertial positions and velocities, each of shape (N, 3), of lane ``b``
    (see :func:`from_lanes`)."""
    n = xj.shape[0]
    x = np.zeros((n, 3))
    v = np.zeros((n, 3))
    _synchronize_lane(xj, vj, gm, eta, owed, n_active, b, np.zeros((6, n, 3)),
                      np.zeros((2, n)), np.zeros((0, 2)), x, v)
    return x, v


@njit
def _synchronize_lane(xj, vj, gm, eta, owed, n_active, b, sc, ge, corr, x, v):
    # the scalar synchronisation of lane b into x, v (shape (N, 3)); sc
    # (shape (6, N, 3)) and ge (shape (2, N)) are scratch: the lane's Jacobi
    # state, masses and interior masses, the copy that drifts, and the
    # drift's scratch
    n = xj.shape[0]
    g = ge[0]
    e = ge[1]
    for i in range(n):
        for c in range(3):
            sc[0, i, c] = xj[i, c, b]
            sc[1, i, c] = vj[i, c, b]
        g[i] = gm[i, b]
        e[i] = eta[i, b]
    synchronize(sc[0], sc[1], g, e, owed[b], sc[2], sc[3], x, v, sc[5], n_active, corr,
                0.0, (), 0)


@njit
def record_lanes(xj, vj, gm, eta, owed, live, n_active, m, G, which, sc, ge, corr, x, v,
                 rows):
    """One output row of every live lane: its inertial state at the current
    time (:func:`orbits._kernels.wisdom_holman.synchronize`, on a copy) and
    the monitors of :func:`orbits._kernels.invariants.monitor_row`, in the
    layout of the rows that the scalar loops record
    (:func:`orbits._kernels.stepping.record_state`).

    Parameters
    ----------
    xj, vj, gm, eta, owed, live, n_active
        As :func:`advance_lanes`.
    m : ndarray, shape (B, N)
        Each system's masses.
    G : float
    which : int
        The monitors' bits (:mod:`orbits._kernels.invariants`).
    sc, ge, corr : ndarray, shapes (6, N, 3), (2, N) and (0, 2)
        Scratch, and the (empty) corrector table.
    x, v : ndarray, shape (N, 3)
        Scratch: a lane's inertial state.
    rows : ndarray, shape (B, MONITOR_WIDTH + 6 N)
        Row ``b`` written for each live lane ``b`` (the others left).
    """
    n = xj.shape[0]
    w = MONITOR_WIDTH
    for b in range(xj.shape[2]):
        if live[b] == 0.0:
            continue
        _synchronize_lane(xj, vj, gm, eta, owed, n_active, b, sc, ge, corr, x, v)
        row = rows[b]
        monitor_row(x, v, m[b], G, n_active, 0.0, which, row)
        for i in range(n):
            for c in range(3):
                row[w + 3 * i + c] = x[i, c]
                row[w + 3 * (n + i) + c] = v[i, c]
