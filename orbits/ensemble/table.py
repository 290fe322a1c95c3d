"""The table of a sweep: its columns' names, their order, and the values of
the ``outcome`` column.

A run's row (:mod:`orbits.ensemble.worker`) and the index that stores it
(:mod:`orbits.ensemble.index`) name their columns here: a parameter ``x``
given as a Quantity becomes ``x_<unit>``, the stop time ``t_stop_<time
unit>``; a failed run's outcome is its exception's class name in lower case
with hyphens.  A parameter may not take a result column's name.
"""

import functools

import astropy.units as u
import numpy as np

from .._monitor_specs import CHOSEN
from ..errors import RunError
from .errors import EnsembleOptionError

__all__ = []


#: The monitors with a column each, as their specs declare it: the largest
#: relative error over the run (``energy_error_max``), or the last value
#: (``megno``; ``lyapunov_per_<time unit>`` for a series with a unit)
_ERROR_MONITORS = tuple(s for s in CHOSEN if s.ensemble and s.error is not None)
_LAST_VALUE_MONITORS = tuple(s for s in CHOSEN if s.ensemble and s.error is None)
#: the columns of the largest errors
_ERROR_COLUMNS = tuple(s.ensemble for s in _ERROR_MONITORS)
#: the last values' columns without a unit, and the beginnings of those with one
_PLAIN_VALUE_COLUMNS = tuple(s.ensemble for s in _LAST_VALUE_MONITORS
                             if s.kind == "dimensionless")
_VALUE_PREFIXES = tuple(s.ensemble for s in _LAST_VALUE_MONITORS if s.kind != "dimensionless")

_FIRST = ("outcome", "message", "stop_bodies")
_MIDDLE = ("steps", *_ERROR_COLUMNS)
_LAST = ("wall_time_s", "worker", "kernels_compiled", "kernels_loaded", "file")

#: Columns of the results whatever the bodies (those of the elements,
#: ``<body>_a_<unit>``, ``<body>_e``, ``<body>_inc_rad``, depend on them), and
#: the beginnings of those that end with a unit (``t_stop_day``)
_RESULT_COLUMNS = frozenset(("run", *_FIRST, *_MIDDLE, *_PLAIN_VALUE_COLUMNS, "collisions",
                             "bodies_left", *_LAST))
_RESULT_PREFIXES = ("t_stop", *_VALUE_PREFIXES)


def _column_order(columns, parameters):
    """run, parameters, outcome, stop time, errors, chaos indicators, elements
    (sorted), where it ran: the same order whether the rows were computed now or
    read from the index."""
    columns = list(columns)
    params = []
    for p in parameters:
        for k, val in p.items():
            name = _column(k, val.unit) if isinstance(val, u.Quantity) else k
            if name not in params:
                params.append(name)
    t_stop = sorted(c for c in columns if c.startswith("t_stop"))
    values = [c for s in _LAST_VALUE_MONITORS
              for c in ([s.ensemble] if s.kind == "dimensionless"
                        else sorted(c for c in columns if c.startswith(s.ensemble)))]
    fixed = ["run", *params, *_FIRST, *t_stop, *_MIDDLE, *values]
    elements = sorted(c for c in columns if c not in fixed and c not in _LAST)
    return [c for c in (*fixed, *elements, *_LAST) if c in columns]


def _check_parameter_names(params, i):
    """Refuse a parameter whose column would be a result column: the result
    would overwrite it (``run`` would even lose the rows' numbering)."""
    for k, val in params.items():
        col = _column(k, val.unit) if isinstance(val, u.Quantity) else k
        if col in _RESULT_COLUMNS or any(col == p or col.startswith(p + "_")
                                         for p in _RESULT_PREFIXES):
            named = f"{k!r}" if col == k else f"{k!r} (the column {col!r})"
            raise EnsembleOptionError(
                f"parameter set {i}: the parameter {named} has the name of a column "
                f"of the results, which would overwrite it; give it another name")


def _parameter_row(params, index):
    """A row's run number and parameter columns."""
    row = {"run": index}
    for k, val in params.items():
        if isinstance(val, u.Quantity):
            row[_column(k, val.unit)] = float(val.value)
        else:
            row[k] = _plain(val)
    return row


def _is_result_column(name):
    """Whether ``name`` is, or has the form of, a column of a run's results."""
    return (name in _RESULT_COLUMNS
            or any(name == p or name.startswith(p + "_") for p in _RESULT_PREFIXES)
            or name.endswith(("_e", "_inc_rad", "_a")) or "_a_" in name)


def _outcome(exc):
    """The exception's class name in lower case with hyphens: ``CloseEncounter``
    -> ``"close-encounter"``, so that every kind of failure has its own outcome."""
    return _outcome_name(type(exc))


def _outcome_name(cls):
    name = cls.__name__
    return "".join(("-" + ch.lower()) if ch.isupper() and k else ch.lower()
                   for k, ch in enumerate(name))


def _known_outcomes():
    names, classes = {"completed", "invalid"}, [RunError]
    while classes:
        cls = classes.pop()
        names.add(_outcome_name(cls))
        classes.extend(cls.__subclasses__())
    return names


def _monitor_columns(units):
    """``(spec, column, unit)`` of each monitor's last value in a run's row, in
    the unit system ``units``: ``unit`` None for a dimensionless series, else
    the unit of the value, which the column's name ends with
    (``lyapunov_per_day``: the Lyapunov estimate in 1 / day)."""
    out = []
    for spec in _LAST_VALUE_MONITORS:
        if spec.kind == "dimensionless":
            out.append((spec, spec.ensemble, None))
        else:
            unit = spec.unit(units)
            # "1 / time" is named "<name>_per_<time unit>"
            named = units.unit("time") if spec.kind == "1 / time" else unit
            out.append((spec, _column(spec.ensemble, named), unit))
    return out


def _frame_attrs(spec, frame):
    return {"until": str(spec.until), "outputs": spec.outputs,
            "elements_primary": "the most massive body"}


def _plain(val):
    if isinstance(val, np.generic):
        return val.item()
    return val


def _column(name, unit):
    """``name_<unit>``, e.g. ``t_stop_day``, ``a_au``; just ``name`` without a unit."""
    return f"{name}{_unit_suffix(u.Unit(unit))}"


@functools.lru_cache(maxsize=256)
def _unit_suffix(unit):
    # "_<unit>" of a column name (a unit's string costs 20 us, several a run)
    s = unit.to_string()
    s = {"d": "day"}.get(s, s.lower())
    s = "".join(ch if ch.isalnum() else "_" for ch in s)
    return f"_{s}" if s else ""


def _value(t, unit):
    if isinstance(t, u.Quantity):
        return float(t.to_value(unit))
    return float(t)
