"""The sweep's record in ``out_dir``: the index of finished runs
(``index.csv``), the sweep's fingerprint (``sweep.json``) and the runs' files.

A sweep run again with the same ``out_dir`` reads the index, keeps its
complete rows and checks that they, and the fingerprint, are of this sweep;
each finished run's row is appended to the index as one durable write.
pandas is imported only when an index is read or written.
"""

import csv
import hashlib
import io
import json
import math
import numbers
import os
import warnings

import numpy as np

from .._csvcells import read_cell, safe_cell
from .errors import EnsembleOptionError
from .perturbation import _Perturbation
from .table import (_ERROR_COLUMNS, _PLAIN_VALUE_COLUMNS, _RESULT_PREFIXES, _is_result_column,
                    _known_outcomes, _parameter_row)

__all__ = ["INDEX_FILE", "SWEEP_FILE"]


#: The index of finished runs in ``out_dir``: one CSV row per run, appended as
#: each finishes (one write of a whole line, then fsync), so that an interrupted
#: sweep knows what it has done.  On reading, only complete rows count: a line
#: cut off by a crash, or any row that does not parse whole, is dropped with a
#: warning and its run is done again.  A text cell that a spreadsheet would take
#: for a formula (a body named ``=HYPERLINK(...)``, in a column's name or in
#: ``stop_bodies``) begins with a single quote, which reading takes away.
INDEX_FILE = "index.csv"

#: What the sweep in ``out_dir`` is (runs, ``until``, outputs, a hash of the
#: parameters), so that a different sweep is not resumed into it by mistake.
#: Every row of the index is also checked against the parameters of the run of
#: its number, so that without this file (deleted) another sweep is still
#: refused.
SWEEP_FILE = "sweep.json"


def _path(out_dir, i):
    """The file of run ``i`` in ``out_dir`` (None without one)."""
    return None if out_dir is None else out_dir / f"run-{i:05d}.h5"


def _fingerprint(build, parameters, spec):
    """What the sweep of ``build`` over ``parameters`` to ``spec`` is, as the hex
    digest that ``sweep.json`` records."""
    h = hashlib.sha1()
    h.update(json.dumps([_describe(build), len(parameters), str(spec.until), spec.outputs,
                         spec.elements, parameters],
                        sort_keys=True, default=str).encode())
    if isinstance(build, _Perturbation):
        h.update(build.fingerprint())
    return h.hexdigest()


def _describe(build):
    """What ``build`` is, in a few words: its name, or what a perturbed ensemble's is."""
    if isinstance(build, _Perturbation):
        return "perturbed copies of a simulation"
    return getattr(build, "__qualname__", type(build).__name__)


def _open_out_dir(out_dir, fingerprint, parameters):
    """Create ``out_dir`` or check it holds this sweep; the rows already finished.

    The sweep is this one if ``sweep.json`` says so and every row of the index
    has the parameters of this sweep's run of its number; without a
    ``sweep.json`` (deleted), the rows alone decide.
    """
    out_dir.mkdir(parents=True, exist_ok=True)
    sweep = out_dir / SWEEP_FILE
    stored = _stored_fingerprint(sweep) if sweep.exists() else None
    if stored is not None and stored != fingerprint:
        raise EnsembleOptionError(f"{out_dir} holds another sweep (different build, "
                                  f"parameters, until, outputs or elements); use a new "
                                  f"out_dir")
    index = out_dir / INDEX_FILE
    rows = {}
    if index.exists():
        frame = _read_index(index, len(parameters))
        for rec in frame.to_dict(orient="records"):
            rec = {k: _from_csv(k, val) for k, val in rec.items()}
            rows[int(rec["run"])] = rec
        _check_rows_are_of(rows, parameters, out_dir)
    if stored is None:
        _write_whole(sweep, json.dumps({"fingerprint": fingerprint}) + "\n")
    return rows


def _stored_fingerprint(sweep):
    """The fingerprint ``sweep.json`` records; a file that holds none is refused
    by name rather than trusted or overwritten."""
    try:
        stored = json.loads(sweep.read_bytes().decode("utf-8"))
    except (UnicodeDecodeError, ValueError) as exc:
        stored = exc
    if not (isinstance(stored, dict) and isinstance(stored.get("fingerprint"), str)):
        raise EnsembleOptionError(
            f"{sweep} does not record a sweep (expected a JSON object with its "
            f"'fingerprint'); delete it to resume the sweep whose rows {INDEX_FILE} "
            f"holds, which are checked against the parameters, or use a new out_dir")
    return stored["fingerprint"]


