"""The collision resolver: the collisions of a step that a run resolves and goes
on from (``collisions="merge"``, ``"bounce"`` or a function), in the order of
their contact times, with what they take out of the bodies' energy and angular
momentum kept as offsets of the monitors.

The physics of one pair (a merger, a bounce, the answer of a user's function)
is :mod:`orbits.collisions`; this module applies it to a simulation whose
compiled loop stopped at a contact (:meth:`orbits._driver.Driven.execute`).
"""

import math

import numpy as np

from . import _stop_conditions as _stops
from . import collisions as _collisions
from ._kernels import invariants as _inv
from ._kernels import stopping as _s
from ._kernels.status import Status
from .bodies import BodySet

__all__ = ["resolves", "resolve", "offset_rows", "table", "merge_energy_change"]


def resolves(sim):
    """Whether the simulation's run resolves collisions and goes on (not "halt")."""
    c = sim._stop_config.get("collisions")
    return c is not None and c != "halt"


def offset_rows(sim, rows):
    """Monitor rows (shape (k, MONITOR_WIDTH)) with what the collisions resolved
    before them took out of the bodies: the energy into the work column, the
    angular momentum into its columns (see :mod:`orbits.collisions`)."""
    off = sim._ws.get("collision_offset")
    if off is not None and len(rows) and off.any():
        rows[:, _inv.WORK_COLUMN] += off[0]
        rows[:, 1:4] += off[1:4]
    return rows


def table(sim):
    """What makes ``result.collisions``, an astropy QTable of the collisions
    resolved so far (None when the run does not resolve collisions): a
    function of no arguments, called where the field is first read."""
    if not resolves(sim):
        return None
    rows, units = list(sim._collisions), sim.units
    return lambda: _collisions.table(rows, units)


