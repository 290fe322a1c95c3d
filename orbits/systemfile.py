"""Body sets in files: TOML for a person to write, CSV for a table.

``orbits run system.toml`` and :meth:`orbits.BodySet.read` read these files;
:func:`write` and :meth:`orbits.BodySet.write` write them.  Every value carries
its unit, so a file says what it means without a convention to remember.

TOML
----
One ``[[body]]`` table per body, in order; an optional ``[units]`` table; an
optional ``[run]`` table of defaults for ``orbits run``; an optional
``epoch``, before the tables::

    epoch = "2000-01-01T12:00:00 TDB"   # optional: the date of the states

    [units]                     # optional; as orbits.UnitSystem takes them
    length = "au"               # default au
    mass = "Msun"               # default Msun
    time = "day"                # default day
    # G = 2.95912208286e-4      # optional, in length^3 / (mass time^2), or
                                # a string with a unit; default: astropy's

    [[body]]
    name = "Sun"
    mass = "1 Msun"             # a string: a number and its unit
    radius = "1 Rsun"           # optional: the physical radius; default 0

    [[body]]                    # by orbital elements about a primary
    name = "Jupiter"
    mass = "9.547919e-4 Msun"
    primary = "Sun"             # default: the centre of mass of the bodies above
    a = "5.2026 au"
    e = 0.0484                  # a plain number: dimensionless
    inc = "1.30 deg"            # angles always with a unit (deg or rad)
    Omega = "100.5 deg"
    omega = "273.9 deg"
    M = "20 deg"                # or f = ..., the true anomaly; default f = 0

    [[body]]                    # by Cartesian state
    name = "probe"
    mass = 0
    position = ["1 au", "0 au", "0 au"]
    velocity = ["0 km/s", "30 km/s", "0 km/s"]

    [run]                       # optional: defaults for 'orbits run' (its
    integrator = "wh"           # options override them)
    dt = "50 day"
    until = "1000 yr"
    outputs = 500
    com = true                  # move to the centre-of-mass frame first
    # encounter_distance = "0.01 au", escape_distance = "1000 au"

    [run.options]               # the integrator's options
    corrector = 17

The ``epoch`` is the date the states hold at (:attr:`orbits.BodySet.epoch`):
text that :func:`orbits.epochs.from_text` reads, a date astropy reads
followed by its time scale (TDB when none is given: ``"2024-03-01 UTC"``,
``"2000-01-01T12:00:00 TDB"``) or a Julian date in one or two parts
(``"2451545.0 TDB"``, ``"2451545.0 + 0.25 TDB"``); :func:`write` writes the
two-part Julian date in TDB, which reads back bit for bit.

Body fields are those of :meth:`orbits.BodySet.add`: ``name``, ``mass``, an
optional ``radius``, and either ``position`` and ``velocity`` (three
components each) or ``a``, ``e``, ``inc``, ``Omega``, ``omega``, ``f`` or ``M``
with an optional ``primary``.
A value is a string with a unit (``"5.2 au"``, ``"30 km/s"``) or a plain
number.  A plain number is read in the ``[units]`` table's units; without a
``[units]`` table only dimensionless values (``e``) and zero take no unit.
Angles always need one.

CSV
---
A header row names the columns with their units in brackets; a row per body;
lines starting with ``#`` are comments, and a ``# units:`` comment before the
header gives the unit system (plain-number columns are then read in it), an
``# epoch:`` comment the date of the states (as the TOML ``epoch``)::

    # units: length = au; mass = Msun; time = day
    # epoch: 2451545.0 + 0.0 TDB
    name,mass [Msun],x [au],y [au],z [au],vx [km/s],vy [km/s],vz [km/s]
    Sun,1,0,0,0,0,0,0
    probe,0,1,0,0,0,30,0

The columns are ``name``, ``mass``, ``radius``, ``x``, ``y``, ``z``, ``vx``,
``vy``, ``vz``, ``primary``, ``a``, ``e``, ``inc``, ``Omega``, ``omega``, ``f``,
``M``; a row gives either the state or elements, and leaves the other cells
empty.  ``radius`` is optional (an empty cell or no column: 0).

A file saved by a spreadsheet reads as it is: a UTF-8 byte-order mark at its
start is skipped.  A name that a spreadsheet would take for a formula (one
beginning with ``=``, ``+``, ``-``, ``@``, a tab or a carriage return) is
written with a single quote before it, as spreadsheets write such text, and a
name beginning with a quote gets one more; reading takes one such quote away
(``orbits._csvcells``).

Exactness
---------
:func:`write` writes the numbers the set holds, in its own units, with the
shortest text that reads back as the same float64 (Python's ``repr``), and
the unit system with its G.  Radii are written where any body has a non-zero
one.  A set written and read back is therefore the same bit for bit, and so
is any run of it.

Errors
------
Everything wrong in a file is a :class:`~orbits.errors.SystemFileError` whose
message starts with the file and the line, then names the body and the field:
``system.toml, line 12: body 'Jupiter', field 'inc': ...``.  That includes a
file that is not UTF-8 text, a whole number too large for a float or with
more digits than Python converts, and arrays nested too deeply to read.
"""

import csv
import difflib
import io as _io
import json
import math
import os
import re
from typing import NamedTuple

import astropy.units as u
import numpy as np

from . import epochs as _epochs
from ._csvcells import read_cell, safe_cell
from .bodies import BodySet
from .bodies._elements import bound_elements, relative_state
from .bodies._input import unit_string
from .errors import BodyError, EpochError, SystemFileError, _where
from .units import UnitSystem

