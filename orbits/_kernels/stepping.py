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

After every step a loop checks the stopping conditions of its stopping
record ``stopping = (sargs, check)`` (:mod:`.stopping`: a pointer and the
conditions as data, so one loop serves a run with or without them; without,
the check is a branch); a check that fires ends the loop with its status and
``steps_done`` counting the step that triggered it.

Monitors (energy, angular momentum, ...) are recorded every ``every`` steps,
counted from the start of the simulation (``step0``), into ``mon_t`` and
``mon_out``; ``every = 0`` switches them off and costs one branch a step.
Outputs use the same mechanism: rows ``6 N`` wider than the monitors' also
take the bodies' state (:func:`record_state`), so that a run's evenly
spaced outputs are recorded inside the loop, ``step0`` then counting from
the run's start (:meth:`orbits._driver.Driven.execute`); such a row's
energy and angular momentum are made after the loop, from the state it
holds, a block of rows at a time (:func:`~.invariants.fill_monitors`).
Outputs that do not fall a whole number of steps apart are recorded in the
fixed-step loops too: with ``every = -1``, ``mon_t`` holds on entry the steps
after which to record (:func:`first_record`).

The work of non-conservative force terms.  A force built by :func:`with_terms`
carries a third item in ``fargs``, the work arguments ``(their args, m,
scratch, box)``, whose table holds the non-conservative terms among its
terms, maybe none (``work_on`` says at run time, so that one loop serves
terms with and without work): the loops integrate
``W = -int P dt``, ``P = sum_i m_i a_i . v_i`` over those terms' accelerations
alone, each with its own quadrature (the splitting kicks with the kick's
midpoint velocity, Runge-Kutta methods with their weights ``b``, IAS15 with
the Radau rule of its nodes), and add it to ``box[0]`` (``box[1]`` keeps what
rounding lost, Neumaier's compensation), so that ``E + W`` is conserved up to
the integration error; a monitor row records ``W`` in its work column.  The
box is the workspace's ``"work"`` array (:func:`work_bound`), so that the
state and its work are saved, restored and checkpointed together (for a
force with such terms, ``ForceKernel.dissipative``).  Loops compiled for
gravity alone bind ``HAS_WORK = False`` and no-op kernels, and compile to
what they were without it.
"""

import math
from typing import Callable, NamedTuple

import numba
import numpy as np
from numba.core import types as nbtypes

from ._jit import idle_pointer, njit, pointer, slots, specialize
from .gravity import (accelerate_pairwise, accelerate_pairwise_lanes,
                      accelerate_pairwise_parallel, accelerate_pairwise_rebound,
                      accelerate_pairwise_small)
from .invariants import ENERGY, FILLED, MONITOR_WIDTH, WORK_COLUMN, holds_state, monitor_row
from .status import Status
from .stopping import call_check
from .terms import table_rows
from .variational import tangent_kernels, variational_work_kernels

# the names the templates below are written against, bound by specialize
#: the slots that :func:`work_kernels` binds, which every loop that integrates
#: the work of non-conservative terms declares (:func:`~._jit.slots`)
WORK_SLOTS = ("HAS_WORK", "work_rate", "work_add", "work_note", "work_on")
HAS_WORK, work_rate, work_add, work_note, work_on = slots(*WORK_SLOTS)
(force, step_end, pair_kernel, base, extra, extra_energy, nc_accel,
 user_accel, stop_check, tangent_step, record, record_mark, kick_kernel) = slots(
    "force", "step_end", "pair_kernel", "base", "extra", "extra_energy",
    "nc_accel", "user_accel", "stop_check", "tangent_step", "record", "record_mark",
    "kick_kernel")
stages, = slots("stages")

__all__ = ["DRIFT", "KICK", "Splitting", "splitting_loop", "runge_kutta_loop", "gravity_force",
           "user_force", "user_force_call", "state_is_finite", "ForceKernel", "with_terms",
           "step_epilogue", "epilogue", "GO", "first_record", "work_kernels", "work_args",
           "work_bound", "work_total", "rk_stage", "rk_sums", "adaptive_start", "must_return",
           "clock_step", "landing_step", "add_compensated", "stop_info", "mark_recorder",
           "terms_recorder", "flat_rows", "flat_stages", "stage_views", "stage_errors", "dop853_error", "accept_fsal",
           "step_lander", "rk_stages"]

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


@njit(inline="always")
def flat_rows(a, b):
    """Views of two (N, 3) arrays as rows of their 3N components, for loops
    over every component that LLVM turns into vector instructions."""
    return a.reshape(a.size), b.reshape(b.size)


@njit(inline="always")
def stage_views(x, v, xs, vs, kx, kv):
    """A Runge-Kutta loop's flat views (:func:`flat_rows`, :func:`flat_stages`)
    of the state, a stage's state and the stages: ``(xF, vF, xsF, vsF,
    kxF, kvF)``."""
    xF, vF = flat_rows(x, v)
    xsF, vsF = flat_rows(xs, vs)
    kxF, kvF = flat_stages(kx, kv)
    return xF, vF, xsF, vsF, kxF, kvF


@njit(inline="always")
def flat_stages(a, b):
    """Views of two (S, N, 3) arrays of stages as (S, 3N), as :func:`flat_rows`."""
    m = a.shape[0]
    return a.reshape((m, a.size // m)), b.reshape((m, b.size // m))


@njit(inline="always")
def record_state(x, v, m, row):
    """Outputs recorded in the loop: a row wider than :data:`MONITOR_WIDTH` by
    ``6 N`` (N = ``len(m)``, the bodies; :func:`~.invariants.holds_state`)
    takes their positions and velocities after the monitors."""
    w = MONITOR_WIDTH
    n = m.shape[0]
    for i in range(n):
        for d in range(3):
            row[w + 3 * i + d] = x[i, d]
            row[w + 3 * (n + i) + d] = v[i, d]


@njit(inline="always")
def _record_row(x, v, m, G, n_active, eps2, which, row, e_terms):
    # one row of monitors, e_terms (the force terms' energy, 0 without terms)
    # added to its energy.  A row that holds the state gets its energy and
    # angular momentum after the loop, from that state
    # (invariants.fill_monitors, which adds column 0 to the energy), its
    # other monitors here
    if holds_state(row, m):
        row[0] = e_terms
        if which & ~FILLED:
            monitor_row(x, v, m, G, n_active, eps2, which & ~FILLED, row)
        record_state(x, v, m, row)
    else:
        monitor_row(x, v, m, G, n_active, eps2, which, row)
        if which & ENERGY:
            row[0] += e_terms


@njit
def _record(x, v, t, mon, n_mon, mon_t, mon_out):
    every, which, m, G, n_active, eps2 = mon
    mon_t[n_mon] = t
    _record_row(x, v, m, G, n_active, eps2, which, mon_out[n_mon], 0.0)


#: the status of a step epilogue (:func:`step_epilogue`) that lets a loop carry on
GO = -1


# -- the bookkeeping of the adaptive loops (orbits._kernels.ias15, .taylor) ---------

@njit(inline="always")
def adaptive_start(t, t_end, tc, marks, counts, info, mon, step0, mon_t):
    """The counts and stop info of an adaptive loop's call reset, and its
    ``(direction, ct, target, has_marks, every, cap, until_record)``: ``ct``
    the time's compensation (``tc = (time reached, what t + dt rounded
    away)``, used only when the call starts at the time the last one
    reached), ``target`` the first time to land on (the first mark, else
    ``t_end``; an empty marks array: none, so that one compiled loop serves
    both uses), and the monitors' ``every``, the rows' capacity and the
    steps to the first record (:func:`first_record`)."""
    counts[0] = 0
    counts[1] = 0
    counts[2] = 0
    info[0] = -1
    info[1] = -1
    direction = 1.0 if t_end > t else -1.0
    ct = tc[1] if t == tc[0] else 0.0
    has_marks = marks.shape[0] > 0
    target = marks[0] if has_marks else t_end
    every = mon[0]
    return (direction, ct, target, has_marks, every, mon_t.shape[0],
            first_record(every, step0, mon_t))


@njit(inline="always")
def must_return(counts, max_steps, has_marks, n_mon, mon_out, until_record, cap, t, t_end):
    """Whether an adaptive loop returns before its next step: at ``t_end``
    (a call that starts there takes no step), its steps for this call
    taken, or its rows full (the caller collects them first)."""
    return (t == t_end or counts[0] >= max_steps or (has_marks and n_mon >= mon_out.shape[0])
            or (until_record == 1 and n_mon >= cap))


@njit(inline="always")
def landing_step(t, ct, target, proposed, min_dt):
    """The step an adaptive loop takes from ``t``: the proposal, or what is
    left to ``target`` (less the time's compensation ``ct``, see
    :func:`clock_step`) when the proposal reaches it; ``(dt, trimmed,
    underflow)``, underflow when a step that is not trimmed is below
    ``min_dt`` or too small to move ``t``."""
    remaining = (target - t) - ct
    trimmed = abs(proposed) >= abs(remaining)
    dt = remaining if trimmed else proposed
    return dt, trimmed, not trimmed and (abs(dt) < min_dt or t + dt == t)


@njit(inline="always")
def add_compensated(x, dx, cs):
    """``x += dx`` element by element with Kahan's compensation ``cs`` (what
    the last additions rounded away, carried into the next), as the
    adaptive loops add their steps' increments."""
    for i in range(x.shape[0]):
        for d in range(3):
            y = dx[i, d] + cs[i, d]
            xn = x[i, d] + y
            cs[i, d] = y - (xn - x[i, d])
            x[i, d] = xn


