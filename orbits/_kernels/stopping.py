"""Stopping conditions checked inside the compiled loops.

A check has the signature ``check(x, v, t, sargs) -> status`` (``t`` the
time of the state) and, when it fires, writes the bodies concerned into
``sargs[6]`` (an int64 array of two: the pair for an encounter or a
collision; the body and -1 for an escape).

The conditions are data: a loop takes the stopping record ``sargs, check``
(:func:`stop_record`), ``check`` a pointer to :func:`check_stop` compiled as
a C callable of the signature :data:`CHECK` (numba's first-class functions,
:class:`~._jit.Pointer`), and calls it after a step only where ``sargs[0]``
(the mask) is not 0 (:func:`call_check`, on the pair ``(sargs, check)``): one
loop serves every combination of conditions, and a run without any pays a
branch a step.  The pointer is compiled once, on
first use, and cached (:func:`check_escapes`' where the conditions are
escapes alone; an idle pointer, compiled from nothing, where there are
none); every simulation's ``sargs`` has the type
:data:`SARGS`, a run without conditions :func:`no_conditions`.  A C callable
cannot raise into its caller; :func:`check_stop` raises nothing (numpy's
error model, no allocation).

``sargs = (mask, distance2, hill_k, escape2, gm, central, info, radii, prev,
clock, work, hit, log_hill, log_distance, log, log_n)``:

* ``mask``: bits :data:`ENCOUNTER_DISTANCE`, :data:`ENCOUNTER_HILL`,
  :data:`ESCAPE`, :data:`UNBOUND`, :data:`COLLISION`, :data:`ENCOUNTER_LOG`;
* ``distance2``: squared encounter distance;
* ``hill_k``: encounter at ``k`` mutual Hill radii,
  ``R_H = ((m_i + m_j) / (3 m_c))^(1/3) (r_i + r_j) / 2`` with ``r`` the
  distances from the central (most massive) body ``c`` (Chambers 1996),
  taken at the end of the step; an encounter is found at the end of a step
  or inside it (:func:`encounter_check`), as a collision is;
* ``escape2``: squared escape distance from the centre of mass; with
  :data:`UNBOUND` a body beyond it counts only if its energy about the centre
  of mass, ``v^2/2 - G M / r``, is positive;
* ``gm``: G times the masses; ``central``: index of the central body;
* ``radii`` (shape (n,)): the bodies' radii; with :data:`COLLISION` two
  bodies collide when their separation falls below the sum of their radii,
  at the end of a step or inside it (:func:`collision_check`);
* ``prev`` (shape (2, n, 3)) and ``clock`` (``[t, valid]``): the positions
  and velocities at the previous check and their time, for looking inside
  the step (the conditions of :data:`LOOKS_INSIDE`); the simulation records
  its state there before the first step, so that the first step is looked
  inside as every other; ``clock[1] = 0`` makes the next check look at the
  end of its step only;
* ``work`` (shape (4, 3)): scratch;
* ``hit`` (``[t, d, speed]``): where a collision or an encounter fired, its
  time (of the closest approach inside the step, or the end of the step
  where the pair is inside already), the separation and the relative speed
  there;
* with :data:`ENCOUNTER_LOG` (:func:`encounter_log`), every closest approach
  of a pair inside ``log_hill`` mutual Hill radii (pairs without the central
  body; 0: not used) or ``log_distance`` is written as a row ``(t, j, i,
  distance, speed)`` of ``log`` (shape (capacity, 5)), ``log_n[0]`` counting
  them; the run does not stop for it, but hands back
  :data:`~orbits._kernels.status.Status.LOG_FULL` when the log is half full,
  for the driver to empty it and carry on, or at once when it fills inside a
  step: the look at that step then stops at the pair ``(log_n[1], log_n[2])``
  (``log_n[1] = 0`` when none is pending), with the state of the step before
  kept, and the driver, having emptied (and enlarged) the log, calls
  :func:`check_stop` again on the same state to finish it.
"""

