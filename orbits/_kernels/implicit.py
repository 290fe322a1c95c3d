"""The compiled loop of the implicit one-stage methods, solved by Newton's method.

Implicit Euler and the implicit midpoint rule are the one-leg theta-methods
``y1 = y0 + h f(t0 + theta h, y0 + theta (y1 - y0))`` with ``theta = 1`` and
``theta = 1/2`` (Hairer & Wanner 1996, *Solving ODEs II*, section IV.3; Hairer,
Lubich & Wanner 2006, *Geometric Numerical Integration*, section I.1 and
VI.3).  For ``y = (x, v)``, ``y' = (v, a(x, v, t))`` they read

    W  = h a(x*, v*, t0 + theta h),   v* = v0 + theta W,   x* = x0 + theta h v*,
    v1 = v0 + W,                      x1 = x0 + h v*.

The positions at the stage point are an explicit linear function of the
velocity increment ``W``, so the implicit system is solved for ``W`` alone:
3N unknowns for every force, velocity dependent or not.  The (x, v) system of
6N unknowns would cost eight times as much to factor for nothing: eliminating
x is exact.  Newton's method on ``R(W) = W - h a(x*(W), v*(W)) = 0`` uses

    J = I - theta^2 h^2 da/dx - theta h da/dv

(the da/dv term only for velocity-dependent forces), factored by dense LU
with partial pivoting (:func:`lu_factor`, :func:`lu_solve`; no LAPACK, so no
scipy at run time).  The iteration is a simplified Newton method (Hairer &
Wanner, section IV.8): ``J`` is computed at the first iterate of a step and
kept while the updates contract by at least :data:`REFRESH`; otherwise it is
recomputed at the current iterate, which makes hard steps full Newton steps.

Convergence: the update is at most :data:`NEWTON_ULPS` units in the last
place of the size of the velocities and of ``W`` (max norm), or, once the
updates have stopped decreasing while below :data:`ROUNDOFF_ULPS` such units,
the iteration has reached the round-off level of the residual (the criterion
of Hairer, Lubich & Wanner, section VIII.5: stop when the increment no longer
decreases).  After :data:`NEWTON_MAX_ITER` iterations without either, the
loop returns ``Status.NO_CONVERGENCE`` with the state of the last good step.
A non-finite iterate ends it with ``Status.NON_FINITE``, the state again that
of the last good step.

The step itself is taken with the accelerations at the last stage point, so
that ``v1 - v0 = h a*`` and ``x1 - x0 = h (v0 + theta h a*)`` hold as written;
those accelerations also predict the next step's ``W`` (``W = h a``), and a
flag in ``cache`` says whether they belong to the current state (a
restart keeps both; ``invalidate`` clears the flag and the prediction falls
back to ``W = 0``).

The Jacobian is the force's (:func:`~.jacobians.jacobian_for`): analytic for
gravity and the package's terms, a user's, or central differences.

The work of non-conservative force terms (:mod:`.stepping`) is the method
applied to ``W' = -P``: ``W += -h P(x*, v*, t0 + theta h)`` at the last stage
point, which for the midpoint rule is the non-conservative part of the
kinetic-energy change ``h sum m a* . (v0 + v1) / 2`` of the step.
"""

import math
from typing import NamedTuple

import numpy as np

from ._jit import njit, slots, specialize
from .jacobians import POINTER_KEY, jacobian_for
from .status import Status
from .stepping import GO, WORK_SLOTS, first_record, state_is_finite, step_epilogue, work_kernels

# the names the templates below are written against, bound by specialize
force, jacobian, step_end = slots("force", "jacobian", "step_end")
HAS_WORK, work_rate, work_add, work_note, work_on = slots(*WORK_SLOTS)

__all__ = ["implicit_loop", "lu_factor", "lu_solve", "NEWTON_MAX_ITER", "NEWTON_ULPS",
           "ROUNDOFF_ULPS", "REFRESH"]

