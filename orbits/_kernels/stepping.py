"""The compiled loops that advance a state many steps.

For a few bodies the cost of a step is dominated by getting in and out of
Python, so the whole loop over steps is compiled, not only the force.  Each
loop is written once as a plain function over a global name ``force`` and
compiled per force by :func:`orbits._kernels._jit.specialize`; a scene compiles
only the loop and force it uses.

Forces have the signature ``force(x, v, t, fargs, acc)`` and write the
accelerations into ``acc``; ``fargs`` is a tuple of whatever the force needs.

Every loop returns ``(status, steps_done, n_monitor_rows)``.  Every
``check_every`` steps, and after the last, it checks that the state is
finite; NaN and inf never turn finite again under these updates, so a failure
is never missed, only seen up to ``check_every - 1`` steps late.  On failure
the loop returns at once with ``Status.NON_FINITE``; with ``check_every = 1``
``steps_done`` is then exactly the number of good steps.  The caller keeps a
copy of the state it passed in and, the loops being deterministic, finds the
exact failing step and recomputes the last good state from it
(:func:`orbits._driver.advance_checked`), so the loop pays for neither a
copy nor a check every step.

After every step a loop calls its stopping check (:mod:`.stopping`); a
check that fires ends the loop with its status and ``steps_done`` counting
the step that triggered it.  Loops compiled without conditions call
:func:`~.stopping.no_stop`, which compiles to nothing.

Monitors (energy, angular momentum, ...) are recorded every ``every`` steps,
counted from the start of the simulation (``step0``), into ``mon_t`` and
``mon_out``; ``every = 0`` switches them off and costs one branch a step.
"""

import math
from typing import Callable, NamedTuple

import numpy as np

from ._jit import njit, specialize
from .gravity import (accelerate_pairwise, accelerate_pairwise_parallel,
                      accelerate_pairwise_rebound, accelerate_pairwise_small)
from .invariants import ENERGY, monitor_row
from .status import Status
from .stopping import check_stop, no_stop

__all__ = ["DRIFT", "KICK", "splitting_loop", "runge_kutta_loop", "gravity_force",
           "user_force", "state_is_finite", "ForceKernel", "NO_STOP_ARGS", "with_terms"]

#: the stopping arguments of a loop compiled without conditions
NO_STOP_ARGS = (0, 0.0, 0.0, 0.0, np.zeros(1), 0, np.zeros(2, dtype=np.int64))

#: operator codes of a splitting table
DRIFT = 0
KICK = 1


@njit
def state_is_finite(x, v):
    """True if every position and velocity component is finite."""
    s = 0.0
    for i in range(x.shape[0]):
        s += x[i, 0] + x[i, 1] + x[i, 2] + v[i, 0] + v[i, 1] + v[i, 2]
    # a sum with a NaN or an inf term is itself NaN or inf
    return math.isfinite(s)


@njit
def _record(x, v, t, mon, n_mon, mon_t, mon_out):
    every, which, m, G, n_active, eps2 = mon
    mon_t[n_mon] = t
    monitor_row(x, v, m, G, n_active, eps2, which, mon_out[n_mon])


# -- forces ------------------------------------------------------------------------

def _gravity_force(x, v, t, fargs, acc):
    gm, n_active, eps2, work, G, m = fargs
    pair_kernel(x, gm, n_active, eps2, acc, work)  # noqa: F821 - bound by specialize


def _gravity_force_exact(x, v, t, fargs, acc):
    # few bodies: REBOUND's arithmetic, so that leapfrog matches it bit for bit
    gm, n_active, eps2, work, G, m = fargs
    accelerate_pairwise_rebound(x, G, m, n_active, eps2, acc)


#: the message of the error a user force of the wrong size raises in the loop
USER_FORCE_SIZE = "orbits: the user force returned a different number of values than the state has"