try:
    import tomllib as _toml
except ModuleNotFoundError:  # pragma: no cover - Python 3.10
    try:
        import tomli as _toml
    except ModuleNotFoundError:
        _toml = None

__all__ = ["SystemFile", "read", "write", "loads", "dumps", "BODY_FIELDS", "UNIT_FIELDS",
           "RUN_FIELDS", "CSV_COLUMNS"]

#: ``[[body]]`` keys and the physical kind each is read as
BODY_FIELDS = {"name": "text", "mass": "mass", "radius": "length", "position": "length",
               "velocity": "velocity", "primary": "text", "a": "length", "e": "dimensionless",
               "inc": "angle", "Omega": "angle", "omega": "angle", "f": "angle", "M": "angle"}

#: ``[units]`` keys (the arguments of :class:`~orbits.units.UnitSystem`)
UNIT_FIELDS = ("length", "mass", "time", "G", "G_source", "name")

#: ``[run]`` keys and what each holds
RUN_FIELDS = {"integrator": "text", "dt": "time", "until": "time", "outputs": "integer",
              "com": "boolean", "encounter_distance": "length",
              "escape_distance": "length", "options": "table"}

#: CSV columns: the body fields, with the vectors as one column per component
CSV_COLUMNS = ("name", "mass", "radius", "x", "y", "z", "vx", "vy", "vz", "primary", "a", "e",
               "inc", "Omega", "omega", "f", "M")

_VECTORS = {"position": ("x", "y", "z"), "velocity": ("vx", "vy", "vz")}
_ELEMENTS = ("a", "e", "inc", "Omega", "omega", "f", "M")
# units suggested in messages about a missing one
_EXAMPLE_UNIT = {"mass": "Msun", "length": "au", "velocity": "km/s", "time": "day",
                 "angle": "deg"}
_FORMATS = {".toml": "toml", ".csv": "csv"}
# each part can end in only one way (no two adjacent runs of digits), so a
# long string of digits that fails does so in linear time
_NUMBER = re.compile(r"\s*[-+]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][-+]?\d+)?\s*")
# a CSV column, "mass [Msun]", stripped: one way to match again
_COLUMN = re.compile(r"([A-Za-z_]\w*)(?:\s*\[(.*)\])?")
_BOM = "\ufeff"


class SystemFile(NamedTuple):
    """What :func:`read` gives: the bodies, the ``[run]`` defaults, and the source.

    Examples
    --------
    >>> from orbits import systemfile
    >>> text = '''
    ... [[body]]
    ... name = "Sun"
    ... mass = "1 Msun"
    ... [[body]]
    ... name = "Jupiter"
    ... mass = "1 Mjup"
    ... a = "5.2 au"
    ... [run]
    ... integrator = "wh"
    ... dt = "50 day"
    ... '''
    >>> sf = systemfile.loads(text)
    >>> sf.bodies.names, sf.run["integrator"], sf.run["dt"], sf.path
    (['Sun', 'Jupiter'], 'wh', <Quantity 50. d>, '<string>')
    """

    bodies: BodySet
    #: the ``[run]`` table: ``integrator`` (str), ``dt`` and ``until``
    #: (Quantity, time), ``outputs`` (int), ``com`` (bool), ``encounter_distance``
    #: and ``escape_distance`` (Quantity, length), ``options`` (dict); only the
    #: keys the file gives (empty for CSV)
    run: dict
    path: str


# -- reading ------------------------------------------------------------------------
def read(path):
    """Read a body set from a TOML or CSV file.

    Parameters
    ----------
    path : str or os.PathLike
        A file ending in ``.toml`` or ``.csv`` (the format is the module
        docstring's).

    Returns
    -------
    SystemFile
        ``bodies`` (a :class:`~orbits.BodySet` in the file's unit system),
        ``run`` (the ``[run]`` table's defaults) and ``path``.

    Raises
    ------
    SystemFileError
        The file is malformed; the message gives the file, the line, the body
        and the field.
    FileNotFoundError
        There is no such file.

    Examples
    --------
    >>> import os, tempfile
    >>> import orbits
    >>> from orbits import systemfile
    >>> path = os.path.join(tempfile.mkdtemp(), "kepler.toml")
    >>> systemfile.write(orbits.scenes.kepler(), path)
    >>> systemfile.read(path).bodies.names
    ['Star', 'Planet']
    """
    path = os.fspath(path)
    kind = _format_of(path)
    with open(path, "rb") as fh:
        data = fh.read()
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        start = data.rfind(b"\n", 0, exc.start) + 1
        raise SystemFileError(f"not UTF-8 text: the byte {data[exc.start]:#04x} at column "
                              f"{exc.start - start + 1} is not UTF-8; save the file as "
                              f"UTF-8", path=path, line=data.count(b"\n", 0, exc.start) + 1) \
            from None
    return loads(text, kind, source=path)


def loads(text, kind="toml", source="<string>"):
    """Read a body set from text.

    Parameters
    ----------
    text : str
        The file's contents.
    kind : {"toml", "csv"}
    source : str
        The name used in error messages.

    Returns
    -------
    SystemFile

    Examples
    --------
    >>> from orbits import systemfile
    >>> text = '''
    ... [[body]]
    ... name = "Sun"
    ... mass = "1 Msun"
    ... [[body]]
    ... name = "Earth"
    ... mass = "1 Mearth"
    ... primary = "Sun"
    ... a = "1 au"
    ... '''
    >>> bodies = systemfile.loads(text).bodies
    >>> round(float(bodies.elements("Earth", primary="Sun")["a"].to_value("au")), 12)
    1.0
    """
    if text.startswith(_BOM):   # a spreadsheet's UTF-8 mark
        text = text[len(_BOM):]
    if kind == "toml":
        return _TomlReader(text, source).read()
    if kind == "csv":
        return _CsvReader(text, source).read()
    raise ValueError(f"unknown body-set file format {kind!r}; expected 'toml' or 'csv'")


