"""Reading a file back: :func:`load` gives a :class:`~orbits.Result` of
Quantities, :func:`describe` the sentences ``orbits info`` prints, and
:func:`whole_run` the totals of every run that wrote a file.

A file whose writer was killed reads as the last flush left it; the readers
open it through :func:`~orbits.io.h5md.checks._open_read`, which checks it
first.
"""

import json

import astropy.units as u
import numpy as np

from ... import epochs as _epochs
from ... import forces
from ..._kernels.status import Status
from ...collisions import table
from ...errors import OrbitsError
from ..._monitor_specs import BY_NAME, WITH_ERROR, added_to
from ...result import Result
from ...units import UnitSystem, format_time, time_unit
from .checks import _damaged, _epoch, _log_rows, _open_read
from .errors import OrbitsFileError, TangentShapeError
from .layout import (FORMAT, FORMAT_VERSION, _COLLISION_COLUMNS, _ENCOUNTER_COLUMNS, _SLOTS,
                     _config, _config_layout, _decode, _radii, _series_errors)
from .lock import _writer
from .safety import _covered

__all__ = ["load", "describe", "whole_run"]

def _rows(f, monitors, in_loop=False):
    """Rows that every series of the outputs (or the in-loop monitors) holds: a
    reader of a live file may see one series extended before the next."""
    obs = f["observables/in_loop"] if in_loop else f["observables"]
    names = _kept(obs, monitors)
    if in_loop:
        groups = [obs[name] for name in names]
    else:
        b = f["particles/bodies"]
        groups = [b["position"], b["velocity"]] + [obs[name] for name in names]
        if "masses_at_outputs" in b:
            groups.append(b["masses_at_outputs"])
    # only the rows the file stores data for (see safety._covered)
    return min((_covered(g[k]) for g in groups for k in ("step", "time", "value")), default=0)


def _kept(group, monitors):
    """The series of ``monitors`` in ``group`` (``observables`` or its
    ``in_loop``): theirs, and those added to them (the work) where the file
    keeps them."""
    return list(monitors) + [s.name for name in monitors for s in added_to(name)
                             if s.name in group]


def _totals(f):
    """(steps, force evaluations, rejected steps, wall seconds) of the runs that wrote
    the file, at its last checkpoint; None for files from before they were kept."""
    r, par = f["restart"], f["parameters"]
    count = int(r["count"][()])
    if count == 0 or "wall" not in r or "start_clock" not in par:
        return None
    slot = (count - 1) % _SLOTS
    clock = r["clock"][slot]
    start = par["start_clock"][()]
    return (int(clock[0] - start[0]), int(clock[2] - start[1]), int(clock[4] - start[2]),
            float(r["wall"][slot]))


@_damaged
def whole_run(path):
    """What a summary of every run that wrote a file needs, without its outputs:
    the fields of :class:`~orbits.Result` that :func:`load` gives for the
    whole file, for a result that holds only a last output (from
    :meth:`orbits.Simulation.resume` or a run continued into the file).

    Parameters
    ----------
    path : str or path-like

    Returns
    -------
    dict
        ``steps``, ``force_evaluations``, ``steps_rejected`` and ``wall_time``
        (totals at the last checkpoint, as :func:`load` reads them),
        ``start_time`` (the first output's time, a Quantity), and
        ``largest_errors`` (the largest relative errors of the monitored
        invariants at every output and in-loop row); ``collisions`` and
        ``encounters`` where the file logs them.

    Examples
    --------
    >>> from orbits.io import h5md
    >>> last = sim.run(until=20 * u.day, outputs=3, output=run_file, progress=False)
    >>> whole = h5md.whole_run(run_file)
    >>> last.steps, last.start_time, whole["steps"], whole["start_time"]
    (10, <Quantity 10. d>, 20, <Quantity 0. d>)
    """

    with _open_read(path) as f:
        b, par, obs = f["particles/bodies"], f["parameters"], f["observables"]
        monitors = json.loads(par.attrs["monitors"])
        n = _rows(f, monitors)
        totals = _totals(f)
        if totals is None:
            step = b["position/step"]
            totals = (int(step[n - 1] - step[0]) if n else 0, None, 0, None)
        t = b["position/time"]
        fields = dict(zip(("steps", "force_evaluations", "steps_rejected", "wall_time"),
                          totals))
        if n:
            fields["start_time"] = float(t[0]) << u.Unit(t.attrs["unit"])
        ref = par["reference"][()]
        scales = par["scales"][()]
        m = _rows(f, monitors, in_loop=True)
        largest = {}
        for spec in WITH_ERROR:
            if spec.name not in monitors:
                continue
            errors = [_series_errors(group, spec.name, slice(0, rows), ref, scales)
                      for group, rows in ((obs, n), (obs["in_loop"], m)) if rows]
            if errors:
                largest[spec.name] = float(max(np.max(e) for e in errors))
        fields["largest_errors"] = largest
        if "encounters" in f:
            fields["encounters"] = _encounters(f["encounters"])
        if "masses" in f["restart"]:
            fields["collisions"] = _collisions(f.get("collisions"), par)
    return fields