@njit(inline="always")
def stop_info(stopping, info):
    """The bodies behind a stopping condition (``sargs[6]`` of the stopping
    record ``stopping``) into an adaptive loop's ``info``."""
    sinfo = stopping[0][6]
    info[0] = sinfo[0]
    info[1] = sinfo[1]


@njit(inline="always")
def clock_step(t, ct, dt, trimmed, target):
    """The time and its compensation after a step ``dt``: ``target`` exactly
    for a step shortened to land on it, else ``t + (dt + ct)`` and what its
    rounding lost, exactly (Knuth's two-sum: ``t`` may be smaller than the
    step at the start)."""
    if trimmed:
        return target, 0.0
    y = dt + ct
    tn = t + y
    yb = tn - t
    return tn, (t - (tn - yb)) + (y - yb)


@njit(inline="always")
def first_record(every, step0, mon_t):
    """Steps until a loop's first record (-1: none).  ``every > 0``: a record
    every ``every`` steps counted from step 0, ``step0`` steps having been
    done before this call.  ``every = -1`` (fixed-step loops): after the steps
    ``mon_t`` holds on entry, counted from this call's start as floats and
    increasing, each overwritten by its record's time (outputs that do not fall
    a whole number of steps apart, :class:`orbits._driver.Driver`)."""
    if every > 0:
        return every - step0 % every
    if every < 0 and mon_t.shape[0] > 0:
        return int(mon_t[0])
    return -1