_EPS = 2.220446049250313e-16
_TINY = 2.2250738585072014e-308  # smallest normal number: below it no ulps to count

#: Newton iterations allowed per step before the step is declared a failure.
#: Converging iterations need 2 to 5 (a linear force: 2); 50 leaves room for
#: slow contraction after a Jacobian refresh without hiding divergence.
NEWTON_MAX_ITER = 50
#: converged: the update is at most this many ulps of max(|v|, |W|)
NEWTON_ULPS = 4.0
#: stalled updates below this many ulps are taken as round-off, not divergence
ROUNDOFF_ULPS = 1024.0
#: recompute the Jacobian when an update shrinks by less than this factor
REFRESH = 0.25


# -- linear algebra ---------------------------------------------------------------------

@njit
def lu_factor(a, piv):
    """Factor the square matrix ``a`` in place as ``P a = L U`` (partial pivoting).

    ``L`` (unit diagonal, not stored) is left below the diagonal of ``a`` and
    ``U`` on and above it; ``piv[k]`` is the row swapped with row ``k`` at
    step ``k``.  Returns False if a pivot is zero or not finite (singular).
    """
    m = a.shape[0]
    for k in range(m):
        p = k
        big = abs(a[k, k])
        for i in range(k + 1, m):
            if abs(a[i, k]) > big:
                big = abs(a[i, k])
                p = i
        piv[k] = p
        if not (big > 0.0 and big < math.inf):
            return False
        if p != k:
            for j in range(m):
                tmp = a[k, j]
                a[k, j] = a[p, j]
                a[p, j] = tmp
        inv = 1.0 / a[k, k]
        for i in range(k + 1, m):
            lik = a[i, k] * inv
            a[i, k] = lik
            if lik != 0.0:
                for j in range(k + 1, m):
                    a[i, j] -= lik * a[k, j]
    return True


@njit
def lu_solve(a, piv, b):
    """Solve ``A y = b`` in place in ``b`` (1-D) from :func:`lu_factor`'s output."""
    m = a.shape[0]
    for k in range(m):
        p = piv[k]
        if p != k:
            tmp = b[k]
            b[k] = b[p]
            b[p] = tmp
    for i in range(m):
        s = b[i]
        for j in range(i):
            s -= a[i, j] * b[j]
        b[i] = s
    for i in range(m - 1, -1, -1):
        s = b[i]
        for j in range(i + 1, m):
            s -= a[i, j] * b[j]
        b[i] = s / a[i, i]


# -- the loop ---------------------------------------------------------------------------

class Work(NamedTuple):
    """The Newton loop's workspace: the unknown velocity increment ``w``,
    the residual and then the Newton update ``dw``, the stage point ``xs``,
    ``vs`` and its accelerations ``acc`` (kept for the next prediction,
    valid when ``cache[0] == 1``), the Jacobian's blocks ``jx``, ``jv``, its
    LU factors ``lu`` with pivots ``piv``, and ``newton_iterations[0]``, the
    iterations counted."""
    w: np.ndarray
    dw: np.ndarray
    xs: np.ndarray
    vs: np.ndarray
    acc: np.ndarray
    cache: np.ndarray
    jx: np.ndarray
    jv: np.ndarray
    lu: np.ndarray
    piv: np.ndarray
    newton_iterations: np.ndarray


