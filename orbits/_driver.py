"""Advancing an integrator with the guarantee that a failure loses nothing."""

import contextlib
import signal as _signal
import sys
import threading
import time as _time

import _signal as _csignal
import numpy as np
from tqdm.auto import tqdm

from ._compiling import CHECKS, OUTPUT_MONITORS, CompileClock, loop_label
from ._kernels.invariants import FILLED, MONITOR_WIDTH, fill_kernel
from ._kernels.status import Status
from ._kernels.stepping import USER_FORCE_SIZE
from .errors import ForceTermError, RunInterrupted, WallTimeExceeded

__all__ = ["advance_checked", "restored_on_error", "Signals", "CHECK_EVERY", "Driven",
           "CHUNK_SECONDS", "FIRST_CHUNK", "next_chunk", "PROGRESS_DELAY"]

#: The compiled loops test the state for NaN and inf every this many steps
#: (a test is a dependent chain of 6N additions, as dear as the force for a few
#: bodies); a failure is then located exactly by re-running from a copy.
CHECK_EVERY = 16


def _filled(mon, rows):
    """``rows``, outputs a compiled loop recorded with the bodies' state, with
    their energy and angular momentum made from that state (``mon``: the
    loop's monitor arguments; see
    :func:`orbits._kernels.invariants.fill_monitors`)."""
    if mon[1] & FILLED:
        fill_kernel()(rows, mon[2], mon[3], mon[4], mon[5], mon[1])
    return rows


def advance_checked(integ, ws, x, v, t, dt, n, force, fargs, mon, step0, mon_t, mon_out,
                    velocity_dependent=False, stop=None):
    """Advance ``n`` steps; on failure, leave ``x``, ``v`` at the last good state.

    Returns ``(status, good_steps, n_monitor_rows, ws)``; ``ws`` is the
    workspace to keep (a restored copy after a failure).  After a failure the
    monitor rows are those of the good steps only.  The compiled loops are
    deterministic, so the failing step and the last good state are recomputed
    from a copy taken here rather than saved by the loop every step.
    """
    saved = (x.copy(), v.copy(), _copy_workspace(ws))
    kw = {} if stop is None else {"stop": stop}
    # the stopping conditions' own arrays (the state a collision check keeps
    # from the step before), so that a re-run checks as the run did
    saved_stop = () if stop is None else tuple(
        a.copy() if isinstance(a, np.ndarray) else None for a in stop)
    with restored_on_error(x, v, ws, saved):
        status, steps, n_mon = integ.advance(ws, x, v, t, dt, n, force, fargs, mon, step0,
                                             mon_t, mon_out, velocity_dependent, CHECK_EVERY,
                                             **kw)
    if status == Status.OK:
        return Status.OK, n, n_mon, ws
    if status != Status.NON_FINITE:
        # a stopping condition: the state is good, and it is where the run ends
        return Status(status), steps, n_mon, ws

    def rerun(nsteps, monitors):
        x[...] = saved[0]
        v[...] = saved[1]
        for a, b in zip(stop or (), saved_stop):
            if b is not None:
                a[...] = b
        work = _copy_workspace(saved[2])
        m = mon if monitors else (0,) + tuple(mon[1:])
        result = integ.advance(work, x, v, t, dt, nsteps, force, fargs, m, step0, mon_t,
                               mon_out, velocity_dependent, 1, **kw)
        return result, work

    (status, good, n_mon), _ = rerun(n, monitors=True)    # finds the failing step
    (_, _, _), ws = rerun(good, monitors=False)             # back to the last good state
    return Status(status), good, n_mon, ws