def _step_end(x, v, t, k, nsteps, check, until_check, check_every, until_record, every,
              mon, n_mon, mon_t, mon_out, stopping, fargs):
    # The epilogue of every loop's step, at time t after step k (of nsteps):
    # the finite check (fixed-step loops, check=True: every check_every
    # steps and after the last; adaptive loops test their error estimate
    # instead), the monitors when due, and the stopping conditions.  Returns
    # (status, steps_done, until_check, until_record, n_mon): status GO to
    # carry on, else what the loop returns with steps_done.  A plain call, not
    # inlined at numba's level: arrays handed to an inlined function are
    # reference-counted on every call (see orbits._kernels._jit), which costs
    # more than the call LLVM then inlines anyway.
    if check:
        until_check -= 1
        if until_check == 0 or k + 1 == nsteps:
            until_check = check_every
            if not state_is_finite(x, v):
                return Status.NON_FINITE, k, until_check, until_record, n_mon
    renormalise = tangent_step(x, v, t, fargs)
    until_record -= 1
    if until_record == 0:
        if every > 0:
            until_record = every
        elif n_mon + 1 < mon_t.shape[0]:
            # marks (every = -1, fixed-step loops): the next record's step,
            # counted from the call's start, before this record overwrites
            # its own entry with its time (first_record)
            until_record = int(mon_t[n_mon + 1]) - (k + 1)
        else:
            until_record = -1
        # n_mon as a variable: a constant 0 would compile the recorder once more
        record(x, v, t, mon, np.int64(n_mon), mon_t, mon_out)
        work_note(fargs, mon_out, n_mon)
        n_mon += 1
    status = stop_check(x, v, t, stopping)
    if status != 0:
        if check and not state_is_finite(x, v):
            return Status.NON_FINITE, k, until_check, until_record, n_mon
        return status, k + 1, until_check, until_record, n_mon
    if renormalise:
        # the chaos indicators' tangent vector has grown large: the driver
        # scales it back between calls (orbits._kernels.variational)
        return Status.RENORMALISE, k + 1, until_check, until_record, n_mon
    return GO, k + 1, until_check, until_record, n_mon


def step_epilogue(force):
    """The step epilogue of the loops compiled for a :class:`ForceKernel`,
    which take a stopping record (:func:`~.stopping.stop_record`)."""
    return epilogue(force.recorder, force.key, jit=force.jit, cache=force.cache,
                    runtime=force.runtime, work_note=work_kernels(force)["work_note"],
                    tangent_step=tangent_kernels(force)["tangent_step"])


def epilogue(record, key, jit=True, cache=True, runtime=False, stop=None, work_note=None,
             tangent_step=None):
    """The step epilogue with monitor recorder ``record``, compiled under ``key``
    (``runtime``: for loops that need numba's runtime; ``stop``: the
    stopping check ``stop(x, v, t, stop_args) -> status`` that a loop binds,
    by default :func:`~.stopping.call_check` of a stopping record;
    ``work_note``: what writes the work of non-conservative terms into a
    monitor row, see :func:`work_kernels`; none by default;
    ``tangent_step``: the chaos indicators' update after a step, see
    :mod:`.variational`; none by default)."""
    stop_check = call_check if stop is None else stop
    return specialize(_step_end, key, jit=jit, inline=True, nrt=runtime, cache=cache,
                      record=record, stop_check=stop_check,
                      work_note=_no_work_note if work_note is None else work_note,
                      tangent_step=_no_tangent_step if tangent_step is None else tangent_step)


def step_lander(force):
    """What an adaptive loop compiled for a :class:`ForceKernel` does after
    each accepted step (:func:`_land`): the step epilogue, a stop, a step
    below the smallest allowed, and landing on the next mark or the end."""
    return specialize(_land, force.key, jit=force.jit, inline=True, nrt=force.runtime,
                      cache=force.cache, step_end=step_epilogue(force),
                      record_mark=mark_recorder(force))


def _land(x, v, t, steps, underflow, worst, has_marks, target, k_mark, until_record, n_mon,
          outputs, marks, mark_steps, stopping, info, fargs):
    # after an accepted step that reached t, the call's steps-th: the step
    # epilogue (monitor rows, stopping conditions), then the step control's
    # underflow (worst: the body that set the step, into info[0]), then the
    # landing on target, a mark recorded as the driver would record it on
    # return; returns (GO or the status to return with, target, k_mark,
    # until_record, n_mon)
    mon, step0, mon_t, mon_out = outputs
    stop, _, _, until_record, n_mon = step_end(
        x, v, t, 0, 0, False, 0, 0, until_record, mon[0], mon, n_mon, mon_t, mon_out,
        stopping, fargs)
    if stop != GO:
        stop_info(stopping, info)
        return stop, target, k_mark, until_record, n_mon
    if underflow:
        info[0] = worst
        return Status.STEP_UNDERFLOW, target, k_mark, until_record, n_mon
    if t == target:
        if not has_marks:
            return Status.OK, target, k_mark, until_record, n_mon
        n_mon, k_mark, target, last = record_mark(
            x, v, t, step0 + steps, mon, n_mon, mon_t, mon_out, marks, mark_steps, k_mark,
            fargs)
        if last:
            return Status.OK, target, k_mark, until_record, n_mon
    return GO, target, k_mark, until_record, n_mon


