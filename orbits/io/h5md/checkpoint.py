"""Checkpoints and restart: a file's last checkpoint read back
(:func:`read_checkpoint`, from which :meth:`orbits.Simulation.from_file`
rebuilds a simulation), and a file cut back to it before a run resumes
(:func:`truncate`).  Files written before the configuration record was kept
give the same record from the attributes they have.
"""

import json
import os
import pathlib
from typing import NamedTuple

import numpy as np

from ...bodies import BodySet
from ...errors import OrbitsError
from ...records import RunPlan, SimulationState
from .checks import _check_config, _damaged, _epoch, _open_read, _unit_system
from .disk import _METADATA_BYTES, _close_written, _descriptor, _new_file, _reserve, _trim
from .errors import (OrbitsFileError, TangentShapeError, _DISK_FULL, _error_number,
                     _write_error)
from .layout import _SLOTS, _config_layout, _decode, _radii, _read_box
from .lock import _acquire, _release
from .reader import _rows
from .safety import _covered

__all__ = ["Checkpoint", "ResumePoint", "read_checkpoint", "truncate"]

class Checkpoint(NamedTuple):
    """What a file's last checkpoint rebuilds a simulation from
    (:meth:`orbits.Simulation.from_file`).

    Examples
    --------
    >>> from orbits.io import h5md
    >>> cp = h5md.read_checkpoint(run_file)
    >>> cp.bodies.names, cp.config["integrator"], cp.state.steps
    (['Star', 'Planet'], 'leapfrog', 10)
    """

    bodies: object          # the BodySet at the checkpoint (its epoch: the date there)
    config: dict            # SimulationConfig.to_dict() of the simulation
    state: SimulationState  # put back with Simulation.set_state
    point: object           # the ResumePoint: where the run that wrote the file stood
    path: str
    epoch: object = None    # astropy Time (TDB) of the simulation's time 0, or None


@_damaged
def read_checkpoint(path):
    """The file's last complete checkpoint, as a :class:`Checkpoint`;
    :class:`OrbitsFileError` for a file that is damaged or holds none.

    Parameters
    ----------
    path : str or path-like

    Returns
    -------
    Checkpoint

    Examples
    --------
    >>> from orbits.io import h5md
    >>> cp = h5md.read_checkpoint(run_file)
    >>> cp.point.finished, cp.point.time            # time in the file's unit (days)
    (True, 10.0)
    """

    with _open_read(path) as f:
        count = int(f["restart/count"][()])
        if count == 0:
            raise OrbitsFileError(f"{path}: holds no complete checkpoint to restore from")
        slot = (count - 1) % _SLOTS
        par = f["parameters"]
        r = f["restart"]
        units = _unit_system(par, path)
        order = r["order"][()]
        inv = np.argsort(order)
        names = _decode(f["particles/bodies/names"][()])
        m = f["particles/bodies/mass"][()]
        radii, _ = _radii(f["particles/bodies"])
        n0 = len(names)
        x = r["x"][slot]
        v = r["v"][slot]
        if "masses" in r:
            # the bodies at this checkpoint: those of the start that collisions left
            m = r["masses"][slot]
            alive = np.isfinite(m)
            n = int(alive.sum())
            names = [name for name, keep in zip(names, alive) if keep]
            m, radii = m[alive], r["radii"][slot][alive]
            order = r["orders"][slot][:n]
            inv = np.argsort(order)
            x, v = x[:n], v[:n]
        try:
            bodies = BodySet.from_arrays(m, x[inv], v[inv], names=names, units=units,
                                         radii=radii)
        except OrbitsError as exc:
            raise OrbitsFileError(f"{path}: the bodies at its last checkpoint are not a body "
                                  f"set: {exc}") from None
        bodies.history = json.loads(par.attrs["bodies_history"])
        epoch = _epoch(par, path)
        if "config" in par.attrs:
            config = json.loads(par.attrs["config"])
        else:
            config = _legacy_config(par, units, path)
            _check_config(config, path, config["monitors"])
        _check_tangent_rows(r["ws"], config, len(names), path)
        clock = r["clock"][slot]
        state = SimulationState(
            x, v, order, float(r["t_base"][slot]), int(clock[1]), int(clock[0]),
            int(clock[2]), int(clock[4]),
            {name: _read_box(r["ws"][name], slot, len(names), n0) for name in r["ws"]},
            par["reference"][()], tuple(par["scales"][()]))
        p = r["plan"][slot]
        plan = RunPlan(float(p[0]), int(p[1]), float(p[2]), int(p[3]), bool(p[4]), int(p[5]),
                       float(p[6]))
        written, finished, _ = (int(a) for a in r["progress"][slot])
        rows = int(clock[3])
        held = _rows(f, json.loads(par.attrs["monitors"]))
        if rows > held:
            raise OrbitsFileError(f"{path}: /restart/clock at the last checkpoint counts "
                                  f"{rows} output rows, but the file holds {held}; the "
                                  f"checkpoint does not belong to these outputs")
        t = state.t_base + state.steps_since_base * float(par.attrs["dt"])
        if epoch is not None:
            bodies.epoch = epoch + units.quantity(t, "time")
    return Checkpoint(bodies, config, state, ResumePoint(plan, written, bool(finished), rows, t),
                      str(path), epoch)


