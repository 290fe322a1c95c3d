"""What a reader trusts: a file opened for reading (:func:`_open_read`), its
layout complete and every value a reader uses checked for type, shape and range.

A file carries data, never code.  Nothing it names is imported (the
functions of a run are named in ``/parameters`` and come back from the
caller of :meth:`orbits.Simulation.from_file`), and nothing outside it is
read: external and user-defined links, datasets stored in external files or
as virtual views, and filters that HDF5 would load as plugins are refused
(:func:`_inventory`).  Declared shapes are checked against the bodies' count
and against the bytes the file stores before anything is read, and of a time
series only the rows stored are read (:func:`_covered`), so that a small file
cannot make a reader allocate for data it does not hold.  Every control
value (the checkpoints' count, clock, plan, progress, the bodies' order, the
units and the recorded configuration) is checked for type, shape and range
(:func:`_check_values`); what fails is an :class:`OrbitsFileError` naming the
dataset or attribute and what was expected.
"""

import functools
import json
import math
import pathlib

import astropy.units as u
import h5py
import numpy as np

from ... import epochs as _epochs
from ..._kernels import invariants as _inv
from ..._monitor_specs import BY_NAME, CHOSEN, MONITOR_SPECS, added_to
from ...errors import OrbitsError
from ...units import UnitSystem
from .errors import OrbitsFileError
from .layout import (FORMAT, FORMAT_VERSION, _COLLISION_COLUMNS, _DATASETS,
                     _ENCOUNTER_COLUMNS, _GROUPS, _PARAMETERS, _SLOTS, _UNITS, _config,
                     _config_layout)
from .safety import _VLEN_BYTES, _covered, _inventory, _open_hdf5

__all__ = []

#: the largest |jd1| an epoch attribute may hold: 1e9 days, 2.7 million years
#: either side of JD 0 (a damaged attribute, not a date, beyond)
_EPOCH_JD_LIMIT = 1e9


def _check_layout(f, path, contents):
    """Raise an OrbitsFileError naming, in words, what the layout misses
    (``contents``: the file's :func:`_inventory`)."""
    missing = []
    absent = set()

    def exists(name, kind):
        if name in absent:
            return False
        parent, _, _ = name.rpartition("/")
        if parent and not exists(parent, h5py.Group):
            return False
        if name in (contents.groups if kind is h5py.Group else contents.datasets):
            return True
        absent.add(name)
        what = _GROUPS.get(name) or _DATASETS.get(name, "")
        noun = "the group /" if kind is h5py.Group else "/"
        missing.append(f"{noun}{name} ({what})" if what else f"{noun}{name}")
        return False

    for name in _DATASETS:
        exists(name, h5py.Dataset)
    exists("observables/in_loop", h5py.Group)
    exists("restart/ws", h5py.Group)
    monitors = ()
    if "parameters" in contents.groups:
        par = f["parameters"].attrs
        missing += [f"the attribute {k!r} of /parameters (the run's metadata)"
                    for k in _PARAMETERS if k not in par]
        if "monitors" in par:
            monitors = _monitors_attr(f["parameters"], path)
    for name in monitors:
        for part in ("step", "time", "value"):
            exists(f"observables/{name}/{part}", h5py.Dataset)
            exists(f"observables/in_loop/{name}/{part}", h5py.Dataset)
    for name in _UNITS:
        obj = f.get(name) if not missing else None
        if isinstance(obj, h5py.Dataset) and "unit" not in obj.attrs:
            missing.append(f"the unit of /{name}")
    if missing:
        shown = missing[:6] + ([f"and {len(missing) - 6} more"] if len(missing) > 6 else [])
        raise OrbitsFileError(f"{path}: damaged or incomplete orbits file: missing "
                              + "; ".join(shown))
    return monitors