import math

import numpy as np
from numba.core import types as nbtypes

from ._jit import idle_pointer, njit, pointer
from .coordinates import centre_of_mass, row_difference
from .encounters import closest_approach, kepler_contact
from .status import Status

__all__ = ["no_stop", "check_stop", "check_escapes", "SARGS", "CHECK", "AHEAD", "no_conditions",
           "stop_record", "call_check", "check_pointer", "check_kind", "ahead_pointer",
           "collision_check",
           "collision_pairs", "keep_state", "encounter_log", "encounter_check",
           "collision_ahead", "ENCOUNTER_DISTANCE", "ENCOUNTER_HILL", "ESCAPE", "UNBOUND",
           "COLLISION", "ENCOUNTER_LOG", "LOOKS_INSIDE"]

ENCOUNTER_DISTANCE = 1
ENCOUNTER_HILL = 2
ESCAPE = 4
UNBOUND = 8
COLLISION = 16
ENCOUNTER_LOG = 32
#: the conditions that look inside the step, from the state of the check before
LOOKS_INSIDE = COLLISION | ENCOUNTER_LOG | ENCOUNTER_DISTANCE | ENCOUNTER_HILL


@njit(inline="always")
def no_stop(x, v, t, sargs):
    """No condition: always carries on."""
    return 0


@njit(inline="always")
def _pair_ends(x, v, prev, work, i, j):
    # rows 0-3 of work: the pair's relative position and velocity at the
    # previous check and now
    for d in range(3):
        work[0, d] = prev[0, i, d] - prev[0, j, d]
        work[1, d] = prev[1, i, d] - prev[1, j, d]
        work[2, d] = x[i, d] - x[j, d]
        work[3, d] = v[i, d] - v[j, d]


@njit(inline="always")
def _pericentre(work, row, mu):
    # the pericentre distance of the two-body orbit of the relative state in
    # rows row, row + 1 of work (mu = G (m_i + m_j) > 0)
    dx, dy, dz = work[row, 0], work[row, 1], work[row, 2]
    ux, uy, uz = work[row + 1, 0], work[row + 1, 1], work[row + 1, 2]
    hx = dy * uz - dz * uy
    hy = dz * ux - dx * uz
    hz = dx * uy - dy * ux
    h2 = hx * hx + hy * hy + hz * hz
    d = math.sqrt(dx * dx + dy * dy + dz * dz)
    energy = 0.5 * (ux * ux + uy * uy + uz * uz) - mu / d
    e = math.sqrt(max(0.0, 1.0 + 2.0 * energy * h2 / (mu * mu)))
    return h2 / mu / (1.0 + e)


@njit(inline="always")
def _may_reach(d2, s2, mu, h, r2):
    # whether a pair sqrt(d2) apart at the end of the step h, at relative
    # speed sqrt(s2) there, may have come within sqrt(r2) during it, from the
    # end alone (no square root, no division: a few multiplications a pair
    # before the look with both ends, _within_reach): going back from the end,
    # while at least D apart its separation grows by at most
    # s |h| + mu h^2 / (2 D^2) (the speed at the end, their mutual pull; twice
    # that allowed for the other bodies' tides).  With D = d / 2 (d above
    # twice the threshold) that stays below d / 2 when d > 8 s |h| and
    # d^3 > 16 mu h^2, and the pair stayed beyond D.
    hh = h * h
    return not (d2 > 4.0 * r2 and d2 > 64.0 * s2 * hh and d2 * d2 * d2 > 256.0 * mu * mu * hh * hh)


