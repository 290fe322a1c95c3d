"""The compiled adaptive loop of RK4 with step doubling.

Each step is taken twice: once with step ``h`` and once as two steps of
``h/2``.  Their difference divided by ``2^4 - 1 = 15`` estimates the error of
the two half steps (Richardson); the step is accepted when that error, in
the root-mean-square norm against ``atol + rtol * |y|``, is at most one, and
the result of the two half steps is kept (no local extrapolation, so the
method stays fourth order).  Step sizes follow the same controller as the
embedded pairs (:mod:`.embedded`), with the error exponent 1/5.  Eleven force
evaluations a step (the first stage is shared).

The work of non-conservative force terms (:mod:`.stepping`) is integrated by
the two half steps that are kept, each with RK4's weights, and committed only
when the step is accepted.
"""

import math
from typing import NamedTuple

import numpy as np

from ._jit import slots, specialize
from .embedded import call_start, next_step, step_underflow, trial_step
from .status import Status
from .stepping import GO, WORK_SLOTS, first_record, step_lander, work_kernels
from .variational import measured_rows

# the names the templates below are written against, bound by specialize
force, land, rk4_step, rows = slots("force", "land", "rk4_step", "rows")
HAS_WORK, work_rate, work_add, work_note = slots(*WORK_SLOTS)

__all__ = ["doubling_loop"]



#: ``track`` of :func:`_rk4_step`: floats, not booleans, so that numba compiles
#: the step once for both (a constant True or False is a type of its own)
UNTRACKED = 0.0
TRACKED = 1.0


def _rk4_step(x, v, t, h, k0x, k0v, kx, kv, xs, vs, xo, vo, fargs, p0, track):
    # classic RK4 from (x, v) with its first stage (k0x, k0v) given; result in
    # (xo, vo).  kx, kv hold stages 1..3.  Returns RK4's mean of the work rate
    # P over the stages (p0 at the first), with track and HAS_WORK, else 0.
    n = x.shape[0]
    pw = p0 / 6.0
    for st in range(3):
        a = 0.5 * h if st < 2 else h
        for i in range(n):
            for d in range(3):
                if st == 0:
                    gx = k0x[i, d]
                    gv = k0v[i, d]
                else:
                    gx = kx[st - 1, i, d]
                    gv = kv[st - 1, i, d]
                xs[i, d] = x[i, d] + a * gx
                vs[i, d] = v[i, d] + a * gv
                kx[st, i, d] = vs[i, d]
        force(xs, vs, t + (0.5 * h if st < 2 else h), fargs, kv[st])
        if HAS_WORK and track:
            pw += (2.0 if st < 2 else 1.0) / 6.0 * work_rate(
                xs, vs, t + (0.5 * h if st < 2 else h), fargs)
    for i in range(n):
        for d in range(3):
            xo[i, d] = x[i, d] + h / 6.0 * (k0x[i, d] + 2.0 * kx[0, i, d]
                                            + 2.0 * kx[1, i, d] + kx[2, i, d])
            vo[i, d] = v[i, d] + h / 6.0 * (k0v[i, d] + 2.0 * kv[0, i, d]
                                            + 2.0 * kv[1, i, d] + kv[2, i, d])
    return pw if HAS_WORK and track else 0.0


class Work(NamedTuple):
    """The step-doubling loop's workspace: the derivative at the state
    (``k0x``, ``k0v``) and at the half step (``kmx``, ``kmv``), the RK4
    stages ``kx``, ``kv``, a stage's state ``xs``, ``vs``, the full step's
    result ``xf``, ``vf``, the half steps' ``xh``, ``vh`` and ``x2``, ``v2``,
    the next step's size ``dt[0]``, ``fsal[0]`` (1: ``k0v`` belongs to the
    state) and ``info`` (where a failure happened)."""
    k0x: np.ndarray
    k0v: np.ndarray
    kmx: np.ndarray
    kmv: np.ndarray
    kx: np.ndarray
    kv: np.ndarray
    xs: np.ndarray
    vs: np.ndarray
    xf: np.ndarray
    vf: np.ndarray
    xh: np.ndarray
    vh: np.ndarray
    x2: np.ndarray
    v2: np.ndarray
    dt: np.ndarray
    fsal: np.ndarray
    info: np.ndarray


