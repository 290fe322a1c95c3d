"""HDF5 output: streamed trajectories, monitors, metadata and restart checkpoints.

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
        position/step        (T,) int64, steps since the simulation was made
        position/time        (T,) float, attr unit
        position/value       (T, N, 3) float, attr unit
        velocity/{step,time,value}   likewise
    /observables             each an H5MD time-dependent element {step, time, value}
        energy               value (T,)
        angular_momentum     value (T, 3)
        momentum             value (T, 3)
        center_of_mass       value (T, 3)
        in_loop/<same>       the series recorded inside the compiled loop every
                             monitor_every steps, when that was asked for
    /parameters              attrs: the run's metadata (orbits and library versions,
                             integrator and its options, dt, unit system, G and its
                             source, softening, monitors, stopping conditions, when
                             written, how the body set was made, as JSON where
                             structured)
        reference            (10,) the monitors' values when the simulation was made
        scales               (2,) energy and angular-momentum scales for relative errors
    /restart                 the last two checkpoints, in alternating slots
        count                () int64: complete checkpoints written; the valid slot
                             is (count - 1) % 2
        x, v                 (2, N, 3) internal order (massive bodies first)
        order                (N,) int64: internal index -> body-set index
        clock                (2, 5) int64: steps, steps_since_base, force_evaluations,
                             output rows written, steps rejected
        t_base               (2,) float
        plan                 (2, 7) float: the run in progress (until, outputs, ratio,
                             n_full, has_partial, start_step, start_time) and
        progress             (2, 3) int64: (outputs of that run written, run finished,
                             status code when it ended early: 1 non-finite state,
                             2 step-size underflow, 3 close encounter, 4 escape)
        ws/<name>            (2, ...) the integrator's workspace arrays

Every float dataset has a ``unit`` attribute (H5MD's convention); ``orbits.load``
gives Quantities back.

Crash safety
------------
The file is written in HDF5's single-writer/multiple-reader (SWMR) mode, which
keeps it consistent on disk whenever the writer stops, and outputs are flushed
in blocks.  A checkpoint goes into the slot not holding the last one, is
flushed, and only then is ``count`` advanced and flushed: the slot ``count``
names is always complete.  A run killed in the middle (even by SIGKILL)
leaves a file that :func:`load` and :func:`describe` open, and that
:meth:`orbits.Simulation.from_file` resumes from its last checkpoint; rows
written after that checkpoint are dropped on resume and computed again, so
the resumed file ends the same as an uninterrupted one.  A file whose writer
died can be read with plain h5py as ``h5py.File(path, "r", swmr=True)``.
"""

import datetime
import json
import os
import pathlib
import time as _time
from typing import NamedTuple

import h5py
import numpy as np

from ..errors import OrbitsError

__all__ = ["FileRecorder", "load", "describe", "restore", "truncate", "ResumePoint",
           "OrbitsFileError",
           "FORMAT", "FORMAT_VERSION", "CHECKPOINT_SECONDS", "BUFFER_ROWS"]

FORMAT = "orbits-h5md"
FORMAT_VERSION = 1
#: default wall-clock seconds between restart checkpoints
CHECKPOINT_SECONDS = 60.0
#: outputs held in memory before they are written as one block
BUFFER_ROWS = 256
_SLOTS = 2
_MONITOR_NAMES = ("energy", "angular_momentum", "momentum", "center_of_mass")
_MONITOR_COLUMNS = {"energy": slice(0, 1), "angular_momentum": slice(1, 4),
                    "momentum": slice(4, 7), "center_of_mass": slice(7, 10)}
_MONITOR_KIND = {"energy": "energy", "angular_momentum": "angular_momentum",
                 "momentum": "momentum", "center_of_mass": "length"}


class OrbitsFileError(OrbitsError, OSError):
    """A file that is not an orbits output, is damaged, or has another layout version."""


# -- opening ---------------------------------------------------------------------------

