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
from .embedded import adaptive_loop
from .stepping import WORK_SLOTS, work_kernels

# the names the templates below are written against, bound by specialize
force, rk4_step = slots("force", "rk4_step")
HAS_WORK, work_rate, work_add, work_note, work_on = slots(*WORK_SLOTS)

__all__ = ["doubling_loop", "Method", "METHOD"]


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


class Method(NamedTuple):
    """Step doubling's record for the adaptive loop: the order ``q`` of its
    error estimate."""
    q: float


#: RK4 with step doubling: the two half steps' error is of fourth order
METHOD = Method(4.0)


def _doubling_step(x, v, t, h, method, tolerances, work, views, fargs, p0, ne):
    # a step of h and two of h / 2 from (x, v), the latter into work's x2,
    # v2: (error, the work of non-conservative terms over the two halves,
    # force evaluations)
    k0x, k0v, kmx, kmv, kx, kv, xs, vs, xf, vf, xh, vh, x2, v2, _, _, _ = work
    rtol, atol = tolerances
    n = x.shape[0]
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
    err = 0.0
    for i in range(ne):
        for d in range(3):
            sx = atol + rtol * max(abs(x[i, d]), abs(x2[i, d]))
            sv = atol + rtol * max(abs(v[i, d]), abs(v2[i, d]))
            err += ((x2[i, d] - xf[i, d]) / (15.0 * sx)) ** 2 \
                + ((v2[i, d] - vf[i, d]) / (15.0 * sv)) ** 2
    return math.sqrt(err / (6 * ne)), 0.5 * h * (pa + pb), 10


def _doubling_accept(x, v, t, method, work, fargs):
    # the two half steps' end becomes the state, with its derivative
    k0x, k0v, x2, v2 = work.k0x, work.k0v, work.x2, work.v2
    for i in range(x.shape[0]):
        for d in range(3):
            x[i, d] = x2[i, d]
            v[i, d] = v2[i, d]
    force(x, v, t, fargs, k0v)
    for i in range(x.shape[0]):
        for d in range(3):
            k0x[i, d] = v[i, d]
    return 1


def _doubling_first(x, v, work):
    return work.k0x, work.k0v, ()


def doubling_loop(force):
    """The RK4 step-doubling loop compiled for a force: the adaptive loop of
    :func:`~.embedded.adaptive_loop`, which takes ``(x, v, t, METHOD,
    tolerances, work, fargs, outputs, landing, sargs, check)``, a
    :class:`Work`, the records of :mod:`.records` and the stopping
    conditions (:func:`~.stopping.stop_record`)."""
    key = f"doubling_{force.key}"
    work = work_kernels(force)
    options = dict(jit=force.jit, cache=force.cache)
    rk4 = specialize(_rk4_step, key, force=force.kernel, HAS_WORK=work["HAS_WORK"],
                     work_rate=work["work_rate"], **options)
    bound = dict(force=force.kernel, rk4_step=rk4, HAS_WORK=work["HAS_WORK"],
                 work_rate=work["work_rate"], **options)
    inlined = dict(inline=True, nrt=force.runtime)
    return adaptive_loop(force, key, specialize(_doubling_step, key, **inlined, **bound),
                         specialize(_doubling_accept, key, **inlined, **bound),
                         specialize(_doubling_first, key, **inlined, **options))
