"""Reading TOML body-set files: the tables checked key by key, and the line
of each table and key found in the text (``tomllib`` keeps no positions) for
the messages."""

import re

from .. import integrators
from ._reader import SystemFile, _Reader
from ._schema import BODY_FIELDS, RUN_FIELDS, _toml_text, _unknown

try:
    import tomllib as _toml
except ModuleNotFoundError:  # pragma: no cover - Python 3.10
    try:
        import tomli as _toml
    except ModuleNotFoundError:
        _toml = None

__all__ = []

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
            try:
                integrators.get(run["integrator"], **run.get("options", {}))
            except (ValueError, TypeError) as exc:
                key = next((k for k in run.get("options", {})
                            if re.search(rf"\b{re.escape(k)}\b", str(exc))), None)
                line = line_of("options", key) if key else line_of("integrator")
                raise self.error(str(exc), line, field=key or "integrator") from None
        return run


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
