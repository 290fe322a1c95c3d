"""Taylor's method for Newtonian gravity: the series of every body's orbit by
automatic differentiation, to a fixed order, with Jorba & Zou's step size.

Over a step from ``t0`` every coordinate is the truncated series
``x(t0 + h) = sum_k x[k] h^k`` (``x[k]`` the k-th derivative over k!), and
the coefficients follow from the equations of motion by recurrences (Jorba &
Zou 2005, sect. 2): ``x[k+1] = v[k] / (k + 1)``, ``v[k+1] = a[k] / (k + 1)``,
and for each pair, with ``d = x_j - x_i`` (linear, so ``d[k] = x_j[k] -
x_i[k]``)::

    r2[k] = sum_{l=0..k} d[l] . d[k-l]                  (+ the softening at k = 0)
    s = r2^(-3/2):  s[0] = r2[0]^(-3/2),
                    s[k] = 1 / (k r2[0]) sum_{l=0..k-1} (-3/2 (k - l) - l) r2[k-l] s[l]
    w[k] = sum_{l=0..k} d[l] s[k-l]
    a_i[k] += G m_j w[k],   a_j[k] -= G m_i w[k]

(the power rule follows from ``r2 s' = -3/2 r2' s``).  Order ``k`` of every
pair needs order ``k`` of every body, which needs order ``k - 1`` of every
pair, so the orders are the outer loop and each pair keeps its series: the
memory is ``(order + 1) (5 P + 6 N)`` doubles for ``P`` pairs.  The loops
over the pairs do the same operations for every pair, in arrays laid out
pair-innermost and padded to a multiple of eight pairs (the padding pairs
keep a constant unit separation, so their series stay finite), so that LLVM
turns them into vector instructions.

The step (Jorba & Zou 2005, sect. 3.2) is ``h = rho / e^2 exp(-0.7 / (p - 1))``
with ``rho = min_k (|x|_max / |x[k]|_max)^(1/k)`` over the last two orders
``k = p - 1, p``: the series' radius of convergence estimated from its last
terms, relative to the largest coordinate (the velocities' series is the
derivative of the positions', with the same radius).  For a tolerance ``tol``
the order is ``p = ceil(-ln(tol) / 2 + 1)``: with ``h = rho / e^2`` the
terms fall as ``e^(-2k)``, so the truncation is near ``tol`` of the largest
coordinate a step.  There is no rejected step.  The increments are summed in
Horner's form (smallest terms first) and added to the state with
compensation, as IAS15 does, and the time too.

References
----------
Jorba, A. & Zou, M. 2005, "A software package for the numerical integration
of ODEs by means of high-order Taylor methods", Experimental Mathematics 14,
99.  Biscani, F. & Izzo, D. 2021, "Revisiting high-order Taylor methods for
astrodynamics and celestial mechanics", MNRAS 504, 2614 (the same step-size
rule and order; the pairwise N-body recurrences).
"""

import math
from typing import NamedTuple

import numpy as np

from ._jit import njit, slots, specialize
from .status import Status
from .stepping import (GO, WORK_SLOTS, adaptive_start, add_compensated, clock_step,
                       landing_step, must_return, step_lander, work_kernels)

# the names the templates below are written against, bound by specialize
land, = slots("land")
HAS_WORK, work_rate, work_add, work_note, work_on = slots(*WORK_SLOTS)

__all__ = ["order_for", "pair_count", "padded_pairs", "Series", "series_arrays", "taylor_loop",
           "expand", "PAD"]

#: the pairs' arrays are padded to a multiple of this many pairs
PAD = 8
#: the exponent of r2 in the pull, r^-3 = (r2)^(-3/2)
ALPHA = -1.5
#: the safety factor of Jorba & Zou's step: exp(-0.7 / (p - 1)) / e^2
SAFETY_EXPONENT = 0.7


def order_for(tol):
    """Jorba & Zou's order for tolerance ``tol``: ``ceil(-ln(tol) / 2 + 1)``, at least 2.

    >>> order_for(2.220446049250313e-16), order_for(1e-10)
    (20, 13)
    """
    return max(2, int(math.ceil(-math.log(tol) / 2.0 + 1.0)))


def pair_count(n, n_active):
    """Pairs with at least one massive body among ``n`` bodies, the first
    ``n_active`` massive."""
    return n_active * (n_active - 1) // 2 + (n - n_active) * n_active