@_damaged
def load(path):
    """Read an output file into a :class:`~orbits.Result` with Quantities.

    Works on a file whose writer was killed: it reads what the last flush left.
    ``steps``, ``force_evaluations``, ``steps_rejected`` and ``wall_time``
    are the totals of the runs that wrote the file, at its last checkpoint
    (None for force evaluations and wall time in files written before they
    were kept).  With variations or chaos monitors, ``jacobian`` and
    ``tangent_vectors`` are those at the last checkpoint too, which for a
    finished run is its last output, and ``seed`` the seed of the random
    tangent vectors.

    Parameters
    ----------
    path : str or path-like

    Returns
    -------
    Result
        Every output row, as Quantities in the file's units.

    Raises
    ------
    OrbitsFileError
        Not an orbits output, or damaged beyond reading.

    Examples
    --------
    >>> from orbits.io import h5md
    >>> result = orbits.load(run_file)
    >>> result.times, result.positions.unit, result.steps
    (<Quantity [ 0.,  5., 10.] d>, Unit("AU"), 10)
    """

    with _open_read(path) as f:
        b = f["particles/bodies"]
        par = f["parameters"]
        monitors = json.loads(par.attrs["monitors"])
        n = _rows(f, monitors)

        def q(ds, rows=n):
            return ds[:rows] << u.Unit(ds.attrs["unit"])

        totals = _totals(f)
        radii, radius_unit = _radii(b)
        if totals is None:
            step = b["position/step"]
            steps = int(step[n - 1] - step[0]) if n else 0
            totals = (steps, None, 0, None)
        fields = dict(
            times=q(b["position/time"]), positions=q(b["position/value"]),
            velocities=q(b["velocity/value"]), names=_decode(b["names"][()]),
            masses=b["mass"][()] << u.Unit(b["mass"].attrs["unit"]),
            radii=radii << u.Unit(radius_unit), steps=totals[0],
            force_evaluations=totals[1], steps_rejected=totals[2], wall_time=totals[3],
            integrator=json.loads(par.attrs["integrator_info"]),
            units=json.loads(par.attrs["units"]),
            dt=par.attrs["dt"] * u.Unit(par.attrs["dt_unit"]), monitors=tuple(monitors),
            status=_status(f, path), path=str(path), metadata=dict(par.attrs),
            epoch=_epoch(par, path))
        ref = par["reference"][()]
        scales = par["scales"][()]
        obs = f["observables"]
        fields.update(_monitor_series(obs, monitors, n, ref, scales))
        m = _rows(f, monitors, in_loop=True)
        if monitors and m:
            fields["monitor"] = {"times": q(obs["in_loop"][monitors[0]]["time"], m),
                                 **_monitor_series(obs["in_loop"], monitors, m, ref, scales)}
        fields.update(_derivatives(f, path))
        if "encounters" in f:
            fields["encounters"] = _encounters(f["encounters"])
        if "masses_at_outputs" in b:
            fields["masses_at_outputs"] = q(b["masses_at_outputs/value"])
        if "masses" in f["restart"]:
            fields["collisions"] = _collisions(f.get("collisions"), par)
    return Result(**fields)


def _collisions(g, par):
    """The collisions a run resolved (group ``collisions``; none yet: an
    empty table) as the QTable of ``Result.collisions``."""
    units = UnitSystem.from_dict(json.loads(par.attrs["units"]))
    if g is None:
        return table([], units)
    k = _log_rows(g, _COLLISION_COLUMNS)
    cols = [_decode(g[name][:k]) if kind == "str" else g[name][:k]
            for name, kind in _COLLISION_COLUMNS.items()]
    return table(list(zip(*cols)), units)


def _encounters(g):
    """The encounter log of a file (group ``encounters``) as the QTable of
    ``Result.encounters``."""
    # (astropy.table is imported where a table is made: 0.24 s a process)
    from astropy.table import QTable
    k = _log_rows(g, _ENCOUNTER_COLUMNS)
    col = lambda name: g[name][:k] << u.Unit(g[name].attrs["unit"])  # noqa: E731
    text = lambda name: np.array(_decode(g[name][:k]), dtype=str)  # noqa: E731
    return QTable({"time": col("time"), "body_1": text("body_1"), "body_2": text("body_2"),
                   "distance": col("distance"), "speed": col("speed")})


