"""A simulation's monitors: the names asked for, checked and made into the
compiled loops' mask and arguments; a row of their values now, with what the
loops keep beside the bodies (the work of non-conservative force terms, the
chaos indicators, what resolved collisions took out); and the values at the
start, to which their errors are relative.

The monitors themselves (what each measures, its columns) are
:mod:`orbits.monitors`; their kernels :mod:`orbits._kernels.invariants`.
"""

import numpy as np

from ._kernels import invariants as _inv
from ._kernels import stepping as _stepping
from ._kernels import variational as _var
from .monitors import monitor_mask

__all__ = ["set_up", "take_references", "row", "loop_args", "has_work"]


def set_up(sim, monitors, monitor_every):
    """``sim.monitors`` (a tuple of names), its mask, and ``monitor_every`` (None:
    at outputs only; else a whole number of steps >= 1)."""
    if isinstance(monitors, str):
        raise ValueError(f"monitors must be a list of monitor names, got the string "
                         f"{monitors!r}; write monitors=[{monitors!r}]")
    sim.monitors = tuple(monitors)
    sim._mask = monitor_mask(sim.monitors)
    if monitor_every is not None and (int(monitor_every) != monitor_every
                                      or monitor_every < 1):
        raise ValueError(f"monitor_every must be a whole number of steps >= 1, "
                         f"got {monitor_every}")
    sim.monitor_every = None if monitor_every is None else int(monitor_every)


def take_references(sim):
    """The monitors' values at the start (only those asked for: the energy of a
    large N costs O(N^2)), and the scales of the energy and the angular
    momentum for the errors of values near zero."""
    sim._reference = row(sim, np.zeros(_inv.MONITOR_WIDTH))
    sim._E_scale = 0.5 * float(np.sum(sim._m * np.sum(sim._v ** 2, axis=1))) or 1.0
    sim._L_scale = float(np.sum(sim._m * np.linalg.norm(sim._x, axis=1)
                                * np.linalg.norm(sim._v, axis=1))) or 1.0


def row(sim, out):
    """``out`` (shape (MONITOR_WIDTH,)) filled with the monitors' values now."""
    _inv.monitor_row(sim._x, sim._v, sim._m, sim.units.G, sim._n_active, sim._eps2,
                     sim._mask, out)
    # (an integrator that takes terms as data holds an empty table without them)
    if sim._terms and sim._mask & _inv.ENERGY:
        out[0] += sim._base_force.terms.energy(sim._x, sim._v, sim._eargs)
        out[_inv.WORK_COLUMN] = _stepping.work_total(sim._ws)
    if sim._chaos_box is not None:
        col = _inv.MONITOR_COLUMNS.index("megno")
        out[col:col + 3] = _var.chaos_values(sim._ws["chaos"])
    sim._offset_rows(out[None])
    return out


def loop_args(sim, every):
    """The monitors' arguments of the compiled loops, rows every ``every`` steps;
    with force terms, their energy arguments too
    (:func:`orbits._kernels.stepping.with_terms`)."""
    mon = (every, sim._mask, sim._m, sim.units.G, sim._n_active, sim._eps2)
    return mon if sim._eargs is None else mon + (sim._eargs,)


def has_work(sim):
    """Whether the energy monitor carries a work column: non-conservative force
    terms, whose work the loops integrate, or collisions that take energy out
    of the bodies."""
    return sim._base_force.dissipative or sim._resolves_collisions