@njit
def _within_reach(work, mu, h, r):
    # whether the pair of _pair_ends could have come within r during the step
    # h: while at least D apart its separation falls by at most
    # max(s0, s1) |h| + mu h^2 / (2 D^2) (end speeds, mutual pull; twice that
    # allowed), with D = max(r, half the nearer end's separation): if that
    # cannot take it below D, it never got there (up to the first time it
    # did, the bound held), so it stayed beyond r.  With D = r alone a
    # planet's pair with its star, whose radius makes mu / r^2 useless,
    # would always be examined.  A pair whose two-body pericentre stays
    # beyond r at both ends, by more than it changed over the step (the
    # other bodies' pull), cannot have come within r either: a
    # planetesimal's orbit about the star is passed over by this second test.
    d0 = work[0, 0] ** 2 + work[0, 1] ** 2 + work[0, 2] ** 2
    d1 = work[2, 0] ** 2 + work[2, 1] ** 2 + work[2, 2] ** 2
    s0 = work[1, 0] ** 2 + work[1, 1] ** 2 + work[1, 2] ** 2
    s1 = work[3, 0] ** 2 + work[3, 1] ** 2 + work[3, 2] ** 2
    dmin = math.sqrt(min(d0, d1))
    near = max(r, 0.5 * dmin)
    reach = math.sqrt(max(s0, s1)) * abs(h) + 0.5 * mu * h * h / (near * near)
    if dmin - near > 2.0 * reach:
        return False
    if mu > 0.0:
        q0 = _pericentre(work, 0, mu)
        q1 = _pericentre(work, 2, mu)
        if min(q0, q1) - r > 2.0 * abs(q1 - q0):
            return False
    return True


@njit(inline="always")
def _pair_contact(x, v, t, sargs, i, j, inside, h):
    # whether the pair (j, i) touched during the step that ended at t:
    # (touched, time, separation, relative speed); see collision_check
    radii, prev, clock, work, gm = sargs[7], sargs[8], sargs[9], sargs[10], sargs[4]
    rs = radii[i] + radii[j]
    if rs <= 0.0:
        return False, 0.0, 0.0, 0.0
    dx, dy, dz = row_difference(x, i, j)
    ux, uy, uz = row_difference(v, i, j)
    # separations compared squared (a square root only for a contact)
    d1 = dx * dx + dy * dy + dz * dz
    rs2 = rs * rs
    if inside:
        d0 = ((prev[0, i, 0] - prev[0, j, 0]) ** 2 + (prev[0, i, 1] - prev[0, j, 1]) ** 2
              + (prev[0, i, 2] - prev[0, j, 2]) ** 2)
        if d0 < rs2:
            # already in contact at the previous check (a bounce that has not
            # yet separated them): a new collision only while still closing
            if d1 < rs2 and dx * ux + dy * uy + dz * uz < 0.0:
                return True, t, math.sqrt(d1), math.sqrt(ux * ux + uy * uy + uz * uz)
            return False, 0.0, 0.0, 0.0
    if d1 < rs2:
        # overlapping at the end (or the state given at the start)
        return True, t, math.sqrt(d1), math.sqrt(ux * ux + uy * uy + uz * uz)
    if not inside:
        return False, 0.0, 0.0, 0.0
    mu = gm[i] + gm[j]
    if not _may_reach(d1, ux * ux + uy * uy + uz * uz, mu, h, rs2):
        return False, 0.0, 0.0, 0.0
    _pair_ends(x, v, prev, work, i, j)
    if not _within_reach(work, mu, h, rs):
        return False, 0.0, 0.0, 0.0
    tm, dm, sm = closest_approach(mu, work[0], work[1], work[2], work[3], h)
    if dm < rs:
        return True, clock[0] + tm, dm, sm
    return False, 0.0, 0.0, 0.0