def _open_read(path):
    path = pathlib.Path(path)
    if not path.exists():
        raise OrbitsFileError(f"{path}: no such file")
    if path.is_dir():
        raise OrbitsFileError(f"{path}: a folder, not an orbits output file")
    f = _open_hdf5(path)
    try:
        fmt = f.attrs.get("orbits_format")
        if not isinstance(fmt, str) or fmt != FORMAT:
            raise OrbitsFileError(f"{path}: not an orbits output file (no "
                                  f"orbits_format = {FORMAT!r} attribute)")
        version = f.attrs.get("orbits_format_version", -1)
        if not _is_int(version) or version != FORMAT_VERSION:
            shown = int(version) if _is_int(version) else repr(version)
            raise OrbitsFileError(f"{path}: layout version {shown}, but this orbits "
                                  f"reads version {FORMAT_VERSION}")
        # nothing is opened by name before the links are known to stay in the file
        contents = _inventory(f, path)
        _check_values(f, contents.datasets, path, _check_layout(f, path, contents))
    except BaseException as exc:
        f.close()
        if isinstance(exc, (OSError, RuntimeError)) and not isinstance(exc, OrbitsFileError):
            raise OrbitsFileError(f"{path}: damaged orbits file: {exc}") from None
        raise
    return f


_KINDS = {"float": "f", "int": "iu", "str": "OS", "number": "fiub"}


def _checked(stored, name, path, shape, kind, backed=True):
    """The :class:`_Stored` of the dataset ``name``, checked before anything is
    read from it: its ``shape`` (None for an axis of any length), its type,
    and (``backed``) that the file stores all the data that shape declares."""
    ds = stored.get(name)
    if ds is None:
        raise OrbitsFileError(f"{path}: damaged or incomplete orbits file: /{name} is not "
                              f"a dataset")
    if ds.shape is None or len(ds.shape) != len(shape) or any(
            want is not None and have != want for have, want in zip(ds.shape, shape)):
        want = "(" + ", ".join("any" if k is None else str(k) for k in shape) + \
            ("," if len(shape) == 1 else "") + ")"
        raise OrbitsFileError(f"{path}: /{name} has shape {ds.shape}; expected {want}")
    ok = ds.dtype is not None and ds.dtype.kind in _KINDS[kind]
    if ok and ds.dtype.kind == "O":
        ok = kind == "str" and h5py.check_string_dtype(ds.dtype) is not None
    if not ok:
        raise OrbitsFileError(f"{path}: /{name} holds values of type {ds.dtype}; expected "
                              f"{'strings' if kind == 'str' else kind + 's'}")
    element = _VLEN_BYTES if ds.dtype.kind == "O" else ds.dtype.itemsize
    declared = int(np.prod(ds.shape, dtype=np.int64)) * element
    if backed and declared > ds.stored:
        raise OrbitsFileError(
            f"{path}: /{name} declares shape {ds.shape} ({declared} bytes), but the file "
            f"stores less of it; refused before reading")
    return ds


@functools.lru_cache(maxsize=256)
def _parsed_unit(text, like):
    """``(unit, of the kind of like)`` for a unit's name; None if it names none
    (parsed once: astropy takes about a millisecond for ``"AU / d"``).  The
    empty name, plain numbers, stands for every kind: N-body units
    (``UnitSystem.nbody()``) write it for lengths, masses and times alike."""
    try:
        unit = u.Unit(text)
    except (ValueError, TypeError):
        return None
    return unit, (like is None or unit == u.dimensionless_unscaled
                  or unit.is_equivalent(u.Unit(like)))


#: the physical type that a unit's name in _unit's ``like`` stands for
_KIND_OF = {"m": "length", "kg": "mass", "s": "time", "m / s": "speed"}


def _unit(f, name, path, like=None):
    """The ``unit`` attribute of the dataset ``name``, parsed, and (``like``, a
    unit's name) of the physical type of that unit."""
    text = f[name].attrs.get("unit")
    parsed = _parsed_unit(text, like) if isinstance(text, str) else None
    if parsed is None:
        raise OrbitsFileError(f"{path}: /{name} has the unit {text!r}; expected a unit's "
                              f"name")
    if not parsed[1]:
        raise OrbitsFileError(f"{path}: /{name} has the unit {text!r}; expected a unit of "
                              f"{_KIND_OF[like]}")
    return parsed[0]


