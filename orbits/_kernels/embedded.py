"""The compiled adaptive loop of the Runge-Kutta methods with error control:
the embedded pairs (dopri5, dop853) and, with a step of its own, RK4 with
step doubling (:mod:`.doubling`).

The loop (:func:`adaptive_loop`) holds the step control, the landing on
output times and the stops; a method gives it its step and error.  One
step serves every pair: the method is its Butcher table ``A``, ``b``,
``c`` and error weights ``e`` (and, for DOP853, ``e3``), all over the last
stage being the first stage of the next step ("first same as last"), so a step
costs ``s`` force evaluations.  The state is ``y = (x, v)`` with
``y' = (v, a(x, v, t))``.

Step control (Hairer, Nørsett & Wanner 1993, section II.4): the error of a
step is measured against ``atol + rtol * max(|y0|, |y1|)`` component by
component in the root-mean-square norm (DOP853 combines its 5th- and
3rd-order estimates as in section II.10); a step with error <= 1 is accepted,
and the next step is ``h * min(FAC_MAX, max(FAC_MIN, SAFETY * err^(-1/(q+1))))``
with ``q`` the order of the error estimator.  A step shortened to land on an
output time does not change the proposed step size, so outputs do not disturb
the step sequence.

The work of non-conservative force terms (:mod:`.stepping`) is integrated
with the weights ``b`` of the propagated solution, ``W += -h sum_j b_j
P(stage j)``, and committed only when the step is accepted.
"""

import math
from typing import NamedTuple

import numpy as np

from ._jit import njit, slots, specialize
from .status import Status
from .stepping import (GO, WORK_SLOTS, accept_fsal, dop853_error, first_record, flat_rows,
                       rk_stages, rk_sums, stage_errors, stage_views, step_lander, work_kernels)
from .variational import measured_rows

# the names the templates below are written against, bound by specialize
force, land, rows, attempt, accept, first_stage, stages = slots(
    "force", "land", "rows", "attempt", "accept", "first_stage", "stages")
HAS_WORK, work_rate, work_add, work_note, work_on = slots(*WORK_SLOTS)

__all__ = ["embedded_loop", "adaptive_loop", "initial_step", "next_step", "step_underflow", "SAFETY",
           "FAC_MIN", "FAC_MAX"]

SAFETY = 0.9   # step-size safety factor (HNW II.4)
FAC_MIN = 0.2  # a rejected step shrinks by at most 5
FAC_MAX = 10.0  # an accepted step grows by at most 10
_EPS = 2.220446049250313e-16


@njit
def initial_step(x, v, fx, fv, rtol, atol, span):
    """A first step size from the sizes of y and y' in the error norm (HNW II.4)."""
    n = x.shape[0]
    d0 = 0.0
    d1 = 0.0
    for i in range(n):
        for d in range(3):
            sx = atol + rtol * abs(x[i, d])
            sv = atol + rtol * abs(v[i, d])
            d0 += (x[i, d] / sx) ** 2 + (v[i, d] / sv) ** 2
            d1 += (fx[i, d] / sx) ** 2 + (fv[i, d] / sv) ** 2
    d0 = math.sqrt(d0 / (6 * n))
    d1 = math.sqrt(d1 / (6 * n))
    h = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    return min(h, span)


@njit
def next_step(h, err, q):
    """The step after one of size ``h`` with error ``err`` (<= 1: accepted), for an
    error estimate of order ``q``: ``h * SAFETY * err^(-1/(q+1))``, kept within
    ``[FAC_MIN, FAC_MAX]`` times ``h``; an overflowed step (``err = inf``)
    shrinks by ``FAC_MIN``."""
    if err == 0.0:
        return h * FAC_MAX
    if err == math.inf:
        return h * FAC_MIN
    return h * min(FAC_MAX, max(FAC_MIN, SAFETY * err ** (-1.0 / (q + 1))))


@njit
def step_underflow(h, t, t_end):
    """True when a step no longer moves ``t`` by more than a few roundings."""
    return h <= 4.0 * _EPS * max(abs(t), abs(t_end))


@njit(inline="always")
def call_start(x, v, fx, fv, ne, t, t_end, dtbox, rtol, atol, marks):
    """An adaptive Runge-Kutta loop's call set up: ``(direction, h_prop,
    target, has_marks)``, the direction of time, the first step to try (the
    last call's, kept in ``dtbox[0]``, else :func:`initial_step`'s from the
    state ``x``, ``v`` and its derivative ``fx``, ``fv``, rows below
    ``ne``), and the first time to land on (the first mark, else
    ``t_end``; an empty marks array: none, so that one compiled loop serves
    both uses)."""
    direction = 1.0 if t_end > t else -1.0
    h_prop = dtbox[0]
    if h_prop <= 0.0:
        h_prop = initial_step(x[:ne], v[:ne], fx[:ne], fv[:ne], rtol, atol, abs(t_end - t))
    has_marks = marks.shape[0] > 0
    return direction, h_prop * direction, marks[0] if has_marks else t_end, has_marks