def _record_mark(x, v, t, steps, mon, n_mon, mon_t, mon_out, marks, mark_steps, k_mark, fargs):
    # An adaptive loop's output at the mark k_mark it has landed on (t),
    # recorded as the driver would record it on return: a row of mon_out
    # (monitors and state) with its time in mon_t and its step count, steps
    # from the run's start, in mark_steps.  Returns (the rows, the next
    # mark's index, its time (t after the last), whether it was the last).
    mon_t[n_mon] = t
    record(x, v, t, mon, n_mon, mon_t, mon_out)
    work_note(fargs, mon_out, n_mon)
    mark_steps[n_mon] = steps
    k_mark += 1
    last = k_mark == marks.shape[0]
    return n_mon + 1, k_mark, t if last else marks[k_mark], last


def mark_recorder(force):
    """The recording of an output at a mark (an output time an adaptive loop
    lands on) for the loops compiled for a :class:`ForceKernel`: it takes
    ``(x, v, t, steps, mon, n_mon, mon_t, mon_out, marks, mark_steps,
    k_mark, fargs)`` and returns ``(n_mon, k_mark, target, last)``, the
    rows, the next mark and its time, and whether the mark was the last."""
    return specialize(_record_mark, force.key, jit=force.jit, inline=True, nrt=force.runtime,
                      cache=force.cache, record=force.recorder,
                      work_note=work_kernels(force)["work_note"])


# -- forces ------------------------------------------------------------------------

def _gravity_force(x, v, t, fargs, acc):
    gm, n_active, eps2, work, G, m = fargs
    pair_kernel(x, gm, n_active, eps2, acc, work)


def _gravity_force_exact(x, v, t, fargs, acc):
    # few bodies: REBOUND's arithmetic, so that leapfrog matches it bit for bit
    gm, n_active, eps2, work, G, m = fargs
    accelerate_pairwise_rebound(x, G, m, n_active, eps2, acc)


#: the message of the error a user's Python force of the wrong size raises in the loop
USER_FORCE_SIZE = "orbits: the user force returned a different number of values than the state has"


def _user_force(x, v, t, fargs, acc):
    # a user's compiled force, through its pointer (orbits._user_functions):
    # fargs = (size, shape, pointer, flag)
    fargs[2](x, v, t, fargs[0], fargs[1], fargs[3], acc)


def _user_python_force(x, v, t, fargs, acc):
    # a user's Python function, run as Python: the user's arrays (any shape,
    # size values) fill the (rows, 3) state arrays in order; the padding stays zero
    size, shape = fargs[0], fargs[1]
    xu = x.ravel()[:size].reshape(shape)
    vu = v.ravel()[:size].reshape(shape)
    a = np.asarray(user_accel(xu, vu, t)).ravel()
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
    # it needs numba's runtime although it is the package's own (the threaded
    # gravity kernel, whose thread pool does)
    allocates: bool = False
    # for gravity with terms (with_terms): the TermKernel of the work
    # arguments, whose non-conservative terms' work the loops integrate (none
    # among them: no work, at run time); fargs then has the work arguments
    # third
    work: object = None
    # for a force with variations (orbits._kernels.variational.with_variations):
    # the force whose variational equations it integrates alongside (fargs
    # are then (its fargs, the variations' args), and the state has tangent
    # rows after the bodies'), and whether tangent vector 0 carries the chaos
    # indicators
    inner: "ForceKernel" = None
    chaos: bool = False
    # whether non-conservative terms are among the terms: the monitors then
    # report their work, and the workspace keeps it
    dissipative: bool = False

    @property
    def runtime(self):
        """Whether loops calling it need numba's runtime (reference counts).

        A user's function (which cannot be cached) may allocate, and the
        threaded gravity kernel needs it; the package's other force and term
        kernels allocate nothing, so their loops are compiled without the
        runtime, whose reference counts on the arrays of every inlined call
        would cost more than a small step (see :mod:`orbits._kernels._jit`)."""
        return self.allocates or not self.cache

    @property
    def recorder(self):
        """The monitor recorder the compiled loops call."""
        return _record if self.record is None else self.record


_PAIR_KERNELS = {
    "small": accelerate_pairwise_small,
    "lanes": accelerate_pairwise_lanes,
    "serial": accelerate_pairwise,
    "parallel": accelerate_pairwise_parallel,
}


def gravity_force(kind):
    """The pairwise-gravity force: ``kind`` is ``"small"``, ``"lanes"``, ``"serial"``, ``"parallel"``
    or ``"rebound"`` (REBOUND's arithmetic; see :mod:`orbits._kernels.gravity`)."""
    key = f"gravity_{kind}"
    if kind == "rebound":
        kernel = specialize(_gravity_force_exact, key, inline=True)
        return ForceKernel(kernel, key, True, True)
    kernel = specialize(_gravity_force, key, inline=True, pair_kernel=_PAIR_KERNELS[kind])
    return ForceKernel(kernel, key, True, True, allocates=kind == "parallel")


def _forced(x, v, t, fargs, acc):
    base(x, v, t, fargs[0], acc)
    extra(x, v, t, fargs[1], acc)


def _record_terms(x, v, t, mon, n_mon, mon_t, mon_out):
    # mon carries the terms' energy arguments as its seventh item
    every, which, m, G, n_active, eps2, eargs = mon
    mon_t[n_mon] = t
    e_terms = extra_energy(x, v, eargs) if which & ENERGY else 0.0
    _record_row(x, v, m, G, n_active, eps2, which, mon_out[n_mon], e_terms)


def terms_recorder(terms):
    """The monitor recorder of gravity with the terms of the
    :class:`~orbits._kernels.terms.TermKernel` ``terms``, whose monitors
    ``mon`` carry the terms' energy arguments as a seventh item (with an
    empty table, :func:`_record`'s rows)."""
    return specialize(_record_terms, terms.key, cache=terms.cache, extra_energy=terms.energy)


