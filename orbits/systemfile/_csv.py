"""Reading CSV body-set files: a table of states or elements read a column at
a time, and row by row where a file has an error to find, with the same
numbers bit for bit; the ``# units:`` and ``# epoch:`` comments; names as a
spreadsheet writes them (:mod:`orbits._csvcells`)."""

import csv
import io as _io
import re

import astropy.units as u
import numpy as np

from .._csvcells import read_cell
from ..bodies import BodySet
from ..bodies._elements import relative_state
from ..bodies._input import unit_string
from ..errors import BodyError, SystemFileError
from ..units import UnitSystem
from ._reader import SystemFile, _Reader
from ._schema import (_ELEMENTS, _EXAMPLE_UNIT, _VECTORS, BODY_FIELDS, CSV_COLUMNS, _example,
                      _unknown)

__all__ = []

# a CSV column, "mass [Msun]", stripped: one way to match again
_COLUMN = re.compile(r"([A-Za-z_]\w*)(?:\s*\[(.*)\])?")


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


def _blank(row):
    return not row or not "".join(row).strip()


def _comment(row):
    return row[0].lstrip().startswith("#")


def _comment_text(row):
    # the row's cells put back together: the line's text, or the text of the
    # one quoted cell that a CSV writer makes of a line with commas
    return ",".join(row).lstrip()[1:].strip()