def _monitor_series(group, monitors, rows, reference, scales):
    """The first ``rows`` values of the series of ``monitors`` in ``group``
    (``observables`` or its ``in_loop``) and of those added to them, and the
    monitors' relative errors, as a result holds them (the fields of
    :func:`orbits.monitors.monitor_fields`)."""
    out = {}
    for name in _kept(group, monitors):
        out[name] = _series(group[name], name, rows)
    for spec in WITH_ERROR:
        if spec.name in monitors:
            out[spec.error_field] = _series_errors(group, spec.name, slice(0, rows),
                                                   reference, scales)
    return out


def _series(group, name, rows):
    """The first ``rows`` values of a monitor series, as a result holds them:
    Quantities, but dimensionless series (MEGNO, the FLI) as plain arrays."""
    values = group["value"][:rows]
    if BY_NAME[name].kind == "dimensionless":
        return values
    return values << u.Unit(group["value"].attrs["unit"])


def _jacobian(tangents, layout):
    """The Jacobian (6 N, 6 N) or (6 N, 7 N) that tangent vectors (k, N, 6)
    laid out as ``layout`` hold, as :attr:`orbits.Simulation.jacobian`; None
    without ``variations="state"`` or ``"all"``."""
    chaos, random, state, mass = layout
    if not state:
        return None
    n = tangents.shape[1]
    return tangents[chaos + random:].reshape(state + mass, 6 * n).T.copy()


def _derivatives(f, path):
    """``jacobian``, ``tangent_vectors`` and ``seed`` of a file with variations or
    chaos monitors, at its last checkpoint (the last output of a finished run),
    as a Result holds them; {} for a file without (or written before the
    derivatives were kept, or before its first checkpoint)."""
    config = _config(f)
    n = f["particles/bodies/names"].shape[0]
    layout = _config_layout(config, n)
    if not sum(layout):
        return {}
    out = {"seed": config.get("seed")}
    r = f["restart"]
    count = int(r["count"][()])
    if "tangent_vectors" not in r or not count:
        return out
    d = r["tangent_vectors"]
    want = (_SLOTS, sum(layout), n, 6)
    stored = tuple(int(k) for k in d.attrs.get("layout", layout))
    if d.shape != want or stored != tuple(layout):
        raise TangentShapeError(
            f"{path}: holds tangent vectors of shape {d.shape[1:]} (laid out as {stored}: "
            f"chaos, random, state, mass), but its configuration (variations="
            f"{config.get('variations')!r}, monitors {', '.join(config['monitors']) or 'none'}"
            f") calls for {want[1:]} (laid out as {tuple(layout)})",
            expected=want[1:], found=d.shape[1:])
    tangents = d[(count - 1) % _SLOTS]
    out.update(tangent_vectors=tangents, jacobian=_jacobian(tangents, layout))
    return out


def _status(f, path=None):
    count = int(f["restart/count"][()])
    finished = code = 0
    if count:
        _, finished, code = (int(a) for a in f["restart/progress"][(count - 1) % _SLOTS])
    if code:
        return {Status.NON_FINITE: "non-finite state", Status.CLOSE_ENCOUNTER:
                "close encounter", Status.ESCAPE: "escape",
                Status.STEP_UNDERFLOW: "step-size underflow",
                Status.NO_CONVERGENCE: "no convergence",
                Status.COLLISION: "collision"}.get(code, f"stopped ({code})")
    if finished:
        return "completed"
    rec, alive = _writer(path) if path is not None else (None, False)
    if rec is not None and alive is not False:
        who = f"process {rec.get('pid')}" + (f" on {rec.get('host')}" if alive is None
                                              else "")
        return f"running (being written by {who})"
    if count == 0:
        return "no checkpoint yet (the writer stopped early)"
    return "interrupted (resumable from the last checkpoint)"


def _read_ends(f, monitors):
    # the first and last rows of every series: what describe() says is there can be read
    n = _rows(f, monitors)
    groups = [f["particles/bodies/position"], f["particles/bodies/velocity"]]
    groups += [f["observables"][name] for name in monitors]
    for g in groups:
        for k in ("step", "time", "value"):
            if n:
                g[k][0]
                g[k][n - 1]
    count = int(f["restart/count"][()])
    if count:
        slot = (count - 1) % _SLOTS
        r = f["restart"]
        for name in ("x", "v", "clock", "t_base", "plan", "progress"):
            r[name][slot]
    return n