@contextlib.contextmanager
def restored_on_error(x, v, ws, saved=None):
    """Put ``x``, ``v`` and ``ws`` back as they were if the block raises.

    A compiled loop works in place; an error raised inside it (a user force
    of the wrong size) would otherwise leave the state some steps on and the
    clock not.  A user force's size error becomes a named
    :class:`~orbits.errors.ForceTermError`.
    """
    if saved is None:
        saved = (x.copy(), v.copy(), _copy_workspace(ws))
    try:
        yield
    except BaseException as exc:
        x[...] = saved[0]
        v[...] = saved[1]
        for k, a in saved[2].items():
            if isinstance(a, np.ndarray):
                ws[k][...] = a
        if isinstance(exc, ValueError) and str(exc) == USER_FORCE_SIZE:
            raise ForceTermError("a user force returned an array of another shape than "
                                 "during the check before the run; the simulation was left "
                                 "at the start of this chunk", term="UserForce",
                                 field="func") from None
        raise


def _copy_workspace(ws):
    return {k: (a.copy() if isinstance(a, np.ndarray) else a) for k, a in ws.items()}


class Signals:
    """SIGINT and SIGTERM held while a run is in compiled code, acted on between chunks.

    Python runs a signal's handler between bytecodes only.  Ctrl-C's handler
    raising while a compiled loop returns would leave the loop's in-place
    state advanced and the clock not (and surfaces as ``SystemError``).  During
    a run, in the main thread, the handler only notes the signal; the run
    looks between chunks, at a consistent state, and stops there
    (``Simulation._check_signal``, :func:`orbits.integrate`).  Signals that were ignored stay
    ignored, and the handlers are put back when the run ends.  A signal noted
    after the last look is delivered when the run has finished.
    """

    SIGNALS = (int(_signal.SIGINT), int(_signal.SIGTERM))

    def __init__(self):
        self.caught = None
        self.saved = {}

    def __enter__(self):
        # the C-level calls of the signal module: its Python wrappers' enum
        # conversions made up most of the cost of a short run's set-up
        if threading.current_thread() is threading.main_thread():
            for signum in self.SIGNALS:
                previous = _csignal.getsignal(signum)
                if previous == _csignal.SIG_IGN or previous is None:
                    continue
                try:
                    _csignal.signal(signum, self._note)
                except (ValueError, OSError):  # pragma: no cover - not the main interpreter
                    continue
                self.saved[signum] = previous
        return self

    def _note(self, signum, frame):
        if self.caught is None:
            self.caught = signum

    def restore(self):
        for signum, previous in self.saved.items():
            _csignal.signal(signum, previous)
        self.saved = {}

    def __exit__(self, kind, exc, tb):
        self.restore()
        if self.caught is not None and kind is None:
            _signal.raise_signal(self.caught)
        return False


#: A run's compiled loop returns to Python about this often, so that progress
#: bars move and Ctrl-C, SIGTERM, ``wall_limit`` and checkpoints are acted on;
#: each chunk's length in steps is sized from the time a step took in the
#: chunk before (:func:`next_chunk`).
CHUNK_SECONDS = 0.25

#: Steps in a simulation's first call of its compiled loop.  What a step costs
#: is not known before one is taken (0.2 us for the outer solar system on
#: ``leapfrog``, 40 ms for 2000 bodies on ``ias15``), so the first call takes
#: one and its time sizes the next (a call's fixed cost, 20 to 100 us, makes
#: the next chunk of a cheap step some 10^3 to 10^4 steps, and the one after
#: it ``CHUNK_SECONDS`` long).
FIRST_CHUNK = 1

#: The shortest time :func:`next_chunk` takes a call to have lasted: below a
#: call's fixed cost, so only a clock that did not advance is raised to it.
_CLOCK_FLOOR = 1e-6