def padded_pairs(n, n_active):
    """:func:`pair_count` rounded up to a multiple of :data:`PAD` (at least one
    multiple)."""
    p = pair_count(n, n_active)
    return max(PAD, -(-p // PAD) * PAD)


class Series(NamedTuple):
    """The arrays the loop expands the series in, in the order of its
    arguments (``P``: the pairs, padded; ``p``: the order)."""

    X: np.ndarray    # (p + 1, 3, N): the positions' coefficients
    V: np.ndarray    # (p + 1, 3, N): the velocities'
    D: np.ndarray    # (p + 1, 3, P): the pairs' separations'
    R2: np.ndarray   # (p + 1, P): their squared distances'
    S: np.ndarray    # (p + 1, P): r2^(-3/2)'s
    W: np.ndarray    # (3, P): the pulls' coefficient of the order at hand
    IR: np.ndarray   # (P,): 1 / r2
    A: np.ndarray    # (3, N, 3): the accelerations' coefficient, a step's increments
    PI: np.ndarray   # (P,) int64: each pair's massive body
    PJ: np.ndarray   # (P,) int64: its other body


def series_arrays(order, n, n_active):
    """:class:`Series` for ``n`` bodies (the first ``n_active`` massive) to ``order``."""
    pairs = padded_pairs(n, n_active)
    z = np.zeros
    return Series(z((order + 1, 3, n)), z((order + 1, 3, n)), z((order + 1, 3, pairs)),
                  z((order + 1, pairs)), z((order + 1, pairs)), z((3, pairs)), z(pairs),
                  z((3, n, 3)), z(pairs, dtype=np.int64), z(pairs, dtype=np.int64))


@njit
def pairs_and_padding(n, n_active, PI, PJ, D):
    """Fill the pair indices ``PI < PJ`` (``PI`` massive) and set the padding
    pairs' separation series to a constant unit vector; returns the pair count."""
    q = 0
    for j in range(1, n):
        for i in range(min(j, n_active)):
            PI[q] = i
            PJ[q] = j
            q += 1
    for p in range(q, PI.shape[0]):
        PI[p] = 0
        PJ[p] = 0
        for k in range(D.shape[0]):
            for c in range(3):
                D[k, c, p] = 0.0
        D[0, 0, p] = 1.0
    return q


@njit(inline="always")
def expand(x, v, X, V, D, R2, S, W, IR, A, PI, PJ, npair, gm, eps2, order):
    """The series of positions ``X[k, c, i]`` and velocities ``V[k, c, i]``
    (``k = 0 .. order``) of the state ``(x, v)``; returns whether every
    coefficient is finite.  ``D``, ``R2``, ``S`` (the pairs' series), ``W``,
    ``IR`` and ``A[0]`` (shape (N, 3)) are scratch (see the module notes)."""
    n = x.shape[0]
    P = np.uint64(R2.shape[1])
    Ak = A[0]
    for c in range(3):
        for i in range(n):
            X[0, c, i] = x[i, c]
            V[0, c, i] = v[i, c]
    for k in range(order):
        # the separations' coefficient of order k (the padding keeps its own)
        for c in range(3):
            Xk = X[k, c]
            Dk = D[k, c]
            for q in range(npair):
                Dk[q] = Xk[PJ[q]] - Xk[PI[q]]
        R2k = R2[k]
        Sk = S[k]
        if k == 0:
            D0 = D[0]
            for q in range(P):
                r2 = D0[0, q] * D0[0, q] + D0[1, q] * D0[1, q] + D0[2, q] * D0[2, q] + eps2
                R2k[q] = r2
                IR[q] = 1.0 / r2
                Sk[q] = 1.0 / (r2 * math.sqrt(r2))
        else:
            # r2[k] = sum_l d[l] . d[k-l]: each product twice but the middle one
            for q in range(P):
                R2k[q] = 0.0
            for l in range((k + 1) // 2):
                Dl = D[l]
                Dm = D[k - l]
                for q in range(P):
                    R2k[q] += Dl[0, q] * Dm[0, q] + Dl[1, q] * Dm[1, q] + Dl[2, q] * Dm[2, q]
            if k % 2 == 0:
                Dh = D[k // 2]
                for q in range(P):
                    R2k[q] = 2.0 * R2k[q] + (Dh[0, q] * Dh[0, q] + Dh[1, q] * Dh[1, q]
                                             + Dh[2, q] * Dh[2, q])
            else:
                for q in range(P):
                    R2k[q] = 2.0 * R2k[q]
            # s[k] by the power rule
            for q in range(P):
                Sk[q] = 0.0
            for l in range(k):
                cf = (ALPHA * (k - l) - l) / k
                Rl = R2[k - l]
                Sl = S[l]
                for q in range(P):
                    Sk[q] += cf * Rl[q] * Sl[q]
            for q in range(P):
                Sk[q] *= IR[q]
        # w[k] = sum_l d[l] s[k-l]
        for c in range(3):
            Wc = W[c]
            for q in range(P):
                Wc[q] = 0.0
            for l in range(k + 1):
                Dl = D[l, c]
                Sm = S[k - l]
                for q in range(P):
                    Wc[q] += Dl[q] * Sm[q]
        # the accelerations' coefficient of order k, pair by pair
        for c in range(3):
            for i in range(n):
                Ak[i, c] = 0.0
        for q in range(npair):
            i = PI[q]
            j = PJ[q]
            gi = gm[i]
            gj = gm[j]
            for c in range(3):
                w = W[c, q]
                Ak[i, c] += gj * w
                Ak[j, c] -= gi * w
        f = 1.0 / (k + 1)
        for c in range(3):
            for i in range(n):
                V[k + 1, c, i] = Ak[i, c] * f
                X[k + 1, c, i] = V[k, c, i] * f
    s = 0.0
    for c in range(3):
        for i in range(n):
            s += X[order, c, i] + V[order, c, i]
    return math.isfinite(s)


@njit(inline="always")
def radius_step(X, order):
    """Jorba & Zou's step from the series ``X`` (see the module notes); 0 for
    a series that ends in zeros (a state that does not move: no limit)."""
    n = X.shape[2]
    scale = 0.0
    top1 = 0.0
    top2 = 0.0
    for c in range(3):
        for i in range(n):
            scale = max(scale, abs(X[0, c, i]))
            top1 = max(top1, abs(X[order - 1, c, i]))
            top2 = max(top2, abs(X[order, c, i]))
    if scale == 0.0:
        scale = 1.0
    rho = math.inf
    if top1 > 0.0:
        rho = (scale / top1) ** (1.0 / (order - 1))
    if top2 > 0.0:
        rho = min(rho, (scale / top2) ** (1.0 / order))
    if rho == math.inf:
        return 0.0
    return rho * math.exp(-2.0 - SAFETY_EXPONENT / (order - 1))


class Work(NamedTuple):
    """The Taylor loop's workspace besides its :class:`Series`: the last
    step's proposal ``dt[0]``, ``info`` (bodies behind a stop), the
    compensation of ``x`` and ``v``, ``tc`` (the time reached and the part
    of it that ``t + dt`` rounded away, as in :mod:`.ias15`) and ``counts``
    (accepted steps, 0, series expanded times the order) of a call."""
    dt: np.ndarray
    info: np.ndarray
    csx: np.ndarray
    csv: np.ndarray
    tc: np.ndarray
    counts: np.ndarray


def _taylor_loop(x, v, t, order, series, work, fargs, outputs, landing, sargs, check):
    # marks, mark_steps as in the IAS15 loop (orbits._kernels.ias15)
    X, V, D, R2, S, W, IR, A, PI, PJ = series
    dtp, info, csx, csv, tc, counts = work
    mon, step0, mon_t, mon_out = outputs
    t_end, max_steps, min_dt, marks, mark_steps = landing
    stopping = (sargs, check)
    n = x.shape[0]
    gm = fargs[0]
    n_active = fargs[1]
    eps2 = fargs[2]
    npair = pairs_and_padding(n, n_active, PI, PJ, D)
    n_mon = 0
    direction, ct, target, has_marks, every, cap, until_record = adaptive_start(
        t, t_end, tc, marks, counts, info, mon, step0, mon_t)
    k_mark = 0
    while True:
        if must_return(counts, max_steps, has_marks, n_mon, mon_out, until_record, cap, t,
                       t_end):
            return Status.OK, t, n_mon
        finite = expand(x, v, X, V, D, R2, S, W, IR, A, PI, PJ, npair, gm, eps2, order)
        counts[2] += order
        if not finite:
            return Status.NON_FINITE, t, n_mon
        proposed = radius_step(X, order)
        if proposed == 0.0:
            proposed = math.inf
        proposed *= direction
        dt, trimmed, underflow = landing_step(t, ct, target, proposed, min_dt)
        if underflow:
            dtp[0] = proposed
            return Status.STEP_UNDERFLOW, t, n_mon
        # the increments in Horner's form, first, so that a non-finite one
        # leaves (x, v) untouched
        s = 0.0
        for c in range(3):
            for i in range(n):
                dx = X[order, c, i]
                dv = V[order, c, i]
                for k in range(order - 1, 0, -1):
                    dx = X[k, c, i] + dt * dx
                    dv = V[k, c, i] + dt * dv
                dx *= dt
                dv *= dt
                A[1, i, c] = dx
                A[2, i, c] = dv
                s += dx + dv
        if not math.isfinite(s):
            return Status.NON_FINITE, t, n_mon
        add_compensated(x, A[1], csx)
        add_compensated(v, A[2], csv)
        t, ct = clock_step(t, ct, dt, trimmed, target)
        tc[0] = t
        tc[1] = ct
        counts[0] += 1
        dtp[0] = proposed
        code, target, k_mark, until_record, n_mon = land(
            x, v, t, counts[0], False, 0, has_marks, target, k_mark, until_record, n_mon,
            outputs, marks, mark_steps, stopping, info, fargs)
        if code != GO:
            return code, t, n_mon


def taylor_loop(force):
    """The Taylor loop compiled for gravity's :class:`~orbits._kernels.stepping.ForceKernel`.

    The loop is ``loop(x, v, t, order, series, work, fargs, outputs, landing,
    sargs, check)``: the series' order, a :class:`Series`, a :class:`Work`
    over the arrays of :meth:`orbits.integrators.taylor.Taylor.workspace`,
    the records of :mod:`.records` and the stopping conditions
    (:func:`~orbits._kernels.stopping.stop_record`); it returns ``(status,
    t_reached, n_monitor_rows)`` and leaves the counts in ``counts``.
    """
    return specialize(_taylor_loop, force.key, jit=force.jit, cache=force.cache,
                      nrt=force.runtime, land=step_lander(force), **work_kernels(force))
