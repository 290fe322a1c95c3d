"""The compiled IAS15 loop: Gauss-Radau predictor-corrector with adaptive steps.

Over a step of length ``dt`` from ``t0`` the acceleration is written as a
polynomial in the fraction ``h = (t - t0) / dt`` of the step (Everhart 1985)::

    a(h) = a0 + b0 h + b1 h^2 + ... + b6 h^7
         = a0 + g0 h + g1 h (h - h1) + ... + g6 h (h - h1) ... (h - h6),

with ``h1 .. h7`` the Gauss-Radau spacings.  The ``g`` are divided
differences of the accelerations at the spacings, so each force evaluation at
``h_n`` fixes ``g_{n-1}`` once the others are known; ``b = C g`` and
``g = D b`` convert between the two forms.  Integrating the polynomial twice
gives the predictor::

    x(h) = x0 + h dt v0 + (h dt)^2 (a0/2 + b0 h/6 + b1 h^2/12 + ... + b6 h^7/72)
    v(h) = v0 + h dt (a0 + b0 h/2 + b1 h^2/3 + ... + b6 h^7/8).

A step predicts the state at ``h1 .. h7``, evaluates the force there,
updates ``g`` and ``b``, and repeats until the last coefficient stops
changing (the corrector, an implicit Runge-Kutta iteration of order 15).

Step control follows Rein & Spiegel (2015): the step just taken is accepted
unless the step it implies is smaller by more than the factor :data:`SAFETY`,
and the next one is ``dt (epsilon / b6~)^(1/7)`` with
``b6~ = max|b6| / max|a|`` over all components ("global").  Option
``prs24`` uses instead the timescale of Pham, Rein & Spiegel (2024), per
body, from the acceleration, jerk and snap at the end of the step::

    tau_i^2 = 2 |a_i|^2 / (|j_i|^2 + |a_i| |s_i|),  dt_next = (7! epsilon)^(1/7) min_i tau_i.

The first guess of the next step's ``b`` extrapolates the polynomial of an
earlier step (Everhart's ``e``), corrected by how wrong that step's own guess
was (``b - e`` of that step, kept as ``br - er``).  Positions and velocities
are accumulated with compensated summation so that rounding does not grow
with the number of steps, and the ``b`` that a step ends with are computed
afresh from its ``g`` (``b = C g``), not carried over from the prediction,
so that the rounding errors of successive steps are independent and the
energy error is a random walk (Brouwer's law; see ``_ias15_loop``).

The work of non-conservative force terms (:mod:`.stepping`) over a step is
``-dt`` times the Gauss-Radau quadrature of the work rate ``P`` on the step's
eight nodes, ``h = 0`` and the seven spacings, with the states of the last
predictor-corrector iteration: the left Radau rule of eight nodes, exact for
polynomials of degree 14 (:data:`RADAU_WEIGHTS`).

References
----------
.. [1] Everhart, E. 1985, "An efficient integrator that uses Gauss-Radau
   spacings", in Dynamics of Comets: Their Origin and Evolution, IAU Coll. 83,
   ed. A. Carusi & G. B. Valsecchi, Reidel, p. 185.
.. [2] Rein, H. & Spiegel, D. S. 2015, "IAS15: a fast, adaptive, high-order
   integrator for gravitational dynamics, accurate to machine precision over
   a billion orbits", MNRAS 446, 1424.
.. [3] Pham, D., Rein, H. & Spiegel, D. S. 2024, "A new timestep criterion
   for N-body simulations", Open Journal of Astrophysics 7, 1.
"""

import math
from fractions import Fraction
from typing import NamedTuple

import numpy as np

from ._jit import fma, njit, slots, specialize
from .status import Status
from .stepping import (GO, WORK_SLOTS, adaptive_start, add_compensated, clock_step, flat_rows,
                       flat_stages, landing_step, must_return, step_lander, work_kernels)
from .variational import measured_rows, velocity_reader

__all__ = ["SPACINGS", "C_TABLE", "D_TABLE", "R_TABLE", "R_LOW_TABLE", "SAFETY", "PC_TOLERANCE",
           "PC_MAX_ITERATIONS", "PC_EPSILON_SQUARED", "MODE_GLOBAL", "MODE_PRS24",
           "ias15_loop", "B6_ROUNDING_GAIN",
           "radau_spacings", "RADAU_WEIGHTS", "radau_weights"]

