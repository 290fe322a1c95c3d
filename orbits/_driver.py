"""Advancing an integrator with the guarantee that a failure loses nothing."""

import copy

import numpy as np

from ._kernels.status import Status

__all__ = ["advance_checked", "MONITOR_OFF"]

MONITOR_OFF_ROWS = (np.empty(0), np.zeros((0, 10)))


def advance_checked(integ, ws, x, v, t, dt, n, force, fargs, mon, step0, mon_t, mon_out,
                    velocity_dependent=False):
    """Advance ``n`` steps; on failure, leave ``x``, ``v`` at the last good state.

    Returns ``(status, good_steps, n_monitor_rows, ws)``; ``ws`` is the
    workspace to keep (a restored copy after a failure).  The compiled loops
    are deterministic, so the last good state is recomputed from a copy taken
    here rather than saved by the loop every step.
    """
    saved = (x.copy(), v.copy(), copy.deepcopy(ws))
    status, steps, n_mon = integ.advance(ws, x, v, t, dt, n, force, fargs, mon, step0,
                                         mon_t, mon_out, velocity_dependent)
    if status == Status.OK:
        return Status.OK, n, n_mon, ws
    x[...] = saved[0]
    v[...] = saved[1]
    ws = saved[2]
    if steps:
        off = (0,) + tuple(mon[1:])
        integ.advance(ws, x, v, t, dt, steps, force, fargs, off, step0, *MONITOR_OFF_ROWS,
                      velocity_dependent)
    return Status(status), steps, n_mon, ws