def with_terms(base, terms, velocity_dependent, work=None, dissipative=False):
    """Gravity ``base`` (a :class:`ForceKernel`) plus the terms of a
    :class:`~orbits._kernels.terms.TermKernel`: ``fargs = (base fargs, terms' args)``,
    and monitors ``mon`` with the terms' energy arguments as a seventh item.

    ``work``, the :class:`~orbits._kernels.terms.TermKernel` of the
    work arguments (a table of the non-conservative terms among them, maybe
    none), makes the loops integrate their work (see the module notes);
    ``fargs`` is then ``(base fargs, terms' args, work args)`` with the work
    arguments of :func:`work_args`.  ``dissipative``: the table holds some.
    """
    key = f"{base.key}+{terms.key}"
    cache = base.cache and terms.cache
    kernel = specialize(_forced, key, cache=cache, inline=True, base=base.kernel,
                        extra=terms.accel)
    # the recorder does not call gravity's pair kernel: named by the terms
    # alone, it is one compilation for every gravity kernel, and so is a loop
    # that takes the terms' kick and this recorder but not the force
    # (Wisdom-Holman's and trace's, whose kick is their own: one loop for
    # both sides of gravity.LANES_FROM)
    record = terms_recorder(terms)
    if work is not None:
        key += f"+work_{work.key}"
        cache = cache and work.cache
    return ForceKernel(kernel, key, True, cache, velocity_dependent=bool(velocity_dependent),
                       record=record, base=base, terms=terms, allocates=base.allocates,
                       work=work, dissipative=bool(dissipative))


# -- the work of the non-conservative terms -----------------------------------------

def _work_rate(x, v, t, fargs):
    # P = sum_i m_i a_i . v_i, a the non-conservative terms' accelerations
    # alone (none: 0, at once)
    wargs = fargs[2]
    nargs, m, scratch = wargs[0], wargs[1], wargs[2]
    if not work_on(fargs):
        return 0.0
    n = x.shape[0]
    for i in range(n):
        scratch[i, 0] = 0.0
        scratch[i, 1] = 0.0
        scratch[i, 2] = 0.0
    nc_accel(x, v, t, nargs, scratch)
    s = 0.0
    for i in range(n):
        s += m[i] * (scratch[i, 0] * v[i, 0] + scratch[i, 1] * v[i, 1]
                     + scratch[i, 2] * v[i, 2])
    return s


@njit(inline="always")
def _work_add(fargs, dw):
    # W += dw with Neumaier's compensation in box[1]: a long run adds millions
    # of increments, whose rounding would otherwise grow with their number
    box = fargs[2][3]
    s = box[0]
    t = s + dw
    if abs(s) >= abs(dw):
        box[1] += (s - t) + dw
    else:
        box[1] += (dw - t) + s
    box[0] = t


@njit(inline="always")
def _work_note(fargs, mon_out, row):
    # the monitor row just recorded gets the work done so far
    box = fargs[2][3]
    mon_out[row, WORK_COLUMN] = box[0] + box[1]


@njit(inline="always")
def _no_work_rate(x, v, t, fargs):
    return 0.0


@njit(inline="always")
def _table_work_on(fargs):
    # whether the terms' work arguments hold non-conservative terms
    return table_rows(fargs[2][0]) > 0


@njit(inline="always")
def _no_work_on(fargs):
    return False


@njit(inline="always")
def _no_work_add(fargs, dw):
    pass


@njit(inline="always")
def _no_work_note(fargs, mon_out, row):
    pass


@njit(inline="always")
def _no_tangent_step(x, v, t, fargs):
    return False


def work_kernels(force):
    """The bindings of a loop compiled for ``force`` that integrate the work of
    its non-conservative terms (see the module notes): ``HAS_WORK`` and the
    kernels ``work_rate(x, v, t, fargs) -> P``, ``work_add(fargs, dW)`` and
    ``work_note(fargs, mon_out, row)`` (records W in the monitor row just
    written, called by the step epilogue).  For a force without such terms
    they are no-ops, which compile to nothing.  A force with variations
    (``force.inner``) gets its inner force's, on the bodies' rows."""
    if force.inner is not None:
        return variational_work_kernels(force, work_kernels(force.inner))
    if force.work is None:
        return dict(HAS_WORK=False, work_rate=_no_work_rate, work_add=_no_work_add,
                    work_note=_no_work_note, work_on=_no_work_on)
    rate = specialize(_work_rate, force.work.key, cache=force.work.cache, inline=True,
                      nc_accel=force.work.accel, work_on=_table_work_on)
    return dict(HAS_WORK=True, work_rate=rate, work_add=_work_add, work_note=_work_note,
                work_on=_table_work_on)


def work_args(args, m):
    """The work arguments of :func:`with_terms`: the non-conservative terms'
    ``args`` (nested as :func:`~orbits._kernels.terms.chain` takes them), the
    masses ``m`` (shape (N,), internal order), a scratch (N, 3) array and a
    box ``(W, compensation)``, which :func:`work_bound` replaces by the
    workspace's."""
    return (args, m, np.zeros((len(m), 3)), np.zeros(2))


