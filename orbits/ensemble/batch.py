"""Batch mode of ensembles: runs integrated several at a time, one per vector lane.

:meth:`orbits.Ensemble.run` with ``batch=B`` hands each task's runs here
(:func:`run_batched`).  Every run is built as it would be alone; those that
:func:`batch_key` accepts (``wh`` with its default options, no added forces,
stopping conditions, variations, chaos monitors, ``monitor_every`` or
softening, and a fresh integrator state) are grouped by what they must share
(bodies, massive bodies, step, units, monitors, start and the run's plan) and
advanced B at a time by :func:`orbits._kernels.wh_batch.advance_lanes`.  The
others run alone, as without ``batch``.

A batched run keeps its own simulation and recorder (the one ``Simulation.run``
would make: in memory, or its file in ``out_dir``).  At each output the lanes'
rows (monitors, then positions and velocities) are computed in the compiled
loop (:func:`orbits._kernels.wh_batch.record_lanes`) and handed to the
recorders as a run's in-loop outputs are; at the end each simulation takes
its lane's state (:meth:`orbits.Simulation.set_state`: Jacobi state, owed
drift, clock and counters) and records its last output itself.  As the lanes
do the scalar arithmetic bit for bit, the rows equal those of the runs made
one by one.  A run whose state turned non-finite is run again alone from its
start, so that its outcome, message, stop time and errors are those of its
own failure.
"""

import time as _time

import numpy as np

from .._kernels import wh_batch as _lanes
from .._kernels.invariants import MONITOR_WIDTH
from ..errors import OrbitsError
from ..integrators.wisdom_holman import MASS_RATIO_LIMIT
from ..io import hdf5
from ..monitors import CHAOS_MONITORS, monitor_mask
from ..recorder import Recorder
from .compiles import _cache_loads, _CompileRecorder, _sync_numba_config, _worker_fields
from .table import _parameter_row
from .worker import _advance, _invalid_row, _run_row

__all__ = ["run_batched", "batch_key", "FLUSH_OUTPUTS"]

#: Outputs of a batch kept before they are handed to the runs' recorders (a
#: file recorder takes at most 16 * 256 rows a call).
FLUSH_OUTPUTS = 256


class _Lane:
    """One run of a batch: where its row goes, the row so far, its simulation,
    file, plan, masses (internal order) and massive bodies."""

    def __init__(self, pos, row, sim, path, plan, m, n_active):
        self.pos = pos
        self.row = row
        self.sim = sim
        self.path = path
        self.plan = plan
        self.m = m
        self.n_active = n_active


def batch_key(sim, spec):
    """``(key, plan, masses, n_active)`` for a simulation that can join a batch
    (runs with equal keys can share one), or None.

    Parameters
    ----------
    sim : Simulation
        Freshly built.
    spec : orbits.ensemble.worker._Spec
        The sweep's ``until`` and ``outputs``.
    """
    if not sim.integrator.batchable or sim.forces:
        return None
    desc = sim.description()
    cfg = desc.config
    if (cfg.stop_conditions or cfg.variations is not None or desc.monitor_every is not None
            or any(name in CHAOS_MONITORS for name in desc.monitors)
            or desc.softening != 0.0 or desc.parallel or desc.rebound_arithmetic):
        return None
    state = sim.state
    if int(state.workspace["state"][0]) != 0:
        return None     # the integrator holds an internal state of its own already
    m = np.ascontiguousarray(desc.masses[state.order])
    n_active = int(np.count_nonzero(m > 0))
    if n_active < 1 or not m[0] > 0:
        return None
    G = desc.units.G
    gm = G * m
    if n_active > 2 and float(np.max(gm[1:n_active]) / gm[0]) > MASS_RATIO_LIMIT:
        return None     # alone it warns (NoDominantBodyWarning): leave it to say so
    try:
        plan = sim._plan(sim._time_value(spec.until, "until"), spec.outputs, spec.until)
    except Exception:   # alone it raises: let it
        return None
    if plan.direction < 0:
        return None     # the lanes' loop steps forwards only: a run backwards goes alone
    key = (len(m), n_active, float(desc.dt), float(G), desc.units.name, tuple(desc.monitors),
           float(state.t_base), int(state.steps_since_base), int(state.steps), tuple(plan))
    return key, plan, m, n_active