def next_chunk(chunk, steps, elapsed):
    """The length in steps of the chunk after one of ``chunk`` steps that took
    ``steps`` steps in ``elapsed`` seconds.

    A chunk that ran to its end sets the next to last ``CHUNK_SECONDS`` at its
    time a step, ``CHUNK_SECONDS steps / elapsed`` (at least one step); that
    time includes the call's fixed cost, so a short sample overestimates what
    a step costs and the next chunk errs short.  A call that ended before its
    chunk (at an output, the end of the run) says only that its steps took
    ``elapsed``: it shortens the chunk if it took longer than
    ``CHUNK_SECONDS``, and otherwise leaves it.

    Parameters
    ----------
    chunk : int
        Steps the call was allowed.
    steps : int
        Steps it took (accepted steps, for an adaptive method).
    elapsed : float
        Wall-clock seconds the call took.

    Returns
    -------
    int
        The next chunk's length in steps, at least 1.

    Examples
    --------
    A first step that took 40 ms (2000 bodies on ``ias15``) sizes the next
    chunk to six steps:

    >>> from orbits._driver import next_chunk
    >>> next_chunk(1, 1, 0.04)
    6
    >>> next_chunk(1, 1, 25e-6)        # a step of a few bodies, with the call's cost
    10000
    >>> next_chunk(1000, 10, 1e-4)     # ended at an output: no longer
    1000
    """
    if steps <= 0:
        return chunk
    want = max(1, int(CHUNK_SECONDS * steps / max(elapsed, _CLOCK_FLOOR)))
    if steps < chunk:
        return min(chunk, want) if elapsed > CHUNK_SECONDS else chunk
    return want

#: A progress bar appears once a run has gone on this long, so short runs stay quiet.
PROGRESS_DELAY = 3.0