def _user_force(x, v, t, fargs, acc):
    # the user's arrays (any shape, ``size`` values) fill the (rows, 3) state
    # arrays in order; the padding stays zero
    size, shape = fargs
    xu = x.ravel()[:size].reshape(shape)
    vu = v.ravel()[:size].reshape(shape)
    a = np.asarray(user_accel(xu, vu, t)).ravel()  # noqa: F821 - bound by specialize
    if a.size != size:
        # checked before the run too (orbits.custom); here for a size that varies
        raise ValueError(USER_FORCE_SIZE)
    flat = acc.ravel()
    for i in range(size):
        flat[i] = a[i]


class ForceKernel(NamedTuple):
    """A force function and how loops that call it are compiled."""

    kernel: Callable
    key: str       # names the loops compiled for it
    jit: bool      # False: everything runs as plain Python (a user's Python function)
    cache: bool    # False where the force cannot be cached on disk (a user's function)
    # its Jacobian kernel, for implicit methods (orbits._kernels.implicit); None:
    # the analytic one for gravity, central differences for other forces
    jacobian: Callable = None
    # whether the accelerations read the velocities (the loops then predict or
    # iterate them)
    velocity_dependent: bool = False
    # the monitor recorder of the compiled loops (None: _record, gravity's energy)
    record: Callable = None
    # for gravity with added terms (with_terms): the gravity force alone and the
    # terms' TermKernel; fargs is then (gravity fargs, terms' args)
    base: "ForceKernel" = None
    terms: object = None
    # a user's function replacing gravity (orbits.integrate): nothing is known
    # of it, so ias15 predicts velocities for it and Wisdom-Holman refuses it
    opaque: bool = False

    @property
    def recorder(self):
        """The monitor recorder the compiled loops call."""
        return _record if self.record is None else self.record


_PAIR_KERNELS = {
    "small": accelerate_pairwise_small,
    "serial": accelerate_pairwise,
    "parallel": accelerate_pairwise_parallel,
}


def gravity_force(kind):
    """The pairwise-gravity force: ``kind`` is ``"small"``, ``"serial"``, ``"parallel"``
    or ``"rebound"`` (REBOUND's arithmetic; see :mod:`orbits._kernels.gravity`)."""
    key = f"gravity_{kind}"
    if kind == "rebound":
        kernel = specialize(_gravity_force_exact, key, inline=True)
        return ForceKernel(kernel, key, True, True)
    kernel = specialize(_gravity_force, key, inline=True, pair_kernel=_PAIR_KERNELS[kind])
    return ForceKernel(kernel, key, True, True)


def _forced(x, v, t, fargs, acc):
    base(x, v, t, fargs[0], acc)  # noqa: F821 - bound by specialize
    extra(x, v, t, fargs[1], acc)  # noqa: F821


def _record_terms(x, v, t, mon, n_mon, mon_t, mon_out):
    # mon carries the terms' energy arguments as its seventh item
    every, which, m, G, n_active, eps2, eargs = mon
    mon_t[n_mon] = t
    row = mon_out[n_mon]
    monitor_row(x, v, m, G, n_active, eps2, which, row)
    if which & ENERGY:
        row[0] += extra_energy(x, v, eargs)  # noqa: F821 - bound by specialize


def with_terms(base, terms, velocity_dependent):
    """Gravity ``base`` (a :class:`ForceKernel`) plus the terms of a
    :class:`~orbits._kernels.terms.TermKernel`: ``fargs = (base fargs, terms' args)``,
    and monitors ``mon`` with the terms' energy arguments as a seventh item."""
    key = f"{base.key}+{terms.key}"
    cache = base.cache and terms.cache
    kernel = specialize(_forced, key, cache=cache, inline=True, base=base.kernel,
                        extra=terms.accel)
    record = specialize(_record_terms, key, cache=cache, extra_energy=terms.energy)
    return ForceKernel(kernel, key, True, cache, velocity_dependent=bool(velocity_dependent),
                       record=record, base=base, terms=terms)