def _check_tangent_rows(ws, config, n, path):
    """Raise :class:`TangentShapeError` where the checkpoints' tangent rows
    (``ws/tangent``: positions and velocities of every tangent vector, after
    the bodies' rows) do not have the shape the configuration calls for."""
    k = sum(_config_layout(config, n))
    want = (2, n * k, 3) if k else None
    found = ws["tangent"].shape[1:] if "tangent" in ws else None
    if found != want:
        what = ("no tangent rows" if found is None else
                f"tangent rows of shape {found}" + (f" ({found[1] / n:g} vectors of {n} bodies)"
                                                     if len(found) == 3 else ""))
        raise TangentShapeError(
            f"{path}: its checkpoints hold {what}, but its configuration (variations="
            f"{config.get('variations')!r}, monitors {', '.join(config['monitors']) or 'none'}"
            f") calls for " + (f"{k} tangent vectors, rows of shape {want}" if k else "none")
            + "; the file cannot restore the simulation", expected=want, found=found)


def _legacy_config(par, units, path):
    # files written before the configuration record: the same record, from the
    # attributes they have
    try:
        return _legacy_record(par, units)
    except (KeyError, TypeError, ValueError, IndexError, AttributeError) as exc:
        raise OrbitsFileError(f"{path}: the attributes of /parameters do not make a "
                              f"configuration ({type(exc).__name__}: {exc})") from None


def _legacy_record(par, units):
    soft = float(par.attrs["softening"])
    unit = lambda val, kind: None if val is None else [val, units.unit(kind).to_string()]  # noqa: E731
    stop = json.loads(par.attrs["stop_conditions"])
    dt = float(par.attrs["dt"])
    adaptive = json.loads(par.attrs.get("integrator_info", "{}")).get("adaptive", dt == 0)
    return {"integrator": par.attrs["integrator"],
            "integrator_options": json.loads(par.attrs["integrator_options"]),
            "dt": unit(dt, "time") if dt > 0 or not adaptive else None,
            "forces": [{"type": "Gravity",
                        "softening": unit(soft, "length") if soft > 0 else None,
                        "parallel": bool(par.attrs["parallel"]),
                        "rebound_arithmetic": bool(par.attrs.get("rebound_arithmetic", False))}],
            "monitors": json.loads(par.attrs["monitors"]),
            "monitor_every": int(par.attrs["monitor_every"]) or None,
            "stop_conditions": {
                "encounter_distance": unit(stop["encounter_distance"], "length"),
                "encounter_hill": stop["encounter_hill"],
                "escape_distance": unit(stop["escape_distance"], "length"),
                "escape_unbound": stop["escape_unbound"],
                "collisions": stop.get("collisions"),
                "encounter_log": _encounter_log_option(stop.get("encounter_log"), unit)}}


def _encounter_log_option(value, unit):
    # (distance or None, Hill radii or None) as written -> the keyword's value
    if not value:
        return None
    distance, hill = value
    return unit(distance, "length") if distance else hill


