"""One run on a worker: build its simulation, run it, and make its row.

:func:`run_one` is what a task does for each of its runs
(:func:`orbits.ensemble.tasks.run_chunk`); batch mode
(:mod:`orbits.ensemble.batch`) makes its rows with the same functions.  A
failure of the run becomes its ``outcome``; an
:class:`~orbits.errors.OrbitsError` from ``build`` makes the outcome
``"invalid"``; any other exception from ``build`` stops the sweep.
"""

import math
import time as _time

import numpy as np

from ..errors import OrbitsError, RunError
from ..io.hdf5 import load
from .compiles import _cache_loads, _CompileRecorder, _sync_numba_config, _worker_fields
from .errors import EnsembleOptionError
from .table import (_ERROR_MONITORS, _column, _monitor_columns, _outcome, _parameter_row,
                    _value)

__all__ = ["run_one", "ELEMENTS_MAX_BODIES"]

#: Final elements are reported for every non-central body up to this many
#: bodies; above it only for the bodies named in ``elements=``.
ELEMENTS_MAX_BODIES = 16


class _Spec:
    """What every run of a sweep shares; small, so that it travels with each task."""

    def __init__(self, until, outputs, elements):
        self.until = until
        self.outputs = outputs
        self.elements = elements


def run_one(build, params, index, spec, path=None):
    """Build and run one simulation; return its row (a dict).  Runs on a worker.

    Failures of the run become its outcome; an :class:`~orbits.errors.OrbitsError`
    from ``build`` is the outcome ``"invalid"``.
    """
    _sync_numba_config()
    row = _parameter_row(params, index)
    loaded0 = _cache_loads()
    with _CompileRecorder() as log:
        try:
            sim = build(**params)
            outcome, exc, wall, result = _advance(sim, spec, path)
        except OrbitsError as err:     # parameters that make no simulation
            return _invalid_row(row, err, _worker_fields(loaded0, log))
    return _run_row(row, sim, spec, path, outcome, exc, wall, result,
                    lambda: _worker_fields(loaded0, log))


def _advance(sim, spec, path):
    wall0 = _time.perf_counter()
    try:
        result = sim.run(spec.until, outputs=spec.outputs, progress=False, output=path,
                         overwrite=True)
    except RunError as exc:
        return _outcome(exc), exc, _time.perf_counter() - wall0, exc.result
    return "completed", None, _time.perf_counter() - wall0, result


def _invalid_row(row, err, worker):
    """The row of a run whose parameters made no simulation (``err``)."""
    return _add_results(row, dict(
        outcome="invalid", message=str(err), stop_bodies="", steps=0,
        **{monitor.ensemble: math.nan for monitor in _ERROR_MONITORS},
        wall_time_s=0.0, **worker, file=""))


def _run_row(row, sim, spec, path, outcome, exc, wall, result, worker):
    """The row of a run that ran (``worker()``: where, and its kernels)."""
    out = {"outcome": outcome}
    out["message"] = "" if exc is None else str(exc)
    out["stop_bodies"] = ",".join(getattr(exc, "bodies", ()) or ())
    units = sim.units
    t_end = sim.time_value if exc is None or exc.time is None else exc.time
    out[_column("t_stop", units.time)] = _value(t_end, units.time)
    out["steps"] = sim.steps
    if path is not None:   # the result of a run to a file holds only its last output
        result = load(path)
    for monitor in _ERROR_MONITORS:
        largest = result._max_error(monitor.name) if result is not None else None
        out[monitor.ensemble] = math.nan if largest is None else largest
    out.update(_last_values(sim, result))
    if result is not None and getattr(result, "collisions", None) is not None:
        # collisions the run resolved (merged or bounced) and the bodies left
        out["collisions"] = len(result.collisions)
        out["bodies_left"] = len(sim.bodies.names)
    out.update(_final_elements(sim, spec.elements))
    out["wall_time_s"] = wall
    out.update(worker())
    out["file"] = "" if path is None else path.name
    return _add_results(row, out)


def _add_results(row, results):
    """``row`` (the run number and parameters) with the run's ``results``; a
    parameter whose name a result takes (a body's final elements,
    ``<body>_e``, above all) stops the sweep rather than lose its values."""
    clash = [k for k in results if k in row]
    if clash:
        raise EnsembleOptionError(
            f"the parameter {clash[0]!r} has the name of a column of the results of "
            f"run {row['run']} (the final elements of a body are '<body>_a_<unit>', "
            f"'<body>_e' and '<body>_inc_rad'), which would overwrite it; give the "
            f"parameter another name")
    row.update(results)
    return row


def _last_values(sim, result):
    """The last values in ``result`` of the monitors ``sim`` follows that have
    one in the table (the chaos indicators), NaN where it has none, as
    ``{"megno": ..., "lyapunov_per_<time unit>": ..., "fli": ...}``."""
    out = {}
    for spec, column, unit in _monitor_columns(sim.units):
        if spec.name not in sim.monitors:
            continue
        series = None if result is None else getattr(result, spec.name, None)
        if series is None or not len(series):
            out[column] = math.nan
        else:
            out[column] = float(series[-1] if unit is None else series[-1].to_value(unit))
    return out


def _final_elements(sim, names):
    bodies = sim.bodies
    m = bodies._m
    central = bodies.names[int(np.argmax(m))]
    if names is None:
        names = ([b for b in bodies.names if b != central]
                 if len(bodies) <= ELEMENTS_MAX_BODIES else [])
    out = {}
    for b in names:
        # BodySet.elements' numbers without its Quantities
        try:
            el, status = bodies._element_values(b, central)
        except OrbitsError:
            status = 1
        vals = (float(el[0]), float(el[1]), float(el[2])) if status == 0 else (math.nan,) * 3
        out[_column(f"{b}_a", bodies.units.length)] = vals[0]
        out[f"{b}_e"] = vals[1]
        out[f"{b}_inc_rad"] = vals[2]
    return out