def resolve(sim, rec, wall0):
    """Resolve every collision of the step just taken, in the order of
    their contact times (the loop stopped at the first it found); see
    :mod:`orbits.collisions`.  A ``"halt"`` from a collisions function
    stops the run there, after the collisions before it were resolved."""
    sim.integrator.synchronize(sim._ws, sim._rows_x, sim._rows_v)
    t = sim._now()
    n = len(sim._m)
    out = np.zeros((max(1, min(n * (n - 1) // 2, 65536)), 5))
    found_rows = []
    seen = sim.integrator.checked_state(sim._ws, t)
    if seen is not None:
        # the loop looked (and found the first pair) at a state before t:
        # the pairs up to there, then those of the rest of the step
        xk, vk, tk = seen
        found = _s.collision_pairs(xk, vk, tk, sim._stop, out)
        found_rows += out[:found].tolist()
        _stops.log_step(sim, xk, vk, tk, rec)
        _s.keep_state(xk, vk, tk, sim._stop)
    found = _s.collision_pairs(sim._x, sim._v, t, sim._stop, out)
    found_rows += out[:found].tolist()
    j, i = (float(k) for k in sim._stop_info)
    if rec is not None and j != i and (j, i) not in {(row[0], row[1]) for row in found_rows}:
        # the pair the loop stopped for, touching after the state it left
        # (an integrator that could not carry them through their contact,
        # Trace.behind): resolved here, before its contact
        found_rows.append([j, i] + [float(a) for a in sim._stop_hit])
    first = {}
    for row in sorted(found_rows, key=lambda row: row[2]):
        first.setdefault((row[0], row[1]), row)    # a pair once, at its first contact
    pairs = list(first.values())
    how = sim._stop_config["collisions"]
    e = sim._stop_config.get("restitution")
    e = 1.0 if e is None else e
    m, r = sim._m.copy(), sim._r.copy()
    x, v = sim._x.copy(), sim._v.copy()
    alive = np.ones(n, dtype=bool)
    into = np.arange(n)          # a merged body's survivor
    internal = sim._names_internal()
    G = sim.units.G
    E0, L0 = _invariants(sim)
    rows, halted = [], None

    def root(k):
        while into[k] != k:
            k = into[k]
        return k

    def resolve(a, b, tc, dist, speed):
        # one collision of bodies a, b (internal indices, both alive)
        nonlocal halted
        a, b = min(a, b), max(a, b)
        answer = how
        if callable(how):
            answer = _collisions.check_answer(how(_event(sim, 
                (a, b), m, r, x, v, tc, t, dist, speed)), (internal[a], internal[b]))
        if answer == "halt":
            halted = (a, b, tc, dist, speed)
            return False
        if answer == "bounce":
            va, vb, closing = _collisions.bounce_pair(m, x, v, a, b, e)
            dE = _collisions.pair_energy_change(m, x, v, a, b, va, vb)
            v[a], v[b] = va, vb
            rows.append((tc, t, internal[a], internal[b], "bounce", "", dist, speed, dE))
            return False
        # merge: the more massive survives (the first in the body set on a tie)
        keep, gone = (a, b) if (m[a] > m[b] or (m[a] == m[b] and sim._order[a]
                                                < sim._order[b])) else (b, a)
        dE = merge_energy_change(m, x, v, alive, keep, gone, G, sim._eps2)
        m[keep], r[keep], x[keep], v[keep] = _collisions.merge_pair(m, r, x, v, keep, gone)
        alive[gone] = False
        into[gone] = keep
        rows.append((tc, t, internal[a], internal[b], "merge", internal[keep], dist,
                     speed, dE))
        return True

    merged = set()
    for j, i, tc, dist, speed in pairs:
        a, b = root(int(j)), root(int(i))
        if a == b:
            continue
        if (a, b) != (int(j), int(i)):
            # one of them merged earlier in this step: the merger, at the end
            d = float(np.linalg.norm(x[a] - x[b]))
            if d >= r[a] + r[b]:
                continue
            tc, dist, speed = t, d, float(np.linalg.norm(v[a] - v[b]))
        if resolve(a, b, tc, dist, speed):
            merged.add(root(a))
        if halted:
            break
    # chains: a merged body that now overlaps another collides again
    while merged and not halted:
        k = merged.pop()
        if not alive[k]:
            continue
        d = np.linalg.norm(x - x[k], axis=1)
        hit = np.flatnonzero(alive & (d < r + r[k]) & (np.arange(n) != k))
        if hit.size:
            o = int(hit[0])
            if resolve(k, o, t, float(d[o]), float(np.linalg.norm(v[k] - v[o]))):
                merged.add(root(k))
    if not alive.all():
        _stops.drain_log(sim, rec)
        new_index = _replace_bodies(sim, m, r, x, v, alive)
    else:
        new_index = np.arange(n)
        sim._v[...] = v
        sim.integrator.invalidate(sim._ws)
    E1, L1 = _invariants(sim)
    off = sim._ws["collision_offset"]
    off[0] -= E1 - E0
    off[1:4] -= L1 - L0
    _stops.log_step(sim, sim._x, sim._v, t, rec)   # the step's approaches, which the loop left
    _s.keep_state(sim._x, sim._v, t, sim._stop)
    sim._collisions.extend(rows)
    keep = getattr(rec, "collision_rows", None)
    if keep is not None and rows:
        keep(sim, rows)
    if halted:
        a, b, tc, dist, speed = halted
        sim._stop_info[:] = (new_index[a], new_index[b])
        sim._stop_hit[:] = (tc, dist, speed)
        sim._fail(Status.COLLISION, rec, wall0)


def _invariants(sim):
    """Energy (gravity and the conservative terms) and angular momentum of
    the current state, whatever monitors were asked for."""
    row = np.zeros(_inv.MONITOR_WIDTH)
    _inv.monitor_row(sim._x, sim._v, sim._m, sim.units.G, sim._n_active, sim._eps2,
                     _inv.ENERGY | _inv.ANGULAR_MOMENTUM, row)
    if sim._terms:
        row[0] += sim._base_force.terms.energy(sim._x, sim._v, sim._eargs)
    return row[0], row[1:4].copy()


def _event(sim, pair, m, r, x, v, tc, t, dist, speed):
    q = sim.units.quantity
    a, b = pair
    names = sim._names_internal()
    return _collisions.CollisionEvent(
        q(tc, "time"), q(t, "time"), (names[a], names[b]), q(m[[a, b]], "mass"),
        q(r[[a, b]], "length"), q(x[[a, b]], "length"), q(v[[a, b]], "velocity"),
        q(dist, "length"), q(speed, "velocity"))


def _replace_bodies(sim, m, r, x, v, alive):
    """Go on with the bodies ``alive`` of these arrays (internal order),
    after mergers: the clock, counters, monitors' reference, encounter and
    collision lists and the integrator's scalar state carry over; returns
    each old internal index's new one (-1: gone)."""
    user = np.flatnonzero(alive[sim._inverse])     # survivors' places in the body set
    old = sim._inverse[user]                        # their internal indices
    bs = BodySet(sim.units)
    bs._bare_ok = sim._bare_ok
    bs._names = [sim._names[k] for k in user]
    bs._m, bs._r = m[old].copy(), r[old].copy()
    bs._x, bs._v = x[old].copy(), v[old].copy()
    bs.history = list(sim._history)
    bs._epoch = sim._epoch
    prev, clock = sim._stop[8], sim._stop[9]   # the state before the step
    new = type(sim).__new__(type(sim))
    new._touching_ok = True
    stops = dict(sim.stop_conditions)
    stops = {k: val for k, val in stops.items() if val is not None and val is not False}
    new.__init__(bs, sim.integrator, dt=None if sim._dt == 0 else sim.dt,
                 forces=list(sim._terms), monitors=sim.monitors,
                 monitor_every=sim.monitor_every,
                 softening=sim._softening, parallel=sim.parallel,
                 rebound_arithmetic=sim.rebound_arithmetic, **stops)
    # the integrator's state that does not depend on the number of bodies
    # (an adaptive method's next step, the clock's compensation, the work)
    for key, arr in sim._ws.items():
        mine = new._ws.get(key)
        if isinstance(arr, np.ndarray) and isinstance(mine, np.ndarray) \
                and mine.shape == arr.shape and mine.dtype == arr.dtype:
            mine[...] = arr
    new.integrator.invalidate(new._ws)
    carry = ("_t_base", "_steps_since_base", "steps", "force_evaluations",
             "steps_rejected", "_chunk", "output_path", "_resume", "_reference",
             "_E_scale", "_L_scale", "_encounters", "_collisions", "_wall0", "_signals",
             "_compile_clock", "_wall_limit", "_in_loop", "_history", "_bodies_changed")
    for key in carry:
        if key in sim.__dict__:
            new.__dict__[key] = sim.__dict__[key]
    del new.__dict__["_touching_ok"]
    # the survivors' state before the step, for the encounter log's look
    # inside it (a merged body's own)
    new._stop[8][...] = prev[:, old[new._order]]
    new._stop[9][...] = clock
    sim.__dict__.clear()
    sim.__dict__.update(new.__dict__)
    sim._bodies_changed += 1
    index = np.full(len(alive), -1)
    index[old] = sim._inverse
    return index


def merge_energy_change(m, x, v, alive, a, b, G, eps2):
    """The energy change (Newtonian gravity, softened as the simulation is)
    when bodies ``a`` and ``b`` merge: their kinetic energy of relative motion
    and their mutual binding go, and the others' pull on them now acts on the
    centre of mass."""
    M = m[a] + m[b]
    if not M > 0:
        return 0.0
    X = (m[a] * x[a] + m[b] * x[b]) / M
    u = v[a] - v[b]
    dE = -0.5 * m[a] * m[b] / M * float(u @ u)
    dE += G * m[a] * m[b] / math.sqrt(float((x[a] - x[b]) @ (x[a] - x[b])) + eps2)
    others = alive.copy()
    others[[a, b]] = False
    mk, xk = m[others], x[others]
    pot = lambda p: np.sqrt(((xk - p) ** 2).sum(axis=1) + eps2)  # noqa: E731
    dE -= G * float(np.sum(mk * (M / pot(X) - m[a] / pot(x[a]) - m[b] / pot(x[b]))))
    return dE