#: Gauss-Radau spacings h_1 .. h_7 on [0, 1] (h_0 = 0 is the start of the
#: step): the roots of the degree-7 Radau polynomial, as printed by Everhart
#: (1985) and Rein & Spiegel (2015, eq. 8); tests/integrators/test_ias15.py
#: checks them against the roots computed from Legendre polynomials.
SPACINGS = np.array([
    0.0562625605369221464656521910318,
    0.180240691736892364987579942780,
    0.352624717113169637373907769648,
    0.547153626330555383001448554766,
    0.734210177215410531523210605558,
    0.885320946839095768090359771030,
    0.977520613561287501891174488626,
])

#: A step is redone when the step it implies is below SAFETY times itself, and
#: the next step grows at most by 1 / SAFETY (Rein & Spiegel 2015, sect. 3.4).
SAFETY = 0.25
#: The corrector has converged when the last change of b6 relative to the
#: largest acceleration is below this (Rein & Spiegel 2015, sect. 3.2) ...
PC_TOLERANCE = 1e-16
#: ... or when that change stopped decreasing (it reached rounding) after at
#: least two iterations; a step is never iterated more often than this.
PC_MAX_ITERATIONS = 12
#: At a loose ``epsilon`` the corrector need not reach rounding: it stops once its
#: change is below ``PC_EPSILON_SQUARED * epsilon**2`` (when that exceeds
#: :data:`PC_TOLERANCE`).  The step follows ``epsilon**(1/7)`` and the error of a step
#: its 16th power, so a run's truncation error falls as about ``epsilon**(15/7)``; a
#: corrector tolerance that falls as ``epsilon**2`` keeps about the same ratio to it at
#: every ``epsilon``.  With the share 1e-2 the final positions of Kepler orbits, the
#: Earth and Moon and planetary systems at epsilon 1e-1 to 1e-6 move by a small part
#: of the run's own truncation error, or within its scatter where that error is
#: rounding, for up to half the force evaluations (the runs are in
#: benchmarks/RESULTS.md).  At ``epsilon <= 1e-7`` (the default 1e-9 included) the
#: corrector runs to :data:`PC_TOLERANCE`.
PC_EPSILON_SQUARED = 1e-2

#: How much b6 = g6, the seventh divided difference of the accelerations at
#: 0 and the seven spacings, magnifies independent rounding errors of those
#: accelerations: the root sum of squares of its weights
#: ``1 / prod_{j != k} (h_k - h_j)`` (about 4550; their sum is 11525).
B6_ROUNDING_GAIN = float(np.sqrt(sum(
    (1.0 / np.prod([hk - hj for hj in np.concatenate([[0.0], SPACINGS]) if hj != hk])) ** 2
    for hk in np.concatenate([[0.0], SPACINGS]))))
_UNIT_ROUNDOFF = 2.0 ** -53
#: b6 below this many times its rounding estimate counts as rounding: the
#: estimate takes ``|da/dx|`` along the step, which in a close encounter is
#: smaller than its norm by about the ratio of a body's speed to the speed of
#: the encounter (6 for Earth-mass planets meeting at 5 km/s, where the
#: estimate comes out at 0.2 to 1 times the b6 of tiny steps); 10 covers
#: that, and lies far below the truncation error of any useful step
ROUNDING_MARGIN = 10.0

MODE_GLOBAL = 0
MODE_PRS24 = 1


def radau_spacings():
    """The spacings computed afresh: roots of ``(P_7(s) + P_8(s)) / (1 + s)`` with
    ``s = 2h - 1`` (Gauss-Radau nodes with the fixed node at ``h = 0``)."""
    from numpy.polynomial import legendre as L
    p = L.Legendre.basis(7) + L.Legendre.basis(8)
    roots = np.sort(p.roots().real)
    roots = roots[roots > -1 + 1e-8]            # drop the fixed node s = -1
    # polish by Newton's method on the full polynomial
    for _ in range(3):
        roots = roots - p(roots) / p.deriv()(roots)
    return (roots + 1.0) / 2.0