def _json_attr(par, key, path, kind):
    """The /parameters attribute ``key``, a JSON text, parsed and of type ``kind``."""
    text = par.attrs[key]
    try:
        value = json.loads(text)
    except (TypeError, ValueError, RecursionError):
        raise OrbitsFileError(f"{path}: the {key!r} attribute of /parameters is not "
                              f"readable JSON") from None
    if not isinstance(value, kind):
        raise OrbitsFileError(f"{path}: the {key!r} attribute of /parameters is "
                              f"{type(value).__name__}; expected a JSON "
                              f"{'object' if kind is dict else 'array'}")
    return value


def _monitors_attr(par, path):
    """The monitors a file records: a list of distinct known names."""
    monitors = _json_attr(par, "monitors", path, list)
    known = [s.name for s in CHOSEN]
    for name in monitors:
        if not isinstance(name, str) or name not in known:
            raise OrbitsFileError(f"{path}: the 'monitors' attribute of /parameters names "
                                  f"{name!r}; expected monitors among {', '.join(known)}")
    if len(set(monitors)) != len(monitors):
        raise OrbitsFileError(f"{path}: the 'monitors' attribute of /parameters names a "
                              f"monitor twice: {monitors}")
    return tuple(monitors)


def _is_int(value):
    return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))


def _is_number(value):
    return isinstance(value, (int, float, np.integer, np.floating)) and \
        not isinstance(value, (bool, np.bool_)) and math.isfinite(value)


def _attr(par, key, path, check, expected):
    value = par.attrs[key]
    if not check(value):
        raise OrbitsFileError(f"{path}: the {key!r} attribute of /parameters is {value!r}; "
                              f"expected {expected}")
    return value


def _epoch(par, path):
    """The file's epoch (``astropy.time.Time``, TDB) from the ``epoch_tdb``
    attribute of /parameters, or None where it has none; an
    :class:`OrbitsFileError` where the attribute is not two finite float64
    parts of a Julian date (``|jd2| <= 1``, as :func:`orbits.epochs.to_pair`
    writes them)."""
    if "epoch_tdb" not in par.attrs:
        return None
    value = par.attrs["epoch_tdb"]
    arr = np.asarray(value)
    ok = arr.shape == (2,) and arr.dtype.kind == "f"
    if ok:
        jd1, jd2 = (float(a) for a in arr)
        ok = math.isfinite(jd1) and math.isfinite(jd2) and abs(jd2) <= 1.0 \
            and abs(jd1) < _EPOCH_JD_LIMIT
    if not ok:
        raise OrbitsFileError(f"{path}: the 'epoch_tdb' attribute of /parameters is "
                              f"{value!r}; expected the Julian date of the run's time 0 in "
                              f"TDB as two float64 parts (jd1, jd2), |jd2| <= 1")
    return _epochs.from_pair(jd1, jd2)


def _check_units_record(units, path):
    """Raise an OrbitsFileError where the unit system a file records (a
    UnitSystem.to_dict()) does not have the fields and kinds of units it needs."""
    plain = []
    for key, like in (("length", "m"), ("mass", "kg"), ("time", "s")):
        text = units.get(key)
        parsed = _parsed_unit(text, like) if isinstance(text, str) else None
        if parsed is None or not parsed[1]:
            raise OrbitsFileError(f"{path}: the unit system in /parameters has {key} "
                                  f"{text!r}; expected a unit of {_KIND_OF[like]}")
        plain.append(text == "")
    if any(plain) and not all(plain):
        raise OrbitsFileError(f"{path}: the unit system in /parameters has plain numbers "
                              f"for some of length, mass and time but not all: "
                              f"{[units[k] for k in ('length', 'mass', 'time')]}")
    if not (_is_number(units.get("G")) and units["G"] > 0):
        raise OrbitsFileError(f"{path}: the unit system in /parameters has G = "
                              f"{units.get('G')!r}; expected a number > 0")
    for key in ("name", "G_source"):
        if not isinstance(units.get(key), str):
            raise OrbitsFileError(f"{path}: the unit system in /parameters has {key} "
                                  f"{units.get(key)!r}; expected a string")