@_damaged
def describe(path):
    """A few sentences saying what an output file holds.

    Raises :class:`OrbitsFileError` for a damaged file, as :func:`load` does.

    Parameters
    ----------
    path : str or path-like

    Returns
    -------
    str

    Examples
    --------
    >>> from orbits.io import h5md
    >>> text = h5md.describe(run_file)
    >>> [line.split()[0] for line in text.splitlines()[1:4]]
    ['bodies', 'integrator', 'units']
    """
    with _open_read(path) as f:
        b = f["particles/bodies"]
        par = f["parameters"]
        names = _decode(b["names"][()])
        monitors = json.loads(par.attrs["monitors"])
        n_out = _read_ends(f, monitors)
        t = b["position/time"]
        tu = u.Unit(t.attrs["unit"])
        units = json.loads(par.attrs["units"])
        # times in the unit of the larger end of the outputs', so that they read alike
        ends = (t[0], t[n_out - 1]) if n_out else (0.0,)
        shown = time_unit(max(abs(v) for v in ends) * tu)
        lines = [
            f"{path}: orbits output (layout {FORMAT} v{FORMAT_VERSION}), written by "
            f"orbits {par.attrs['orbits_version']} on {par.attrs['written']}",
            f"bodies          {len(names)}: {', '.join(names[:8])}"
            + (", ..." if len(names) > 8 else ""),
            f"integrator      {par.attrs['integrator']} {par.attrs['integrator_options']}, "
            f"dt = {format_time(par.attrs['dt'] * u.Unit(par.attrs['dt_unit']))}",
            f"units           {units['name']}, G = {units['G']!r} ({units['G_source']})",
            f"epoch           {_describe_epoch(_epoch(par, path))}",
            f"outputs         {n_out}"
            + (f", t = {(t[0] * tu).to_value(shown):.6g} .. "
               f"{format_time(t[n_out - 1] * tu, shown)}" if n_out else ""),
            f"monitors        {', '.join(monitors) or 'none'}",
            f"forces          {_describe_forces(par, path)}",
        ]
        config = _config(f)
        layout = _config_layout(config, len(names))
        if sum(layout):
            kinds = [f"{k} {what}" for k, what in zip(
                layout, ("for the chaos monitors", "random", "of the state", "of the masses"))
                if k]
            lines.append(f"variations      {config.get('variations')}; {sum(layout)} tangent "
                         f"vectors ({', '.join(kinds)}), seed {config.get('seed')}")
        count = int(f["restart/count"][()])
        if count:
            slot = (count - 1) % _SLOTS
            clock = f["restart/clock"][slot]
            tb = f["restart/t_base"][slot]
            t_ck = tb + clock[1] * par.attrs["dt"]
            lines.append(f"checkpoint      {count} written; the last at step {clock[0]}, "
                         f"t = {format_time(t_ck * tu, shown)}")
        totals = _totals(f)
        if totals is not None:
            lines.append(f"work            {totals[0]} steps, {totals[1]} force evaluations, "
                         f"wall time {totals[3]:.3g} s")
        if "masses" in f["restart"]:
            k = _log_rows(f["collisions"], _COLLISION_COLUMNS) if "collisions" in f else 0
            left = (int(np.isfinite(f["restart/masses"][(count - 1) % _SLOTS]).sum())
                    if count else None)
            lines.append(f"collisions      {k} resolved" + (
                f"; {left} bodies at the last checkpoint" if left is not None else ""))
        if "encounters" in f:
            lines.append(f"encounters      {_log_rows(f['encounters'], _ENCOUNTER_COLUMNS)} "
                         f"logged")
        lines.append(f"status          {_status(f, path)}")
        return "\n".join(lines)


def _describe_epoch(epoch):
    # the date of time 0, or that there is none
    return "none (times only)" if epoch is None else f"{_epochs.describe(epoch)} at t = 0"


def _describe_forces(par, path):
    # Newtonian gravity and the added terms, as their constructors would be
    # written; a term of the user's functions by the names the file records
    # (a file names functions, never holds them, and nothing is imported)
    text = ["Newtonian gravity"]
    records = json.loads(par.attrs["forces"]) if "forces" in par.attrs else []
    for d in records:
        try:
            needed = forces.functions_needed([d])
            if needed:
                text.append(f"{d['type']}({', '.join(needed)})")
            else:
                text.append(repr(forces.from_dict(d)))
        except (OrbitsError, TypeError, ValueError, KeyError) as exc:
            raise OrbitsFileError(f"{path}: the force term {d!r} in /parameters does not "
                                  f"rebuild: {exc}") from None
    return " + ".join(text)
