"""The layout of an orbits output file: its paths, attributes and version, and a
new file made in it.

Layout
------
The file follows H5MD 1.1 (de Buyl, Colberg & Höfling 2014, the published
HDF5 layout for particle simulations) where it has a place for a thing, and
adds two groups of its own::

    /                        attrs: orbits_format = "orbits-h5md", orbits_format_version
    /h5md                    attrs: version = [1, 1]; /h5md/author, /h5md/creator (name, version)
    /particles/bodies
        names                (N,) str, in the order of the body set
        mass                 (N,) float, attr unit
        radius               (N,) float, attr unit (length): the bodies' physical
                             radii, 0 for a point mass (files written before it
                             was kept lack it, and read as all 0)
        position/step        (T,) int64, steps since the simulation was made
        position/time        (T,) float, attr unit
        position/value       (T, N, 3) float, attr unit
        velocity/{step,time,value}   likewise
    /observables             each an H5MD time-dependent element {step, time, value},
                             with the name, shape and unit its monitor's spec
                             gives (orbits.monitors.MONITOR_SPECS)
        energy               value (T,)
        angular_momentum     value (T, 3)
        momentum             value (T, 3)
        center_of_mass       value (T, 3)
        work                 value (T,): W, the energy non-conservative force terms
                             took out since the simulation was made (with the
                             energy monitor and such terms only; the energy error
                             is that of E + W)
        megno, fli           value (T,), dimensionless (unit "1"): the chaos monitors'
                             running mean of MEGNO and fast Lyapunov indicator
        lyapunov             value (T,), unit 1 / time: the Lyapunov exponent's estimate
        in_loop/<same>       the series recorded inside the compiled loop every
                             monitor_every steps, when that was asked for
    /parameters              attrs: the run's metadata (orbits and library versions,
                             integrator and its options, dt, unit system, G and its
                             source, softening, monitors, stopping conditions, when
                             written, how the body set was made, as JSON where
                             structured); epoch_tdb, where the bodies carried an
                             epoch: (2,) float64, the Julian date of time 0 in
                             TDB in two parts (jd1 + jd2, as astropy's Time
                             keeps it; files without it have no date)
        reference            (14,) the monitors' values when the simulation was made
                             (the layout of orbits._kernels.invariants.MONITOR_COLUMNS;
                             older files have (10,), without the work, or (11,),
                             without the chaos indicators)
        scales               (2,) energy and angular-momentum scales for relative errors
    /restart                 the last two checkpoints, in alternating slots
        count                () int64: complete checkpoints written; the valid slot
                             is (count - 1) % 2
        x, v                 (2, N, 3) internal order (massive bodies first)
        order                (N,) int64: internal index -> body-set index
        clock                (2, 5) int64: steps, steps_since_base (negative in a
                             run backwards in time: time = t_base +
                             steps_since_base * dt, dt > 0), force_evaluations,
                             output rows written, steps rejected
        t_base               (2,) float
        plan                 (2, 7) float: the run in progress (until, outputs, ratio,
                             n_full, has_partial, start_step, start_time) and
        progress             (2, 3) int64: (outputs of that run written, run finished,
                             status code when it ended early: 1 non-finite state,
                             2 step-size underflow, 3 close encounter, 4 escape)
        wall                 (2,) float, seconds: wall-clock time the runs writing
                             the file had taken at the checkpoint
        ws/<name>            (2, ...) the integrator's workspace arrays (with
                             non-conservative terms, ws/work: W and its rounding
                             compensation; with variations or chaos monitors,
                             ws/tangent (2, 2, k N, 3): the k tangent vectors'
                             position and velocity rows, internal order, and
                             ws/chaos: the chaos monitors' accumulators)
        tangent_vectors      (2, k, N, 6) with variations or chaos monitors: the
                             tangent vectors at the checkpoint as
                             Simulation.tangent_vectors gives them (synchronised,
                             body-set order, internal units); attr layout = the
                             numbers of vectors (chaos, random, state, mass), from
                             which load() rebuilds the Jacobian
    /parameters/start_clock  (3,) int64: steps, force evaluations and rejected steps
                             of the simulation when the file was made (the
                             totals since are ``clock`` less these)

Files written before ``wall`` and ``start_clock`` read back with those totals
"not recorded".  The time series are chunked without compression, so that a
partly filled chunk written at a checkpoint is rewritten in place: a
compressed chunk changes size, and HDF5 gives it new space each time (a run
with a checkpoint at every output grew to 180 times its data).

Every float dataset has a ``unit`` attribute (H5MD's convention); ``orbits.load``
gives Quantities back.
"""

