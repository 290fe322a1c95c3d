"""Writing a body set as TOML or CSV text, exactly: the numbers it holds in
its own units as the shortest text that reads back as the same float64, with
the unit system and its G."""

import csv
import io as _io
import json
import math

import astropy.units as u
import numpy as np

from .. import epochs as _epochs
from .._csvcells import safe_cell
from ..bodies._elements import bound_elements
from ._schema import RUN_FIELDS, _unknown

__all__ = []

def _dump_toml(bodies, run):
    units = bodies.units
    out = ["# A body set for orbits: 'orbits run FILE --until 100yr' runs it,",
           "# orbits.BodySet.read(FILE) reads it.  Plain numbers are in the [units]",
           "# below; with the G written here a run reproduces exactly.", ""]
    if bodies.epoch is not None:
        out += [f"# the date of the states: {bodies.epoch.isot} TDB",
                f"epoch = {_toml_value(_epochs.to_text(bodies.epoch))}", ""]
    out += ["[units]"]
    for key, value in units.to_dict().items():
        out.append(f"{key} = {_toml_value(value)}")
    for i, name in enumerate(bodies.names):
        out += ["", "[[body]]"]
        note = _elements_note(bodies, i)
        if note:
            out.append(f"# {note}")
        out += [f"name = {_toml_value(name)}",
                f"mass = {_toml_value(float(bodies._m[i]))}"]
        if bodies._r[i] != 0:
            out.append(f"radius = {_toml_value(float(bodies._r[i]))}")
        out += [f"position = {_toml_value([float(c) for c in bodies._x[i]])}",
                f"velocity = {_toml_value([float(c) for c in bodies._v[i]])}"]
    if run:
        out += ["", "[run]"]
        options = None
        for key, value in run.items():
            if key not in RUN_FIELDS:
                raise ValueError(_unknown("field", key, RUN_FIELDS, "of [run]"))
            if key == "options":
                options = value
                continue
            out.append(f"{key} = {_toml_value(value)}")
        if options:
            out += ["", "[run.options]"]
            out += [f"{k} = {_toml_value(v)}" for k, v in options.items()]
    return "\n".join(out) + "\n"


def _toml_value(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        value = float(value)
        if math.isnan(value):
            return "nan"
        return repr(value) if math.isfinite(value) else ("inf" if value > 0 else "-inf")
    if isinstance(value, u.Quantity):
        return _toml_value(f"{float(value.value)!r} {value.unit.to_string()}")
    if isinstance(value, str):
        # JSON's escapes are TOML's basic-string escapes
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    raise TypeError(f"cannot write {value!r} ({type(value).__name__}) to TOML")


def _elements_note(bodies, i):
    """``a = ..., e = ..., inc = ...`` about the bodies above, for a bound orbit."""
    el = bound_elements(bodies, i)
    if el is None:
        return ""
    a, e, inc = el
    return (f"a = {a:.6g} {bodies.units.length}, e = {e:.4g}, inc = {math.degrees(inc):.4g} "
            f"deg (about the bodies above)")


def _dump_csv(bodies):
    units = bodies.units
    d = units.to_dict()
    buf = _io.StringIO()
    buf.write("# A body set for orbits; plain numbers are in these units, and with this G "
              "a run reproduces exactly\n")
    writer = csv.writer(buf, lineterminator="\n")
    # one cell (quoted where the unit system's name has a comma), so that a
    # spreadsheet finds no other cell in it
    writer.writerow(["# units: " + "; ".join(f"{k} = {str(v).replace(';', ',')}"
                                             if k != "G" else f"G = {float(v)!r}"
                                             for k, v in d.items())])
    if bodies.epoch is not None:
        writer.writerow([f"# epoch: {_epochs.to_text(bodies.epoch)}"])

    def col(name, kind):
        unit = units.unit(kind).to_string()
        return f"{name} [{unit}]" if unit else name
    # a table of point masses, the usual case, keeps its columns as they were
    sized = bool(np.any(bodies._r != 0))
    writer.writerow(["name", col("mass", "mass"), *([col("radius", "length")] if sized else []),
                     *(col(c, "length") for c in "xyz"),
                     *(col(c, "velocity") for c in ("vx", "vy", "vz"))])
    for i, name in enumerate(bodies.names):
        writer.writerow([safe_cell(name), repr(float(bodies._m[i])),
                         *([repr(float(bodies._r[i]))] if sized else []),
                         *(repr(float(c)) for c in bodies._x[i]),
                         *(repr(float(c)) for c in bodies._v[i])])
    return buf.getvalue()