def _unit_system(par, path):
    """The UnitSystem of a file's /parameters (checked by :func:`_check_values`)."""
    try:
        return UnitSystem.from_dict(json.loads(par.attrs["units"]))
    except (OrbitsError, ValueError, TypeError, u.UnitsError) as exc:
        raise OrbitsFileError(f"{path}: the unit system in /parameters does not rebuild: "
                              f"{exc}") from None


def _check_config(config, path, monitors):
    """Raise an OrbitsFileError where the configuration record (a
    SimulationConfig.to_dict()) a file keeps is not of the types that record has."""
    def bad(field, value, expected):
        return OrbitsFileError(f"{path}: the configuration in /parameters has {field} = "
                               f"{value!r}; expected {expected}")

    def quantity(value):
        return (isinstance(value, list) and len(value) == 2 and isinstance(value[1], str)
                and (_is_number(value[0]) or isinstance(value[0], list)))

    for key in ("integrator", "integrator_options", "dt", "forces", "monitors",
                "monitor_every", "stop_conditions"):
        if key not in config:
            raise OrbitsFileError(f"{path}: the configuration in /parameters lacks "
                                  f"{key!r}")
    if not isinstance(config["integrator"], str):
        raise bad("integrator", config["integrator"], "an integrator's name")
    if not isinstance(config["integrator_options"], dict):
        raise bad("integrator_options", config["integrator_options"], "a JSON object")
    if config["dt"] is not None and not quantity(config["dt"]):
        raise bad("dt", config["dt"], "null or [value, unit]")
    forces = config["forces"]
    if not isinstance(forces, list) or not forces or not all(
            isinstance(d, dict) and isinstance(d.get("type"), str) for d in forces):
        raise bad("forces", forces, "a list of force terms' records, gravity's first")
    if config["monitors"] != list(monitors):
        raise bad("monitors", config["monitors"],
                  f"the monitors the file keeps, {list(monitors)}")
    every = config["monitor_every"]
    if every is not None and not (_is_int(every) and every >= 1):
        raise bad("monitor_every", every, "null or a whole number >= 1")
    stops = config["stop_conditions"]
    if not isinstance(stops, dict) or not all(
            v is None or isinstance(v, (bool, str)) or _is_number(v) or quantity(v)
            for v in stops.values()):
        raise bad("stop_conditions", stops, "an object of numbers, names and [value, unit]")
    variations = config.get("variations")
    if not (variations is None or variations in ("state", "all")
            or (_is_int(variations) and variations >= 1)):
        raise bad("variations", variations, 'null, "state", "all" or a whole number >= 1')
    seed = config.get("seed")
    if seed is not None and not (_is_int(seed) and seed >= 0):
        raise bad("seed", seed, "null or a whole number >= 0")