def _format_of(path):
    ext = os.path.splitext(path)[1].lower()
    try:
        return _FORMATS[ext]
    except KeyError:
        raise SystemFileError(f"unknown file type {ext or '(none)'!r}: a body-set file "
                              f"ends in .toml or .csv", path=path) from None


class _Reader:
    """What the TOML and CSV readers share: values, units, and adding bodies."""

    def __init__(self, text, source):
        self.text = text
        self.source = source
        self.units = None          # the file's UnitSystem, if it gives one
        self.epoch = None          # the file's epoch (astropy Time, TDB), if it gives one
        self.names = {}            # body name -> line where it was given

    def error(self, message, line, body=None, field=None):
        return SystemFileError(message, path=self.source, line=line, body=body, field=field)

    def epoch_text(self, raw, line):
        """The ``epoch`` (text, :func:`orbits.epochs.from_text`) as a TDB Time."""
        if not isinstance(raw, str):
            raise self.error(f"expected a date as text, such as '2000-01-01T12:00:00 TDB' "
                             f"or '2451545.0 TDB', got {_toml_text(raw)}", line,
                             field="epoch")
        try:
            return _epochs.from_text(raw)
        except EpochError as exc:
            raise self.error(str(exc).removeprefix("epoch: "), line, field="epoch") from None

    # values -----------------------------------------------------------------------
    def value(self, raw, kind, line, body=None, field=None):
        """A plain float (read in the file's units) or a Quantity, checked for form."""
        if kind == "text":
            if not isinstance(raw, str) or not raw:
                raise self.error(f"expected a non-empty string in quotes, got {raw!r}",
                                 line, body, field)
            return raw
        if isinstance(raw, bool) or not isinstance(raw, (int, float, str)):
            raise self.error(f"expected a number or a string with a unit (such as "
                             f"'{_example(kind)}'), got {_toml_text(raw)}", line, body, field)
        if isinstance(raw, str):
            if not _NUMBER.fullmatch(raw):
                return self.quantity_text(raw, line, body, field)
            raw = float(raw)  # "0.05" is the number 0.05
        raw = self.as_float(raw, line, body, field)
        if kind == "dimensionless":
            return raw
        if kind == "angle":
            raise self.error(f"an angle needs a unit: write '{raw!r} deg' or "
                             f"'{raw!r} rad'", line, body, field)
        if self.units is not None:
            return raw
        if raw == 0:
            return 0.0 * UnitSystem.default().unit(kind)
        raise self.error(f"the number {raw!r} has no unit, and the file gives no unit "
                         f"system: write it with a unit, such as '{raw!r} "
                         f"{_EXAMPLE_UNIT.get(kind, '')}', or give the units "
                         f"({self.units_hint})", line, body, field)

    units_hint = "a [units] table"

    def as_float(self, raw, line, body=None, field=None):
        """``raw`` (an int or a float) as a float; a whole number beyond the
        floats' range is an error, not an OverflowError."""
        try:
            return float(raw)
        except OverflowError:
            raise self.error(f"the whole number of {raw.bit_length()} bits is too large "
                             f"for a 64-bit float (at most about 1.8e308)", line, body,
                             field) from None

    def quantity_text(self, raw, line, body=None, field=None):
        try:
            q = u.Quantity(raw)
        except (TypeError, ValueError):
            raise self.error(f"cannot read {raw!r} as a number with a unit (such as "
                             f"'5.2 au' or '30 km/s')", line, body, field) from None
        if not q.isscalar:
            raise self.error(f"expected one number with a unit, got {raw!r}", line, body,
                             field)
        return q

    def quantity(self, raw, kind, line, field):
        """A ``[run]`` value: a Quantity of ``kind`` in the file's units."""
        val = self.value(raw, kind, line, field=field)
        units = self.units or UnitSystem.default()
        if not isinstance(val, u.Quantity):
            return val * units.unit(kind)
        try:
            val.to(units.unit(kind))
        except u.UnitConversionError:
            raise self.error(f"expected a {kind} (such as '{_example(kind)}'), got "
                             f"{raw!r}", line, field=field) from None
        return val

    def unit_system(self, table, line_of):
        """The ``[units]`` table (a dict) as a UnitSystem."""
        for key in table:
            if key not in UNIT_FIELDS:
                raise self.error(_unknown("field", key, UNIT_FIELDS, "of [units]"),
                                 line_of(key), field=key)
        args = {}
        for key in ("length", "mass", "time"):
            if key in table:
                text = table[key]
                if not isinstance(text, str):
                    raise self.error(f"expected a unit in quotes (such as "
                                     f"'{_EXAMPLE_UNIT[key]}'), got {_toml_text(text)}",
                                     line_of(key), field=key)
                try:
                    args[key] = u.Unit(text)
                except ValueError:
                    raise self.error(f"unknown unit {text!r}", line_of(key),
                                     field=key) from None
        if "G" in table:
            g = table["G"]
            if isinstance(g, str):
                g = self.quantity_text(g, line_of("G"), field="G")
            elif isinstance(g, bool) or not isinstance(g, (int, float)):
                raise self.error(f"expected a number or a string with a unit, got "
                                 f"{_toml_text(g)}", line_of("G"), field="G")
            else:
                g = self.as_float(g, line_of("G"), field="G")
            args["G"] = g
        for key in ("name", "G_source"):
            if key in table:
                args[key] = self.value(table[key], "text", line_of(key), field=key)
        try:
            return UnitSystem(**args)
        except (ValueError, u.UnitsError) as exc:
            key = next((k for k in ("length", "mass", "time", "G") if k in str(exc)), None)
            raise self.error(str(exc), line_of(key)) from None

    # bodies -----------------------------------------------------------------------
    def add(self, bodies, fields, line_of):
        """Add one body from its fields (already split into vectors), ``line_of(key)``
        giving the line of each field (and of the body for ``None``)."""
        name = fields.get("name")
        if name is None:
            raise self.error("a body needs a name", line_of(None), field="name")
        name = self.value(name, "text", line_of("name"), field="name")
        if name in self.names:
            raise self.error(f"a body of this name is already given on line "
                             f"{self.names[name]}", line_of("name"), name, "name")
        if "mass" not in fields:
            raise self.error("a body needs a mass (such as '1 Msun', or 0 for a "
                             "massless body)", line_of(None), name, "mass")
        kwargs = {}
        for key, raw in fields.items():
            if key == "name":
                continue
            kind = BODY_FIELDS[key]
            if key in _VECTORS:
                kwargs[key] = self.vector(raw, kind, line_of(key), name, key)
            elif raw is not None:
                kwargs[key] = self.value(raw, kind, line_of(key), name, key)
        try:
            bodies.add(name, **kwargs)
        except BodyError as exc:
            field = exc.field if exc.field in fields else (
                "a" if exc.field == "elements" and "a" in fields else None)
            message = str(exc)
            prefix = _where(exc.body, exc.field) + ": "
            if message.startswith(prefix):
                message = message[len(prefix):]
            raise self.error(message, line_of(field), name, exc.field) from exc
        self.names[name] = line_of(None)

    def vector(self, raw, kind, line, body, field):
        """A three-component list as a Quantity in the set's units, or plain floats."""
        if isinstance(raw, (str, bytes)) or not isinstance(raw, (list, tuple)):
            raise self.error(f"expected a list of 3 components such as "
                             f"['1 au', '0 au', '0 au'], got {_toml_text(raw)}",
                             line, body, field)
        if len(raw) != 3:
            raise self.error(f"expected 3 components [x, y, z], got {len(raw)}",
                             line, body, field)
        parts = [self.value(c, kind, line, body, f"{field}[{k}]") for k, c in enumerate(raw)]
        if all(not isinstance(p, u.Quantity) for p in parts):
            return np.array(parts, dtype=np.float64)
        # each component converted on its own, as BodySet.add converts an array
        target = (self.units or UnitSystem.default()).unit(kind)
        out = np.empty(3)
        for k, p in enumerate(parts):
            if not isinstance(p, u.Quantity):
                raise self.error(f"component {k} has no unit while others have one: give "
                                 f"every component its unit", line, body, field)
            try:
                out[k] = p.to_value(target)
            except u.UnitConversionError:
                raise self.error(f"component {k}: expected a {kind} (such as "
                                 f"'{_example(kind)}'), got {p.unit.physical_type} "
                                 f"({p.unit})", line, body, field) from None
        return out << target

    def new_set(self):
        return BodySet(self.units) if self.units is not None else BodySet()