def _implicit_loop(x, v, t, dt, nsteps, theta, work, fargs, velocity_dependent, outputs,
                   checks, check):
    # theta: 1.0 implicit Euler, 0.5 implicit midpoint (one loop for both);
    # work: a Work record
    w, dw, xs, vs, acc, cache, jx, jv, lu, piv, newton = work
    mon, step0, mon_t, mon_out = outputs
    check_every, sargs = checks
    stopping = (sargs, check)
    n = x.shape[0]
    m = 3 * n
    th = theta
    cx = th * th * dt * dt
    cv = th * dt
    dwf = dw.reshape(m)
    every = mon[0]
    n_mon = 0
    until_check = check_every
    until_record = first_record(every, step0, mon_t)
    for k in range(nsteps):
        ts = t + k * dt + th * dt
        predicted = cache[0] != 0
        for i in range(n):
            for d in range(3):
                w[i, d] = dt * acc[i, d] if predicted else 0.0
        refresh = True
        prev = math.inf
        converged = False
        for it in range(NEWTON_MAX_ITER):
            for i in range(n):
                for d in range(3):
                    vsid = v[i, d] + th * w[i, d]
                    vs[i, d] = vsid
                    xs[i, d] = x[i, d] + th * dt * vsid
            force(xs, vs, ts, fargs, acc)
            for i in range(n):
                for d in range(3):
                    dw[i, d] = dt * acc[i, d] - w[i, d]
            if refresh:
                jacobian(xs, vs, ts, fargs, jx, jv)
                for p in range(m):
                    for q in range(m):
                        lu[p, q] = -cx * jx[p, q]
                    lu[p, p] += 1.0
                if velocity_dependent:
                    for p in range(m):
                        for q in range(m):
                            lu[p, q] -= cv * jv[p, q]
                if not lu_factor(lu, piv):
                    if not state_is_finite(xs, acc):
                        cache[0] = 0
                        newton[0] += it + 1
                        return Status.NON_FINITE, k, n_mon
                    break
                refresh = False
            lu_solve(lu, piv, dwf)
            dnorm = 0.0
            scale = 0.0
            for i in range(n):
                for d in range(3):
                    w[i, d] += dw[i, d]
                    dnorm = max(dnorm, abs(dw[i, d]))
                    scale = max(scale, abs(v[i, d]), abs(w[i, d]))
            if not math.isfinite(dnorm):
                cache[0] = 0
                newton[0] += it + 1
                return Status.NON_FINITE, k, n_mon
            tol = max(_EPS * scale, _TINY)
            if dnorm <= NEWTON_ULPS * tol or (dnorm >= prev and dnorm <= ROUNDOFF_ULPS * tol):
                converged = True
                newton[0] += it + 1
                break
            if dnorm > REFRESH * prev:
                refresh = True
            prev = dnorm
        if not converged:
            cache[0] = 0
            return Status.NO_CONVERGENCE, k, n_mon
        if HAS_WORK:
            work_add(fargs, -dt * work_rate(xs, vs, ts, fargs))
        # the step, with the accelerations at the last stage point
        for i in range(n):
            for d in range(3):
                hv = dt * acc[i, d]
                x[i, d] += dt * (v[i, d] + th * hv)
                v[i, d] += hv
        cache[0] = 1
        status, done, until_check, until_record, n_mon = step_end(
            x, v, t + (k + 1) * dt, k, nsteps, True, until_check, check_every, until_record,
            every, mon, n_mon, mon_t, mon_out, stopping, fargs)
        if status != GO:
            if status == Status.NON_FINITE:
                cache[0] = 0
            return status, done, n_mon
    return Status.OK, nsteps, n_mon


def implicit_loop(force, velocity_dependent):
    """The Newton loop of the one-leg theta-methods compiled for a
    :class:`~.stepping.ForceKernel`, for every theta.

    The Jacobian is :func:`~.jacobians.jacobian_for`'s.  The loop takes
    ``(x, v, t, dt, nsteps, theta, work, fargs, velocity_dependent, outputs,
    checks, check)``: theta 1.0 (implicit Euler) or 0.5 (implicit midpoint),
    a :class:`Work`, the records of :mod:`.records` and the stopping
    conditions' pointer (:func:`~.stopping.stop_record`).
    """
    jac, jkey = jacobian_for(force, velocity_dependent)
    if jkey == "fd" and velocity_dependent:
        jkey = "fd_v"
    return specialize(_implicit_loop, f"theta_{force.key}_{jkey}",
                      jit=force.jit,
                      cache=force.cache and (jkey == POINTER_KEY or not jkey.startswith("own")),
                      force=force.kernel, jacobian=jac, step_end=step_epilogue(force),
                      **work_kernels(force))