def user_force(accel, jit):
    """A force from a user's ``accel(x, v, t)``; compiled if ``accel`` is a numba function."""
    key = f"user{id(accel)}"
    kernel = specialize(_user_force, key, jit=jit, cache=False, user_accel=accel)
    return ForceKernel(kernel, key, jit, False, opaque=True)


# -- splitting methods --------------------------------------------------------------

def _splitting_loop(x, v, t, dt, nsteps, acc, vm, cache, fargs, velocity_dependent, mon,
                    step0, mon_t, mon_out, check_every, sargs):
    # A splitting step is a sequence of drifts (x += c dt v) and kicks
    # (v += c dt a(x)), the table KINDS/COEFS bound by specialize as constant
    # tuples, so that the compiler unrolls it.  The acceleration depends only
    # on positions (unless velocity_dependent), so it is recomputed only after
    # a drift: velocity Verlet's closing kick and the next step's opening kick
    # share one force evaluation.  `fresh` (kept in cache[0] between calls)
    # says whether acc belongs to the current positions.  A velocity-dependent
    # force is kicked with the implicit midpoint velocity (implicit_kick), so
    # the kick stays symmetric; vm is its scratch.
    n = x.shape[0]
    every = mon[0]
    n_mon = 0
    fresh = cache[0] != 0
    until_check = check_every
    until_record = every - step0 % every if every > 0 else -1
    for k in range(nsteps):
        tx = t + k * dt
        for op in range(len(KINDS)):  # noqa: F821 - bound by specialize
            h = COEFS[op] * dt  # noqa: F821
            if KINDS[op] == DRIFT:  # noqa: F821
                for i in range(n):
                    x[i, 0] += h * v[i, 0]
                    x[i, 1] += h * v[i, 1]
                    x[i, 2] += h * v[i, 2]
                tx += h
                fresh = False
            elif velocity_dependent:
                implicit_kick(x, v, tx, h, fargs, acc, vm)
                fresh = False
            else:
                if not fresh:
                    force(x, v, tx, fargs, acc)  # noqa: F821 - bound by specialize
                    fresh = True
                for i in range(n):
                    v[i, 0] += h * acc[i, 0]
                    v[i, 1] += h * acc[i, 1]
                    v[i, 2] += h * acc[i, 2]
        until_check -= 1
        if until_check == 0 or k + 1 == nsteps:
            until_check = check_every
            if not state_is_finite(x, v):
                cache[0] = 0
                return Status.NON_FINITE, k, n_mon
        until_record -= 1
        if until_record == 0:
            until_record = every
            _record(x, v, t + (k + 1) * dt, mon, n_mon, mon_t, mon_out)
            n_mon += 1
        stop = stop_check(x, v, sargs)  # noqa: F821 - bound by specialize
        if stop != 0:
            cache[0] = 1 if fresh else 0
            if not state_is_finite(x, v):
                return Status.NON_FINITE, k, n_mon
            return stop, k + 1, n_mon
    cache[0] = 1 if fresh else 0
    return Status.OK, nsteps, n_mon


#: iterations of the implicit kick before it settles for the last one; the
#: fixed-point map contracts by about h |da/dv| / 2 a pass (1e-8 for GR on
#: Mercury at a day), so round-off is reached in two to four
KICK_MAX_ITER = 30


def _implicit_kick(x, v, t, h, fargs, acc, vm):
    # v' = v + h a(x, (v + v') / 2, t), solved by fixed-point iteration to
    # round-off: a symmetric map (its inverse is the kick of -h), so a
    # symmetric table keeps its order with velocity-dependent forces
    n = x.shape[0]
    for i in range(n):
        for d in range(3):
            vm[i, d] = v[i, d]
    prev = math.inf
    for it in range(KICK_MAX_ITER):
        force(x, vm, t, fargs, acc)  # noqa: F821 - bound by specialize
        change = 0.0
        scale = 0.0
        for i in range(n):
            for d in range(3):
                new = v[i, d] + 0.5 * h * acc[i, d]
                change = max(change, abs(new - vm[i, d]))
                scale = max(scale, abs(new))
                vm[i, d] = new
        if change <= 2.0 * 2.220446049250313e-16 * scale or change >= prev:
            break
        prev = change
    for i in range(n):
        for d in range(3):
            v[i, d] += h * acc[i, d]