import datetime
import json
import os

import astropy
import h5py
import numba
import numpy as np

from ... import __version__ as _VERSION
from ... import epochs as _epochs
from ..._kernels import invariants as _inv
from ...errors import OrbitsError
from ..._monitor_specs import BY_NAME, WITH_ERROR, added_to
from ...monitors import CHAOS_MONITORS, error_series
from .disk import _close_written, _new_file
from .errors import _write_error

__all__ = ["FORMAT", "FORMAT_VERSION"]

FORMAT = "orbits-h5md"
FORMAT_VERSION = 1
_SLOTS = 2
#: what an orbits file holds, in words for the message that names what is missing
_GROUPS = {
    "particles": "the trajectories",
    "particles/bodies": "the bodies and their trajectories",
    "particles/bodies/position": "the positions",
    "particles/bodies/velocity": "the velocities",
    "observables": "the monitors' series",
    "observables/in_loop": "the monitors' in-loop series",
    "parameters": "the run's metadata",
    "restart": "the restart checkpoints",
    "restart/ws": "the integrator's state in the checkpoints",
}
_DATASETS = {
    "particles/bodies/names": "the bodies' names",
    "particles/bodies/mass": "the bodies' masses",
    "particles/bodies/position/step": "the outputs' step counts",
    "particles/bodies/position/time": "the outputs' times",
    "particles/bodies/position/value": "the positions",
    "particles/bodies/velocity/step": "the outputs' step counts",
    "particles/bodies/velocity/time": "the outputs' times",
    "particles/bodies/velocity/value": "the velocities",
    "parameters/reference": "the monitors' reference values",
    "parameters/scales": "the monitors' error scales",
    "restart/count": "the number of checkpoints",
    "restart/order": "the bodies' order in the checkpoints",
    "restart/x": "the checkpoints' positions",
    "restart/v": "the checkpoints' velocities",
    "restart/clock": "the checkpoints' step counts",
    "restart/t_base": "the checkpoints' times",
    "restart/plan": "the checkpoints' run plans",
    "restart/progress": "the checkpoints' progress",
}
# (each checked where present: older files have no particles/bodies/radius)
_UNITS = ("particles/bodies/mass", "particles/bodies/radius",
          "particles/bodies/position/time", "particles/bodies/position/value",
          "particles/bodies/velocity/value")
_PARAMETERS = ("orbits_version", "written", "integrator", "integrator_options",
               "integrator_info", "dt", "dt_unit", "units", "monitors", "bodies_history")


#: the columns of the logs and the type of each
_COLLISION_COLUMNS = {"time": "float", "step_time": "float", "body_1": "str", "body_2": "str",
                      "resolution": "str", "survivor": "str", "distance": "float",
                      "speed": "float", "energy_change": "float"}
_ENCOUNTER_COLUMNS = {"time": "float", "body_1": "str", "body_2": "str", "distance": "float",
                      "speed": "float"}


def _decode(a):
    return [s.decode() if isinstance(s, bytes) else str(s) for s in a]


def _radii(b):
    """The bodies' radii from the group ``particles/bodies`` (float64 in the run's
    unit of length) and that unit's name; all 0 in a file written before they
    were kept."""
    if "radius" in b:
        return np.asarray(b["radius"][()], dtype=np.float64), b["radius"].attrs["unit"]
    return np.zeros(b["names"].shape[0]), b["position/value"].attrs["unit"]


def _config(f):
    """The configuration record (SimulationConfig.to_dict()) a file keeps; {} for
    files written before it."""
    par = f["parameters"]
    return json.loads(par.attrs["config"]) if "config" in par.attrs else {}


def _bodies_vary(desc):
    """Whether the described simulation's collisions may merge bodies away
    (a resolution other than ``"halt"``)."""
    c = desc.stop_conditions.get("collisions")
    return c is not None and c != "halt"