def work_bound(force, fargs, ws):
    """``fargs`` with the work box of the workspace ``ws`` (its ``"work"`` array,
    made if missing), for a force with non-conservative terms; ``fargs``
    itself otherwise.  Each integrator's ``advance`` calls it, so that a
    workspace copied and run again (:func:`orbits._driver.advance_checked`)
    integrates its own work.  A force with variations also gets the
    workspace's chaos accumulators (its ``"chaos"`` array)."""
    if force.inner is not None:
        inner = work_bound(force.inner, fargs[0], ws)
        vargs = fargs[1]
        box = ws.get("chaos", vargs[4])
        return (inner, vargs[:4] + (box,) + vargs[5:])
    if not force.dissipative:
        return fargs
    box = ws.get("work")
    if box is None:
        box = ws["work"] = np.zeros(2)
    wargs = fargs[2]
    return (fargs[0], fargs[1], (wargs[0], wargs[1], wargs[2], box))


def work_total(ws):
    """W in the workspace ``ws``: the energy the non-conservative terms have taken
    out of the bodies since the workspace was made (0.0 without such terms)."""
    box = ws.get("work")
    return 0.0 if box is None else float(box[0] + box[1])


def user_force_call():
    """:func:`user_force`'s kernel for a compiled function, as a function that
    Python calls (``(x, v, t, fargs, acc)``, the arguments of the loops):
    compiled once, cached, for every such function."""
    return specialize(_user_force, "user_pointer_call")


def user_force(accel, jit):
    """A force from a user's ``accel(x, v, t)``.  A numba function runs through
    its pointer, ``fargs = (size, shape, pointer, flag)``
    (:func:`orbits._user_functions.force_pointer`): the loops are compiled
    once, cached, for any such function.  A Python function runs the loops
    as Python, ``fargs = (size, shape)``."""
    if jit:
        kernel = specialize(_user_force, "user_pointer", inline=True)
        return ForceKernel(kernel, "user_pointer", True, True, opaque=True)
    key = f"user{id(accel)}"
    kernel = specialize(_user_python_force, key, jit=False, cache=False, user_accel=accel)
    return ForceKernel(kernel, key, False, False, opaque=True)


# -- splitting methods --------------------------------------------------------------

#: bodies from which the splitting loop drifts and kicks over flat views
FLAT_FROM_BODIES = 4


@njit(inline="always")
def add_scaled(a, aF, h, b, bF, flat):
    """``a += h b`` for arrays of shape (N, 3), over their flat views ``aF``,
    ``bF`` if ``flat`` (a loop LLVM vectorises), else body by body; each
    component's operation is the same either way."""
    if flat:
        for q in range(aF.shape[0]):
            aF[q] += h * bF[q]
    else:
        for i in range(a.shape[0]):
            a[i, 0] += h * b[i, 0]
            a[i, 1] += h * b[i, 1]
            a[i, 2] += h * b[i, 2]


class SplittingWork(NamedTuple):
    """A splitting loop's workspace: the accelerations, the implicit kick's
    midpoint velocities, and ``cache[0]`` (1: ``acc`` belongs to the
    current positions)."""
    acc: np.ndarray
    vm: np.ndarray
    cache: np.ndarray


class Splitting(NamedTuple):
    """A splitting method's table: each operator's kind (:data:`DRIFT` or
    :data:`KICK`) and its fraction of the step."""
    kinds: np.ndarray
    coefs: np.ndarray


def _splitting_loop(x, v, t, dt, nsteps, table, work, fargs, velocity_dependent, kick,
                    outputs, checks, check):
    # A splitting step is a sequence of drifts (x += c dt v) and kicks
    # (v += c dt a(x)), the method's table (a Splitting record), data of the
    # one loop every method shares.  The acceleration depends only
    # on positions (unless velocity_dependent), so it is recomputed only after
    # a drift: velocity Verlet's closing kick and the next step's opening kick
    # share one force evaluation.  `fresh` (kept in cache[0] between calls)
    # says whether acc belongs to the current positions.  A velocity-dependent
    # force is kicked with the implicit midpoint velocity (the pointer kick,
    # implicit_kick's), so the kick stays symmetric; vm is its scratch.  A
    # kick v' = v + h a changes the kinetic energy by exactly
    # h sum m a . (v + v') / 2: the non-conservative terms' part of it is
    # their work (HAS_WORK).
    kinds, coefs = table
    acc, vm, cache = work
    mon, step0, mon_t, mon_out = outputs
    check_every, sargs = checks
    stopping = (sargs, check)
    n = x.shape[0]
    # flat views of the (N, 3) arrays: the drifts and kicks as loops LLVM
    # turns into vector instructions, each component's operation that of
    # the nested loops (bit for bit); below FLAT_FROM_BODIES bodies the
    # vector loop's set-up costs more than it saves, and the nested loops
    # are faster (benchmarks/RESULTS.md)
    flat = n >= FLAT_FROM_BODIES
    m3 = 3 * n
    xF, vF = flat_rows(x, v)
    aF = acc.reshape(m3)
    every = mon[0]
    n_mon = 0
    fresh = cache[0] != 0
    until_check = check_every
    until_record = first_record(every, step0, mon_t)
    # terms without non-conservative ones among them do no work (data: the
    # loop serves both)
    has_work = HAS_WORK and work_on(fargs)
    for k in range(nsteps):
        tx = t + k * dt
        for op in range(kinds.shape[0]):
            h = coefs[op] * dt
            if kinds[op] == DRIFT:
                add_scaled(x, xF, h, v, vF, flat)
                tx += h
                fresh = False
            elif velocity_dependent:
                kick(x, v, tx, h, fargs, acc, vm)
                fresh = False
                if has_work:
                    # vm is the kick's midpoint velocity (v + v') / 2
                    work_add(fargs, -h * work_rate(x, vm, tx, fargs))
            else:
                if not fresh:
                    force(x, v, tx, fargs, acc)
                    fresh = True
                add_scaled(v, vF, h, acc, aF, flat)
                if has_work:
                    for i in range(n):
                        for d in range(3):
                            vm[i, d] = v[i, d] - 0.5 * h * acc[i, d]
                    work_add(fargs, -h * work_rate(x, vm, tx, fargs))
        status, done, until_check, until_record, n_mon = step_end(
            x, v, t + (k + 1) * dt, k, nsteps, True, until_check, check_every, until_record,
            every, mon, n_mon, mon_t, mon_out, stopping, fargs)
        if status != GO:
            cache[0] = 1 if fresh and status != Status.NON_FINITE else 0
            return status, done, n_mon
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
        force(x, vm, t, fargs, acc)
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