class _TomlReader(_Reader):
    def read(self):
        if _toml is None:  # pragma: no cover - Python 3.10 without tomli
            raise ImportError("reading TOML needs Python 3.11 or the tomli package")
        try:
            data = _toml.loads(self.text)
        except _toml.TOMLDecodeError as exc:
            m = re.search(r"at line (\d+)", str(exc))
            raise self.error(f"not valid TOML: {exc}", int(m.group(1)) if m else None) \
                from None
        except RecursionError:
            raise self.error("not valid TOML here: arrays or inline tables nested too "
                             "deeply to read", _failing_line(self.text, RecursionError)) \
                from None
        except ValueError as exc:
            # a value of valid form that Python cannot hold: an integer of
            # more digits than int() converts (4300)
            raise self.error(f"not valid TOML here: {exc}",
                             _failing_line(self.text, ValueError)) from None
        lines = _TomlLines(self.text)
        for key in data:
            if key not in ("units", "body", "run", "epoch"):
                raise self.error(_unknown("table", key, ("units", "body", "run", "epoch")),
                                 lines.find((key,)))
        if "epoch" in data:
            self.epoch = self.epoch_text(data["epoch"], lines.find(("epoch",)))
        if "units" in data:
            table = self.table(data["units"], "units", lines.find(("units",)))
            self.units = self.unit_system(table, lambda k: lines.find(("units", k)))
        tables = data.get("body")
        if not tables:
            raise self.error("no bodies: give each body as a [[body]] table with a name "
                             "and a mass", None)
        if not isinstance(tables, list):
            raise self.error("body must be an array of tables: write [[body]], with two "
                             "brackets, before each body", lines.find(("body",)))
        bodies = self.new_set()
        for i, table in enumerate(tables):
            header = lines.find(("body", i))
            table = self.table(table, "body", header)
            name = table.get("name") if isinstance(table.get("name"), str) else None
            for key in table:
                if key not in BODY_FIELDS:
                    raise self.error(_unknown("field", key, BODY_FIELDS, "of a body"),
                                     lines.find(("body", i, key)), name, key)
            self.add(bodies, table,
                     lambda k, i=i: lines.find(("body", i) if k is None else ("body", i, k)))
        bodies.history.append({"from": "file", "path": self.source})
        bodies.epoch = self.epoch
        run = {}
        if "run" in data:
            run = self.run_table(self.table(data["run"], "run", lines.find(("run",))),
                                 lambda *k: lines.find(("run", *k)))
        return SystemFile(bodies, run, self.source)

    def table(self, value, name, line):
        if not isinstance(value, dict):
            raise self.error(f"{name} must be a table ([{name}] above its keys), got "
                             f"{_toml_text(value)}", line, field=name)
        return value

    def run_table(self, table, line_of):
        run = {}
        for key, raw in table.items():
            kind = RUN_FIELDS.get(key)
            line = line_of(key)
            if kind is None:
                raise self.error(_unknown("field", key, RUN_FIELDS, "of [run]"), line,
                                 field=key)
            if kind in ("time", "length"):
                run[key] = self.quantity(raw, kind, line, key)
            elif kind == "text":
                run[key] = self.value(raw, "text", line, field=key)
            elif kind == "integer":
                if isinstance(raw, bool) or not isinstance(raw, int):
                    raise self.error(f"expected a whole number, got {_toml_text(raw)}",
                                     line, field=key)
                run[key] = raw
            elif kind == "boolean":
                if not isinstance(raw, bool):
                    raise self.error(f"expected true or false, got {_toml_text(raw)}",
                                     line, field=key)
                run[key] = raw
            else:
                run[key] = dict(self.table(raw, "run.options", line))
        for key, raw in run.get("options", {}).items():
            if isinstance(raw, int) and not isinstance(raw, bool):
                self.as_float(raw, line_of("options", key), field=key)
        if "integrator" in run:
            from . import integrators
            try:
                integrators.get(run["integrator"], **run.get("options", {}))
            except (ValueError, TypeError) as exc:
                key = next((k for k in run.get("options", {})
                            if re.search(rf"\b{re.escape(k)}\b", str(exc))), None)
                line = line_of("options", key) if key else line_of("integrator")
                raise self.error(str(exc), line, field=key or "integrator") from None
        return run