@njit
def collision_check(x, v, t, sargs):
    """The first pair (in the order of the pair loop) whose separation fell
    below the sum of their radii during the step that ended at ``t``: at its
    end, or inside it, where :func:`~orbits._kernels.encounters.closest_approach`
    of the pair from both ends of the step comes below it.  Writes the pair
    into ``info`` and its time, separation and speed into ``hit``; returns
    True if there was one.  The state of the step before (``prev``) is left
    as it was, for :func:`collision_pairs`.

    Inside a step, only pairs that could have closed the gap are examined:
    with the relative speeds ``s0``, ``s1`` at the ends, a pair's separation
    can fall by at most ``max(s0, s1) |h| + mu h^2 / (2 R^2)`` (its mutual
    pull while at least ``R`` apart; the tides of the other bodies are left
    out), and twice that is allowed for; the same bound from the end of the
    step alone, at half the pair's separation there, passes over most pairs
    first with a few multiplications.  A pair that was already in contact
    at the previous check (bodies that bounced and have not yet separated)
    counts again only if it overlaps at the end and is still closing."""
    clock, hit, info = sargs[9], sargs[11], sargs[6]
    n = min(x.shape[0], sargs[4].shape[0])
    h = t - clock[0]
    inside = clock[1] != 0.0 and h != 0.0
    for i in range(1, n):
        for j in range(i):
            found, tc, d, s = _pair_contact(x, v, t, sargs, i, j, inside, h)
            if found:
                info[0], info[1] = j, i
                hit[0], hit[1], hit[2] = tc, d, s
                return True
    return False


@njit
def collision_pairs(x, v, t, sargs, out):
    """Every pair that touched during the step that ended at ``t`` (the test
    of :func:`collision_check`), as rows ``(j, i, time, separation, speed)``
    of ``out`` (shape (capacity, 5)); returns how many (at most the
    capacity).  For resolving all the collisions of one step, after the loop
    stopped at the first."""
    clock = sargs[9]
    n = min(x.shape[0], sargs[4].shape[0])
    h = t - clock[0]
    inside = clock[1] != 0.0 and h != 0.0
    k = 0
    for i in range(1, n):
        for j in range(i):
            if k == out.shape[0]:
                return k
            found, tc, d, s = _pair_contact(x, v, t, sargs, i, j, inside, h)
            if found:
                out[k, 0] = j
                out[k, 1] = i
                out[k, 2] = tc
                out[k, 3] = d
                out[k, 4] = s
                k += 1
    return k


@njit
def keep_state(x, v, t, sargs):
    """Keep ``x``, ``v`` (the bodies' rows) as the state of a check at ``t``
    (after the driver resolved the collisions of a step)."""
    n = min(x.shape[0], sargs[4].shape[0])
    _keep(x, v, t, sargs[8], sargs[9], n)


@njit(inline="always")
def _keep(x, v, t, prev, clock, n):
    # the state of this check, for the next one's look inside its step
    for i in range(n):
        for d in range(3):
            prev[0, i, d] = x[i, d]
            prev[1, i, d] = v[i, d]
    clock[0] = t
    clock[1] = 1.0