def run_batched(build, params, indices, spec, paths, batch):
    """Rows of the runs ``indices`` (in order) and the exception that stopped the
    task, or None: :func:`orbits.ensemble.tasks.run_chunk` with up to ``batch``
    runs integrated together."""
    _sync_numba_config()
    rows = {}
    groups = {}
    error = None
    for pos, (p, i, path) in enumerate(zip(params, indices, paths)):
        row = _parameter_row(p, i)
        loaded0 = _cache_loads()
        with _CompileRecorder() as log:
            try:
                sim = build(**p)
                found = batch_key(sim, spec)
                if found is None:
                    outcome, exc, wall, result = _advance(sim, spec, path)
            except OrbitsError as err:
                rows[pos] = _invalid_row(row, err, _worker_fields(loaded0, log))
                continue
            except Exception as exc:     # build's own errors stop the sweep, as alone
                error = exc
                break
        if found is None:
            rows[pos] = _run_row(row, sim, spec, path, outcome, exc, wall, result,
                                      lambda: _worker_fields(loaded0, log))
            continue
        key, plan, m, n_active = found
        groups.setdefault(key, []).append(_Lane(pos, row, sim, path, plan, m, n_active))
    for lanes in groups.values():
        for k in range(0, len(lanes), batch):
            part = lanes[k:k + batch]
            rows.update(_run_lanes(part, spec, lane_width(len(part), batch)))
    return [rows[k] for k in sorted(rows)], error


def lane_width(runs, batch):
    """The lanes a batch of ``runs`` runs in: the smallest power of two that
    holds them, or ``batch`` where that is smaller.  The batch loop's kick is
    compiled for its number of lanes, so a sweep's last, partial batch (and a
    group of few runs) takes one of a few widths instead of a width of its
    own; the lanes beyond the runs stay idle.

    Examples
    --------
    >>> from orbits.ensemble.batch import lane_width
    >>> [lane_width(n, 8) for n in (1, 2, 3, 5, 8)], lane_width(5, 6)
    ([1, 2, 4, 8, 8], 6)
    """
    width = 1
    while width < runs:
        width *= 2
    return min(width, batch)


def _recorder(sim, plan, path):
    # the recorder Simulation.run would make for this run
    if path is None:
        return Recorder(sim, initial=plan.outputs > 1, capacity=plan.outputs)
    return hdf5.FileRecorder(path, sim, plan, overwrite=True)