class ResumePoint(NamedTuple):
    """Where a restored simulation stands in the run its file was written by.

    Examples
    --------
    >>> from orbits.io import h5md
    >>> point = h5md.read_checkpoint(run_file).point
    >>> point.outputs_written, point.rows, point.finished, point.plan.until
    (3, 3, True, 10.0)
    """

    plan: object            # the RunPlan of that run
    outputs_written: int    # of that run, at the checkpoint
    finished: bool
    rows: int               # output rows in the file at the checkpoint
    time: float             # simulation time at the checkpoint


def truncate(path, point):
    """Drop what was written after the checkpoint ``point`` (a :class:`ResumePoint`).

    The file is copied (into ``<path>.resume``, made exclusively, with room
    for the whole copy reserved first), which also leaves a file whose writer
    was killed clean for writing again.  The writers' lock is taken first
    (:class:`FileInUse` if a live process holds it) and kept for the
    :class:`FileRecorder` that writes on, which releases it when it closes.

    Parameters
    ----------
    path : str or path-like
    point : ResumePoint
        Rows after ``point.rows``, and in-loop monitor rows after
        ``point.time`` (in the file's unit of time), are dropped.

    Raises
    ------
    FileInUse
        Another live process is writing the file.
    OrbitsFileError
        ``path`` is a symbolic link, is damaged, or the disk has no room for
        the copy (the message says which); the file is then as it was, and
        neither the copy nor the lock is left behind.

    Examples
    --------
    >>> from orbits.io import h5md
    >>> point = h5md.read_checkpoint(run_file).point
    >>> h5md.truncate(run_file, point._replace(rows=1, time=0.0))   # back to the first output
    >>> orbits.load(run_file).times
    <Quantity [0.] d>
    """
    if os.path.islink(path):
        raise OrbitsFileError(f"{path}: a symbolic link (to {os.readlink(path)}); resume the "
                              f"file it names, so that the copy resuming makes does not "
                              f"replace the link")
    _acquire(path)
    tmp = pathlib.Path(str(path) + ".resume")
    size = os.path.getsize(path)
    need = size + size // 8 + _METADATA_BYTES       # the copy, laid out anew, and HDF5's own
    dst = None
    try:
        with _open_read(path) as src:
            dst = _new_file(tmp)
            fd = _descriptor(dst)
            if fd is not None:
                # room for the whole copy first: a full disk stops it before it starts
                _reserve(fd, 0, need)
            for k, v in src.attrs.items():
                dst.attrs[k] = v
            for name in src:
                src.copy(src[name], dst, name=name)
            groups = [dst["particles/bodies/position"], dst["particles/bodies/velocity"]]
            groups += [dst["observables"][k] for k in dst["observables"] if k != "in_loop"]
            for g in groups:
                for ds in g.values():
                    ds.resize(min(ds.shape[0], point.rows), axis=0)
            for g in dst["observables/in_loop"].values():
                # only the rows stored (see safety._covered): a series declared longer holds no more
                keep = int(np.count_nonzero(g["time"][:_covered(g["time"])] <= point.time))
                for ds in g.values():
                    ds.resize(keep, axis=0)
        failed, dst = _close_written(dst), None
        if failed is not None:
            raise failed
        _trim(tmp)
        os.replace(tmp, path)
    except BaseException as exc:
        # the file as it was, and neither the copy nor the lock left behind
        if dst is not None:
            _close_written(dst)
        tmp.unlink(missing_ok=True)
        _release(path)
        if isinstance(exc, OrbitsError) or not isinstance(exc, (OSError, RuntimeError)):
            raise
        if _error_number(exc) in _DISK_FULL:
            raise _write_error(path, exc, f" when copying it to resume (resuming needs "
                                          f"about {need / 1e6:.3g} MB free beside it); the "
                                          f"file is unchanged") from None
        raise OrbitsFileError(f"{path}: damaged, or its copy cannot be written: resuming "
                              f"copies the file, and the copy failed ({exc}); the file is "
                              f"unchanged") from None