@njit
def encounter_log(x, v, t, sargs):
    """Log the closest approaches inside the step that ended at ``t`` (see the
    module docstring); True when the log should be emptied: it is half full,
    or it filled before the look at the step was done (``log_n[1] != 0``:
    the pair to go on from, when called again on the same state).

    A pair's separation has a minimum inside the step where it was closing at
    the start (``dx . dv < 0``) and is not at the end (``>= 0``); that
    minimum is found by :func:`~orbits._kernels.encounters.closest_approach`
    from both ends and logged if it is inside the pair's threshold.  Pairs
    that cannot have come within it (the bound of :func:`collision_check`)
    are passed over.  The threshold in Hill radii is taken with the bodies'
    distances from the central body at the end of the step."""
    gm, central = sargs[4], sargs[5]
    prev, clock, work = sargs[8], sargs[9], sargs[10]
    k_hill, dist, log, log_n = sargs[12], sargs[13], sargs[14], sargs[15]
    n = min(x.shape[0], gm.shape[0])
    h = t - clock[0]
    if clock[1] == 0.0 or h == 0.0:
        return False
    third_gmc = 1.0 / (3.0 * gm[central])
    # where a look that filled the log stopped (0: from the first pair)
    i0 = max(1, log_n[1])
    j0 = log_n[2] if log_n[1] > 0 else 0
    log_n[1] = 0
    log_n[2] = 0
    for i in range(i0, n):
        for j in range(j0 if i == i0 else 0, i):
            if dist > 0.0:
                thr = dist
            else:
                mu = gm[i] + gm[j]
                if i == central or j == central or not (mu > 0.0):
                    continue
                ri = math.sqrt((x[i, 0] - x[central, 0]) ** 2 + (x[i, 1] - x[central, 1]) ** 2
                               + (x[i, 2] - x[central, 2]) ** 2)
                rj = math.sqrt((x[j, 0] - x[central, 0]) ** 2 + (x[j, 1] - x[central, 1]) ** 2
                               + (x[j, 2] - x[central, 2]) ** 2)
                thr = k_hill * (mu * third_gmc) ** (1.0 / 3.0) * 0.5 * (ri + rj)
            dx, dy, dz = row_difference(x, i, j)
            ux, uy, uz = row_difference(v, i, j)
            if dx * ux + dy * uy + dz * uz < 0.0:
                continue    # still closing at the end: no minimum inside the step
            mu = gm[i] + gm[j]
            if not _may_reach(dx * dx + dy * dy + dz * dz, ux * ux + uy * uy + uz * uz, mu, h,
                              thr * thr):
                continue
            _pair_ends(x, v, prev, work, i, j)
            closing0 = work[0, 0] * work[1, 0] + work[0, 1] * work[1, 1] + work[0, 2] * work[1, 2]
            if not closing0 < 0.0:
                continue
            if not _within_reach(work, mu, h, thr):
                continue
            tm, dm, sm = closest_approach(mu, work[0], work[1], work[2], work[3], h)
            if dm < thr:
                r = log_n[0]
                if r == log.shape[0]:
                    # full: this pair and the rest when the driver has emptied it
                    log_n[1] = i
                    log_n[2] = j
                    return True
                log[r, 0] = clock[0] + tm
                log[r, 1] = j
                log[r, 2] = i
                log[r, 3] = dm
                log[r, 4] = sm
                log_n[0] = r + 1
    return 2 * log_n[0] > log.shape[0]


@njit(inline="always")
def _note(info, hit, j, i, tc, d, speed):
    # the pair behind a condition, and where it was found
    info[0] = j
    info[1] = i
    hit[0] = tc
    hit[1] = d
    hit[2] = speed