def _tables(h):
    """C (b = C g), D = C^-1 (g = D b), R (R[n, j] = 1 / (h_n - h_j), h_0 = 0)
    and R's low parts (``R + R_low`` is ``1 / (h_n - h_j)`` to about 2^-106
    of it), computed in exact rational arithmetic from the float spacings
    ``h``."""
    hs = [Fraction(0)] + [Fraction(float(x)) for x in h]
    # N_k(h) = h (h - h_1) ... (h - h_k) = sum_m C[m, k] h^(m+1)
    C = [[Fraction(0)] * 7 for _ in range(7)]
    poly = [Fraction(1)]                         # coefficients of h^1, h^2, ... of N_k
    for k in range(7):
        if k > 0:
            hk = hs[k]
            new = [Fraction(0)] * (len(poly) + 1)
            for m, c in enumerate(poly):
                new[m + 1] += c
                new[m] -= hk * c
            poly = new
        for m, c in enumerate(poly):
            C[m][k] = c
    # D = C^-1, upper triangular with unit diagonal
    D = [[Fraction(0)] * 7 for _ in range(7)]
    for k in range(7):
        D[k][k] = Fraction(1)
        for m in range(k - 1, -1, -1):
            D[m][k] = -sum(C[m][j] * D[j][k] for j in range(m + 1, k + 1))
    R = np.zeros((8, 8))
    R_low = np.zeros((8, 8))
    for n in range(1, 8):
        for j in range(n):
            exact = 1 / (hs[n] - hs[j])
            R[n, j] = float(exact)
            R_low[n, j] = float(exact - Fraction(R[n, j]))
    return (np.array([[float(c) for c in row] for row in C]),
            np.array([[float(c) for c in row] for row in D]), R, R_low)


#: The corrector multiplies by ``R_TABLE + R_LOW_TABLE`` with a fused
#: multiply-add (``fma(d, R, d * R_low)``), so that each divided difference is
#: its exact value rounded once.  With ``R`` alone each factor would keep its
#: own fixed rounding, the same at every step: a force linear in time would
#: get a spurious second divided difference, the velocity would weigh the
#: force's change by a constant factor off one, and the energy would drift
#: with one sign at every step (benchmarks/RESULTS.md, validation/brouwer.py).
C_TABLE, D_TABLE, R_TABLE, R_LOW_TABLE = _tables(SPACINGS)


def radau_weights(h):
    """The weights of the quadrature on [0, 1] with nodes 0 and ``h`` (the
    spacings): ``w_k`` is the integral of the Lagrange polynomial of node
    ``k``, computed in exact rational arithmetic from the float nodes, so that
    the rule integrates ``t^j`` exactly for ``j`` below the number of nodes; at
    the Gauss-Radau spacings it is the left Radau rule, exact up to
    ``j = 2 * 8 - 2 = 14``.

    Examples
    --------
    >>> from orbits._kernels.ias15 import SPACINGS, radau_weights
    >>> w = radau_weights(SPACINGS)
    >>> len(w), round(float(w.sum()), 15), round(float(w[0]), 15)   # w_0 = 1 / n^2
    (8, 1.0, 0.015625)
    """
    hs = [Fraction(0)] + [Fraction(float(x)) for x in h]
    weights = []
    for k, hk in enumerate(hs):
        poly = [Fraction(1)]               # coefficients of h^0, h^1, ...
        for j, hj in enumerate(hs):
            if j == k:
                continue
            new = [Fraction(0)] * (len(poly) + 1)
            for m, c in enumerate(poly):
                new[m + 1] += c / (hk - hj)
                new[m] -= c * hj / (hk - hj)
            poly = new
        weights.append(float(sum(c / (m + 1) for m, c in enumerate(poly))))
    return np.array(weights)


#: weights of the Gauss-Radau quadrature on the step's nodes 0, h_1 .. h_7
#: (:func:`radau_weights`), for the work of non-conservative terms
RADAU_WEIGHTS = radau_weights(SPACINGS)