def _open_read(path):
    path = pathlib.Path(path)
    if not path.exists():
        raise OrbitsFileError(f"{path}: no such file")
    try:
        f = h5py.File(path, "r", swmr=True)
    except OSError:
        try:
            f = h5py.File(path, "r")
        except OSError as exc:
            raise OrbitsFileError(f"{path}: not a readable HDF5 file (truncated or "
                                  f"damaged?): {exc}") from None
    fmt = f.attrs.get("orbits_format")
    if fmt != FORMAT:
        f.close()
        raise OrbitsFileError(f"{path}: not an orbits output file (no "
                              f"orbits_format = {FORMAT!r} attribute)")
    version = int(f.attrs.get("orbits_format_version", -1))
    if version != FORMAT_VERSION:
        f.close()
        raise OrbitsFileError(f"{path}: layout version {version}, but this orbits reads "
                              f"version {FORMAT_VERSION}")
    try:
        f["particles/bodies/position/value"]
        f["restart/count"]
    except KeyError as exc:
        f.close()
        raise OrbitsFileError(f"{path}: incomplete orbits file, missing {exc}") from None
    return f


def _decode(a):
    return [s.decode() if isinstance(s, bytes) else str(s) for s in a]


# -- writing ---------------------------------------------------------------------------

class FileRecorder:
    """Streams one run's outputs into an HDF5 file (used by ``Simulation.run``)."""

    def __init__(self, path, sim, plan, overwrite=False, checkpoint_interval=None,
                 resume_rows=None):
        self.path = pathlib.Path(path)
        self.sim = sim
        self.plan = plan
        self.interval = (CHECKPOINT_SECONDS if checkpoint_interval is None
                         else float(checkpoint_interval))
        self.inv = np.argsort(sim._order)
        self.buffer = []
        self.mon_buffer = []
        self.outputs_written = 0     # in this plan
        self.last = None
        self.steps0 = sim.steps
        self.forces0 = sim.force_evaluations
        self.closed = False
        self.end_status = 0          # a Status code when a run ends early
        mine = getattr(sim, "_output_path", None)
        if self.path.exists() and not overwrite and (mine is None or
                                                      os.path.abspath(mine) != os.path.abspath(self.path)):
            raise OrbitsFileError(f"{self.path}: exists; pass overwrite=True (or --force) "
                                  f"to replace it")
        if self.path.exists() and mine is not None and not overwrite:
            self.f = h5py.File(self.path, "a", libver="latest")
            self._check_same_layout()
            self.f.swmr_mode = True
        else:
            self.f = _create(self.path, sim)
        sim._output_path = str(self.path)
        self.rows = self.f["particles/bodies/position/value"].shape[0]
        if resume_rows is not None:
            self.outputs_written = resume_rows
        self.last_checkpoint = _time.perf_counter()
        if resume_rows is None and plan.outputs > 1:
            self.output(sim)

    def _check_same_layout(self):
        n = self.f["particles/bodies/names"].shape[0]
        if n != len(self.sim._m):
            raise OrbitsFileError(f"{self.path}: holds {n} bodies, the simulation "
                                  f"{len(self.sim._m)}")

    # Recorder interface ----------------------------------------------------------------
    def output(self, sim, final=False):
        self.last = tuple(sim.snapshot())
        self.buffer.append(self.last)
        self.outputs_written += 1
        if len(self.buffer) >= BUFFER_ROWS:
            self._flush_outputs()
        if final or _time.perf_counter() - self.last_checkpoint >= self.interval:
            self.checkpoint(finished=final)

    def monitor_rows(self, t, rows):
        self.mon_buffer.append((t.copy(), rows.copy()))

    def close(self):
        if not self.closed:
            self.closed = True
            self._flush_outputs()
            self.f.close()

    def result(self, sim, wall, status="completed"):
        from ..result import Result
        q = sim.units.quantity
        t, step, x, v, row = self.last
        fields = dict(times=q(np.array([t]), "time"), positions=q(x[None], "length"),
                      velocities=q(v[None], "velocity"), names=list(sim._names),
                      masses=q(sim._m[self.inv].copy(), "mass"), steps=sim.steps - self.steps0,
                      force_evaluations=sim.force_evaluations - self.forces0, wall_time=wall,
                      integrator=sim.integrator.info(), units=sim.units.to_dict(),
                      dt=sim.dt, status=status, monitors=sim.monitors, path=str(self.path),
                      forces=tuple(map(repr, sim.forces)))
        if sim._mask:
            from ..simulation import _monitor_fields
            fields.update(_monitor_fields(row[None], sim, sim._reference))
        return Result(**fields)

    # writing ---------------------------------------------------------------------------
    def _flush_outputs(self):
        if self.buffer:
            k = len(self.buffer)
            n0 = self.rows
            t = np.array([b[0] for b in self.buffer])
            steps = np.array([b[1] for b in self.buffer], dtype=np.int64)
            p = self.f["particles/bodies"]
            for name, col in (("position", 2), ("velocity", 3)):
                _append(p[name], n0, steps, t, np.array([b[col] for b in self.buffer]))
            rows = np.array([b[4] for b in self.buffer])
            obs = self.f["observables"]
            for name in self.sim.monitors:
                _append(obs[name], n0, steps, t, rows[:, _MONITOR_COLUMNS[name]].squeeze(-1)
                        if name == "energy" else rows[:, _MONITOR_COLUMNS[name]])
            self.rows = n0 + k
            self.buffer = []
        if self.mon_buffer:
            t = np.concatenate([b[0] for b in self.mon_buffer])
            rows = np.concatenate([b[1] for b in self.mon_buffer])
            sim = self.sim
            steps = (sim.steps - sim._steps_since_base
                     + np.round((t - sim._t_base) / sim._dt)).astype(np.int64)
            obs = self.f["observables/in_loop"]
            for name in self.sim.monitors:
                g = obs[name]
                n0 = g["time"].shape[0]
                vals = rows[:, _MONITOR_COLUMNS[name]]
                _append(g, n0, steps, t, vals[:, 0] if name == "energy" else vals)
            self.mon_buffer = []
        self.f.flush()

    def checkpoint(self, finished=False):
        """Write the restart state into the free slot, then advance ``count``."""
        sim = self.sim
        self._flush_outputs()
        r = self.f["restart"]
        count = int(r["count"][()])
        slot = count % _SLOTS
        state = sim.state
        r["x"][slot] = state.x
        r["v"][slot] = state.v
        r["clock"][slot] = (state.steps, state.steps_since_base, state.force_evaluations,
                            self.rows, state.steps_rejected)
        r["t_base"][slot] = state.t_base
        p = self.plan
        r["plan"][slot] = (p.until, p.outputs, p.ratio, p.n_full, float(p.has_partial),
                           p.start_step, p.start_time)
        r["progress"][slot] = (self.outputs_written, int(finished), self.end_status)
        for name, arr in state.workspace.items():
            r["ws"][name][slot] = arr
        self.f.flush()
        r["count"][()] = count + 1
        r["count"].flush()
        self.f.flush()
        self.last_checkpoint = _time.perf_counter()


