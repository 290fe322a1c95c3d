"""Advancing an integrator with the guarantee that a failure loses nothing."""

import contextlib
import signal as _signal
import threading

import _signal as _csignal
import numpy as np

from ._kernels.status import Status
from ._kernels.stepping import USER_FORCE_SIZE
from .errors import ForceTermError

__all__ = ["advance_checked", "restored_on_error", "Signals", "CHECK_EVERY"]

#: The compiled loops test the state for NaN and inf every this many steps
#: (a test is a dependent chain of 6N additions, as dear as the force for a few
#: bodies); a failure is then located exactly by re-running from a copy.
CHECK_EVERY = 16


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