class _CsvReader(_Reader):
    units_hint = "a '# units: length = au; mass = Msun; time = day' line above the header"

    def read(self):
        bodies = self.read_table()
        if bodies is None:
            self.units, self.epoch, self.names = None, None, {}
            bodies = self.read_rows()
        bodies.history.append({"from": "file", "path": self.source})
        bodies.epoch = self.epoch
        return SystemFile(bodies, {}, self.source)

    def read_rows(self):
        """The bodies, added row by row as they come: the reading that finds an
        error in a file, first in the order of the file, with its line, body
        and field; and that reads rows of elements, each about the bodies
        above it."""
        reader = csv.reader(_io.StringIO(self.text))
        header = header_line = None
        bodies = None
        while True:
            line = reader.line_num + 1
            try:
                row = next(reader)
            except StopIteration:
                break
            except csv.Error as exc:
                raise self.error(f"not valid CSV: {exc}", reader.line_num) from None
            if _blank(row):
                continue
            if _comment(row):
                self.comment(row, line, header is not None)
                continue
            if header is None:
                header, header_line = self.header(row, line), line
                bodies = self.new_set()
                continue
            if len(row) != len(header):
                raise self.error(f"expected {len(header)} cells, as in the header on line "
                                 f"{header_line}, got {len(row)}", line)
            self.add(bodies, self.fields(header, row, line), lambda key, n=line: n)
        if header is None or not len(bodies):
            raise self.error("no bodies: a header row (name,mass [Msun],x [au],...) and "
                             "a row per body are needed", header_line)
        return bodies

    def read_table(self):
        """The bodies of a table of states or elements, read a column at a
        time; None for anything else (a cell that is not a number, a row of the
        wrong length, a bad header, elements that are no orbit, a primary not
        among the rows above...), which :meth:`read_rows` reads, or finds the
        error in.

        A column's numbers are converted to the set's unit at once, with the
        factor by which a cell-by-cell reading converts each: the same numbers,
        bit for bit.  A row of elements is then turned into a state with the
        arithmetic of :meth:`~orbits.BodySet.add` (:mod:`orbits.bodies._elements`
        and the primary's state, or the centre of mass of the rows above), and
        its history entry is the one ``add`` records: the same set, bit for
        bit.  (Row by row, each body costs a few astropy conversions and an
        ``add``, and each ``add`` copies the arrays: 1e5 bodies take minutes.)
        """
        try:
            # a row whose first cell has text is not blank: the question is
            # settled without joining the row, for almost every row
            records = [r for r in csv.reader(_io.StringIO(self.text))
                       if r and (r[0].strip() or not _blank(r))]
        except csv.Error:
            return None
        k = 0                   # the header's record: after the comments
        while k < len(records) and _comment(records[k]):
            k += 1
        if k == len(records):
            return None
        try:
            for row in records[:k]:
                self.comment(row, None, False)
            header = self.header(records[k], None)
        except SystemFileError:
            return None
        later = records[k + 1:]
        rows = [r for r in later if not _comment(r)]
        if len(rows) < len(later) and any(
                _comment_text(r).lower().startswith(("units:", "epoch:"))
                for r in later if _comment(r)):
            return None         # the units or the epoch after the header
        if not rows or set(map(len, rows)) != {len(header)}:
            return None
        units = dict(header)
        at = {c: j for j, c in enumerate(units)}
        names = [read_cell(r[at["name"]].strip()) for r in rows]
        try:
            numbers = {c: self.column([r[at[c]] for r in rows], c, units[c]) for c in units
                       if self.kind(c) != "text"}
        except ValueError:
            return None
        mass, empty, _ = numbers.pop("mass")
        n = len(names)
        if not all(names) or empty.any() or len(set(names)) != n:
            return None
        radius = numbers.pop("radius", (np.zeros(n), None, None))[0]
        state = {}
        stated = np.zeros(n, dtype=bool)
        for vec, comps in _VECTORS.items():
            if comps[0] not in numbers:
                state[vec] = np.zeros((n, 3))
                continue
            (x, ex, _), (y, ey, _), (z, ez, _) = (numbers[c] for c in comps)
            if not (np.array_equal(ex, ey) and np.array_equal(ey, ez)):
                return None      # a vector given in part: read_rows names the row
            state[vec] = np.column_stack((x, y, z))
            stated |= ~ex
        primaries = [None] * n
        if "primary" in at:
            primaries = [read_cell(r[at["primary"]].strip()) or None
                         if r[at["primary"]].strip() else False for r in rows]
            if None in primaries:
                return None      # a cell that reads as no name
            primaries = [p or None for p in primaries]
        elements = {c: numbers[c] for c in _ELEMENTS if c in numbers}
        given = np.array([p is not None for p in primaries])
        for _, e_empty, _ in elements.values():
            given |= ~e_empty
        if (given & stated).any():
            return None          # both a state and elements: read_rows names the row
        history = None
        if given.any():
            history = self.element_states(names, mass, primaries, elements, units, given,
                                          state)
            if history is None:
                return None
        to = (self.units or UnitSystem.default()).unit
        try:
            bodies = BodySet.from_arrays(mass << to("mass"), state["position"] << to("length"),
                                         state["velocity"] << to("velocity"), names=names,
                                         units=self.units, radii=radius << to("length"))
        except BodyError:
            return None
        if history is not None:
            bodies.history = history     # what BodySet.add records, a body at a time
        return bodies

    def element_states(self, names, mass, primaries, elements, column_units, given, state):
        """Fill ``state``'s rows of the bodies ``given`` by elements, in order,
        as :meth:`~orbits.BodySet.add` computes them; the history entries that
        ``add`` records, or None where a row is in error (:meth:`read_rows`
        names it)."""
        units = self.units or UnitSystem.default()
        x, v = state["position"], state["velocity"]
        if not (np.all(mass >= 0) and np.all(np.isfinite(mass)) and np.all(np.isfinite(x))
                and np.all(np.isfinite(v))):
            return None          # read_rows names the row before any orbit about it
        index = {}
        history = []
        # the history's text of each cell: str of the Quantity's value and its
        # unit, as orbits.bodies._input.describe writes a cell of a column with a unit
        text = {}
        for c, (_, empty, raw) in elements.items():
            unit = column_units[c]
            ustr = unit_string(unit) if unit is not None else ""
            if unit is None:
                text[c] = [None if e else str(float(r)) for r, e in zip(raw, empty)]
            elif ustr:
                text[c] = [None if e else f"{r} {ustr}" for r, e in zip(raw, empty)]
            else:
                text[c] = [None if e else str(r) for r, e in zip(raw, empty)]
        columns = {c: (values.tolist(), empty.tolist()) for c, (values, empty, _)
                   in elements.items()}
        for i, name in enumerate(names):
            index[name] = i
            if not given[i]:
                history.append({"name": name, "from": "state"})
                continue
            el = {c: (None if c not in columns or columns[c][1][i] else columns[c][0][i])
                  for c in _ELEMENTS}
            primary = primaries[i]
            if el["a"] is None:
                return None
            if primary is None:
                m = mass[:i]
                if i == 0 or not np.any(m > 0):
                    return None
                mt = m.sum()
                if not mt > 0:
                    return None
                mp, xp, vp = mt, (m @ x[:i]) / mt, (m @ v[:i]) / mt
            else:
                j = index.get(primary)
                if j is None or j == i:
                    return None
                mp, xp, vp = mass[j], x[j], v[j]
            e = 0.0 if el["e"] is None else el["e"]
            try:
                pos, vel = relative_state(name, units, mp, float(mass[i]), el["a"], e,
                                          el["inc"], el["Omega"], el["omega"], el["f"],
                                          el["M"])
            except BodyError:
                return None
            x[i] = xp + pos
            v[i] = vp + vel
            history.append({"name": name, "from": "elements", "primary": primary,
                            **{c: text[c][i] for c in _ELEMENTS
                               if c in text and text[c][i] is not None}})
        return history

    def column(self, cells, column, unit):
        """``(values, empty, raw)`` of a column of numbers (a list of its
        cells): in the set's unit, and as written; an empty cell 0; ValueError
        where a cell is not a number to ``float``, as in :meth:`fields`."""
        cells = list(map(str.strip, cells))
        empty = np.array(cells) == ""
        if empty.any():
            cells = [c or "0" for c in cells]
        raw = values = np.fromiter(map(float, cells), dtype=np.float64, count=len(cells))
        if unit is not None:
            values = (values * unit).to_value((self.units or UnitSystem.default())
                                              .unit(self.kind(column)))
        return values, empty, raw

    def comment(self, row, line, after_header):
        """A comment row: the ``# units:`` line gives the unit system."""
        text = _comment_text(row)
        if text.lower().startswith("units:"):
            if after_header:
                raise self.error("the '# units:' line must come before the header", line)
            self.units = self.unit_system(self.units_line(text[6:], line),
                                          lambda key, n=line: n)
        elif text.lower().startswith("epoch:"):
            if after_header:
                raise self.error("the '# epoch:' line must come before the header", line)
            self.epoch = self.epoch_text(text[6:].strip(), line)

    def units_line(self, text, line):
        table = {}
        for part in text.split(";"):
            if not part.strip():
                continue
            key, eq, value = part.partition("=")
            key, value = key.strip(), value.strip()
            if not eq:
                raise self.error(f"cannot read {part.strip()!r} in the units line: expected "
                                 f"key = value pairs separated by ';'", line)
            if key == "G":
                try:
                    value = float(value)
                except ValueError:
                    pass
            table[key] = value
        return table

    def header(self, row, line):
        columns = []
        for cell in row:
            m = _COLUMN.fullmatch(cell.strip())
            if not m:
                raise self.error(f"cannot read the column {cell!r}: expected a name with "
                                 f"its unit in brackets, such as 'mass [Msun]'", line)
            name, unit_text = m.group(1), m.group(2)
            if name not in CSV_COLUMNS:
                raise self.error(_unknown("column", name, CSV_COLUMNS), line, field=name)
            if name in (c for c, _ in columns):
                raise self.error(f"the column {name!r} is given twice", line, field=name)
            kind = self.kind(name)
            unit = None
            if kind == "text" and unit_text is not None:
                raise self.error(f"the column {name!r} holds names and takes no unit",
                                 line, field=name)
            if unit_text is not None and unit_text.strip():
                try:
                    unit = u.Unit(unit_text.strip())
                except ValueError:
                    raise self.error(f"unknown unit {unit_text.strip()!r} of the column "
                                     f"{name!r}", line, field=name) from None
                if not unit.is_equivalent(
                        UnitSystem.default().unit(kind)):
                    raise self.error(f"the column {name!r} is in {unit}, which is not a "
                                     f"{kind} unit (such as '{_example(kind)}')", line,
                                     field=name)
            elif kind == "angle":
                raise self.error(f"the angle column {name!r} needs a unit: write "
                                 f"'{name} [deg]' or '{name} [rad]'", line, field=name)
            elif kind not in ("text", "dimensionless") and self.units is None:
                raise self.error(f"the column {name!r} has no unit, and the file gives no "
                                 f"unit system: write '{name} [{_EXAMPLE_UNIT[kind]}]', or "
                                 f"give the units ({self.units_hint})", line, field=name)
            columns.append((name, unit))
        names = [c for c, _ in columns]
        for key in ("name", "mass"):
            if key not in names:
                raise self.error(f"a column {key!r} is needed", line, field=key)
        for vec, comps in _VECTORS.items():
            given = [c for c in comps if c in names]
            if given and len(given) != 3:
                raise self.error(f"{vec} needs the 3 columns {', '.join(comps)}; got only "
                                 f"{', '.join(given)}", line, field=vec)
        return columns

    @staticmethod
    def kind(column):
        for vec, comps in _VECTORS.items():
            if column in comps:
                return BODY_FIELDS[vec]
        return BODY_FIELDS[column]

    def fields(self, header, row, line):
        cells = {}
        name = read_cell(row[[c for c, _ in header].index("name")].strip()) or None
        for (column, unit), cell in zip(header, row):
            cell = cell.strip()
            if not cell:
                continue
            if self.kind(column) == "text":
                cells[column] = read_cell(cell)
                continue
            try:
                number = float(cell)
            except ValueError:
                raise self.error(f"cannot read {cell!r} as a number", line, name,
                                 column) from None
            cells[column] = number if unit is None else number * unit
        fields = {k: v for k, v in cells.items() if k not in ("x", "y", "z", "vx", "vy", "vz")}
        for vec, comps in _VECTORS.items():
            given = [c for c in comps if c in cells]
            if given and len(given) != 3:
                missing = [c for c in comps if c not in cells]
                raise self.error(f"{vec} needs x, y and z: {', '.join(missing)} empty",
                                 line, name, vec)
            if given:
                fields[vec] = [cells[c] for c in comps]
        return fields

    def value(self, raw, kind, line, body=None, field=None):
        # a cell of a column with a unit is already a Quantity
        if isinstance(raw, u.Quantity):
            return raw
        return super().value(raw, kind, line, body, field)