class Driven:
    """The one run driver, shared by :class:`orbits.Simulation` and
    :func:`orbits.integrate`.

    A class that mixes it in holds one state and says how to advance it:
    ``integrator``, ``_ws`` (its workspace), ``_x``, ``_v``, ``_rows_x`` and
    ``_rows_v`` (the arrays the compiled loops advance: the state, and after
    it the tangent rows of a simulation with variations), ``_force`` and
    ``_fargs``, ``_stop`` (stopping arguments or None), ``_mon(every)`` and
    ``monitor_every``, the clock (``_t_base``, ``_steps_since_base``, ``_dt``,
    ``_now()``, ``time``), the counters (``steps``, ``steps_rejected``,
    ``force_evaluations``), ``_chunk``, ``_stop_info``, ``_wall_limit`` and
    ``_fail(status, rec, wall0)``, which raises the named error of a failed
    status.  :meth:`execute` carries out a plan (a
    :class:`~orbits.records.RunPlan` or anything with its ``marks``,
    ``n_full``, ``has_partial``, ``total_steps``, ``start_step``,
    ``outputs``, ``output_time``, ``output_times`` and ``until``) into a
    recorder, which takes
    ``output(owner, final)``, ``monitor_rows(t, rows)``, ``checkpoint()``,
    ``stopped(owner)``, ``close()`` and ``result(owner, wall, status)``.
    """

    _wall_limit = None

    #: +1 or -1: the direction of time of the run being carried out (its
    #: plan's ``direction``).  ``_dt`` is the step's size, always >= 0; the
    #: compiled loops take the signed step :attr:`_step`, and the clock
    #: counts ``_steps_since_base`` down in a run backwards, so that
    #: ``time = t_base + steps_since_base * dt`` holds in either direction.
    _sign = 1

    @property
    def _step(self):
        # the signed step the compiled loops take
        return self._sign * self._dt

    def _renormalise(self):
        # scale back the chaos indicators' tangent vector (a run with them only)
        raise NotImplementedError

    def execute(self, plan, rec, progress, first_mark=0):
        """Carry out ``plan`` from its output ``first_mark`` on (resuming).

        The one driver of every run, fixed-step and adaptive: the compiled
        loop is entered in chunks of about :data:`CHUNK_SECONDS`, and between
        chunks the progress bar, the wall-time limit and any SIGINT or SIGTERM
        that arrived are looked at.

        Fixed-step runs whose outputs fall every ``k`` steps (outputs that
        divide the run's steps evenly), for a recorder that gives a
        ``row_buffer(k)`` to write the next k into and takes
        ``output_rows(owner, steps, times, rows)``, record them inside the compiled
        loop, with the monitors, into rows of :data:`MONITOR_WIDTH` + ``6 N``
        columns (:func:`orbits._kernels.stepping.record_state`): one call
        into the loop for many outputs rather than one each.  Their times
        are computed as :meth:`_now` would at their steps, and the state and
        monitors are those the output would have taken outside the loop.

        The seconds spent compiling are measured (the result's
        ``compile_time``), and a stepping loop that starts to compile says
        so on the standard error, unless ``progress`` is False
        (:class:`~orbits._compiling.CompileClock`).
        """
        adaptive = self.integrator.adaptive
        self._sign = getattr(plan, "direction", 1)
        if adaptive:
            bar = _ProgressBar(plan.outputs - 1, progress, unit="output")
            bar.update(first_mark)
        else:
            bar = _ProgressBar(plan.total_steps, progress)
            bar.update(self.steps - plan.start_step)
            if isinstance(self._ws, dict):
                # the simulation's step count at the run's end, for the
                # integrators that choose a loop by the length of the run
                # (wh's lanes="auto")
                self._ws["steps_by_end"] = plan.start_step + plan.total_steps
        lanes = getattr(self.integrator, "lanes_wanted", None)
        lanes = (lanes is not None and getattr(self._force, "inner", None) is None
                 and getattr(self, "_stop", None) is None
                 and lanes(self._ws, self._x.shape[0], self._force.recorder))
        force = self._force
        inner = getattr(force, "inner", None)
        # an integrator that takes terms as data runs one loop with and without them
        separate = not getattr(self.integrator, "terms_as_data", False)
        adds = ("terms+variations" if separate and getattr(inner, "terms", None) is not None
                else "variations" if inner is not None else
                "terms" if separate and getattr(force, "terms", None) is not None else "")
        self._compile_clock = CompileClock(loop_label(self.integrator, lanes, adds),
                                           quiet=progress is False)
        wall0 = _time.perf_counter()
        self._wall0 = wall0
        self._encounters = []
        with self._compile_clock, Signals() as self._signals:
            try:
                self._compile_check()
                if adaptive:
                    self._outputs_adaptive(plan, rec, bar, first_mark)
                else:
                    self._outputs_fixed(plan, rec, bar, first_mark)
            finally:
                bar.close()
                self._log_into(rec)
                rec.close()
        return self._with_log(rec.result(self, _time.perf_counter() - wall0))

    def _log_into(self, rec):
        """The encounter log's last rows into the run's list and ``rec``'s file,
        before it closes (an owner without a log has nothing to do)."""
        if getattr(self, "_log_n", None) is not None:
            self._drain_log(rec)

    def _with_log(self, result):
        """``result`` with the encounter log and the collisions of the run (if
        the owner keeps them), and the seconds it spent compiling."""
        clock = getattr(self, "_compile_clock", None)
        if clock is not None and result is not None and hasattr(result, "compile_time"):
            result.compile_time = clock.seconds
        table = getattr(self, "_encounter_table", None)
        if table is not None and result is not None:
            self._drain_log()
            result._defer("encounters", table())
        table = getattr(self, "_collision_table", None)
        if table is not None and result is not None:
            result._defer("collisions", table())
        return result

    def _offset_rows(self, rows):
        # monitor rows as the owner reports them (orbits.Simulation adds what
        # resolved collisions took out); unchanged by default
        return rows

    _resolves_collisions = False

    @property
    def _loop_may_raise(self):
        # whether the compiled loop can raise: it runs a user's Python force
        # as Python, or calls a function it was compiled with and not loaded
        # from the cache; the package's own kernels are compiled with numpy's
        # error model and raise nothing, and users' compiled functions run
        # through pointers that report a failure in a flag instead
        # (orbits._user_functions)
        force = self._force
        return force.opaque or not force.jit or not force.cache

    #: (k, origin, plan): outputs are being recorded in the loop every k steps
    #: counted from step ``origin`` (see :meth:`execute`), or, with k = -1, at
    #: the plan's marks
    _in_loop = None

    def _outputs_fixed(self, plan, rec, bar, first_mark):
        wall0 = self._wall0
        done = self.steps - plan.start_step
        k = self._output_interval(plan, rec)
        if k:
            # the last output before the final one
            last = (plan.outputs - 2) * k if k > 0 else next(plan.marks(plan.outputs - 3))
            if done < last:
                self._fill_ahead()
                self._in_loop = (k, plan.start_step, plan)
                try:
                    done = self._advance_to(done, last, rec, bar, wall0)
                finally:
                    self._in_loop = None
        else:
            for mark in plan.marks(first_mark):
                done = self._advance_to(done, mark, rec, bar, wall0)
                rec.output(self)
        done = self._advance_to(done, plan.n_full, rec, bar, wall0)
        if plan.has_partial and done == plan.n_full:
            self._advance(1, rec, wall0, dt=plan.until - self._now())
            bar.update(1)
        rec.output(self, final=True)

    def _output_interval(self, plan, rec):
        # k when the plan's outputs between the first and the last fall every
        # k steps and can be recorded in the loop (see execute); -1 when they
        # fall at least a step apart but not evenly, and the integrator's loop
        # records at marks (every = -1, orbits._kernels.stepping.first_record);
        # else 0 (recorded from here, one loop call an output)
        if (getattr(rec, "row_buffer", None) is None
                or not getattr(rec, "records_in_loop", True) or self.monitor_every
                or plan.outputs < 3 or self._resolves_collisions):
            return 0
        k = int(round(plan.ratio / (plan.outputs - 1)))
        # the marks are round(i ratio / (outputs - 1)): all i k when ratio is
        # within a quarter step of (outputs - 1) k
        if k >= 1 and abs(plan.ratio - k * (plan.outputs - 1)) < 0.25 \
                and (plan.outputs - 2) * k <= plan.n_full:
            return k
        if plan.ratio >= plan.outputs - 1 and getattr(self.integrator, "records_step_marks",
                                                       False):
            return -1
        return 0

    def _outputs_adaptive(self, plan, rec, bar, first_mark):
        wall0 = self._wall0
        first = first_mark + 1
        if self._marks_in_loop(plan, rec):
            # the outputs before the last, recorded inside the compiled loop
            self._fill_ahead()
            last = plan.outputs - 1
            while first < last:
                first = self._advance_marks(plan, first, last, rec, bar, wall0)
        for k in range(first, plan.outputs):
            self._advance_adaptive(plan.output_time(k), rec, wall0)
            bar.update(1)
            rec.output(self, final=k == plan.outputs - 1)
        if plan.outputs == 1:
            self._advance_adaptive(plan.until, rec, wall0)
            rec.output(self, final=True)

    def _fill_ahead(self):
        # the outputs' monitors (orbits._kernels.invariants.fill_kernel),
        # compiled or loaded before a loop that records outputs, where the
        # run asks for them (see _filled), announced as themselves
        if self._mon(0)[1] & FILLED:
            with self._compile_clock.part(OUTPUT_MONITORS):
                fill_kernel()

    def _compile_check(self):
        # the stopping conditions' check, one compiled C callable for every
        # integrator (orbits._kernels.stopping.check_pointer), compiled, or
        # loaded from the cache, before the loop: so that its first compile
        # is announced as the check's and not as the loop's (the check of
        # collisions and encounters takes 20-25 s, a loop a few); and the
        # look-ahead of an integrator whose step may not finish (trace's)
        # and the parts the integrator compiles besides its loop (the
        # splitting methods' implicit kick), each announced as itself
        for label, make in self.integrator.parts_ahead(self._force, self._rows_x, self._fargs):
            with self._compile_clock.part(label):
                make()
        stop = getattr(self, "_stop", None)
        if stop is None:
            return
        from ._kernels.stopping import ahead_pointer, check_kind, check_pointer
        conditions = int(stop[0])
        kind = check_kind(conditions)
        if kind in CHECKS:
            with self._compile_clock.part(CHECKS[kind]):
                check_pointer(conditions)
        if getattr(self.integrator, "looks_ahead", False):
            with self._compile_clock.part(CHECKS["ahead"]):
                ahead_pointer(True)

    def _marks_in_loop(self, plan, rec):
        # whether an adaptive run's outputs can be recorded in its loop: a
        # method that lands on them there, a recorder that takes rows, and
        # nothing an output adds beyond the state and its monitors (chaos
        # indicators, collision offsets, a monitor series)
        return (getattr(self.integrator, "records_marks", False)
                and getattr(rec, "row_buffer", None) is not None
                and getattr(rec, "records_in_loop", True) and not self.monitor_every
                and plan.outputs >= 3 and len(self._rows_x) == len(self._x)
                and not self._resolves_collisions)

    def _advance_marks(self, plan, first, last, rec, bar, wall0):
        """Outputs ``first`` to ``last - 1`` of an adaptive run, as many as one
        call of the compiled loop takes (see :meth:`execute`); returns the
        next output's index."""
        integ = self.integrator
        cap = getattr(rec, "max_rows", None) or 65536
        m = min(last - first, cap)
        marks = plan.output_times(first, m)
        rows = rec.row_buffer(m)
        mon_t = np.empty(m)
        steps = np.zeros(m, dtype=np.int64)
        t0 = _time.perf_counter()
        guard = (restored_on_error(self._rows_x, self._rows_v, self._ws)
                 if self._loop_may_raise else contextlib.nullcontext())
        mon = self._mon(0)
        with guard, self._compile_clock.loop():
            status, t_reached, acc, rej, fev, n_mon = integ.advance_to(
                self._ws, self._rows_x, self._rows_v, self._t_base, marks[-1], self._force,
                self._fargs, mon, self.steps, mon_t, rows, self._stop, self._chunk,
                marks, steps)
        elapsed = _time.perf_counter() - t0
        if n_mon:
            rec.output_rows(self, steps[:n_mon], mon_t[:n_mon], _filled(mon, rows[:n_mon]))
            bar.update(n_mon)
        self._t_base = float(t_reached)
        self.steps += int(acc)
        self.steps_rejected += int(rej)
        self.force_evaluations += int(fev)
        if status == Status.LOG_FULL:
            self._log_full(rec, wall0)
        elif status != Status.OK:
            if status != Status.NON_FINITE and status != Status.STEP_UNDERFLOW:
                self._stop_info[:] = self._ws["info"]
            self._fail(status, rec, wall0)
        self._chunk = next_chunk(self._chunk, int(acc), elapsed)
        self._between_chunks(rec, wall0)
        return first + n_mon

    def _advance_adaptive(self, t_end, rec, wall0):
        integ = self.integrator
        every = self.monitor_every or 0
        while (t_end - self._t_base) * self._sign > 0:
            n = self._chunk
            size = n // every + 1 if every else 0
            mon_t = np.empty(size)
            mon_out = np.zeros((size, MONITOR_WIDTH))
            mon = self._mon(every)
            t0 = _time.perf_counter()
            # a copy to put back is taken only where the loop can raise (a
            # user's function in it): the package's kernels cannot
            guard = (restored_on_error(self._rows_x, self._rows_v, self._ws)
                     if self._loop_may_raise else contextlib.nullcontext())
            with guard, self._compile_clock.loop():
                status, t_reached, acc, rej, fev, n_mon = integ.advance_to(
                    self._ws, self._rows_x, self._rows_v, self._t_base, t_end, self._force,
                    self._fargs, mon, self.steps, mon_t, mon_out, self._stop, n)
            elapsed = _time.perf_counter() - t0
            if n_mon:
                rec.monitor_rows(mon_t[:n_mon], self._offset_rows(mon_out[:n_mon]))
            self._t_base = float(t_reached)
            self.steps += int(acc)
            self.steps_rejected += int(rej)
            self.force_evaluations += int(fev)
            if status == Status.RENORMALISE:
                self._renormalise()
                self._between_chunks(rec, wall0)
                continue
            if status == Status.LOG_FULL:
                self._log_full(rec, wall0)
                self._between_chunks(rec, wall0)
                continue
            if status == Status.COLLISION and self._resolves_collisions:
                self._resolve_collisions(rec, wall0)
                self._between_chunks(rec, wall0)
                continue
            if status != Status.OK:
                if status != Status.NON_FINITE and status != Status.STEP_UNDERFLOW:
                    self._stop_info[:] = self._ws["info"]
                self._fail(status, rec, wall0)
            self._chunk = next_chunk(n, int(acc), elapsed)
            self._between_chunks(rec, wall0)

    def _advance_to(self, done, target, rec, bar, wall0):
        # the loop returns to Python about every CHUNK_SECONDS (progress bar,
        # signals, wall_limit); the chunk length adapts (next_chunk) and is
        # kept from one call to the next
        cap = getattr(rec, "max_rows", None) if self._in_loop else None
        while done < target:
            n = min(self._chunk, target - done)
            if cap:
                # a recorder that streams (a file) holds at most cap outputs:
                # marks are at least floor(ratio / (outputs - 1)) steps apart
                k, _, plan = self._in_loop
                n = min(n, cap * k if k > 0
                        else max(1, cap - 1) * int(plan.ratio / (plan.outputs - 1)))
            t0 = _time.perf_counter()
            self._advance(n, rec, wall0)
            elapsed = _time.perf_counter() - t0
            done += n
            bar.update(n)
            self._chunk = next_chunk(self._chunk, n, elapsed)
            self._between_chunks(rec, wall0)
        return done

    def _between_chunks(self, rec, wall0):
        note = getattr(rec, "between_chunks", None)
        if note is not None:
            note()
        self._check_signal(rec, wall0)
        self._check_wall(rec, wall0)

    def _check_signal(self, rec, wall0):
        """Stop at this consistent point if SIGINT or SIGTERM arrived meanwhile."""
        signals = getattr(self, "_signals", None)
        if signals is None or signals.caught is None:
            return
        signum = signals.caught
        signals.caught = None
        previous = signals.saved.get(signum)
        rec.checkpoint()
        if callable(previous) and previous is not _signal.default_int_handler:
            previous(signum, None)   # the caller's own handler decides; the state is whole
            return
        name = _signal.Signals(signum).name
        rec.stopped(self)
        self._log_into(rec)
        rec.close()
        result = self._with_log(rec.result(self, _time.perf_counter() - wall0,
                                           status=f"stopped by {name}"))
        if previous is _signal.default_int_handler:
            path = getattr(rec, "path", None)
            raise RunInterrupted(
                f"{name} at t = {self.time:.10g} (step {self.steps}): the simulation was "
                f"left at the last completed step, clock and state agreeing"
                + (f", and a restart checkpoint was written to {path}" if path else "")
                + "; the result up to here is kept on .result",
                signal=signum, time=self.time, step=self.steps, result=result)
        # the default action (SIGTERM ends the process): taken now that the file is whole
        signals.restore()
        _signal.raise_signal(signum)

    def _check_wall(self, rec, wall0):
        limit = getattr(self, "_wall_limit", None)
        if limit is None or _time.perf_counter() - wall0 <= limit:
            return
        rec.output(self, final=True)
        self._log_into(rec)
        rec.close()
        result = self._with_log(rec.result(self, _time.perf_counter() - wall0,
                                           status="wall-time limit"))
        raise WallTimeExceeded(
            f"the run passed its wall-time limit of {limit:g} s at t = {self.time:.10g} "
            f"(step {self.steps}); the result up to here is kept on .result and the "
            f"simulation was left there", time=self.time, step=self.steps, result=result)

    def _advance(self, n, rec, wall0, dt=None):
        dt = self._step if dt is None else dt
        if self._in_loop:
            every, origin, plan = self._in_loop
            width = MONITOR_WIDTH + 6 * len(self._x)
        else:
            every, origin, width = self.monitor_every or 0, 0, MONITOR_WIDTH
        left = n
        while True:
            mon = self._mon(every)   # anew: a collision may have changed the bodies
            s0 = self.steps - origin
            if every > 0:
                first = (s0 // every + 1) * every  # next step index that records
                size = max(0, (s0 + left - first) // every + 1)
                mon_t = np.empty(size)
            elif every < 0:
                # the steps (from this call's start) after which the loop records
                ahead = plan.marks_between(s0, s0 + left) - s0
                size = len(ahead)
                mon_t = ahead.astype(float)
            else:
                size = 0
                mon_t = np.empty(0)
            # outputs are written straight where the recorder keeps them
            mon_out = (rec.row_buffer(size) if self._in_loop and size
                       else np.zeros((size, width)))
            with self._compile_clock.loop():
                status, steps, n_mon, self._ws = advance_checked(
                    self.integrator, self._ws, self._rows_x, self._rows_v, self._now(), dt, left,
                    self._force, self._fargs, mon, s0, mon_t, mon_out, stop=self._stop)
            if n_mon and self._in_loop:
                # the outputs' steps, and their times as _now() gives them there
                if every > 0:
                    ahead = (first - s0) + every * np.arange(n_mon)
                else:
                    ahead = ahead[:n_mon]
                rec.output_rows(self, self.steps + ahead,
                                self._t_base + (self._steps_since_base + self._sign * ahead)
                                * self._dt, _filled(mon, mon_out[:n_mon]))
            elif n_mon:
                rec.monitor_rows(mon_t[:n_mon], self._offset_rows(mon_out[:n_mon]))
            resolve = status == Status.COLLISION and self._resolves_collisions
            if status != Status.RENORMALISE and status != Status.LOG_FULL and not resolve:
                break
            # the chaos indicators' tangent vector grew large, the encounter
            # log filled, or bodies collided: scaled back, emptied or
            # resolved, the rest of the chunk goes on
            lag, grid = self._count_stopped(steps, dt)
            if status == Status.RENORMALISE:
                self._renormalise()
            elif resolve:
                self._resolve_collisions(rec, wall0)
                if lag:
                    # resolved where the loop left the bodies, before the step
                    # count: the survivors are carried up to it
                    self._advance(1, rec, wall0, dt=lag)
                    self._t_base, self._steps_since_base = grid
            else:
                self._log_full(rec, wall0)
            left -= steps
            if left == 0:
                return
        if status != Status.OK:
            self._count_stopped(steps, dt)
            self._fail(status, rec, wall0)
        self._count(left, dt)

    def _count_stopped(self, steps, dt):
        """Count the ``steps`` of a loop that stopped early; where the integrator
        left the state before them (:meth:`~orbits.integrators.base.Integrator.behind`:
        a step it could not finish), the clock goes back to it.  Returns that
        lag and the clock at the steps' end, ``(t_base, steps_since_base)``."""
        self._count(steps, dt)
        grid = (self._t_base, self._steps_since_base)
        lag = self.integrator.behind(self._ws)
        if lag:
            self._t_base = self._now() - lag
            self._steps_since_base = 0
        return lag, grid

    def _log_full(self, rec, wall0):
        # the loop handed back a full encounter log: emptied (an owner with
        # one finishes a check that the log cut short, orbits.Simulation)
        self._drain_log(rec)

    def _count(self, n, dt):
        if n == 0:
            return
        if dt == self._step:
            self._steps_since_base += self._sign * n
        else:
            self._t_base = self._now() + dt
            self._steps_since_base = 0
        self.steps += n
        self.force_evaluations += n * self.integrator.forces_per_step


class _ProgressBar:
    """A tqdm bar that appears only for long runs (or always, or never)."""

    def __init__(self, total, progress, unit="step"):
        self.total = total
        self.unit = unit
        if progress is None and not _stderr_is_terminal():
            progress = False  # a log file gets no bar
        self.progress = progress
        self.done = 0
        self.start = _time.perf_counter()
        self.bar = None
        if progress:
            self._open()

    def _open(self):
        self.bar = tqdm(total=self.total, initial=self.done, unit=self.unit, unit_scale=True,
                        leave=False, desc="orbits")

    def update(self, n):
        self.done += n
        if self.bar is not None:
            self.bar.update(n)
        elif (self.progress is None
              and _time.perf_counter() - self.start > PROGRESS_DELAY):
            self._open()

    def close(self):
        if self.bar is not None:
            self.bar.close()


def _stderr_is_terminal():
    try:
        return sys.stderr.isatty()
    except (AttributeError, ValueError):
        return False