# constants read by the compiled loop (numba freezes global arrays)
_H = SPACINGS
_C = C_TABLE
_D = D_TABLE
_R = R_TABLE
_RL = R_LOW_TABLE
_WR = RADAU_WEIGHTS
# binomial(k + 1, m + 1) for the extrapolation of b to the next step
_BINOM = np.array([[float(math.comb(k + 1, m + 1)) for k in range(7)] for m in range(7)])
# 1 / ((k + 2) (k + 3)) and 1 / (k + 2): the predictor's integration weights
_X0, _X1, _X2, _X3, _X4, _X5, _X6 = (1.0 / ((k + 2) * (k + 3)) for k in range(7))
_V0, _V1, _V2, _V3, _V4, _V5, _V6 = (1.0 / (k + 2) for k in range(7))
# 7! = 5040: the Taylor coefficient of the seventh derivative (Pham et al. 2024)
_FACT7 = 5040.0


def _predict(b, e, br, er, u, q, P):
    # The reference step's polynomial a(h), h in units of its length, re-expanded
    # about h = u with the new step's scale q:
    # e_m = q^(m+1) sum_{k >= m} binom(k+1, m+1) u^(k-m) br_k;  b = e + (br - er).
    qm = 1.0
    for m in range(7):
        qm *= q
        uk = qm
        for k in range(7):
            if k >= m:
                P[m, k] = _BINOM[m, k] * uk
                uk *= u
            else:
                P[m, k] = 0.0
    _upper_times(P, br, e)
    n = b.shape[1]
    for i in range(n):
        for d in range(3):
            for m in range(7):
                b[m, i, d] = e[m, i, d] + (br[m, i, d] - er[m, i, d])


def _g_from_b(b, g):
    _upper_times(_D, b, g)


@njit(inline="always")
def _upper_times(M, src, out):
    # out[m] = sum_{k >= m} M[m, k] src[k] for each body's component: the
    # products of the upper triangle of a 7 x 7 table with the coefficients
    n = src.shape[1]
    for i in range(n):
        for d in range(3):
            for m in range(7):
                s = 0.0
                for k in range(m, 7):
                    s += M[m, k] * src[k, i, d]
                out[m, i, d] = s


def _b_from_g(g, b):
    # b = C g, smallest terms first; C is upper triangular with unit diagonal
    n = b.shape[1]
    for i in range(n):
        for d in range(3):
            for m in range(7):
                s = 0.0
                for k in range(6, m, -1):
                    s += _C[m, k] * g[k, i, d]
                b[m, i, d] = g[m, i, d] + s


@njit(inline="always")
def _b6_rounding(x, xs, a0, acc, n):
    """The size of b6 that rounding alone can give (with :data:`ROUNDING_MARGIN`):
    each acceleration is off by
    about ``u |x|max |da/dx|`` (positions are rounded to ``u |x|max``; the
    derivative along the step is estimated as ``|a(h7) - a0| / |x(h7) - x0|``),
    and b6, a divided difference of the eight accelerations, multiplies such
    independent errors by :data:`B6_ROUNDING_GAIN`."""
    xmax = 0.0
    for i in range(n):
        for d in range(3):
            ax = abs(x[i, d])
            if ax > xmax:
                xmax = ax
    worst = 0.0
    for i in range(n):
        da = 0.0
        dx = 0.0
        for d in range(3):
            da += (acc[i, d] - a0[i, d]) ** 2
            dx += (xs[i, d] - x[i, d]) ** 2
        if dx > 0.0:
            slope = math.sqrt(da / dx)
            if slope > worst:
                worst = slope
    return ROUNDING_MARGIN * B6_ROUNDING_GAIN * _UNIT_ROUNDOFF * xmax * worst


class Work(NamedTuple):
    """The IAS15 loop's workspace (:meth:`orbits.integrators.ias15.IAS15.workspace`)."""
    dt: np.ndarray
    info: np.ndarray
    a0: np.ndarray
    b: np.ndarray
    g: np.ndarray
    e: np.ndarray
    br: np.ndarray
    er: np.ndarray
    csx: np.ndarray
    csv: np.ndarray
    ref: np.ndarray
    tc: np.ndarray
    flags: np.ndarray
    xs: np.ndarray
    vs: np.ndarray
    acc: np.ndarray
    P: np.ndarray
    counts: np.ndarray


class Control(NamedTuple):
    """The step control: the tolerance ``epsilon`` of the predictor-corrector
    and of the next step's size, chosen as ``mode`` says (a ``MODE_*``)."""
    epsilon: float
    mode: int