class _TomlLines:
    """Where each table and key of a TOML text is: ``find(("body", 2, "mass"))``
    gives the line of the third ``[[body]]``'s ``mass`` (tomllib keeps no positions)."""

    _KEY = re.compile(r"""^\s*((?:[A-Za-z0-9_-]+|"[^"]*"|'[^']*')"""
                      r"""(?:\s*\.\s*(?:[A-Za-z0-9_-]+|"[^"]*"|'[^']*'))*)\s*=""")

    def __init__(self, text):
        self.where = {}
        counts = {}
        table = ()
        open_string, depth = None, 0
        for n, line in enumerate(text.split("\n"), start=1):   # TOML's lines end at "\n"
            if open_string or depth:
                open_string, depth = _scan(line, open_string, depth)
                continue
            header = _table_header(line)
            if header:
                double, key = header
                keys = tuple(_split_key(key))
                if double:
                    k = counts[keys] = counts.get(keys, -1) + 1
                    table = (*keys, k)
                else:
                    table = keys
                self.where.setdefault(table, n)
                continue
            m = self._KEY.match(line)
            if m:
                self.where.setdefault((*table, _split_key(m.group(1))[0]), n)
                open_string, depth = _scan(line[m.end():], None, 0)

    def find(self, path):
        """The line of ``path``, or of the nearest enclosing table; None if unknown."""
        path = tuple(p for p in path if p is not None)
        for k in range(len(path), 0, -1):
            if path[:k] in self.where:
                return self.where[path[:k]]
        return None