def _check_values(f, stored, path, monitors):
    """Raise an OrbitsFileError for a value a reader would use that is not of the
    type, shape or range the layout gives it; called by :func:`_open_read`
    once the layout is complete, with the file's :func:`_inventory`.

    Shapes are checked against the bodies' count and the file's own size
    before anything is read, so that a small file cannot make a reader
    allocate for data it does not hold; the control values (the checkpoints'
    count, clock, plan and progress) are read and checked.
    """
    par = f["parameters"]
    for key in ("orbits_version", "written", "integrator", "dt_unit"):
        _attr(par, key, path, lambda v: isinstance(v, str), "a string")
    _attr(par, "dt", path, lambda v: _is_number(v) and v >= 0, "a number >= 0")
    parsed = _parsed_unit(par.attrs["dt_unit"], "s")
    if parsed is None or not parsed[1]:
        raise OrbitsFileError(f"{path}: the 'dt_unit' attribute of /parameters is "
                              f"{par.attrs['dt_unit']!r}; expected a unit of time")
    _json_attr(par, "integrator_options", path, dict)
    info = _json_attr(par, "integrator_info", path, dict)
    if not (isinstance(info.get("name"), str) and _is_int(info.get("order"))
            and isinstance(info.get("symplectic"), bool)
            and isinstance(info.get("adaptive", False), bool)):
        raise OrbitsFileError(f"{path}: the 'integrator_info' attribute of /parameters is "
                              f"{info!r}; expected the integrator's name, order and kind")
    _json_attr(par, "bodies_history", path, list)
    _check_units_record(_json_attr(par, "units", path, dict), path)
    if "forces" in par.attrs:
        records = _json_attr(par, "forces", path, list)
        if not all(isinstance(d, dict) and isinstance(d.get("type"), str) for d in records):
            raise OrbitsFileError(f"{path}: the 'forces' attribute of /parameters is "
                                  f"{records!r}; expected force terms' records")
    if "config" in par.attrs:
        _check_config(_json_attr(par, "config", path, dict), path, monitors)
    _epoch(par, path)

    # the bodies: their count N is the length of every per-body axis
    b = "particles/bodies"
    n = _checked(stored, f"{b}/names", path, (None,), "str").shape[0]
    if n < 1:
        raise OrbitsFileError(f"{path}: /{b}/names is empty; expected one name a body")
    _checked(stored, f"{b}/mass", path, (n,), "float")
    _unit(f, f"{b}/mass", path, "kg")
    if f"{b}/radius" in stored:
        _checked(stored, f"{b}/radius", path, (n,), "float")
        _unit(f, f"{b}/radius", path, "m")
    # the time series: any number of rows, of which only those stored are read
    series = {f"{b}/position": ((n, 3), "m"), f"{b}/velocity": ((n, 3), "m / s")}
    if f"{b}/masses_at_outputs/value" in stored:
        series[f"{b}/masses_at_outputs"] = ((n,), "kg")
    kept = list(monitors) + [s.name for name in monitors for s in added_to(name)
                             if f"observables/{s.name}/value" in stored]
    for name in kept:
        shape = BY_NAME[name].shape
        series[f"observables/{name}"] = (shape, None)
        if f"observables/in_loop/{name}/value" in stored:
            series[f"observables/in_loop/{name}"] = (shape, None)
    for group, (shape, like) in series.items():
        _checked(stored, f"{group}/step", path, (None,), "int", backed=False)
        _checked(stored, f"{group}/time", path, (None,), "float", backed=False)
        _checked(stored, f"{group}/value", path, (None,) + shape, "float", backed=False)
        _unit(f, f"{group}/time", path, "s")
        _unit(f, f"{group}/value", path, like)
    # the parameters' arrays
    # files written before the series added to others (the work) were kept
    # have the columns before them
    width = len(_inv.MONITOR_COLUMNS)
    oldest = min(s.row_slice.start for s in MONITOR_SPECS if s.adds_to is not None)
    ref = _checked(stored, "parameters/reference", path, (None,), "float")
    if not oldest <= ref.shape[0] <= width:
        raise OrbitsFileError(f"{path}: /parameters/reference has {ref.shape[0]} values; "
                              f"expected {oldest} to {width}")
    _checked(stored, "parameters/scales", path, (2,), "float")
    if "parameters/start_clock" in stored:
        _checked(stored, "parameters/start_clock", path, (3,), "int")
        start = par["start_clock"][()]
        if (start < 0).any():
            raise OrbitsFileError(f"{path}: /parameters/start_clock is {start.tolist()}; "
                                  f"expected counts >= 0")
    _check_restart(f, stored, path, n)
    # the logs, one row per event
    for group, columns in (("collisions", _COLLISION_COLUMNS),
                           ("encounters", _ENCOUNTER_COLUMNS)):
        if group in f:
            _check_log(f, stored, group, columns, path)