def _kick_call(x, v, t, h, fargs, acc, vm):
    # the body of the implicit kick's pointer: a call of the kick compiled
    # as a function of its own, so that compiling it is announced and timed
    # (numba broadcasts its compile events for compiled functions, not for
    # the C callables that call them)
    kick_kernel(x, v, t, h, fargs, acc, vm)


_KICK_POINTERS = {}
#: the forces (key, cache, runtime) whose kick a run of this process has made
_KICKS_MADE = set()


def kick_made(force):
    """Whether :func:`implicit_kick` has made ``force``'s kick in this
    process (so that a run need not type the force's arguments to find it
    again)."""
    return (force.key, force.cache, force.runtime) in _KICKS_MADE


def implicit_kick(force, x, fargs, velocity_dependent):
    """The splitting loop's ``kick`` argument for a run of ``force`` on a state
    like ``x`` with the force's arguments ``fargs``: the implicit kick
    (``v' = v + h a(x, (v + v') / 2, t)``) as a C callable, compiled on first
    use and cached on disk, where the run's force reads velocities; else a
    pointer of the same type that is never called
    (:func:`~._jit.idle_pointer`).  So the loop serves both, and a run
    without velocity-dependent forces compiles no kick.  A force that runs as
    plain Python gets the kick as plain Python."""
    if not force.jit:
        return specialize(_implicit_kick, force.key, jit=False, force=force.kernel)
    a = numba.typeof(x)
    signature = nbtypes.none(a, a, nbtypes.float64, nbtypes.float64, numba.typeof(fargs), a, a)
    if not velocity_dependent:
        return idle_pointer(signature)
    key = (force.key, force.cache, force.runtime, signature)
    found = _KICK_POINTERS.get(key)
    if found is None:
        kick = specialize(_implicit_kick, force.key, cache=force.cache, nrt=force.runtime,
                          force=force.kernel)
        call = specialize(_kick_call, force.key, cache=force.cache, nrt=force.runtime,
                          kick_kernel=kick)
        found = _KICK_POINTERS[key] = pointer(call, signature, force.cache, nrt=force.runtime)
        _KICKS_MADE.add((force.key, force.cache, force.runtime))
    return found


def splitting_loop(force):
    """The splitting loop compiled for a :class:`ForceKernel`, for every
    splitting method.

    The loop takes ``(x, v, t, dt, nsteps, table, work, fargs,
    velocity_dependent, kick, outputs, checks, check)``: the method's
    :class:`Splitting` table, a :class:`SplittingWork`, whether the force
    reads velocities and the implicit kick's pointer for it
    (:func:`implicit_kick`), the records of :mod:`.records` and the
    stopping conditions' pointer (:func:`~.stopping.stop_record`).
    """
    return specialize(_splitting_loop, f"splitting_{force.key}",
                      jit=force.jit, cache=force.cache, nrt=force.runtime, force=force.kernel,
                      step_end=step_epilogue(force), **work_kernels(force))


# -- explicit Runge-Kutta ---------------------------------------------------------------

@njit(inline="always")
def rk_stage(xF, vF, xsF, vsF, kxF, kvF, A, st, h):
    """Stage ``st`` of a Runge-Kutta step of ``h`` on flat views (length 3 N;
    ``kxF``, ``kvF`` one row a stage): its state ``y + h sum_j A[st, j] k_j``
    into ``xsF``, ``vsF`` and its velocity into ``kxF[st]``.  Passes over every
    component that LLVM turns into vector instructions, each operation as the
    sum over j per component makes it (``h A[st, j]`` computed once)."""
    m3 = xF.shape[0]
    for q in range(m3):
        xsF[q] = xF[q]
        vsF[q] = vF[q]
    for j in range(st):
        a = A[st, j]
        if a != 0.0:
            ha = h * a
            for q in range(m3):
                xsF[q] += ha * kxF[j, q]
                vsF[q] += ha * kvF[j, q]
    for q in range(m3):
        kxF[st, q] = vsF[q]


@njit(inline="always")
def rk_sums(sx, sv, kxF, kvF, b, count):
    """``sum_s b[s] k_s`` over the first ``count`` stages into ``sx``, ``sv``
    (flat views, as :func:`rk_stage`), summed in stage order per component."""
    m3 = sx.shape[0]
    for q in range(m3):
        sx[q] = 0.0
        sv[q] = 0.0
    for s in range(count):
        bs = b[s]
        for q in range(m3):
            sx[q] += bs * kxF[s, q]
            sv[q] += bs * kvF[s, q]


