"""A simulation's state: taken from a body set (massive bodies first, with the
integrator's workspace for them), read out as records in the body set's order
(the :class:`~orbits.records.SimulationState` a checkpoint stores, the current
:class:`~orbits.BodySet`, an output's :class:`~orbits.records.Snapshot`, the
:class:`~orbits.records.SimulationDescription` a file records) and put back
from a state record.

The simulation keeps its bodies massive first (``sim._order``); these records
undo that order, and the integrator is synchronised before its state is read.
"""

import math

import numpy as np

from . import _stop_conditions as _stops
from ._kernels import invariants as _inv
from .bodies import BodySet
from .records import SimulationDescription, SimulationState, Snapshot, _function_name

__all__ = ["take_bodies", "workspace", "body_set", "record", "saved_workspace", "put_back",
           "description", "snapshot", "twin_parts", "rebuilt"]


def take_bodies(sim, bodies):
    """The simulation's arrays of ``bodies``: massive bodies first (stable), as
    the gravity kernels expect, with the order and its inverse."""
    m = bodies._m
    sim._order = np.concatenate([np.flatnonzero(m > 0), np.flatnonzero(m == 0)])
    sim._m = np.ascontiguousarray(m[sim._order])
    sim._r = np.ascontiguousarray(bodies._r[sim._order])
    sim._x = np.ascontiguousarray(bodies._x[sim._order])
    sim._v = np.ascontiguousarray(bodies._v[sim._order])
    sim._n_active = int(np.count_nonzero(sim._m > 0))
    sim._inverse = np.argsort(sim._order)


def workspace(sim):
    """The integrator's workspace for the simulation's rows (bodies and tangent
    rows), bound to its force, with what else a checkpoint keeps with the
    state: the work ``W`` of non-conservative terms, the chaos indicators, and
    what resolved collisions took out of the bodies (energy, and angular
    momentum into the merged bodies' spins; :mod:`orbits.collisions`)."""
    rows = len(sim._rows_x)
    integ = sim.integrator
    ws = integ.workspace(rows, sim._dt) if integ.adaptive else integ.workspace(rows)
    integ.bind(ws, sim._force, sim._fargs)
    if sim._base_force.dissipative:
        ws["work"] = sim._base_fargs[2][3]
    if sim._chaos_box is not None:
        ws["chaos"] = sim._chaos_box
    if sim._resolves_collisions:
        ws["collision_offset"] = np.zeros(4)
    return ws


def body_set(sim):
    """The current state as a new :class:`~orbits.BodySet` (:attr:`Simulation.bodies`)."""
    sim.integrator.synchronize(sim._ws, sim._rows_x, sim._rows_v)
    inv = np.argsort(sim._order)
    bs = BodySet(sim.units)
    bs._bare_ok = sim._bare_ok
    bs._names = list(sim._names)
    bs._m = sim._m[inv].copy()
    bs._r = sim._r[inv].copy()
    bs._x = sim._x[inv].copy()
    bs._v = sim._v[inv].copy()
    bs.history = list(sim._history)
    if sim._epoch is not None:
        bs._epoch = sim._epoch + sim.time
    return bs


def record(sim):
    """The :class:`~orbits.records.SimulationState` (copies) of ``sim``."""
    return SimulationState(
        sim._x.copy(), sim._v.copy(), sim._order.copy(), sim._t_base,
        sim._steps_since_base, sim.steps, sim.force_evaluations, sim.steps_rejected,
        saved_workspace(sim), sim._reference.copy(), (sim._E_scale, sim._L_scale))