def _body_axes(integrator, n):
    """The axes of each workspace array that run over the bodies (those whose
    length differs between a workspace of ``n`` and of ``n + 1`` bodies)."""
    a, b = integrator.workspace(n), integrator.workspace(n + 1)
    axes = {name: tuple(k for k, (p, q) in enumerate(zip(arr.shape, b[name].shape)) if p != q)
            for name, arr in a.items() if isinstance(arr, np.ndarray)}
    # the collision check's state of the step before: (positions and velocities, bodies, 3)
    axes["stop_prev"] = (1,)
    return axes


def _padded(x, n):
    """Rows of ``x`` followed by NaN rows up to ``n`` (a state after mergers,
    in a dataset made for the bodies at the start)."""
    if len(x) == n:
        return x
    out = np.full((n,) + x.shape[1:], np.nan)
    out[:len(x)] = x
    return out


def _write_box(d, slot, arr):
    """``d[slot]`` gets ``arr``, in its leading corner where ``arr`` is smaller
    (a workspace of fewer bodies than the file was made for)."""
    if arr.shape == d.shape[1:]:
        _write_rows(d, slot, arr[None], extend=False)
    else:
        d[(slot,) + tuple(slice(0, k) for k in arr.shape)] = arr


def _read_box(d, slot, n, n0):
    """``d[slot]`` for ``n`` bodies where it was made for ``n0`` (its
    ``body_axes`` attribute says which axes run over them)."""
    axes = set(d.attrs.get("body_axes", ())) if n != n0 else set()
    return d[(slot,) + tuple(slice(0, n if k in axes else size)
                             for k, size in enumerate(d.shape[1:]))]


def _datasets(group):
    return group["step"], group["time"], group["value"]


def _keeps_work(desc):
    """Whether a file of the simulation ``desc`` describes keeps the work series:
    with the energy monitor and a non-conservative force term, or collisions
    that the run resolves (what they take out of the bodies' energy)."""
    return "energy" in desc.monitors and (any(not t.conservative for t in desc.forces)
                                          or _bodies_vary(desc))


def _append(dsets, n0, steps, t, values):
    for d, data in zip(dsets, (steps, t, values)):
        _write_rows(d, n0, data)


def _write_rows(d, n0, data, extend=True):
    """``d[n0:n0 + len(data)] = data``, extending ``d`` first if asked.

    Through h5py's low-level calls: its slicing costs ten times the write
    itself (0.2 ms against 0.02), which a checkpoint at every output pays
    some thirty times.
    """
    data = np.ascontiguousarray(data, dtype=d.dtype)
    shape = data.shape
    if extend:
        d.id.set_extent((n0 + shape[0],) + shape[1:])
    space = d.id.get_space()
    space.select_hyperslab((n0,) + (0,) * (len(shape) - 1), shape)
    d.id.write(h5py.h5s.create_simple(shape), space, data)


#: bytes of a time series' chunk: 1024 outputs of a few bodies, fewer of many
_CHUNK_BYTES = 1 << 16