def _check_restart(f, stored, path, n):
    r = "restart"
    _checked(stored, f"{r}/count", path, (), "int")
    count = f[r]["count"][()]
    if count < 0:
        raise OrbitsFileError(f"{path}: /{r}/count is {count}; expected the number of "
                              f"checkpoints written, >= 0")
    written = count > 0          # the slots hold data only once one was written
    _checked(stored, f"{r}/order", path, (n,), "int")
    order = f[r]["order"][()]
    if not np.array_equal(np.sort(order), np.arange(n)):
        raise OrbitsFileError(f"{path}: /{r}/order is not an order of the {n} bodies (a "
                              f"permutation of 0 .. {n - 1})")
    arrays = {"x": ((_SLOTS, n, 3), "float"), "v": ((_SLOTS, n, 3), "float"),
              "clock": ((_SLOTS, 5), "int"), "t_base": ((_SLOTS,), "float"),
              "plan": ((_SLOTS, 7), "float"), "progress": ((_SLOTS, 3), "int"),
              "wall": ((_SLOTS,), "float"), "masses": ((_SLOTS, n), "float"),
              "radii": ((_SLOTS, n), "float"), "orders": ((_SLOTS, n), "int")}
    varying = [name in stored for name in (f"{r}/masses", f"{r}/radii", f"{r}/orders")]
    if any(varying) and not all(varying):
        raise OrbitsFileError(f"{path}: /{r} holds some of masses, radii and orders but "
                              f"not all three")
    for name, (shape, kind) in arrays.items():
        if f"{r}/{name}" in stored:
            _checked(stored, f"{r}/{name}", path, shape, kind, backed=written)
    g = f[r]
    # tangent vectors of a shape other than the configuration's are named by
    # TangentShapeError where they would be read (_check_tangent_rows,
    # _derivatives), before anything is read from them
    k = sum(_config_layout(_config(f), n))
    tangent_shapes = {"tangent": (_SLOTS, 2, n * k, 3), "tangent_vectors": (_SLOTS, k, n, 6)}
    for name, ds in g["ws"].items():
        shape = stored[f"{r}/ws/{name}"].shape or ()
        d = _checked(stored, f"{r}/ws/{name}", path, (_SLOTS,) + (None,) * (
            max(1, len(shape)) - 1), "number",
            backed=written and tangent_shapes.get(name, shape) == shape)
        if "body_axes" in ds.attrs:
            axes = ds.attrs["body_axes"]
            if not (isinstance(axes, np.ndarray) and axes.ndim == 1
                    and (axes.dtype.kind in "iu" or axes.size == 0)
                    and all(0 <= k < len(d.shape) - 1 for k in axes.tolist())):
                raise OrbitsFileError(f"{path}: /{r}/ws/{name} has body_axes {axes!r}; "
                                      f"expected axes of its slot's shape {d.shape[1:]}")
    if f"{r}/tangent_vectors" in stored:
        _checked(stored, f"{r}/tangent_vectors", path, (_SLOTS, None, n, 6), "float",
                 backed=written and tangent_shapes["tangent_vectors"]
                 == stored[f"{r}/tangent_vectors"].shape)
        layout = g["tangent_vectors"].attrs.get("layout")
        if layout is not None and not (isinstance(layout, np.ndarray)
                                       and layout.shape == (4,) and layout.dtype.kind in "iu"
                                       and (layout >= 0).all()):
            raise OrbitsFileError(f"{path}: /{r}/tangent_vectors has the layout {layout!r}; "
                                  f"expected four counts (chaos, random, state, mass)")
    if written:
        _check_slot(g, path, (count - 1) % _SLOTS)