@njit(inline="always")
def trial_step(t, h_prop, target, direction):
    """The step to try from ``t``, ``(h, shortened)``: the proposal, or what
    is left to ``target`` when the proposal would reach within 1 % of it
    (landing also when only a sliver would be left, as HNW's DOPRI5 does)."""
    if (t + 1.01 * h_prop - target) * direction >= 0.0:
        return target - t, True
    return h_prop, False


class Method(NamedTuple):
    """An embedded pair: its Butcher tableau ``A``, ``b``, ``c``, the
    weights' difference ``e`` of the error estimate (and ``e3``, a second
    estimate's, or zeros), the estimator's order ``q``, and whether the
    error combines the two estimates as DOP853's does (``has_e3``)."""
    A: np.ndarray
    b: np.ndarray
    c: np.ndarray
    e: np.ndarray
    e3: np.ndarray
    q: float
    has_e3: bool


class Work(NamedTuple):
    """The embedded loop's workspace: the stages' velocities and
    accelerations ``kx``, ``kv`` (one row a stage, the last the FSAL
    stage), a stage's state ``xs``, ``vs``, the proposed state ``x1``,
    ``v1``, the next step's size ``dt[0]``, ``fsal[0]`` (1: ``kv[0]``
    belongs to the state) and ``info`` (where a failure happened)."""
    kx: np.ndarray
    kv: np.ndarray
    xs: np.ndarray
    vs: np.ndarray
    x1: np.ndarray
    v1: np.ndarray
    dt: np.ndarray
    fsal: np.ndarray
    info: np.ndarray


def _adaptive_loop(x, v, t, method, tolerances, work, fargs, outputs, landing, sargs, check):
    # marks (outputs recorded in the loop): the loop lands on each of these
    # times in turn, as it lands on t_end, and records there a row of
    # mon_out (monitors and state) with its time in mon_t and its step count
    # in mark_steps; t_end is then the last mark.  Landing on a mark in the
    # loop is landing on it at the end of a call: the same steps, bit for
    # bit.  Empty marks: the loop lands on t_end alone (the same compiled
    # loop for both uses).  The method's step and error are attempt's, what
    # an accepted step leaves for the next accept's.
    rtol, atol = tolerances
    dtbox, fsal, info = work.dt, work.fsal, work.info
    mon, step0, mon_t, mon_out = outputs
    t_end, max_steps, _, marks, mark_steps = landing
    stopping = (sargs, check)
    n = x.shape[0]
    n_mon = 0
    until_record = first_record(mon[0], step0, mon_t)
    steps = 0
    rejected = 0
    fev = 0
    info[0] = -1
    info[1] = -1
    # the error measures the bodies' rows (not the tangent rows of variations)
    ne = rows(x, fargs)
    # the derivative at the start, unless the last call left it (FSAL), and
    # the views the method's step works on, made once a call
    fx, fv, views = first_stage(x, v, work)
    if fsal[0] == 0:
        force(x, v, t, fargs, fv)
        fev += 1
        for i in range(n):
            for d in range(3):
                fx[i, d] = v[i, d]
        fsal[0] = 1
    # dtbox holds the step's size; the steps carry the direction of time
    direction, h_prop, target, has_marks = call_start(x, v, fx, fv, ne, t, t_end, dtbox,
                                                      rtol, atol, marks)
    status = Status.OK
    p0 = work_rate(x, v, t, fargs) if HAS_WORK else 0.0
    k_mark = 0
    while steps < max_steps and (t_end - t) * direction > 0.0:
        if has_marks and n_mon >= mon_out.shape[0]:
            break                                    # caller collects the rows first
        h, shortened = trial_step(t, h_prop, target, direction)
        err, spent, evaluations = attempt(x, v, t, h, method, tolerances, work, views, fargs,
                                          p0, ne)
        fev += evaluations
        if not math.isfinite(err):
            err = math.inf  # a step that overflowed is rejected and shrunk
        if err <= 1.0:
            t = target if shortened else t + h
            fev += accept(x, v, t, method, work, fargs)
            steps += 1
            if not shortened:
                h_prop = next_step(h, err, method.q)
            if HAS_WORK:
                work_add(fargs, -spent)
                p0 = work_rate(x, v, t, fargs)
            code, target, k_mark, until_record, n_mon = land(
                x, v, t, steps, False, 0, has_marks, target, k_mark, until_record, n_mon,
                outputs, marks, mark_steps, stopping, info, fargs)
            if code != GO:
                status = code
                break
        else:
            rejected += 1
            h_prop = next_step(h, err, method.q)
            if step_underflow(abs(h_prop), t, t_end):
                status = Status.STEP_UNDERFLOW
                break
    dtbox[0] = abs(h_prop)
    return status, t, steps, rejected, fev, n_mon