def _append(group, n0, steps, t, values):
    k = len(t)
    for name, data in (("step", steps), ("time", t), ("value", values)):
        d = group[name]
        d.resize(n0 + k, axis=0)
        d[n0:n0 + k] = data


def _element(parent, name, shape, unit):
    g = parent.create_group(name)
    g.create_dataset("step", shape=(0,), maxshape=(None,), dtype=np.int64, chunks=(1024,))
    t = g.create_dataset("time", shape=(0,), maxshape=(None,), dtype=np.float64,
                         chunks=(1024,))
    t.attrs["unit"] = unit[1]
    rows = max(1, min(1024, (1 << 18) // (8 * max(1, int(np.prod(shape))))))
    v = g.create_dataset("value", shape=(0,) + shape, maxshape=(None,) + shape,
                         dtype=np.float64, chunks=(rows,) + shape, compression="gzip",
                         compression_opts=4, shuffle=True)
    v.attrs["unit"] = unit[0]
    return g


def _create(path, sim):
    from .. import __version__
    import astropy
    import numba

    U = sim.units
    tmp = path.with_name(path.name + ".creating")
    f = h5py.File(tmp, "w", libver="latest")
    f.attrs["orbits_format"] = FORMAT
    f.attrs["orbits_format_version"] = FORMAT_VERSION
    h = f.create_group("h5md")
    h.attrs["version"] = np.array([1, 1], dtype=np.int32)
    h.create_group("author").attrs["name"] = os.environ.get("USER", "unknown")
    c = h.create_group("creator")
    c.attrs["name"] = "orbits"
    c.attrs["version"] = __version__
    n = len(sim._m)
    unit = lambda kind: U.unit(kind).to_string()  # noqa: E731
    b = f.create_group("particles/bodies")
    b.create_dataset("names", data=np.array(sim._names, dtype=h5py.string_dtype()))
    b.create_dataset("mass", data=sim._m[np.argsort(sim._order)]).attrs["unit"] = unit("mass")
    _element(b, "position", (n, 3), (unit("length"), unit("time")))
    _element(b, "velocity", (n, 3), (unit("velocity"), unit("time")))
    obs = f.create_group("observables")
    inloop = obs.create_group("in_loop")
    for name in sim.monitors:
        shape = () if name == "energy" else (3,)
        u_ = (unit(_MONITOR_KIND[name]), unit("time"))
        _element(obs, name, shape, u_)
        _element(inloop, name, shape, u_)
    par = f.create_group("parameters")
    meta = {
        "orbits_version": __version__, "numpy_version": np.__version__,
        "numba_version": numba.__version__, "h5py_version": h5py.__version__,
        "astropy_version": astropy.__version__,
        "written": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "integrator": sim.integrator.name,
        "integrator_options": json.dumps(sim.integrator.config),
        "integrator_info": json.dumps(sim.integrator.info()),
        "dt": sim._dt, "dt_unit": unit("time"),
        "units": json.dumps(U.to_dict()), "G": U.G, "G_source": U.G_source,
        "softening": float(np.sqrt(sim._eps2)), "softening_unit": unit("length"),
        "monitors": json.dumps(list(sim.monitors)),
        "monitor_every": sim.monitor_every or 0,
        "parallel": bool(sim.parallel),
        "stop_conditions": json.dumps(sim._stop_config),
        "rebound_arithmetic": bool(sim.rebound_arithmetic),
        "bodies_history": json.dumps(sim._history, default=str),
        # the one record that rebuilds the simulation from its bodies (restore)
        "config": json.dumps(sim.config.to_dict()),
        "forces": json.dumps([t.to_dict() for t in sim.forces]),
    }
    for k, v in meta.items():
        par.attrs[k] = v
    ref = par.create_dataset("reference", data=sim._reference)
    ref.attrs["unit"] = ", ".join([unit("energy")] + [unit("angular_momentum")] * 3
                                  + [unit("momentum")] * 3 + [unit("length")] * 3)
    par.create_dataset("scales", data=np.array([sim._E_scale, sim._L_scale])).attrs["unit"] = \
        f"{unit('energy')}, {unit('angular_momentum')}"
    r = f.create_group("restart")
    r.create_dataset("count", data=np.int64(0))
    r.create_dataset("order", data=sim._order.astype(np.int64))
    for name in ("x", "v"):
        r.create_dataset(name, shape=(_SLOTS, n, 3), dtype=np.float64).attrs["unit"] = \
            unit("length" if name == "x" else "velocity")
    r.create_dataset("clock", shape=(_SLOTS, 5), dtype=np.int64)
    r.create_dataset("t_base", shape=(_SLOTS,), dtype=np.float64).attrs["unit"] = unit("time")
    r.create_dataset("plan", shape=(_SLOTS, 7), dtype=np.float64).attrs["unit"] = \
        f"{unit('time')}, 1, 1, 1, 1, 1, {unit('time')}"
    r.create_dataset("progress", shape=(_SLOTS, 3), dtype=np.int64)
    ws = r.create_group("ws")
    for name, arr in sim._ws.items():
        if isinstance(arr, np.ndarray):
            d = ws.create_dataset(name, shape=(_SLOTS,) + arr.shape, dtype=arr.dtype)
            if arr.dtype.kind == "f":
                # the integrator's own state, in the run's units (see /parameters/units)
                d.attrs["unit"] = "internal"
    f.flush()
    f.close()
    os.replace(tmp, path)
    f = h5py.File(path, "a", libver="latest")
    f.swmr_mode = True
    return f


# -- reading ---------------------------------------------------------------------------

def _damaged(func):
    # a file can open and still fail on reading a truncated chunk: name it
    import functools

    @functools.wraps(func)
    def wrapper(path, *args, **kwargs):
        try:
            return func(path, *args, **kwargs)
        except OrbitsFileError:
            raise
        except (OSError, KeyError, ValueError) as exc:
            raise OrbitsFileError(f"{path}: damaged or incomplete orbits file "
                                  f"(truncated?): {exc}") from None
    return wrapper


@_damaged
def load(path):
    """Read an output file into a :class:`~orbits.Result` with Quantities.

    Works on a file whose writer was killed: it reads what the last flush left.
    """
    from ..result import Result
    import astropy.units as u
    from ..monitors import relative_error, vector_relative_error

    with _open_read(path) as f:
        b = f["particles/bodies"]
        par = f["parameters"]

        def q(ds):
            return ds[()] << u.Unit(ds.attrs["unit"])

        monitors = json.loads(par.attrs["monitors"])
        fields = dict(
            times=q(b["position/time"]), positions=q(b["position/value"]),
            velocities=q(b["velocity/value"]), names=_decode(b["names"][()]),
            masses=q(b["mass"]), steps=int(b["position/step"][-1] - b["position/step"][0])
            if b["position/step"].shape[0] else 0,
            force_evaluations=None, wall_time=float("nan"),
            integrator=json.loads(par.attrs["integrator_info"]),
            units=json.loads(par.attrs["units"]),
            dt=par.attrs["dt"] * u.Unit(par.attrs["dt_unit"]), monitors=tuple(monitors),
            status=_status(f), path=str(path), metadata=dict(par.attrs))
        ref = par["reference"][()]
        e_scale, l_scale = par["scales"][()]
        for name in monitors:
            obs = f["observables"][name]
            fields[name] = q(obs["value"])
        if "energy" in monitors:
            fields["energy_error"] = relative_error(f["observables/energy/value"][()], ref[0],
                                                    scale=e_scale)
        if "angular_momentum" in monitors:
            fields["angular_momentum_error"] = vector_relative_error(
                f["observables/angular_momentum/value"][()], ref[1:4], l_scale)
        inloop = f["observables/in_loop"]
        if monitors and inloop[monitors[0]]["time"].shape[0]:
            mon = {"times": q(inloop[monitors[0]]["time"])}
            if "energy" in monitors:
                mon["energy_error"] = relative_error(inloop["energy/value"][()], ref[0],
                                                     scale=e_scale)
            if "angular_momentum" in monitors:
                mon["angular_momentum_error"] = vector_relative_error(
                    inloop["angular_momentum/value"][()], ref[1:4], l_scale)
            fields["monitor"] = mon
    return Result(**fields)


def _status(f):
    from .._kernels.status import Status
    count = int(f["restart/count"][()])
    if count == 0:
        return "no checkpoint yet (the writer stopped early)"
    _, finished, code = (int(a) for a in f["restart/progress"][(count - 1) % _SLOTS])
    if code:
        return {Status.NON_FINITE: "non-finite state", Status.CLOSE_ENCOUNTER:
                "close encounter", Status.ESCAPE: "escape",
                Status.STEP_UNDERFLOW: "step-size underflow"}.get(code, f"stopped ({code})")
    return "completed" if finished else "interrupted (resumable from the last checkpoint)"


@_damaged
def describe(path):
    """A few sentences saying what an output file holds."""
    with _open_read(path) as f:
        b = f["particles/bodies"]
        par = f["parameters"]
        names = _decode(b["names"][()])
        t = b["position/time"]
        tu = t.attrs["unit"]
        n_out = t.shape[0]
        units = json.loads(par.attrs["units"])
        lines = [
            f"{path}: orbits output (layout {FORMAT} v{FORMAT_VERSION}), written by "
            f"orbits {par.attrs['orbits_version']} on {par.attrs['written']}",
            f"bodies          {len(names)}: {', '.join(names[:8])}"
            + (", ..." if len(names) > 8 else ""),
            f"integrator      {par.attrs['integrator']} {par.attrs['integrator_options']}, "
            f"dt = {par.attrs['dt']:g} {par.attrs['dt_unit']}",
            f"units           {units['name']}, G = {units['G']!r} ({units['G_source']})",
            f"outputs         {n_out}"
            + (f", t = {t[0]:g} .. {t[-1]:g} {tu}" if n_out else ""),
            f"monitors        {', '.join(json.loads(par.attrs['monitors'])) or 'none'}",
            f"forces          {_describe_forces(par)}",
        ]
        count = int(f["restart/count"][()])
        if count:
            slot = (count - 1) % _SLOTS
            clock = f["restart/clock"][slot]
            tb = f["restart/t_base"][slot]
            t_ck = tb + clock[1] * par.attrs["dt"]
            lines.append(f"checkpoint      {count} written; the last at step {clock[0]}, "
                         f"t = {t_ck:g} {tu}")
        lines.append(f"status          {_status(f)}")
        return "\n".join(lines)


def _describe_forces(par):
    # Newtonian gravity and the added terms, as their constructors would be written
    from .. import forces
    text = ["Newtonian gravity"]
    for d in json.loads(par.attrs.get("forces", "[]")):
        try:
            text.append(repr(forces.from_dict(d)))
        except forces.ForceTermError:   # a user function that cannot be imported here
            text.append(f"{d.get('type')}({d.get('func', '')})")
    return " + ".join(text)


@_damaged
def restore(path):
    """The simulation at the file's last checkpoint, and the run it was in.

    Returns ``(sim, plan, outputs_written, finished)``.
    """
    from ..bodies import BodySet
    from ..simulation import RunPlan, Simulation, SimulationState
    from ..units import UnitSystem

    with _open_read(path) as f:
        count = int(f["restart/count"][()])
        if count == 0:
            raise OrbitsFileError(f"{path}: holds no complete checkpoint to restore from")
        slot = (count - 1) % _SLOTS
        par = f["parameters"]
        r = f["restart"]
        units = UnitSystem.from_dict(json.loads(par.attrs["units"]))
        order = r["order"][()]
        inv = np.argsort(order)
        names = _decode(f["particles/bodies/names"][()])
        m = f["particles/bodies/mass"][()]
        x = r["x"][slot]
        v = r["v"][slot]
        bodies = BodySet.from_arrays(m, x[inv], v[inv], names=names, units=units)
        bodies.history = json.loads(par.attrs["bodies_history"])
        if "config" in par.attrs:
            sim = Simulation.from_config(bodies, json.loads(par.attrs["config"]))
        else:
            sim = _legacy_simulation(par, bodies, units)
        if not np.array_equal(sim.state.order, order):
            raise OrbitsFileError(f"{path}: the stored body order does not match the masses")
        clock = r["clock"][slot]
        sim.set_state(SimulationState(
            x, v, order, float(r["t_base"][slot]), int(clock[1]), int(clock[0]),
            int(clock[2]), int(clock[4]), {name: r["ws"][name][slot] for name in r["ws"]},
            par["reference"][()], tuple(par["scales"][()])))
        p = r["plan"][slot]
        plan = RunPlan(float(p[0]), int(p[1]), float(p[2]), int(p[3]), bool(p[4]), int(p[5]),
                       float(p[6]))
        written, finished, _ = (int(a) for a in r["progress"][slot])
        rows = int(clock[3])
    sim._output_path = str(path)
    sim._resume = ResumePoint(plan, written, bool(finished), rows, sim.time.value)
    return sim


def _legacy_simulation(par, bodies, units):
    # files written before the configuration record
    from .. import integrators
    from ..simulation import Simulation
    integ = integrators.get(par.attrs["integrator"],
                            **json.loads(par.attrs["integrator_options"]))
    soft = float(par.attrs["softening"])

    stop = json.loads(par.attrs["stop_conditions"])
    length = lambda val: None if val is None else val << units.length  # noqa: E731
    dt = float(par.attrs["dt"])
    sim = Simulation(bodies, integrator=integ,
                     dt=(dt << units.time) if dt > 0 or not integ.adaptive else None,
                     monitors=tuple(json.loads(par.attrs["monitors"])),
                     monitor_every=int(par.attrs["monitor_every"]) or None,
                     softening=(soft << units.length) if soft > 0 else None,
                     parallel=bool(par.attrs["parallel"]),
                     encounter_distance=length(stop["encounter_distance"]),
                     encounter_hill=stop["encounter_hill"],
                     escape_distance=length(stop["escape_distance"]),
                     escape_unbound=stop["escape_unbound"],
                     rebound_arithmetic=bool(par.attrs.get("rebound_arithmetic", False)))
    return sim


class ResumePoint(NamedTuple):
    """Where a restored simulation stands in the run its file was written by."""

    plan: object            # the RunPlan of that run
    outputs_written: int    # of that run, at the checkpoint
    finished: bool
    rows: int               # output rows in the file at the checkpoint
    time: float             # simulation time at the checkpoint


def truncate(path, point):
    """Drop what was written after the checkpoint ``point`` (a :class:`ResumePoint`).

    The file is copied, which also leaves a file whose writer was killed
    clean for writing again.
    """
    tmp = pathlib.Path(str(path) + ".resume")
    with _open_read(path) as src, h5py.File(tmp, "w", libver="latest") as dst:
        for k, v in src.attrs.items():
            dst.attrs[k] = v
        for name in src:
            src.copy(src[name], dst, name=name)
        groups = [dst["particles/bodies/position"], dst["particles/bodies/velocity"]]
        groups += [dst["observables"][k] for k in dst["observables"] if k != "in_loop"]
        for g in groups:
            for ds in g.values():
                ds.resize(min(ds.shape[0], point.rows), axis=0)
        for g in dst["observables/in_loop"].values():
            keep = int(np.count_nonzero(g["time"][()] <= point.time))
            for ds in g.values():
                ds.resize(keep, axis=0)
    os.replace(tmp, path)