@njit
def encounter_check(x, v, t, sargs):
    """The first pair (in the order of the pair loop) that came within the
    encounter distance, or within ``hill_k`` mutual Hill radii, during the
    step that ended at ``t``: at its end, or inside it, where
    :func:`~orbits._kernels.encounters.closest_approach` of the pair from
    both ends of the step comes within it.  Writes the pair into ``info``
    and its time, separation and speed into ``hit``; returns True if there
    was one.

    The look inside the step costs a few multiplications a pair: from the
    pair's separation ``d`` and relative speed ``s`` at the end, one that
    cannot have come within its threshold ``r`` (``d > 2 r``, ``d > 8 s |h|``
    and ``d^3 > 16 mu h^2``: the bound of :func:`collision_check` taken from
    the end at half the separation) is passed over, first with twice the
    fastest body's speed for ``s`` (without the pair's velocities); the
    others get that bound with both ends and then the closest approach.  A pair that was
    inside its threshold at the previous check already counts only if it is
    at the end (an encounter under way when the run started or went on)."""
    mask, hill_k, gm, central = sargs[0], sargs[2], sargs[4], sargs[5]
    info, prev, clock, work, hit = sargs[6], sargs[8], sargs[9], sargs[10], sargs[11]
    n = min(x.shape[0], gm.shape[0])
    h = t - clock[0]
    inside = clock[1] != 0.0 and h != 0.0
    d2 = sargs[1] if mask & ENCOUNTER_DISTANCE else 0.0
    by_hill = (mask & ENCOUNTER_HILL) != 0
    third_gmc = 1.0 / (3.0 * gm[central]) if by_hill else 0.0
    # the bound of _may_reach for every pair at once, with twice the fastest
    # body's speed at the end for the pair's and the two largest G m for its
    # mu: most pairs are passed over by one comparison
    reach2 = 0.0
    if inside:
        vmax2 = 0.0
        g1 = g2 = 0.0
        for i in range(n):
            vmax2 = max(vmax2, v[i, 0] * v[i, 0] + v[i, 1] * v[i, 1] + v[i, 2] * v[i, 2])
            if gm[i] > g1:
                g2 = g1
                g1 = gm[i]
            elif gm[i] > g2:
                g2 = gm[i]
        hh = h * h
        reach2 = max(256.0 * vmax2 * hh, (256.0 * (g1 + g2) ** 2 * hh * hh) ** (1.0 / 3.0))
    # beyond far2 a pair is neither inside the distance at the end nor can
    # have been inside it (by distance alone: sargs[1] is 0 without it)
    far2 = max(4.0 * d2, reach2) if inside else d2
    for i in range(1, n):
        for j in range(i):
            dx, dy, dz = row_difference(x, i, j)
            r2 = dx * dx + dy * dy + dz * dz
            thr2 = d2
            lim2 = far2
            mu = gm[i] + gm[j]
            if by_hill and i != central and j != central and mu > 0.0:
                ri = math.sqrt((x[i, 0] - x[central, 0]) ** 2 + (x[i, 1] - x[central, 1]) ** 2
                               + (x[i, 2] - x[central, 2]) ** 2)
                rj = math.sqrt((x[j, 0] - x[central, 0]) ** 2 + (x[j, 1] - x[central, 1]) ** 2
                               + (x[j, 2] - x[central, 2]) ** 2)
                rh = hill_k * (mu * third_gmc) ** (1.0 / 3.0) * 0.5 * (ri + rj)
                thr2 = max(thr2, rh * rh)
                lim2 = max(4.0 * thr2, reach2) if inside else thr2
            if r2 > lim2 or (r2 == lim2 and not inside) or not (thr2 > 0.0):
                continue
            ux, uy, uz = row_difference(v, i, j)
            s2 = ux * ux + uy * uy + uz * uz
            if r2 < thr2:
                _note(info, hit, j, i, t, math.sqrt(r2), math.sqrt(s2))
                return True
            if not _may_reach(r2, s2, mu, h, thr2):
                continue
            _pair_ends(x, v, prev, work, i, j)
            if work[0, 0] ** 2 + work[0, 1] ** 2 + work[0, 2] ** 2 < thr2:
                continue
            thr = math.sqrt(thr2)
            if not _within_reach(work, mu, h, thr):
                continue
            tm, dm, sm = closest_approach(mu, work[0], work[1], work[2], work[3], h)
            if dm < thr:
                _note(info, hit, j, i, clock[0] + tm, dm, sm)
                return True
    return False


@njit
def collision_ahead(x, v, t, h, sargs):
    """The pair whose two-body orbit from ``x``, ``v`` at ``t`` touches
    first within ``h > 0`` (:func:`~orbits._kernels.encounters.kepler_contact`),
    with :data:`COLLISION` asked for: for a step an integrator could not
    finish, its step size collapsing as two bodies met head-on.  Writes the
    pair into ``info`` and the time, separation and speed of the contact
    into ``hit``; returns True if one touches."""
    if not (sargs[0] & COLLISION):
        return False
    gm, info, radii, work, hit = sargs[4], sargs[6], sargs[7], sargs[10], sargs[11]
    n = min(x.shape[0], gm.shape[0])
    first = math.inf
    for i in range(1, n):
        for j in range(i):
            rs = radii[i] + radii[j]
            if rs <= 0.0:
                continue
            for d in range(3):
                work[0, d] = x[i, d] - x[j, d]
                work[1, d] = v[i, d] - v[j, d]
            tc, dc, sc = kepler_contact(gm[i] + gm[j], work[0], work[1], rs, h)
            if tc < first:
                first = tc
                _note(info, hit, j, i, t + tc, dc, sc)
    return first < math.inf