def _check_rows_are_of(rows, parameters, out_dir):
    """Refuse rows of another sweep: every row must hold the parameters of the
    run of its number, and no parameter this sweep does not have."""
    expected = [_parameter_row(p, i) for i, p in enumerate(parameters)]
    columns = {k for row in expected for k in row}
    for i, rec in rows.items():
        want = expected[i]
        for col in sorted(set(rec) | set(want)):
            if col == "run" or (col not in columns and _is_result_column(col)):
                continue
            got = rec.get(col, _ABSENT)
            if col not in want and _is_empty(got):
                continue
            if not _same_value(want.get(col, _ABSENT), got):
                raise EnsembleOptionError(
                    f"{out_dir} holds another sweep: in its {INDEX_FILE}, run {i} has "
                    f"{col} = {_shown(got)}, where this sweep's run {i} has "
                    f"{col} = {_shown(want.get(col, _ABSENT))}; use a new out_dir")


_ABSENT = type("_Absent", (), {"__repr__": lambda self: "(no such column)"})()


def _shown(value):
    return "(none)" if value is _ABSENT else repr(value)


def _is_empty(value):
    return value is None or value == "" or (isinstance(value, float) and math.isnan(value))


def _same_value(want, got):
    """Whether ``got``, a parameter as read back from the index, is ``want``."""
    if want is _ABSENT or got is _ABSENT:
        return want is got
    if want is None or _is_empty(want):
        return _is_empty(got)
    if isinstance(want, bool) or isinstance(got, bool):
        return str(want) == str(got)
    if isinstance(want, numbers.Real) or isinstance(got, numbers.Real):
        # a number, or text that pandas reads as one ("5")
        try:
            a, b = float(want), float(got)
        except (TypeError, ValueError):
            return False
        return a == b or (math.isnan(a) and math.isnan(b))
    return str(want) == str(got)


def _index_records(data, n_runs):
    """What an index's bytes hold: ``(header, header_raw, good, dropped)``, the
    header's fields and text, ``(fields, raw text)`` of each complete row, and
    how many rows were not complete (see :func:`_read_index`)."""
    # every write ends a row with "\n": whatever follows the last one is a cut-off row
    end = data.rfind(b"\n") + 1
    records = list(_csv_records(data[:end].decode("utf-8", errors="replace")))
    dropped = int(end < len(data))
    header, header_raw = records.pop(0) if records else (None, "")
    if header is None or "run" not in header or "outcome" not in header:
        header, dropped = None, dropped + len(records)   # without a header no row counts
        records = []
    good = []
    for fields, raw in records:
        if fields is not None and _complete_row(dict(zip(header, fields)), len(fields),
                                                len(header), n_runs):
            good.append((fields, raw))
        else:
            dropped += 1
    return header, header_raw, good, dropped


def _saved_runs(index, n_runs):
    """How many runs ``index`` holds complete rows of (read only)."""
    try:
        header, _, good, _ = _index_records(index.read_bytes(), n_runs)
    except OSError:
        return 0
    if header is None:
        return 0
    at = header.index("run")
    return len({float(fields[at]) for fields, _ in good})


def _read_index(index, n_runs):
    """The complete rows of ``index`` as a DataFrame.

    A row counts only if it ends with its newline, parses as CSV into as many
    fields as the header has, names a run of this sweep and a known outcome, and
    has numbers where numbers belong.  Anything else (the half-written line a
    crash leaves, above all) is dropped with a warning, and the file is rewritten
    without it, so that its runs are done again and the next row starts on a
    line of its own.
    """
    import pandas as pd

    header, header_raw, good, dropped = _index_records(index.read_bytes(), n_runs)
    good = [raw for _, raw in good]
    if dropped:
        warnings.warn(f"{index}: dropped {dropped} incomplete or unreadable row(s) "
                      f"(a write cut off); their runs will be run again", stacklevel=4)
        if header is None:
            index.unlink()
        else:
            _write_whole(index, header_raw + "".join(good))
    if header is None:
        return pd.DataFrame({"run": []})
    return _parse_index(header_raw + "".join(good))


