"""Stopping conditions' set-up: the keywords of :class:`~orbits.Simulation`
that stop a run (close encounters, escapes, collisions) or log it without
stopping (the encounter log), checked and turned into the record that the
compiled loops read (:mod:`orbits._kernels.stopping`); and the encounter log's
table, emptied and enlarged between the loop's calls.
"""

import math
import numbers

import astropy.units as u
import numpy as np

from . import collisions as _collisions
from ._kernels import stopping as _s
from ._kernels.status import Status
from .errors import BodyError, IntegratorOptionError, SimulationOptionError

__all__ = ["set_up", "keywords", "keeps_previous", "keep_current", "drain_log", "log_step",
           "log_full", "encounter_table"]


def set_up(sim, distance, hill, escape, unbound, collisions, log, restitution, log_rows):
    mask = 0
    d2 = esc2 = 0.0
    k = 0.0
    if distance is not None:
        mask |= _s.ENCOUNTER_DISTANCE
        d = _positive_length(sim, distance, "encounter_distance")
        d2 = d * d
    if hill is not None:
        k = float(hill)
        if not (k > 0 and math.isfinite(k)):
            raise ValueError(f"encounter_hill must be a positive number of Hill radii, "
                             f"got {hill}")
        mask |= _s.ENCOUNTER_HILL
    if escape is not None:
        mask |= _s.ESCAPE
        e = _positive_length(sim, escape, "escape_distance")
        esc2 = e * e
    if unbound:
        if escape is None:
            raise ValueError("escape_unbound needs escape_distance (the radius beyond "
                             "which an unbound body counts as escaped)")
        mask |= _s.UNBOUND
    if collisions is not None:
        _check_collisions(sim, collisions)
        mask |= _s.COLLISION
    if restitution is not None:
        if collisions is None or collisions in ("halt", "merge"):
            raise SimulationOptionError(
                f"restitution={restitution!r} is for collisions='bounce' (or a "
                f"collisions function), not collisions={collisions!r}")
        ok = (isinstance(restitution, numbers.Real) and not isinstance(restitution, bool)
              and 0.0 <= float(restitution) <= 1.0)
        if not ok:
            raise SimulationOptionError(f"restitution must be a number from 0 to 1 "
                                        f"(1: elastic), got {restitution!r}")
        restitution = float(restitution)
    log_hill = log_distance = 0.0
    if log is not None:
        mask |= _s.ENCOUNTER_LOG
        if isinstance(log, u.Quantity):
            log_distance = _positive_length(sim, log, "encounter_log")
        else:
            log_hill = float(log)
            if not (log_hill > 0 and math.isfinite(log_hill)):
                raise SimulationOptionError(
                    f"encounter_log must be a positive number of mutual Hill radii or "
                    f"a length, got {log!r}")
    sim._stop_config = {"encounter_distance": d if distance is not None else None,
                         "encounter_hill": k or None,
                         "escape_distance": e if escape is not None else None,
                         "escape_unbound": bool(unbound),
                         "collisions": collisions,
                         "restitution": restitution,
                         "encounter_log": (log_distance or None, log_hill or None)}
    n = len(sim._m)
    # the encounter log's rows (emptied by the driver, enlarged when a
    # step has more approaches than they hold), and its count and where a
    # look that filled it stopped
    sim._log = np.zeros((log_rows if mask & _s.ENCOUNTER_LOG else 0, 5))
    sim._log_n = np.zeros(3, dtype=np.int64)
    sim._encounters = []
    # the state of the previous check and its time (for looking inside a
    # step): the start, so that the first step is looked inside too;
    # scratch, and where a collision or an encounter was found
    sim._stop_clock = np.array([0.0, 1.0])
    sim._stop_hit = np.zeros(3)
    if not mask:
        return None
    checked = sim.integrator.stop_conditions
    if not checked:
        what = "collisions" if collisions is not None else "stopping conditions"
        raise IntegratorOptionError(f"integrator {sim.integrator.name!r} does not check "
                                    f"{what}; use 'ias15' or another method that does")
    if checked is not True:
        given = {"encounter_distance": distance, "encounter_hill": hill,
                 "escape_distance": escape, "escape_unbound": unbound or None,
                 "collisions": collisions, "encounter_log": log}
        refused = [k for k, value in given.items() if value is not None and k not in checked]
        if refused:
            raise IntegratorOptionError(
                f"integrator {sim.integrator.name!r} checks only {', '.join(checked)}, "
                f"not {', '.join(refused)}; use 'ias15' or another method that does")
    central = int(np.argmax(sim._m))
    return (mask, d2, k, esc2, sim._gm, central, sim._stop_info, sim._r,
            np.stack([sim._x, sim._v]), sim._stop_clock, np.zeros((4, 3)),
            sim._stop_hit, log_hill, log_distance, sim._log, sim._log_n)


def keywords(sim):
    """The stopping conditions as the keyword arguments that set them
    (Quantities; :attr:`Simulation.stop_conditions`)."""
    c = sim._stop_config
    q = lambda val: None if val is None else sim.units.quantity(val, "length")  # noqa: E731
    return {"encounter_distance": q(c["encounter_distance"]),
            "encounter_hill": c["encounter_hill"],
            "escape_distance": q(c["escape_distance"]),
            "escape_unbound": c["escape_unbound"],
            "collisions": c["collisions"],
            "restitution": c.get("restitution"),
            "encounter_log": (q(c["encounter_log"][0]) if c["encounter_log"][0]
                              else c["encounter_log"][1])}