@njit(inline="always")
def _predicted_x(x1, csx1, v1, a01, b1, k, h, hdt):
    # component k of the position predicted at the substep h (of the step)
    return x1[k] + (csx1[k] + hdt * (v1[k] + hdt * (
        a01[k] * 0.5 + h * (b1[0, k] * _X0 + h * (
            b1[1, k] * _X1 + h * (b1[2, k] * _X2 + h * (
                b1[3, k] * _X3 + h * (b1[4, k] * _X4 + h * (
                    b1[5, k] * _X5 + h * b1[6, k] * _X6)))))))))


def _ias15_loop(x, v, t, control, work, fargs, outputs, landing, sargs, check):
    # flags[0]: a0 belongs to (x, v); flags[1]: a reference step (br, er, ref) exists.
    # ref = (length of the reference step, time from its start to now).
    # tc = (time, the part of it that t + dt rounded away): the time is carried
    # as t + ct, summed with compensation like x and v, so that after 1e6 steps
    # the state is still at the time it is labelled with.  The compensation is
    # used only when the loop is called again at the time it returned.
    # counts: (accepted, rejected, force evaluations) of this call.
    # marks (outputs recorded in the loop): the loop lands on each of these
    # times in turn, as it lands on t_end, and records there a row of
    # mon_out (monitors and state, orbits._kernels.stepping.record_state) with
    # its time in mon_t and its step count in mark_steps; t_end is then the
    # last mark.  The rows count in n_mon.  Empty marks: the loop lands on
    # t_end alone (the same compiled loop, so that a new force compiles one
    # loop for both uses).
    (dtp, info, a0, b, g, e, br, er, csx, csv, ref, tc, flags, xs, vs, acc, P,
     counts) = work
    epsilon, mode = control
    mon, step0, mon_t, mon_out = outputs
    t_end, max_steps, min_dt, marks, mark_steps = landing
    stopping = (sargs, check)
    n = x.shape[0]
    # the predictor's and the corrector's loops run over every component of
    # these flat views (loops that LLVM turns into vector instructions, not N
    # loops of three)
    m3 = 3 * n
    # velocities at the substeps: for a force that reads them, and for the
    # work of non-conservative terms
    has_work = HAS_WORK and work_on(fargs)
    predict_v = PREDICT_V or has_work or reads_velocities(fargs)
    x1, v1 = flat_rows(x, v)
    a01, acc1 = flat_rows(a0, acc)
    csx1, csv1 = flat_rows(csx, csv)
    xs1, vs1 = flat_rows(xs, vs)
    b1, g1 = flat_stages(b, g)
    # the step control measures the bodies' rows (not the tangent rows of variations)
    ne = rows(x, fargs)
    n_mon = 0
    direction, ct, target, has_marks, every, cap, until_record = adaptive_start(
        t, t_end, tc, marks, counts, info, mon, step0, mon_t)
    k_mark = 0
    eps7 = epsilon ** (1.0 / 7.0)
    pc_tol = max(PC_TOLERANCE, PC_EPSILON_SQUARED * epsilon * epsilon)
    prs7 = (_FACT7 * epsilon) ** (1.0 / 7.0)
    while True:
        if must_return(counts, max_steps, has_marks, n_mon, mon_out, until_record, cap, t,
                       t_end):
            return Status.OK, t, n_mon
        if flags[0] == 0:
            force(x, v, t, fargs, a0)
            counts[2] += 1
            flags[0] = 1
            s = 0.0
            for i in range(n):
                s += a0[i, 0] + a0[i, 1] + a0[i, 2]
            if not math.isfinite(s):
                flags[0] = 0
                return Status.NON_FINITE, t, n_mon
        proposed = dtp[0]
        if proposed == 0.0 or not math.isfinite(proposed):
            proposed = first_step(x[:ne], a0[:ne], target - t)
        proposed = abs(proposed) * direction
        dt, trimmed, underflow = landing_step(t, ct, target, proposed, min_dt)
        if underflow:
            dtp[0] = proposed
            return Status.STEP_UNDERFLOW, t, n_mon

        # first guess of b
        predicted = flags[1] != 0
        if predicted:
            predict(b, e, br, er, ref[1] / ref[0], dt / ref[0], P)
        else:
            b[...] = 0.0
            e[...] = 0.0
        g_from_b(b, g)

        # the work rate at the start of the step, the Radau rule's node h = 0
        p0 = 0.0
        if has_work:
            p0 = work_rate(x, v, t, fargs)

        # predictor-corrector
        err_last = 2.0
        pw = 0.0
        for it in range(PC_MAX_ITERATIONS):
            maxdb6 = 0.0
            maxa = 0.0
            pw = _WR[0] * p0          # the work's quadrature, of this iteration's states
            for sub in range(1, 8):
                h = _H[sub - 1]
                hdt = h * dt
                # the positions (and the velocities, where predicted) at the
                # substep: one loop for each case, so that LLVM vectorises
                # each without a branch inside
                if predict_v:
                    for k in range(m3):
                        xs1[k] = _predicted_x(x1, csx1, v1, a01, b1, k, h, hdt)
                        vs1[k] = v1[k] + (csv1[k] + hdt * (a01[k] + h * (
                            b1[0, k] * _V0 + h * (b1[1, k] * _V1 + h * (
                                b1[2, k] * _V2 + h * (b1[3, k] * _V3 + h * (
                                    b1[4, k] * _V4 + h * (b1[5, k] * _V5 + h * (
                                        b1[6, k] * _V6)))))))))
                else:
                    for k in range(m3):
                        xs1[k] = _predicted_x(x1, csx1, v1, a01, b1, k, h, hdt)
                force(xs, vs, t + (ct + hdt), fargs, acc)
                if has_work:
                    pw += _WR[sub] * work_rate(xs, vs, t + (ct + hdt), fargs)
                # the corrector, a pass over every component at a time (each
                # a loop LLVM vectorises; each component's operations in the
                # order of the nested form): the new divided difference r
                # and its change dg take vs, free until the step's end; each
                # factor 1 / (h_sub - h_j) is R + R_low, applied with one
                # rounding (see R_LOW_TABLE)
                R0 = _R[sub, 0]
                R0_low = _RL[sub, 0]
                for k in range(m3):
                    dd = acc1[k] - a01[k]
                    vs1[k] = fma(dd, R0, dd * R0_low)
                for j in range(1, sub):
                    rj = _R[sub, j]
                    rj_low = _RL[sub, j]
                    for k in range(m3):
                        dd = vs1[k] - g1[j - 1, k]
                        vs1[k] = fma(dd, rj, dd * rj_low)
                for k in range(m3):
                    r = vs1[k]
                    vs1[k] = r - g1[sub - 1, k]
                    g1[sub - 1, k] = r
                for m in range(sub):
                    cm = _C[m, sub - 1]
                    for k in range(m3):
                        b1[m, k] += cm * vs1[k]
                if sub == 7:
                    for k in range(3 * ne):
                        db = abs(vs1[k])
                        if db > maxdb6 or not db == db:
                            maxdb6 = db
                        aa = abs(acc1[k])
                        if aa > maxa:
                            maxa = aa
            counts[2] += 7
            err = maxdb6 / maxa if maxa > 0.0 else maxdb6
            if not math.isfinite(err):
                break
            if err < pc_tol or (it >= 1 and err >= err_last):
                break
            err_last = err

        # The corrector only adds C dg to b, so the b it ends with are the
        # predicted b plus C (g - g_pred), with g_pred = D b_pred rounded: they
        # keep the rounding residue b_pred - C fl(D b_pred) of the prediction.
        # The prediction is a smooth function of the earlier steps, so that
        # residue does not change sign at random from step to step: on the
        # outer solar system every run of an ensemble drifted in energy the same
        # way, by a few 1e-20 of |E| a step: after 1e4 orbits (5e5 steps) as
        # much as the random walk itself.  The g are divided differences of
        # this step's forces alone; b = C g taken afresh from them carry no
        # memory of the prediction, and the drift is gone (validation/brouwer.py).
        b_from_g(g, b)

        # step control: the global criterion always, the per-body timescale on top
        worst = -1
        maxb6 = 0.0
        maxa = 0.0
        for i in range(ne):
            for d in range(3):
                bb = abs(b[6, i, d])
                if bb > maxb6 or not bb == bb:
                    maxb6 = bb
                    worst = i
                aa = abs(acc[i, d])
                if aa > maxa:
                    maxa = aa
        # zero acceleration everywhere, or a polynomial acceleration that the
        # step resolves exactly: nothing limits the step
        if maxa > 0.0 and maxb6 > 0.0:
            dt_new = dt * eps7 / (maxb6 / maxa) ** (1.0 / 7.0)
            # b6 cannot be known better than the rounding of the accelerations
            # it is made of: when it is no larger than that, a smaller step
            # would not make it smaller (it stays at the rounding level whatever
            # the step, and the step would shrink towards zero in a close
            # encounter); keep the step instead
            if abs(dt_new) < abs(dt) and maxb6 <= _b6_rounding(x, xs, a0, acc, ne):
                dt_new = dt
        elif maxb6 == maxb6:
            dt_new = dt / SAFETY
        else:
            dt_new = math.nan
        if mode == MODE_PRS24 and dt_new == dt_new:
            tau2 = math.inf
            worst_prs = -1
            for i in range(ne):
                y2 = 0.0
                y3 = 0.0
                y4 = 0.0
                for d in range(3):
                    a1 = a0[i, d] + (b[0, i, d] + b[1, i, d] + b[2, i, d] + b[3, i, d]
                                     + b[4, i, d] + b[5, i, d] + b[6, i, d])
                    j1 = (b[0, i, d] + 2.0 * b[1, i, d] + 3.0 * b[2, i, d] + 4.0 * b[3, i, d]
                          + 5.0 * b[4, i, d] + 6.0 * b[5, i, d] + 7.0 * b[6, i, d])
                    s1 = (2.0 * b[1, i, d] + 6.0 * b[2, i, d] + 12.0 * b[3, i, d]
                          + 20.0 * b[4, i, d] + 30.0 * b[5, i, d] + 42.0 * b[6, i, d])
                    y2 += a1 * a1
                    y3 += j1 * j1
                    y4 += s1 * s1
                den = y3 + math.sqrt(y2 * y4)
                # a body with no acceleration, or one whose acceleration the step
                # resolves exactly, sets no timescale
                if y2 > 0.0 and den > 0.0:
                    tau = 2.0 * y2 / den
                    if tau < tau2:
                        tau2 = tau
                        worst_prs = i
            if tau2 < math.inf:
                dt_prs = dt * math.sqrt(tau2) * prs7
                # A body's timescale goes to zero as its acceleration passes
                # through zero (a body crossing a symmetry point, the figure-eight's
                # centre): steps would shrink geometrically towards that instant
                # and never reach it.  The global criterion, which measures every
                # body's error against the largest acceleration, does not see such
                # a point, so it bounds the step from below.
                if dt_prs > dt_new or not dt_prs >= 0.0:
                    dt_new = dt_prs
                    worst = worst_prs
            else:
                dt_new = dt / SAFETY
        if not math.isfinite(dt_new):
            info[0] = worst
            return Status.NON_FINITE, t, n_mon

        if abs(dt_new) < SAFETY * abs(dt):
            # rejected: redo from the same state with the smaller step
            counts[1] += 1
            dtp[0] = dt_new
            if abs(dt_new) < min_dt or t + dt_new == t:
                info[0] = worst
                return Status.STEP_UNDERFLOW, t, n_mon
            continue
        if abs(dt_new) > abs(dt) / SAFETY:
            dt_new = dt / SAFETY

        # accept: increments first, so that a non-finite one leaves (x, v) untouched
        s = 0.0
        for i in range(n):
            for d in range(3):
                # smallest terms first, so that they are not lost against a0
                dx = dt * (v[i, d] + dt * (
                    b[6, i, d] / 72.0 + b[5, i, d] / 56.0 + b[4, i, d] / 42.0
                    + b[3, i, d] / 30.0 + b[2, i, d] / 20.0 + b[1, i, d] / 12.0
                    + b[0, i, d] / 6.0 + a0[i, d] / 2.0))
                dv = dt * (b[6, i, d] / 8.0 + b[5, i, d] / 7.0 + b[4, i, d] / 6.0
                           + b[3, i, d] / 5.0 + b[2, i, d] / 4.0 + b[1, i, d] / 3.0
                           + b[0, i, d] / 2.0 + a0[i, d])
                xs[i, d] = dx
                vs[i, d] = dv
                s += dx + dv
        if not math.isfinite(s):
            return Status.NON_FINITE, t, n_mon
        add_compensated(x, xs, csx)
        add_compensated(v, vs, csv)
        flags[0] = 0
        if has_work:
            work_add(fargs, -dt * pw)
        t, ct = clock_step(t, ct, dt, trimmed, target)
        tc[0] = t
        tc[1] = ct
        counts[0] += 1
        # a shortened last step leaves the proposed step as it was
        if not trimmed:
            proposed = dt_new
        dtp[0] = proposed

        # keep this step as the reference for extrapolation if it reaches the
        # next step with the shorter stretch (in units of its own length)
        if flags[1] == 0 or 1.0 + abs(proposed / dt) <= abs((ref[1] + dt + proposed) / ref[0]):
            for m in range(7):
                for i in range(n):
                    for d in range(3):
                        br[m, i, d] = b[m, i, d]
                        er[m, i, d] = e[m, i, d] if predicted else b[m, i, d]
            ref[0] = dt
            ref[1] = dt
            flags[1] = 1
        else:
            ref[1] += dt

        code, target, k_mark, until_record, n_mon = land(
            x, v, t, counts[0], abs(proposed) < min_dt, worst, has_marks, target, k_mark,
            until_record, n_mon, outputs, marks, mark_steps, stopping, info, fargs)
        if code != GO:
            return code, t, n_mon