def _parse_index(text):
    import pandas as pd
    # floats come back bit for bit: pandas 3 parses them exactly by default,
    # pandas 2 only when asked for "round_trip"
    exact = {} if int(pd.__version__.split(".")[0]) >= 3 else {"float_precision": "round_trip"}
    frame = pd.read_csv(io.StringIO(text), keep_default_na=False, na_values=[""], **exact)
    # text cells as they were before _to_csv made them safe for a spreadsheet
    frame = frame.rename(columns=read_cell)
    for c in frame.columns:
        if frame[c].dtype.kind == "O":
            frame[c] = frame[c].map(lambda v: read_cell(v) if isinstance(v, str) else v)
    return frame


def _csv_records(text):
    """``(fields, raw text)`` of each CSV record of ``text``; ``fields`` is None
    for a record that does not parse (an unterminated quote, above all)."""
    raw = []

    def lines():
        for line in io.StringIO(text, newline=""):
            raw.append(line)
            yield line

    reader = csv.reader(lines(), strict=True)
    while True:
        try:
            fields = next(reader)
        except StopIteration:
            return
        except csv.Error:
            fields = None
        yield fields, "".join(raw)
        raw.clear()


_INTEGER_COLUMNS = ("run", "steps", "kernels_compiled", "kernels_loaded")
_REAL_COLUMNS = (*_ERROR_COLUMNS, "wall_time_s", *_PLAIN_VALUE_COLUMNS)


def _complete_row(row, n_fields, n_header, n_runs):
    if n_fields != n_header:
        return False
    try:
        if not 0 <= float(row["run"]) < n_runs:
            return False
        for key, val in row.items():
            if key in _INTEGER_COLUMNS and not float(val).is_integer():
                return False
            if (key in _REAL_COLUMNS or key.startswith(_RESULT_PREFIXES)) \
                    and val != "":
                float(val)
    except ValueError:
        return False
    return row["outcome"] in _known_outcomes()


_TEXT_COLUMNS = ("outcome", "message", "stop_bodies", "worker", "file")


def _from_csv(key, val):
    if key in _TEXT_COLUMNS:
        return "" if isinstance(val, float) and math.isnan(val) else str(val)
    return val.item() if isinstance(val, np.generic) else val


def _finish(row, rows, out_dir):
    rows[row["run"]] = row
    if out_dir is None:
        return
    import pandas as pd

    index = out_dir / INDEX_FILE
    frame = pd.DataFrame([row])
    header = _index_header(index)
    if header is not None and set(frame.columns) <= set(header):
        _append_whole(index, _to_csv(frame.reindex(columns=header), header=False))
        return
    if header is not None:
        # keep one header: a row with columns the file lacks rewrites the file (its
        # rows are all complete: _open_out_dir kept only those, and rows are
        # appended whole)
        frame = pd.concat([_parse_index(index.read_text(encoding="utf-8")), frame],
                          ignore_index=True)
    _write_whole(index, _to_csv(frame, header=True))


def _index_header(index):
    try:
        with open(index, encoding="utf-8", newline="") as f:
            first = f.readline()
    except FileNotFoundError:
        return None
    header = next(csv.reader([first]), None) if first.endswith("\n") else None
    return None if header is None else [read_cell(c) for c in header]


def _to_csv(frame, header):
    """``frame`` as CSV rows, every text cell (a header, a name, a message) safe
    to open in a spreadsheet (``orbits._csvcells``); numbers as they are."""
    frame = frame.rename(columns=safe_cell)
    for c in frame.columns:
        if frame[c].dtype.kind == "O":
            frame[c] = frame[c].map(lambda v: safe_cell(v) if isinstance(v, str) else v)
    return frame.to_csv(index=False, header=header, lineterminator="\n")


def _append_whole(path, text):
    """Append ``text`` (whole lines) in one write and make it durable before the
    next run is counted: a crash leaves the file without the line or with a
    line that lacks its newline, which :func:`_read_index` drops."""
    data = memoryview(text.encode("utf-8"))
    fd = os.open(path, os.O_WRONLY | os.O_APPEND | getattr(os, "O_BINARY", 0))
    try:
        while data:   # one write for a regular file; the loop is for a short write
            data = data[os.write(fd, data):]
        os.fsync(fd)
    finally:
        os.close(fd)


def _write_whole(path, text):
    """Replace ``path`` by ``text`` at once: written to a temporary file, synced,
    then renamed over it, so that a crash leaves the old file or the new one."""
    tmp = path.with_name(path.name + ".tmp")
    with open(tmp, "w", encoding="utf-8", newline="") as f:
        f.write(text)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)