@njit(inline="always")
def stage_errors(kx, kv, e, e3, count, i, d):
    """An embedded pair's two error estimates of component ``(i, d)``:
    ``sum_s e[s] k_s`` and ``sum_s e3[s] k_s`` of the position and velocity
    stages (arrays of shape (S, N, 3)) over the first ``count``, in stage
    order; returns ``(e_x, e_v, e3_x, e3_v)``."""
    ex = 0.0
    ev = 0.0
    fx = 0.0
    fv = 0.0
    for j in range(count):
        ex += e[j] * kx[j, i, d]
        ev += e[j] * kv[j, i, d]
        fx += e3[j] * kx[j, i, d]
        fv += e3[j] * kv[j, i, d]
    return ex, ev, fx, fv


@njit(inline="always")
def dop853_error(err5, err3, h, ncomp):
    """The error of a step of DOP853 (Hairer, Norsett & Wanner 1993, II.10)
    from the scaled sums of squares of its fifth- and third-order estimates
    over ``ncomp`` components."""
    denom = err5 + 0.01 * err3
    return 0.0 if denom == 0.0 else h * err5 / math.sqrt(denom * ncomp)


@njit(inline="always")
def accept_fsal(x, v, x1, v1, kx, kv, last, n):
    """An accepted step of a method whose last stage is the next step's
    first (FSAL): rows below ``n`` of the state set to the step's end
    ``x1``, ``v1``, and of stage 0 to stage ``last``."""
    for i in range(n):
        for d in range(3):
            x[i, d] = x1[i, d]
            v[i, d] = v1[i, d]
            kx[0, i, d] = kx[last, i, d]
            kv[0, i, d] = kv[last, i, d]


def _stages(xF, vF, xsF, vsF, kxF, kvF, xs, vs, kv, tableau, t, h, first, count, pw, fargs):
    # stages first .. count - 1 of a Runge-Kutta step of h from t (flat views
    # and their (N, 3) forms xs, vs, kv as in rk_stage): each stage's state,
    # then its acceleration; returns pw plus the stages' work rates weighted
    # by b (with HAS_WORK)
    A, b, c = tableau
    for st in range(first, count):
        rk_stage(xF, vF, xsF, vsF, kxF, kvF, A, st, h)
        force(xs, vs, t + c[st] * h, fargs, kv[st])
        if HAS_WORK and b[st] != 0.0:
            pw += b[st] * work_rate(xs, vs, t + c[st] * h, fargs)
    return pw


def rk_stages(force):
    """The stages of an explicit Runge-Kutta step for a :class:`ForceKernel`
    (:func:`_stages`), inlined where they are called."""
    work = work_kernels(force)
    return specialize(_stages, force.key, jit=force.jit, cache=force.cache, inline=True,
                      nrt=force.runtime, force=force.kernel, HAS_WORK=work["HAS_WORK"],
                      work_rate=work["work_rate"])


class Tableau(NamedTuple):
    """An explicit Runge-Kutta method's Butcher tableau."""
    A: np.ndarray
    b: np.ndarray
    c: np.ndarray


class RungeKuttaWork(NamedTuple):
    """A Runge-Kutta loop's workspace: each stage's velocities and
    accelerations (one row a stage), and a stage's state."""
    kx: np.ndarray
    kv: np.ndarray
    xs: np.ndarray
    vs: np.ndarray


def _runge_kutta_loop(x, v, t, dt, nsteps, tableau, work, fargs, outputs, checks, check):
    # y = (x, v), y' = (v, a(x, v, t)); stage s has state
    # y + dt sum_j A[s, j] k_j and derivative k_s.  kx[s] = stage velocity,
    # kv[s] = stage acceleration.  The work is the same method applied to
    # W' = -P(x, v, t): W += -dt sum_s b_s P(stage s).
    A, b, c = tableau
    kx, kv, xs, vs = work
    mon, step0, mon_t, mon_out = outputs
    check_every, sargs = checks
    stopping = (sargs, check)
    n = x.shape[0]
    n_stages = b.shape[0]
    # flat views of the (N, 3) arrays, for loops LLVM turns into vector instructions
    m3 = 3 * n
    xF, vF, xsF, vsF, kxF, kvF = stage_views(x, v, xs, vs, kx, kv)
    every = mon[0]
    n_mon = 0
    until_check = check_every
    until_record = first_record(every, step0, mon_t)
    for k in range(nsteps):
        tk = t + k * dt
        pw = stages(xF, vF, xsF, vsF, kxF, kvF, xs, vs, kv, tableau, tk, dt, 0, n_stages, 0.0,
                    fargs)
        # the step's sums b . k, gathered in xs, vs (free until the next step)
        rk_sums(xsF, vsF, kxF, kvF, b, n_stages)
        for q in range(m3):
            xF[q] += dt * xsF[q]
            vF[q] += dt * vsF[q]
        if HAS_WORK:
            work_add(fargs, -dt * pw)
        status, done, until_check, until_record, n_mon = step_end(
            x, v, t + (k + 1) * dt, k, nsteps, True, until_check, check_every, until_record,
            every, mon, n_mon, mon_t, mon_out, stopping, fargs)
        if status != GO:
            return status, done, n_mon
    return Status.OK, nsteps, n_mon


def runge_kutta_loop(force):
    """The explicit Runge-Kutta loop compiled for a :class:`ForceKernel`: it
    takes ``(x, v, t, dt, nsteps, tableau, work, fargs, outputs, checks,
    check)``, a :class:`Tableau`, a :class:`RungeKuttaWork`, the records of
    :mod:`.records` and the stopping conditions' pointer
    (:func:`~.stopping.stop_record`)."""
    return specialize(_runge_kutta_loop, force.key,
                      jit=force.jit, cache=force.cache, nrt=force.runtime, force=force.kernel,
                      step_end=step_epilogue(force), stages=rk_stages(force),
                      **work_kernels(force))