def _first_step(x, a0, span):
    # 1 % of sqrt(size / acceleration): the free-fall time across the system
    # scaled down; the step control corrects it within a few steps
    n = x.shape[0]
    cx = 0.0
    cy = 0.0
    cz = 0.0
    for i in range(n):
        cx += x[i, 0]
        cy += x[i, 1]
        cz += x[i, 2]
    cx /= n
    cy /= n
    cz /= n
    size = 0.0
    amax = 0.0
    for i in range(n):
        r = math.sqrt((x[i, 0] - cx) ** 2 + (x[i, 1] - cy) ** 2 + (x[i, 2] - cz) ** 2)
        a = math.sqrt(a0[i, 0] ** 2 + a0[i, 1] ** 2 + a0[i, 2] ** 2)
        size = max(size, r)
        amax = max(amax, a)
    if size > 0.0 and amax > 0.0:
        return min(0.01 * math.sqrt(size / amax), abs(span))
    return abs(span)


# the names _ias15_loop is written against, bound by ias15_loop (specialize);
# the helpers default to their Python form, for a loop that runs as Python
force, rows, land, PREDICT_V, reads_velocities = slots("force", "rows", "land", "PREDICT_V",
                                                      "reads_velocities")
HAS_WORK, work_rate, work_add, work_note, work_on = slots(*WORK_SLOTS)
predict, g_from_b, b_from_g, first_step = slots(
    predict=_predict, g_from_b=_g_from_b, b_from_g=_b_from_g, first_step=_first_step)