def _doubling_loop(x, v, t, tolerances, work, fargs, outputs, landing, sargs, check):
    # marks: outputs recorded in the loop, as in orbits._kernels.embedded
    k0x, k0v, kmx, kmv, kx, kv, xs, vs, xf, vf, xh, vh, x2, v2, dtbox, fsal, info = work
    rtol, atol = tolerances
    mon, step0, mon_t, mon_out = outputs
    t_end, max_steps, _, marks, mark_steps = landing
    stopping = (sargs, check)
    n = x.shape[0]
    every = mon[0]
    n_mon = 0
    until_record = first_record(every, step0, mon_t)
    steps = 0
    rejected = 0
    fev = 0
    info[0] = -1
    info[1] = -1
    # the error measures the bodies' rows (not the tangent rows of variations)
    ne = rows(x, fargs)
    ncomp = 6 * ne
    if fsal[0] == 0:
        force(x, v, t, fargs, k0v)
        fev += 1
        for i in range(n):
            for d in range(3):
                k0x[i, d] = v[i, d]
        fsal[0] = 1
    # dtbox holds the step's size; the steps carry the direction of time
    direction, h_prop, target, has_marks = call_start(x, v, k0x, k0v, ne, t, t_end, dtbox,
                                                      rtol, atol, marks)
    status = Status.OK
    p0 = work_rate(x, v, t, fargs) if HAS_WORK else 0.0
    k_mark = 0
    while steps < max_steps and (t_end - t) * direction > 0.0:
        if has_marks and n_mon >= mon_out.shape[0]:
            break                                    # caller collects the rows first
        h, shortened = trial_step(t, h_prop, target, direction)
        rk4_step(x, v, t, h, k0x, k0v, kx, kv, xs, vs, xf, vf, fargs, p0, UNTRACKED)
        pa = rk4_step(x, v, t, 0.5 * h, k0x, k0v, kx, kv, xs, vs, xh, vh,
                      fargs, p0, TRACKED)
        for i in range(n):
            for d in range(3):
                kmx[i, d] = vh[i, d]
        force(xh, vh, t + 0.5 * h, fargs, kmv)
        pm = 0.0
        if HAS_WORK:
            pm = work_rate(xh, vh, t + 0.5 * h, fargs)
        pb = rk4_step(xh, vh, t + 0.5 * h, 0.5 * h, kmx, kmv, kx, kv, xs, vs,
                      x2, v2, fargs, pm, TRACKED)
        fev += 10
        err = 0.0
        for i in range(ne):
            for d in range(3):
                sx = atol + rtol * max(abs(x[i, d]), abs(x2[i, d]))
                sv = atol + rtol * max(abs(v[i, d]), abs(v2[i, d]))
                err += ((x2[i, d] - xf[i, d]) / (15.0 * sx)) ** 2 \
                    + ((v2[i, d] - vf[i, d]) / (15.0 * sv)) ** 2
        err = math.sqrt(err / ncomp)
        if not math.isfinite(err):
            err = math.inf
        if err <= 1.0:
            for i in range(n):
                for d in range(3):
                    x[i, d] = x2[i, d]
                    v[i, d] = v2[i, d]
            t = target if shortened else t + h
            force(x, v, t, fargs, k0v)
            fev += 1
            for i in range(n):
                for d in range(3):
                    k0x[i, d] = v[i, d]
            steps += 1
            if not shortened:
                h_prop = next_step(h, err, 4.0)
            if HAS_WORK:
                work_add(fargs, -0.5 * h * (pa + pb))
                p0 = work_rate(x, v, t, fargs)
            code, target, k_mark, until_record, n_mon = land(
                x, v, t, steps, False, 0, has_marks, target, k_mark, until_record, n_mon,
                outputs, marks, mark_steps, stopping, info, fargs)
            if code != GO:
                status = code
                break
        else:
            rejected += 1
            h_prop = next_step(h, err, 4.0)
            if step_underflow(abs(h_prop), t, t_end):
                status = Status.STEP_UNDERFLOW
                break
    dtbox[0] = abs(h_prop)
    return status, t, steps, rejected, fev, n_mon


def doubling_loop(force):
    """The RK4 step-doubling loop compiled for a force: it takes ``(x, v, t,
    tolerances, work, fargs, outputs, landing, sargs, check)``, a
    :class:`Work`, the records of :mod:`.records` and the stopping
    conditions (:func:`~.stopping.stop_record`)."""
    key = force.key
    work = work_kernels(force)
    step = specialize(_rk4_step, key, jit=force.jit, cache=force.cache, force=force.kernel,
                      HAS_WORK=work["HAS_WORK"], work_rate=work["work_rate"])
    return specialize(_doubling_loop, key, jit=force.jit, cache=force.cache,
                      nrt=force.runtime, force=force.kernel, rk4_step=step,
                      land=step_lander(force), rows=measured_rows(force), **work)
