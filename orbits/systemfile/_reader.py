"""Reading a body-set file's values, what the TOML and CSV readers share: a
number with its unit or in the file's units, the unit system, a vector of
three components, and a body added to the set, each failure a
:class:`~orbits.errors.SystemFileError` with its line, body and field; and
the record a reading gives (:class:`SystemFile`)."""

import re
from typing import NamedTuple

import astropy.units as u
import numpy as np

from .. import epochs as _epochs
from ..bodies import BodySet
from ..errors import BodyError, EpochError, SystemFileError, _named, _where
from ..units import UnitSystem
from ._schema import (_EXAMPLE_UNIT, _VECTORS, BODY_FIELDS, UNIT_FIELDS, _example, _toml_text,
                      _unknown)

__all__ = ["SystemFile"]

# each part can end in only one way (no two adjacent runs of digits), so a
# long string of digits that fails does so in linear time
_NUMBER = re.compile(r"\s*[-+]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][-+]?\d+)?\s*")


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
            prefix = _where(_named("body", exc.body), _named("field", exc.field)) + ": "
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
