"""The format of a body-set file: the keys a ``[[body]]``, ``[units]`` and
``[run]`` table and a CSV header may hold, each with the kind of value it is
read as; the file types by ending; and the words of the messages about them
(an unknown key with its near miss, an example value of a kind, a TOML
value described)."""

import difflib
import os

from ..errors import SystemFileError

__all__ = ["BODY_FIELDS", "UNIT_FIELDS", "RUN_FIELDS", "CSV_COLUMNS"]

# the format's keys, each documented where orbits.systemfile exports it
BODY_FIELDS = {"name": "text", "mass": "mass", "radius": "length", "position": "length",
               "velocity": "velocity", "primary": "text", "a": "length", "e": "dimensionless",
               "inc": "angle", "Omega": "angle", "omega": "angle", "f": "angle", "M": "angle"}

UNIT_FIELDS = ("length", "mass", "time", "G", "G_source", "name")

RUN_FIELDS = {"integrator": "text", "dt": "time", "until": "time", "outputs": "integer",
              "com": "boolean", "encounter_distance": "length",
              "escape_distance": "length", "options": "table"}

CSV_COLUMNS = ("name", "mass", "radius", "x", "y", "z", "vx", "vy", "vz", "primary", "a", "e",
               "inc", "Omega", "omega", "f", "M")

_VECTORS = {"position": ("x", "y", "z"), "velocity": ("vx", "vy", "vz")}
_ELEMENTS = ("a", "e", "inc", "Omega", "omega", "f", "M")
# units suggested in messages about a missing one
_EXAMPLE_UNIT = {"mass": "Msun", "length": "au", "velocity": "km/s", "time": "day",
                 "angle": "deg"}
_FORMATS = {".toml": "toml", ".csv": "csv"}


def _format_of(path):
    ext = os.path.splitext(path)[1].lower()
    try:
        return _FORMATS[ext]
    except KeyError:
        raise SystemFileError(f"unknown file type {ext or '(none)'!r}: a body-set file "
                              f"ends in .toml or .csv", path=path) from None


def _unknown(what, key, valid, of=""):
    close = difflib.get_close_matches(str(key), list(valid), n=1)
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    return (f"unknown {what} {key!r}{hint}; the {what}s{' ' + of if of else ''} are "
            f"{', '.join(valid)}")


def _example(kind):
    return {"mass": "1 Msun", "length": "5.2 au", "velocity": "30 km/s", "time": "10 day",
            "angle": "1.3 deg", "dimensionless": "0.05"}.get(kind, "1")


def _toml_text(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, list):
        return "a list"
    if isinstance(value, dict):
        return "a table"
    return repr(value)