def _table_header(line):
    """``(double, key)`` of a table header line, ``[key]`` or ``[[key]]`` with
    an optional comment after it; None for any other line.  Split by hand: a
    regular expression with a space-matching part on each side of the key
    takes time quadratic (or worse) in the spaces of a line that is no header."""
    text = line.strip()
    if not text.startswith("["):
        return None
    double = text.startswith("[[")
    text = text[2 if double else 1:]
    end = text.find("]")
    key = text[:end].strip() if end >= 0 else ""
    if not key or "[" in key:
        return None
    rest = text[end + 1:]
    rest = (rest[1:] if rest.startswith("]") else rest).lstrip()
    if rest and not rest.startswith("#"):
        return None
    return double, key


def _blank(row):
    return not row or not "".join(row).strip()


def _comment(row):
    return row[0].lstrip().startswith("#")


def _comment_text(row):
    # the row's cells put back together: the line's text, or the text of the
    # one quoted cell that a CSV writer makes of a line with commas
    return ",".join(row).lstrip()[1:].strip()


def _failing_line(text, error):
    """The first line of ``text`` from which TOML parsing raises ``error`` (not
    a TOMLDecodeError, which tells its line itself): the shortest run of whole
    lines from the start that raises it, by bisection (a line is parsed in
    full before the next, so the runs that raise it are those that reach it)."""
    lines = [line + "\n" for line in text.split("\n")]   # TOML's lines end at "\n" only

    def fails(k):
        try:
            _toml.loads("".join(lines[:k]))
        except _toml.TOMLDecodeError:
            return False
        except error:
            return True
        return False
    lo, hi = 0, len(lines)     # fails(hi); not fails(lo)
    if not fails(hi):
        return None
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if fails(mid):
            hi = mid
        else:
            lo = mid
    return hi