def _embedded_step(x, v, t, h, method, tolerances, work, views, fargs, p0, ne):
    # one step of the pair from (x, v) into work's x1, v1 with its stages:
    # (error, the work of non-conservative terms over it, force evaluations)
    A, b, c, e, e3, q, has_e3 = method
    rtol, atol = tolerances
    kx, kv, xs, vs, x1, v1 = work.kx, work.kv, work.xs, work.vs, work.x1, work.v1
    xF, vF, xsF, vsF, kxF, kvF, x1F, v1F = views
    m3 = xF.shape[0]
    s = b.shape[0]
    pw = stages(xF, vF, xsF, vsF, kxF, kvF, xs, vs, kv, (A, b, c), t, h, 1, s, b[0] * p0,
                fargs)
    # the step's sums b . k, gathered in x1, v1, then the new state
    rk_sums(x1F, v1F, kxF, kvF, b, s)
    for k in range(m3):
        x1F[k] = xF[k] + h * x1F[k]
        v1F[k] = vF[k] + h * v1F[k]
        kxF[s, k] = v1F[k]
    force(x1, v1, t + h, fargs, kv[s])
    # the error's sums written for each estimator (a constant of each call),
    # so that a pair without the second estimate computes none of it
    if has_e3:
        err5, err3 = _scaled_errors(x, v, x1, v1, kx, kv, e, e3, s + 1, ne, rtol, atol, True)
        err = dop853_error(err5, err3, abs(h), 6 * ne)
    else:
        err5, _ = _scaled_errors(x, v, x1, v1, kx, kv, e, e3, s + 1, ne, rtol, atol, False)
        err = abs(h) * math.sqrt(err5 / (6 * ne))
    return err, h * pw, s


@njit(inline="always")
def _scaled_errors(x, v, x1, v1, kx, kv, e, e3, count, ne, rtol, atol, both):
    # the sums of squares of the error estimates (e's, and e3's if both)
    # scaled by atol + rtol max(|y0|, |y1|), over the rows below ne
    err5 = 0.0
    err3 = 0.0
    for i in range(ne):
        for d in range(3):
            ex, ev, fx, fv = stage_errors(kx, kv, e, e3, count, i, d)
            sx = atol + rtol * max(abs(x[i, d]), abs(x1[i, d]))
            sv = atol + rtol * max(abs(v[i, d]), abs(v1[i, d]))
            err5 += (ex / sx) ** 2 + (ev / sv) ** 2
            if both:
                err3 += (fx / sx) ** 2 + (fv / sv) ** 2
    return err5, err3


def _embedded_accept(x, v, t, method, work, fargs):
    # the step's end becomes the state, its last stage the next step's first
    accept_fsal(x, v, work.x1, work.v1, work.kx, work.kv, method.b.shape[0], x.shape[0])
    return 0


def _embedded_first(x, v, work):
    # the first stage, and flat views of the (N, 3) arrays: the stages run
    # over every component in loops that LLVM turns into vector
    # instructions (stepping.rk_stage)
    kx, kv = work.kx, work.kv
    xF, vF, xsF, vsF, kxF, kvF = stage_views(x, v, work.xs, work.vs, kx, kv)
    x1F, v1F = flat_rows(work.x1, work.v1)
    return kx[0], kv[0], (xF, vF, xsF, vsF, kxF, kvF, x1F, v1F)


def embedded_loop(force):
    """The adaptive embedded Runge-Kutta loop compiled for a force, for every
    pair: it takes ``(x, v, t, method, tolerances, work, fargs, outputs,
    landing, sargs, check)``, a :class:`Method`, a :class:`Work`, the records
    of :mod:`.records` and the stopping conditions
    (:func:`~.stopping.stop_record`)."""
    key = f"embedded_{force.key}"
    options = dict(jit=force.jit, cache=force.cache, inline=True, nrt=force.runtime)
    step = specialize(_embedded_step, key, force=force.kernel, stages=rk_stages(force),
                      **options)
    return adaptive_loop(force, key, step, specialize(_embedded_accept, key, **options),
                         specialize(_embedded_first, key, **options))


def adaptive_loop(force, key, step, accept, first_stage):
    """The adaptive loop (:func:`_adaptive_loop`) compiled for a force and a
    method under ``key``, with the method's compiled kernels: ``step(x, v,
    t, h, method, tolerances, work, views, fargs, p0, rows) -> (error, work,
    force evaluations)`` tries a step, ``accept(x, v, t, method, work,
    fargs) -> force evaluations`` makes its end the state, and
    ``first_stage(x, v, work) -> (fx, fv, views)`` gives the arrays of the
    derivative at the state and what the step takes as ``views`` (made once
    a call).  It takes ``(x, v, t, method, tolerances,
    work, fargs, outputs, landing, sargs, check)``: the method's record
    (with its error estimator's order ``q``), the records of :mod:`.records`
    and the stopping conditions (:func:`~.stopping.stop_record`)."""
    return specialize(_adaptive_loop, key, jit=force.jit, cache=force.cache,
                      nrt=force.runtime, force=force.kernel, land=step_lander(force),
                      rows=measured_rows(force), attempt=step, accept=accept,
                      first_stage=first_stage, **work_kernels(force))