_JITTED = {"predict": njit(_predict), "g_from_b": njit(_g_from_b),
           "b_from_g": njit(_b_from_g), "first_step": njit(_first_step)}


def ias15_loop(force):
    """The IAS15 loop compiled for a :class:`~orbits._kernels.stepping.ForceKernel`.

    Velocities are predicted at the substeps only for forces that read them
    (gravity does not), and for forces whose non-conservative terms' work it
    integrates.

    The loop is ``loop(x, v, t, control, work, fargs, outputs, landing, sargs,
    check)``: a :class:`Control`, a :class:`Work` over the arrays of
    :meth:`orbits.integrators.ias15.IAS15.workspace`, the records of
    :mod:`.records` and the stopping conditions
    (:func:`~orbits._kernels.stopping.stop_record`); it returns ``(status,
    t_reached, n_monitor_rows)`` and leaves the step counts in ``counts``.
    """
    # the work rate P = sum m a . v needs the velocities at the nodes; whether
    # the force reads them and whether its terms do work are its arguments'
    # to say (velocity_reader, work_on), so that one loop serves terms that
    # do and terms that do not
    predict_v = force.opaque
    helpers = _JITTED if force.jit else {}
    return specialize(_ias15_loop, force.key, jit=force.jit, cache=force.cache,
                      nrt=force.runtime, force=force.kernel,
                      land=step_lander(force), PREDICT_V=predict_v,
                      reads_velocities=velocity_reader(force),
                      rows=measured_rows(force), **work_kernels(force), **helpers)