def _split_key(text):
    return [p.strip().strip("\"'") for p in re.findall(r'"[^"]*"|\'[^\']*\'|[^.]+', text)]


def _scan(text, open_string, depth):
    """Follow strings and brackets along a line: the open multi-line string
    delimiter and the bracket depth at its end."""
    i, n = 0, len(text)
    while i < n:
        if open_string:
            j = text.find(open_string, i)
            if j < 0:
                return open_string, depth
            i, open_string = j + 3, None
            continue
        c = text[i]
        if c == "#":
            break
        if text.startswith(('"""', "'''"), i):
            open_string, i = text[i:i + 3], i + 3
            continue
        if c in "\"'":
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if (c == '"' and text[j] == "\\") else 1
            i = j + 1
            continue
        if c in "[{":
            depth += 1
        elif c in "]}":
            depth -= 1
        i += 1
    return open_string, max(depth, 0)


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


# -- writing ------------------------------------------------------------------------
def write(bodies, path, run=None):
    """Write a body set to a TOML or CSV file, exactly.

    Parameters
    ----------
    bodies : BodySet
    path : str or os.PathLike
        Ending in ``.toml`` or ``.csv``; an existing file is replaced.
    run : dict, optional
        TOML only: a ``[run]`` table of defaults for ``orbits run`` (keys as in
        :data:`RUN_FIELDS`; times and lengths as Quantities).

    Notes
    -----
    States are written in the set's own units as the shortest decimal text that
    reads back as the same float64, with the unit system and its G, so
    :func:`read` gives the set back bit for bit.

    Examples
    --------
    >>> import os, tempfile
    >>> import numpy as np
    >>> import orbits
    >>> from orbits import systemfile
    >>> bodies = orbits.scenes.outer_solar_system()
    >>> path = os.path.join(tempfile.mkdtemp(), "outer.csv")
    >>> systemfile.write(bodies, path)
    >>> back = orbits.BodySet.read(path)
    >>> bool(np.array_equal(back.positions, bodies.positions))
    True
    """
    path = os.fspath(path)
    kind = _format_of(path)
    text = dumps(bodies, kind, run=run)
    with open(path, "w", encoding="utf-8", newline="") as fh:
        fh.write(text)


def dumps(bodies, kind="toml", run=None):
    """The text :func:`write` writes.

    Parameters
    ----------
    bodies : BodySet
    kind : {"toml", "csv"}
    run : dict, optional
        TOML only; see :func:`write`.

    Returns
    -------
    str

    Examples
    --------
    >>> import orbits
    >>> from orbits import systemfile
    >>> print(systemfile.dumps(orbits.scenes.kepler()))  # doctest: +ELLIPSIS
    # A body set for orbits...
    [[body]]
    name = "Star"
    mass = 1.0
    ...
    """
    if not isinstance(bodies, BodySet):
        raise TypeError(f"bodies must be a BodySet, got {type(bodies).__name__}")
    if kind == "toml":
        return _dump_toml(bodies, run)
    if kind == "csv":
        if run:
            raise ValueError("a CSV file holds no [run] table; write TOML for run defaults")
        return _dump_csv(bodies)
    raise ValueError(f"unknown body-set file format {kind!r}; expected 'toml' or 'csv'")


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