def splitting_loop(force, name, kinds, coefs, stop=False):
    """The splitting loop compiled for a :class:`ForceKernel` and one method's table.

    ``kinds`` (DRIFT or KICK) and ``coefs`` are tuples; ``name`` names the method;
    ``stop`` compiles in the stopping conditions of :mod:`.stopping`.
    """
    return specialize(_splitting_loop, f"{name}_{force.key}{'_stop' if stop else ''}",
                      jit=force.jit, cache=force.cache, force=force.kernel,
                      _record=force.recorder,
                      implicit_kick=specialize(_implicit_kick, force.key, jit=force.jit,
                                               cache=force.cache, inline=True,
                                               force=force.kernel),
                      stop_check=check_stop if stop else no_stop,
                      KINDS=tuple(int(k) for k in kinds),
                      COEFS=tuple(float(c) for c in coefs))


# -- explicit Runge-Kutta ---------------------------------------------------------------

def _runge_kutta_loop(x, v, t, dt, nsteps, A, b, c, kx, kv, xs, vs, fargs, mon, step0,
                      mon_t, mon_out, check_every, sargs):
    # y = (x, v), y' = (v, a(x, v, t)); stage s has state
    # y + dt sum_j A[s, j] k_j and derivative k_s.  kx[s] = stage velocity,
    # kv[s] = stage acceleration.
    n = x.shape[0]
    n_stages = b.shape[0]
    every = mon[0]
    n_mon = 0
    until_check = check_every
    until_record = every - step0 % every if every > 0 else -1
    for k in range(nsteps):
        tk = t + k * dt
        for s in range(n_stages):
            for i in range(n):
                for d in range(3):
                    xi = x[i, d]
                    vi = v[i, d]
                    for j in range(s):
                        a_sj = A[s, j]
                        if a_sj != 0.0:
                            xi += dt * a_sj * kx[j, i, d]
                            vi += dt * a_sj * kv[j, i, d]
                    xs[i, d] = xi
                    vs[i, d] = vi
                    kx[s, i, d] = vi
            force(xs, vs, tk + c[s] * dt, fargs, kv[s])  # noqa: F821 - bound by specialize
        for i in range(n):
            for d in range(3):
                dx = 0.0
                dv = 0.0
                for s in range(n_stages):
                    dx += b[s] * kx[s, i, d]
                    dv += b[s] * kv[s, i, d]
                x[i, d] += dt * dx
                v[i, d] += dt * dv
        until_check -= 1
        if until_check == 0 or k + 1 == nsteps:
            until_check = check_every
            if not state_is_finite(x, v):
                return Status.NON_FINITE, k, n_mon
        until_record -= 1
        if until_record == 0:
            until_record = every
            _record(x, v, t + (k + 1) * dt, mon, n_mon, mon_t, mon_out)
            n_mon += 1
        stop = stop_check(x, v, sargs)  # noqa: F821 - bound by specialize
        if stop != 0:
            if not state_is_finite(x, v):
                return Status.NON_FINITE, k, n_mon
            return stop, k + 1, n_mon
    return Status.OK, nsteps, n_mon


def runge_kutta_loop(force, stop=False):
    """The explicit Runge-Kutta loop compiled for a :class:`ForceKernel`
    (``stop``: with the stopping conditions of :mod:`.stopping`)."""
    return specialize(_runge_kutta_loop, f"{force.key}{'_stop' if stop else ''}",
                      jit=force.jit, cache=force.cache, force=force.kernel,
                      _record=force.recorder,
                      stop_check=check_stop if stop else no_stop)