@njit
def check_stop(x, v, t, sargs):
    """The conditions in ``sargs`` (see the module docstring); 0 to carry on."""
    mask, d2, hill_k, esc2, gm, central, info = sargs[:7]
    # the bodies' rows (a run with variations has tangent rows after them)
    n = min(x.shape[0], gm.shape[0])
    full = False
    if mask & LOOKS_INSIDE:
        prev, clock = sargs[8], sargs[9]
        if mask & COLLISION and collision_check(x, v, t, sargs):
            # prev stays the state before the step: the driver lists every
            # pair of the step (collision_pairs) and then keeps the state
            return Status.COLLISION
        if mask & ENCOUNTER_LOG:
            full = encounter_log(x, v, t, sargs)
            if sargs[15][1] != 0:
                # the log filled inside the step: prev stays the state before
                # it, for the driver to finish the look once it is emptied
                return Status.LOG_FULL
        close = (mask & (ENCOUNTER_DISTANCE | ENCOUNTER_HILL)) != 0 and encounter_check(
            x, v, t, sargs)
        _keep(x, v, t, prev, clock, n)
        if close:
            return Status.CLOSE_ENCOUNTER
    status = _escaped(x, v, mask, esc2, gm, info, n)
    if status != 0:
        return status
    return Status.LOG_FULL if full else 0


@njit(inline="always")
def _escaped(x, v, mask, esc2, gm, info, n):
    # the escape conditions (ESCAPE, UNBOUND) of the first n bodies: the
    # first body beyond the distance (and unbound, where UNBOUND) into info
    if mask & ESCAPE:
        mt, cx, cy, cz, ux, uy, uz = centre_of_mass(x, v, gm, n)
        for i in range(n):
            r2 = (x[i, 0] - cx) ** 2 + (x[i, 1] - cy) ** 2 + (x[i, 2] - cz) ** 2
            if r2 > esc2:
                if mask & UNBOUND:
                    w2 = (v[i, 0] - ux) ** 2 + (v[i, 1] - uy) ** 2 + (v[i, 2] - uz) ** 2
                    if 0.5 * w2 - mt / math.sqrt(r2) <= 0.0:
                        continue
                info[0] = i
                info[1] = -1
                return Status.ESCAPE
    return 0


@njit
def check_escapes(x, v, t, sargs):
    """:func:`check_stop` for a record whose conditions are escapes alone
    (``ESCAPE``, ``UNBOUND``): the same answer, without the encounters',
    collisions' and log's code, which takes most of :func:`check_stop`'s
    compilation (the estimate of the closest approach)."""
    mask, esc2, gm, info = sargs[0], sargs[3], sargs[4], sargs[6]
    return _escaped(x, v, mask, esc2, gm, info, min(x.shape[0], gm.shape[0]))


# -- the conditions as data: the stopping record of the loops ----------------------

_F1 = nbtypes.float64[::1]
_I1 = nbtypes.int64[::1]
_F2 = nbtypes.float64[:, ::1]
#: the numba type of ``sargs`` (see the module notes), the same for every simulation
SARGS = nbtypes.Tuple((nbtypes.int64, nbtypes.float64, nbtypes.float64, nbtypes.float64, _F1,
                       nbtypes.int64, _I1, _F1, nbtypes.float64[:, :, ::1], _F1, _F2, _F1,
                       nbtypes.float64, nbtypes.float64, _F2, _I1))