def _run_lanes(lanes, spec, width):
    """Run ``lanes`` (runs of one key) together in ``width`` lanes (at least
    as many as runs; the others idle copies of the first run, frozen from the
    start); their rows by position."""
    loaded0 = _cache_loads()
    out = {}
    with _CompileRecorder() as log:
        wall0 = _time.perf_counter()
        first = lanes[0].sim
        desc = first.description()
        plan = lanes[0].plan
        nb = max(width, len(lanes))
        states = [lane.sim.state for lane in lanes]
        filled = states + [states[0]] * (nb - len(lanes))
        n = len(states[0].order)
        n_active = lanes[0].n_active
        G = desc.units.G
        dt = float(desc.dt)
        masses = np.ascontiguousarray(np.stack([lane.m for lane in lanes]
                                               + [lanes[0].m] * (nb - len(lanes))))  # (B, N)
        gm = np.ascontiguousarray((G * masses).T)                             # (N, B)
        x = np.stack([s.x for s in filled], axis=2)
        v = np.stack([s.v for s in filled], axis=2)
        xj, vj, eta = _lanes.to_lanes(x, v, gm)
        ws = _lanes.lanes_workspace(n, nb)
        owed = np.zeros(nb)
        live = np.ones(nb)
        live[len(lanes):] = 0.0         # the idle lanes, frozen
        status = np.zeros(nb, dtype=np.int64)
        good = np.zeros(nb, dtype=np.int64)
        lanes_record = _lanes.Lanes(xj, vj, gm, eta, owed, live, status, good)
        recs = [_recorder(lane.sim, plan, lane.path) for lane in lanes]
        which = monitor_mask(desc.monitors)
        scratch = (np.zeros((6, n, 3)), np.zeros((2, n)), np.zeros((0, 2)), np.zeros((n, 3)),
                   np.zeros((n, 3)))
        buf = np.zeros((FLUSH_OUTPUTS, nb, MONITOR_WIDTH + 6 * n))
        marks = []
        t_base0 = float(states[0].t_base)
        ssb0 = int(states[0].steps_since_base)
        steps0 = int(states[0].steps)

        # the kick written out for this size of system where it is small
        # enough (wh_batch.advance_loop), the same steps bit for bit
        loop = _lanes.advance_loop(n, n_active, nb)

        def advance(k, h):
            if k > 0:
                loop(lanes_record, n_active, h, k, ws)

        def flush():
            k = len(marks)
            if not k:
                return
            steps = np.array([steps0 + mk for mk in marks], dtype=np.int64)
            # the outputs' times as Simulation._now() gives them at their steps
            t = np.array([t_base0 + (ssb0 + mk) * dt for mk in marks])
            for b, rec in enumerate(recs):
                if status[b] == 0:
                    rows = rec.row_buffer(k)
                    rows[...] = buf[:k, b]
                    rec.output_rows(lanes[b].sim, steps, t, rows)
            marks.clear()

        done = 0
        for mark in plan.marks():
            advance(mark - done, dt)
            done = max(done, mark)
            _lanes.record_lanes(xj, vj, gm, eta, owed, live, n_active, masses, G, which,
                                *scratch, buf[len(marks)])
            marks.append(mark)
            if len(marks) == FLUSH_OUTPUTS:
                flush()
        flush()
        advance(plan.n_full - done, dt)
        t_now = t_base0 + (ssb0 + plan.n_full) * dt
        last = plan.until - t_now
        if plan.has_partial:
            advance(1, last)
        taken = plan.n_full + int(plan.has_partial)
        share = (_time.perf_counter() - wall0) / nb
        again = []
        for b, (lane, rec, st) in enumerate(zip(lanes, recs, states)):
            if status[b] != 0:
                rec.close()
                again.append(lane)
                continue
            wsb = st.workspace
            wsb["xj"][...] = xj[:, :, b]
            wsb["vj"][...] = vj[:, :, b]
            wsb["owed"][0] = owed[b]
            wsb["state"][:] = 1
            wsb["gm"][...] = gm[:, b]
            wsb["eta"][...] = eta[:, b]
            wsb["n_active"][0] = n_active
            xb, vb = _lanes.lane_inertial(xj, vj, gm, eta, owed, n_active, b)
            # the clock as Simulation's driver leaves it (a shortened last step
            # starts a new base)
            if plan.has_partial:
                t_base, ssb = t_now + last, 0
            else:
                t_base, ssb = t_base0, ssb0 + plan.n_full
            lane.sim.set_state(st._replace(
                x=xb, v=vb, t_base=t_base, steps_since_base=ssb, steps=steps0 + taken,
                force_evaluations=st.force_evaluations
                + taken * lane.sim.integrator.forces_per_step, workspace=wsb))
            rec.output(lane.sim, final=True)
            rec.close()
            result = rec.result(lane.sim, share)
            out[lane.pos] = (lane, "completed", None, share, result)
        # a run that failed: alone again from its start, for its own failure's row
        for lane in again:
            outcome, exc, wall, result = _advance(lane.sim, spec, lane.path)
            out[lane.pos] = (lane, outcome, exc, wall + share, result)
    fields = _worker_fields(loaded0, log)
    rows = {}
    for k, pos in enumerate(sorted(out)):
        lane, outcome, exc, wall, result = out[pos]
        worker = fields if k == 0 else dict(fields, kernels_compiled=0, kernels_loaded=0)
        rows[pos] = _run_row(lane.row, lane.sim, spec, lane.path, outcome, exc, wall,
                                  result, lambda w=worker: w)
    return rows