def keeps_previous(sim):
    # the stopping conditions keep the state of the step before
    # (collisions, encounters, the encounter log)
    return sim._stop is not None and bool(sim._stop[0] & _s.LOOKS_INSIDE)


def keep_current(sim):
    """The current state as the one the conditions' next look inside a
    step starts from (the state was set from outside)."""
    if sim._stop is not None:
        sim._stop[8][0] = sim._x
        sim._stop[8][1] = sim._v
        sim._stop_clock[:] = (sim._now(), 1.0)


def drain_log(sim, rec=None):
    """Move the encounter log's rows from the loop's buffer into the run's
    list, and into ``rec``'s file if it keeps one."""
    k = int(sim._log_n[0])
    if k:
        name = lambda i: sim._names[sim._order[int(i)]]  # noqa: E731
        rows = [(float(t), name(j), name(i), float(dist), float(speed))
                for t, j, i, dist, speed in sim._log[:k]]
        sim._encounters.extend(rows)
        sim._log_n[0] = 0
        keep = getattr(rec, "encounter_rows", None)
        if keep is not None:
            keep(sim, rows)


def log_step(sim, x, v, t, rec=None):
    """The encounter log's look at the step that ended at ``t`` with state
    ``x``, ``v`` (a look the loop did not take), emptying and enlarging the
    table as it fills."""
    if not sim._stop[0] & _s.ENCOUNTER_LOG:
        return
    while _s.encounter_log(x, v, t, sim._stop):
        drain_log(sim, rec)
        if not sim._log_n[1]:
            break
        _grow_log(sim)


def log_full(sim, rec, wall0):
    """The loop handed the encounter log back (``Status.LOG_FULL``): its rows
    go into the run's list; if it filled inside a step, it is enlarged and
    the loop's check of that step is finished (the log's look from where it
    stopped, then the other conditions, which may stop the run)."""
    drain_log(sim, rec)
    if not sim._log_n[1]:
        return
    sim.integrator.synchronize(sim._ws, sim._rows_x, sim._rows_v)
    t = sim._now()
    x, v, t = sim.integrator.checked_state(sim._ws, t) or (sim._x, sim._v, t)
    status = Status.LOG_FULL
    while status == Status.LOG_FULL and sim._log_n[1]:
        _grow_log(sim)
        status = _s.check_stop(x, v, t, sim._stop)
        drain_log(sim, rec)
    if status not in (0, Status.LOG_FULL):
        sim._fail(Status(status), rec, wall0)


def encounter_table(sim):
    """What makes ``result.encounters``, an astropy QTable of the approaches
    logged so far (None without ``encounter_log``): a function of no
    arguments, called where the field is first read (astropy.table's import
    takes 0.24-0.5 s a process)."""
    if sim._stop_config.get("encounter_log", (None, None)) == (None, None):
        return None
    rows = list(sim._encounters)
    units = sim.units

    def make():
        from astropy.table import QTable
        q = units.quantity
        col = lambda k: [r[k] for r in rows]  # noqa: E731
        return QTable({"time": q(np.array(col(0), dtype=float), "time"),
                       "body_1": np.array(col(1), dtype=str),
                       "body_2": np.array(col(2), dtype=str),
                       "distance": q(np.array(col(3), dtype=float), "length"),
                       "speed": q(np.array(col(4), dtype=float), "length") / units.time})
    return make


def _grow_log(sim):
    """A log table twice as long (a step had more approaches than it held)."""
    sim._log = np.zeros((max(2 * len(sim._log), 1), 5))
    sim._stop = sim._stop[:14] + (sim._log,) + sim._stop[15:]


def _positive_length(sim, value, field):
    d = float(sim.units.to_internal(value, "length", bare_ok=sim._bare_ok, field=field))
    if not (d > 0 and math.isfinite(d)):
        raise ValueError(f"{field} must be a positive length, got {value}")
    return d


def _check_collisions(sim, collisions):
    if not (callable(collisions) or (isinstance(collisions, str)
                                     and collisions in _collisions.RESOLUTIONS)):
        raise SimulationOptionError(
            f"collisions={collisions!r} is not a resolution; expected one of "
            f"{', '.join(map(repr, _collisions.RESOLUTIONS))} or a function")
    r = sim._r
    if not np.any(r > 0):
        raise BodyError("collisions need sizes: give the bodies that can collide a "
                        "radius (BodySet.add(..., radius=...))", field="radius")
    x = sim._x
    if getattr(sim, "_touching_ok", False):
        return   # bodies after a collision step, which may still touch
    for i in range(1, len(r)):
        d = np.sqrt(((x[:i] - x[i]) ** 2).sum(axis=1))
        touch = np.flatnonzero(d < r[:i] + r[i])
        if touch.size and collisions == "merge":
            # what the user asked for: they merge at the start (__init__'s end)
            sim._merge_at_start = True
            return
        if touch.size:
            j = int(touch[0])
            raise BodyError(f"{sim._names[sim._order[j]]!r} and "
                            f"{sim._names[sim._order[i]]!r} touch at the start "
                            f"(separation {d[j]:.6g} < radii {r[j] + r[i]:.6g}"
                            f"{f' {sim.units.length}' if str(sim.units.length) else ''}"
                            f"); with collisions={collisions!r} the "
                            f"bodies must start apart (collisions='merge' merges them "
                            f"at the start)", body=sim._names[sim._order[i]],
                            field="radius")