def put_back(sim, state):
    """Put ``state`` back into ``sim`` (:meth:`Simulation.set_state`)."""
    if not np.array_equal(sim._order, state.order):
        raise ValueError("the state's body order does not match this simulation's "
                         "masses")
    sim._x[...] = state.x
    sim._v[...] = state.v
    sim._t_base = float(state.t_base)
    sim._steps_since_base = int(state.steps_since_base)
    sim.steps = int(state.steps)
    sim.force_evaluations = int(state.force_evaluations)
    sim.steps_rejected = int(state.steps_rejected)
    for name, arr in state.workspace.items():
        if name in sim._ws:
            sim._ws[name][...] = arr
    if _stops.keeps_previous(sim) and "stop_prev" in state.workspace:
        sim._stop[8][...] = state.workspace["stop_prev"]
        sim._stop_clock[...] = state.workspace["stop_clock"]
    else:
        _stops.keep_current(sim)
    if sim._n_tangent:
        tangent = state.workspace.get("tangent")
        if tangent is None or tangent.shape != (2,) + sim._rows_x[len(sim._m):].shape:
            raise ValueError("the state has no tangent vectors of this simulation's "
                             "variations")
        n = len(sim._m)
        sim._rows_x[n:] = tangent[0]
        sim._rows_v[n:] = tangent[1]
    # a reference row written before the work column was kept: its work is 0
    ref = np.asarray(state.reference, dtype=float)
    sim._reference = np.zeros(max(_inv.MONITOR_WIDTH, len(ref)))
    sim._reference[:len(ref)] = ref
    sim._E_scale, sim._L_scale = (float(s) for s in state.scales)


def twin_parts(sim):
    """What makes a simulation equal to ``sim`` bit for bit, in this process
    or another (:func:`rebuilt`; pickling and deep copies): its bodies now,
    its configuration and the user's functions it names (which pickle by
    reference), its exact state (:func:`record`, as a checkpoint keeps it),
    the date of time 0, and the collisions it has resolved."""
    from .forces import functions_of
    return (body_set(sim), sim.config, record(sim), functions_of(sim._terms), sim._epoch,
            list(sim._collisions), sim._bodies_changed)


def rebuilt(cls, bodies, config, state, functions, epoch, collisions, changed):
    """The simulation (a ``cls``) that :func:`twin_parts` describes: made
    from its configuration as a restart from a file is, its state put back.
    Its compiled code comes from numba's cache; a user's functions are made
    into pointers again (their addresses do not travel)."""
    sim = cls.from_config(bodies, config, _restoring=True, functions=functions)
    sim.set_state(state)
    sim._epoch = epoch
    sim._collisions = collisions
    sim._bodies_changed = changed
    return sim


def description(sim):
    """The :class:`~orbits.records.SimulationDescription` of ``sim``."""
    inv = sim._inverse
    stops = dict(sim._stop_config)
    if callable(stops.get("collisions")):
        # a plain record names the function (a file cannot hold it)
        stops["collisions"] = _function_name(stops["collisions"])
    return SimulationDescription(
        tuple(sim._names), sim._m[inv].copy(), sim._r[inv].copy(), sim.units,
        sim.integrator, sim._dt, math.sqrt(sim._eps2), sim.monitors,
        sim.monitor_every, sim.parallel, sim.rebound_arithmetic,
        stops, list(sim._history), sim.config, sim.forces, sim._epoch)


def snapshot(sim):
    """The current output of ``sim`` (:class:`~orbits.records.Snapshot`)."""
    sim.integrator.synchronize(sim._ws, sim._rows_x, sim._rows_v)
    row = np.zeros(_inv.MONITOR_WIDTH)
    if sim._mask:
        sim._monitor_row(row)
    inv = sim._inverse
    if sim._resolves_collisions:
        return Snapshot(sim._now(), sim.steps, sim._x[inv], sim._v[inv], row,
                        tuple(sim._names), sim._m[inv], sim._r[inv])
    return Snapshot(sim._now(), sim.steps, sim._x[inv], sim._v[inv], row)


def saved_workspace(sim):
    # the workspace's arrays, the tangent rows of a run with variations, and
    # the state the collision check and the encounter log keep from the
    # step before (so that a restart looks inside its first step too)
    ws = {k: a.copy() for k, a in sim._ws.items() if isinstance(a, np.ndarray)}
    if _stops.keeps_previous(sim):
        ws["stop_prev"] = sim._stop[8].copy()
        ws["stop_clock"] = sim._stop_clock.copy()
    if sim._n_tangent:
        n = len(sim._m)
        ws["tangent"] = np.stack([sim._rows_x[n:], sim._rows_v[n:]])
    return ws
