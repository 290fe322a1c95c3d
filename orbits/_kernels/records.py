"""The records the compiled loops take: named tuples of arrays and numbers.

A loop's arguments are the state it advances (positions, velocities, the
time and the step or the time to reach), the force's arguments, the check
pointer of the stopping conditions (:func:`.stopping.stop_record`: a pointer
travels as an argument of its own, see :class:`._jit.Pointer`) and records:

* :class:`Outputs`: what the loop records after its steps and where, the
  monitors' settings (:class:`Monitors`) among them;
* :class:`Checks`: how often a fixed-step loop checks that the state is
  finite, and the stopping conditions as data;
* :class:`Landing`: where an adaptive loop stops (the time to reach, the
  output times to land on, the most steps a call takes, the shortest step);
* :class:`Tolerances`: an error-controlled loop's ``rtol`` and ``atol``;
* the integrator's workspace, a record of its kernel module (``Work`` of
  :mod:`.ias15`, :mod:`.taylor`, :mod:`.embedded`, ...).

numba types a named tuple by its fields' types and reads a field by name as
it reads a tuple's item by index, so a record costs nothing in the loop;
called from Python, each field is typed on entry (about a microsecond for
an array), once a call.
"""

from typing import NamedTuple

import numpy as np

__all__ = ["Monitors", "MonitorsWithTerms", "Outputs", "Checks", "Landing", "monitors",
           "outputs", "checks", "landing", "work", "Tolerances", "NO_MARKS", "NO_MARK_STEPS"]

#: an adaptive loop's marks when it records no outputs on the way
NO_MARKS = np.empty(0)
NO_MARK_STEPS = np.empty(0, dtype=np.int64)


class Monitors(NamedTuple):
    """The monitors' settings: a row every ``every`` steps (0: none, -1: at
    the steps the output times name) of the quantities in the bit set
    ``which`` (:mod:`.invariants`) for bodies of masses ``masses`` under
    ``G``, the first ``n_active`` massive, with softening ``eps2``."""
    every: int
    which: int
    masses: np.ndarray
    G: float
    n_active: int
    eps2: float


MonitorsWithTerms = NamedTuple("MonitorsWithTerms",
                               [*Monitors.__annotations__.items(), ("terms", tuple)])
MonitorsWithTerms.__doc__ = """:class:`Monitors` with the energy arguments of the force
terms (:func:`.stepping.with_terms`), whose potential the energy includes."""


class Outputs(NamedTuple):
    """Where a loop records: the monitors' settings, the step count at the
    call's start (outputs fall on whole multiples of ``every`` counted from
    the simulation's start), the rows' times and the rows."""
    monitors: tuple
    first_step: int
    times: np.ndarray
    rows: np.ndarray


class Checks(NamedTuple):
    """How a fixed-step loop checks its state: finite every ``every`` steps
    and after the last, and the stopping conditions ``conditions``
    (:mod:`.stopping`) after each."""
    every: int
    conditions: tuple


class Landing(NamedTuple):
    """Where an adaptive loop stops: at ``t_end`` exactly, landing on each
    output time of ``marks`` on the way (its step count into
    ``mark_steps``), or after ``max_steps`` accepted steps; no step shorter
    than ``min_dt`` (0: any)."""
    t_end: float
    max_steps: int
    min_dt: float
    marks: np.ndarray
    mark_steps: np.ndarray


class Tolerances(NamedTuple):
    """An error-controlled loop's tolerances: a component's error is
    measured against ``atol + rtol * |y|``."""
    rtol: float
    atol: float


def monitors(mon):
    """``mon`` as a :class:`Monitors` record (or :class:`MonitorsWithTerms`
    for seven items), its numbers of the types the loops are compiled for:
    one compiled loop serves every caller."""
    if isinstance(mon, (Monitors, MonitorsWithTerms)):
        return mon
    if len(mon) not in (6, 7):
        raise ValueError(f"the monitors' settings have 6 or 7 items (with the terms' energy "
                         f"arguments), not {len(mon)}")
    every, which, masses, G, n_active, eps2 = mon[:6]
    head = (int(every), int(which), masses, float(G), int(n_active), float(eps2))
    if len(mon) == 7:
        return MonitorsWithTerms(*head, mon[6])
    return Monitors(*head)


def outputs(mon, step0, mon_t, mon_out):
    """The :class:`Outputs` record of the loops' Python callers' arguments."""
    return Outputs(monitors(mon), int(step0), mon_t, mon_out)


def checks(check_every, sargs):
    """The :class:`Checks` record."""
    return Checks(int(check_every), sargs)


def landing(t_end, max_steps, min_dt=0.0, marks=NO_MARKS, mark_steps=NO_MARK_STEPS):
    """The :class:`Landing` record."""
    return Landing(float(t_end), int(max_steps), float(min_dt), marks, mark_steps)


def work(record, ws):
    """The workspace record of type ``record`` (a named tuple whose fields
    are keys of the workspace dict ``ws``) over ``ws``'s arrays."""
    return record._make([ws[name] for name in record._fields])