def _element(parent, name, shape, unit):
    # uncompressed chunks: a partial chunk rewritten at each checkpoint keeps
    # its place in the file (see the module's notes); positions and
    # velocities compress by about 12 % only (gzip level 4, shuffle)
    g = parent.create_group(name)
    g.create_dataset("step", shape=(0,), maxshape=(None,), dtype=np.int64, chunks=(1024,))
    t = g.create_dataset("time", shape=(0,), maxshape=(None,), dtype=np.float64,
                         chunks=(1024,))
    t.attrs["unit"] = unit[1]
    rows = max(1, min(1024, _CHUNK_BYTES // (8 * max(1, int(np.prod(shape))))))
    v = g.create_dataset("value", shape=(0,) + shape, maxshape=(None,) + shape,
                         dtype=np.float64, chunks=(rows,) + shape)
    v.attrs["unit"] = unit[0]
    return g


def _series_errors(group, name, rows, reference, scales):
    """The relative error of monitor ``name`` at ``rows`` (a slice, or
    increasing indices) of the series in ``group`` (``observables`` or
    ``observables/in_loop``), those added to it (the work) included where
    the file keeps them."""
    added = [group[s.name]["value"][rows] for s in added_to(name) if s.name in group]
    return error_series(name, group[name]["value"][rows], reference, scales,
                        added=sum(added) if added else None)


def _tangent_layout(monitors, variations, n):
    """``(chaos, random, state, mass)``: how many tangent vectors of each kind a
    simulation of ``n`` bodies with these ``monitors`` and ``variations``
    integrates, in the order :attr:`orbits.Simulation.tangent_vectors` lists
    them (one for the chaos monitors; an int ``variations`` random ones; 6 n
    for ``"state"``; 6 n and n for ``"all"``).  Read off the configuration,
    as the simulation lays them out, so that a file is checked against what
    its own record says."""
    chaos = int(any(name in CHAOS_MONITORS for name in monitors))
    if isinstance(variations, str):
        state = 6 * n if variations in ("state", "all") else 0
        return chaos, 0, state, (n if variations == "all" else 0)
    random = int(variations) if variations is not None and not isinstance(variations, bool) \
        else 0
    return chaos, random, 0, 0


def _config_layout(config, n):
    # the tangent layout of a configuration dictionary (SimulationConfig.to_dict())
    return _tangent_layout(config.get("monitors", ()), config.get("variations"), n)


def _create(path, desc, state):
    """A new file for the simulation described by ``desc`` (a
    :class:`~orbits.records.SimulationDescription`) at ``state``, open for
    appending in SWMR mode.

    It is written whole as ``<path>.creating`` (made exclusively, see
    :func:`_new_file`), put in SWMR mode and then renamed to ``path``, which
    replaces a file or a link there, never what a link names.  It stays open
    throughout: a reader that opens ``path`` at any moment finds either what
    was there before or this file with its writer in SWMR mode, and never
    holds a lock the writer would need to open it again.  Where that fails (a
    full disk), the temporary is removed and ``path`` is left as it was.
    """
    tmp = path.with_name(path.name + ".creating")
    f = _new_file(tmp)
    try:
        _write_layout(f, desc, state)
        f.swmr_mode = True
        os.replace(tmp, path)
    except BaseException as exc:
        _close_written(f)
        tmp.unlink(missing_ok=True)
        if isinstance(exc, (OSError, RuntimeError)) and not isinstance(exc, OrbitsError):
            raise _write_error(path, exc, " when making it; nothing was written") from None
        raise
    return f


def _write_layout(f, desc, state):
    """The groups, datasets and metadata of a new file ``f`` (the layout of the
    module's notes) for the simulation ``desc`` describes, at ``state``; flushed."""
    U = desc.units
    f.attrs["orbits_format"] = FORMAT
    f.attrs["orbits_format_version"] = FORMAT_VERSION
    h = f.create_group("h5md")
    h.attrs["version"] = np.array([1, 1], dtype=np.int32)
    h.create_group("author").attrs["name"] = os.environ.get("USER", "unknown")
    c = h.create_group("creator")
    c.attrs["name"] = "orbits"
    c.attrs["version"] = _VERSION
    n = len(desc.names)
    unit = lambda kind: U.unit(kind).to_string()  # noqa: E731
    b = f.create_group("particles/bodies")
    b.create_dataset("names", data=np.array(list(desc.names), dtype=h5py.string_dtype()))
    b.create_dataset("mass", data=desc.masses).attrs["unit"] = unit("mass")
    b.create_dataset("radius", data=desc.radii).attrs["unit"] = unit("length")
    _element(b, "position", (n, 3), (unit("length"), unit("time")))
    _element(b, "velocity", (n, 3), (unit("velocity"), unit("time")))
    varying = _bodies_vary(desc)
    if varying:
        # collisions may merge bodies away: the outputs keep the columns of
        # the bodies at the start (NaN for one that is gone) and the masses
        _element(b, "masses_at_outputs", (n,), (unit("mass"), unit("time")))
    obs = f.create_group("observables")
    inloop = obs.create_group("in_loop")
    for name in tuple(desc.monitors) + (("work",) if _keeps_work(desc) else ()):
        spec = BY_NAME[name]
        u_ = (spec.file_unit(U), unit("time"))
        _element(obs, name, spec.shape, u_)
        _element(inloop, name, spec.shape, u_)
    par = f.create_group("parameters")
    meta = {
        "orbits_version": _VERSION, "numpy_version": np.__version__,
        "numba_version": numba.__version__, "h5py_version": h5py.__version__,
        "astropy_version": astropy.__version__,
        "written": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "integrator": desc.integrator.name,
        "integrator_options": json.dumps(desc.integrator.config),
        "integrator_info": json.dumps(desc.integrator.info()),
        "dt": desc.dt, "dt_unit": unit("time"),
        "units": json.dumps(U.to_dict()), "G": U.G, "G_source": U.G_source,
        "softening": float(desc.softening), "softening_unit": unit("length"),
        "monitors": json.dumps(list(desc.monitors)),
        "monitor_every": desc.monitor_every or 0,
        "parallel": bool(desc.parallel),
        "stop_conditions": json.dumps(desc.stop_conditions),
        "rebound_arithmetic": bool(desc.rebound_arithmetic),
        "bodies_history": json.dumps(desc.history, default=str),
        # the one record that rebuilds the simulation from its bodies (Simulation.from_file)
        "config": json.dumps(desc.config.to_dict()),
        "forces": json.dumps([t.to_dict() for t in desc.forces]),
    }
    for k, v in meta.items():
        par.attrs[k] = v
    if desc.epoch is not None:
        par.attrs["epoch_tdb"] = np.array(_epochs.to_pair(desc.epoch), dtype=np.float64)
    ref = par.create_dataset("reference", data=state.reference)
    # each column's unit, in the kernels' layout
    ref_units = {c: spec.file_unit(U) for spec in BY_NAME.values() for c in spec.columns}
    ref.attrs["unit"] = ", ".join([ref_units[c] for c in _inv.MONITOR_COLUMNS]
                                  [:len(state.reference)])
    par.create_dataset("scales", data=np.array(state.scales)).attrs["unit"] = ", ".join(
        s.file_unit(U) for s in sorted(WITH_ERROR, key=lambda s: s.scale))
    par.create_dataset("start_clock", data=np.array(
        [state.steps, state.force_evaluations, state.steps_rejected], dtype=np.int64))
    r = f.create_group("restart")
    r.create_dataset("count", data=np.int64(0))
    r.create_dataset("order", data=np.asarray(state.order, dtype=np.int64))
    for name in ("x", "v"):
        r.create_dataset(name, shape=(_SLOTS, n, 3), dtype=np.float64).attrs["unit"] = \
            unit("length" if name == "x" else "velocity")
    r.create_dataset("clock", shape=(_SLOTS, 5), dtype=np.int64)
    r.create_dataset("t_base", shape=(_SLOTS,), dtype=np.float64).attrs["unit"] = unit("time")
    r.create_dataset("plan", shape=(_SLOTS, 7), dtype=np.float64).attrs["unit"] = \
        f"{unit('time')}, 1, 1, 1, 1, 1, {unit('time')}"
    r.create_dataset("progress", shape=(_SLOTS, 3), dtype=np.int64)
    r.create_dataset("wall", shape=(_SLOTS,), dtype=np.float64).attrs["unit"] = "s"
    layout = _tangent_layout(desc.monitors, desc.config.variations, n)
    if sum(layout):
        # the derivatives at the checkpoint, as Simulation.tangent_vectors gives
        # them (the integrator synchronised, body-set order), so that a reader
        # needs neither the integrator nor the internal order
        d = r.create_dataset("tangent_vectors", shape=(_SLOTS, sum(layout), n, 6),
                             dtype=np.float64)
        d.attrs["unit"] = "internal"
        d.attrs["layout"] = np.array(layout, dtype=np.int64)
    ws = r.create_group("ws")
    axes = _body_axes(desc.integrator, n) if varying else {}
    for name, arr in state.workspace.items():
        if isinstance(arr, np.ndarray):
            d = ws.create_dataset(name, shape=(_SLOTS,) + arr.shape, dtype=arr.dtype)
            if arr.dtype.kind == "f":
                # the integrator's own state, in the run's units (see /parameters/units)
                d.attrs["unit"] = "internal"
            if varying:
                d.attrs["body_axes"] = np.array(axes.get(name, ()), dtype=np.int64)
    if varying:
        # the bodies at each checkpoint, in the columns of those at the start:
        # masses and radii (NaN: merged away) and the internal order
        for name, kind in (("masses", "mass"), ("radii", "length")):
            r.create_dataset(name, shape=(_SLOTS, n), dtype=np.float64).attrs["unit"] = \
                unit(kind)
        r.create_dataset("orders", shape=(_SLOTS, n), dtype=np.int64)
    f.flush()