#: the signature of a check's pointer: ``check(x, v, t, sargs) -> status``
CHECK = nbtypes.int64(_F2, _F2, nbtypes.float64, SARGS)
#: the signature of :func:`ahead_pointer`'s pointer: ``ahead(x, v, t, h, sargs) -> bool``
AHEAD = nbtypes.boolean(_F2, _F2, nbtypes.float64, nbtypes.float64, SARGS)


def _ahead(x, v, t, h, sargs):
    keep_state(x, v, t, sargs)
    return collision_ahead(x, v, t, h, sargs)


_POINTERS = {}


_CHECKS = {"escapes": check_escapes, "all": check_stop}


def check_kind(conditions):
    """Which check a stopping record's mask ``conditions`` takes (True: any
    conditions): a key of ``_CHECKS``, or "none".

    Examples
    --------
    >>> from orbits._kernels.stopping import COLLISION, ESCAPE, UNBOUND, check_kind
    >>> check_kind(0), check_kind(ESCAPE | UNBOUND), check_kind(ESCAPE | COLLISION)
    ('none', 'escapes', 'all')
    """
    if not conditions:
        return "none"
    if conditions is not True and not conditions & ~(ESCAPE | UNBOUND):
        return "escapes"
    return "all"


def check_pointer(conditions=True):
    """The pointer of the check of a stopping record whose mask is
    ``conditions`` (an int; True: any), as a C callable of :data:`CHECK`:
    of :func:`check_stop`, or of :func:`check_escapes` where the conditions
    are escapes alone, each compiled on first use and cached on disk; where
    there are none, an idle pointer (:func:`~._jit.idle_pointer`): the loops
    call the check only where the mask is not 0 (:func:`call_check`), so it
    compiles nothing.  All have one type, so the loops serve them all."""
    key = check_kind(conditions)
    if key == "none":
        return idle_pointer(CHECK)
    if key not in _POINTERS:
        _POINTERS[key] = pointer(_CHECKS[key], CHECK)
    return _POINTERS[key]


def ahead_pointer(conditions=True):
    """For a loop whose step may not finish (``trace``'s inner integration):
    the pointer of :data:`AHEAD` that keeps ``x``, ``v`` at ``t`` as the
    state of the last check (:func:`keep_state`) and answers
    :func:`collision_ahead` within ``h`` (``conditions``), compiled on first
    use and cached on disk; without conditions an idle pointer, which the
    loop does not call."""
    if not conditions:
        return idle_pointer(AHEAD)
    if "ahead" not in _POINTERS:
        _POINTERS["ahead"] = pointer(_ahead, AHEAD)
    return _POINTERS["ahead"]


def no_conditions():
    """``sargs`` without conditions (mask 0), of the type :data:`SARGS`."""
    return (0, 0.0, 0.0, 0.0, np.zeros(1), 0, np.zeros(2, dtype=np.int64), np.zeros(1),
            np.zeros((2, 1, 3)), np.zeros(2), np.zeros((4, 3)), np.zeros(3), 0.0, 0.0,
            np.zeros((0, 5)), np.zeros(3, dtype=np.int64))


_NONE = None


def stop_record(sargs=None):
    """The stopping record ``(sargs, check)`` the loops take, as two arguments,
    for a simulation's ``sargs`` (None: no conditions, and a check never
    called).  Inside a loop the pair is one value, ``(sargs, check)``: the
    pointer second, for numba takes a tuple that starts with a function for
    a sequence of functions (and warns that this is experimental)."""
    global _NONE
    if sargs is None:
        if _NONE is None:
            _NONE = (no_conditions(), check_pointer(False))
        return _NONE
    return (sargs, check_pointer(int(sargs[0])))


@njit(inline="always")
def call_check(x, v, t, stop):
    """The conditions of the stopping record ``stop = (sargs, check)`` after a
    step: 0 to carry on.  Without conditions, a branch."""
    sargs = stop[0]
    if sargs[0] == 0:
        return 0
    return stop[1](x, v, t, sargs)