def _check_slot(g, path, slot):
    # the control values of the checkpoint in ``slot`` of the group /restart ``g``
    def bad(name, value, expected):
        return OrbitsFileError(f"{path}: /restart/{name} at the last checkpoint (slot "
                               f"{slot}) is {value}; expected {expected}")

    clock = g["clock"][slot]
    # every count but steps_since_base, which a run backwards counts down
    if (np.delete(clock, 1) < 0).any():
        raise bad("clock", clock.tolist(), "counts of steps, force evaluations, rows and "
                                           "rejected steps, each >= 0")
    t_base = float(g["t_base"][slot])
    if not math.isfinite(t_base):
        raise bad("t_base", t_base, "a finite time")
    plan = g["plan"][slot]
    until, outputs, ratio, n_full, partial, start_step, start_time = plan.tolist()
    whole = lambda x: x == int(x) and x >= 0  # noqa: E731
    if not (np.isfinite(plan).all() and whole(outputs) and outputs >= 1 and whole(n_full)
            and partial in (0.0, 1.0) and whole(start_step) and ratio >= 0):
        raise bad("plan", plan.tolist(), "a run's plan: finite times, a whole number of "
                                         "outputs >= 1, whole step counts >= 0")
    # the checkpoint's time lies within its run: from the plan's start to its
    # end, either way, up to a step and rounding (steps_since_base may be
    # negative, so its sign says nothing by itself)
    dt = float(g.file["parameters"].attrs["dt"])
    t = t_base + clock[1] * dt
    slack = dt + 1e-9 * max(abs(until), abs(start_time), 1.0)
    if not min(start_time, until) - slack <= t <= max(start_time, until) + slack:
        raise bad("clock", clock.tolist(),
                  f"a clock whose time, t_base + steps_since_base * dt = {t:.10g}, lies "
                  f"within its run, from {start_time:.10g} to {until:.10g}")
    done, finished, code = g["progress"][slot].tolist()
    if not (0 <= done <= outputs and finished in (0, 1) and code >= 0):
        raise bad("progress", [done, finished, code],
                  f"(outputs written, 0 .. {int(outputs)}; finished, 0 or 1; status >= 0)")
    if "wall" in g:
        wall = float(g["wall"][slot])
        if not (math.isfinite(wall) and wall >= 0):
            raise bad("wall", wall, "seconds >= 0")
    if "masses" in g:
        m = g["masses"][slot]
        alive = np.isfinite(m)
        left = int(alive.sum())
        orders = g["orders"][slot]
        if (m[alive] < 0).any() or left < 1 or not np.array_equal(
                np.sort(orders[:left]), np.arange(left)) or (orders[left:] != -1).any():
            raise bad("masses and orders", f"{m.tolist()} and {orders.tolist()}",
                      "masses >= 0 (NaN for a body merged away) and the order of the "
                      "bodies left, then -1")


def _check_log(f, stored, group, columns, path):
    # columns of any length (a live writer extends one before the next): the
    # readers take the rows all of them store (_log_rows)
    for name, kind in columns.items():
        _checked(stored, f"{group}/{name}", path, (None,), kind, backed=False)
        if kind == "float":
            _unit(f, f"{group}/{name}", path)


def _log_rows(g, columns):
    """The rows of a log (group ``collisions`` or ``encounters``) that every one
    of its columns stores."""
    return min(_covered(g[name]) for name in columns)


def _damaged(func):
    # a file can open and still fail on reading a truncated chunk: name it
    @functools.wraps(func)
    def wrapper(path, *args, **kwargs):
        try:
            return func(path, *args, **kwargs)
        except OrbitsFileError:
            raise
        except (OSError, RuntimeError, KeyError, ValueError) as exc:
            raise OrbitsFileError(f"{path}: damaged or incomplete orbits file "
                                  f"(truncated?): {exc}") from None
        except (TypeError, AttributeError, IndexError) as exc:
            # a value of a kind the checks above did not foresee: still the file's
            raise OrbitsFileError(f"{path}: damaged orbits file: a value of the wrong kind "
                                  f"({type(exc).__name__}: {exc})") from exc
    return wrapper
