"""The compiled loop of ``trace``: a time-reversible hybrid of the democratic
heliocentric Wisdom-Holman map and an adaptive integrator for close encounters
(after Lu, Hernandez & Rein 2024 [1]).

The split is that of :mod:`orbits._kernels.wisdom_holman` in democratic
heliocentric coordinates (heliocentric positions ``Q``, barycentric
velocities ``V``): Kepler drifts ``K`` about ``G m_0``, the planets' mutual
interaction ``I`` and the jump ``J``.  A pair ``(i, j)`` of non-central bodies
is *flagged* when its separation is below the switching radius ::

    r_crit = max(k_hill R_H, k_speed |V_i - V_j| |h|),
    R_H = ((m_i + m_j) / (3 m_0))^(1/3) (|Q_i| + |Q_j|) / 2

(the mutual Hill radius of Chambers 1996, and a term for fast flybys).  A
flagged pair's interaction moves from the kick into the drift: the bodies of
flagged pairs (each connected group of them apart) are integrated over the
drift with their Kepler motion about ``G m_0`` and their flagged mutual pulls
by an adaptive 8th-order Runge-Kutta method (Dormand & Prince's DOP853, with
the error measured per body, relative to its position and speed in the
group's own frame), in coordinates relative to the group's first body, so
that a pass at 1e-8 au keeps its separation to 1e-16 relative.  A body whose
step is long against its time scale about the central body flags a close
pericentre passage, ``k_peri^2 h^2 ((v^2 + 3 rdot^2) / r^2 + G m_0 / r^3) >
1`` (heliocentric distance ``r``, speed ``v`` and radial speed ``rdot``:
the central pull's jerk over its size, ``sqrt(v^2 + 3 rdot^2) / r``, and
the Kepler rate at the distance; a body falling straight in is flagged
further out than one passing at the same distance, as in the time scale of
Pham, Rein & Spiegel 2024 that the TRACE paper's criterion uses): the whole
segment is then integrated, all bodies and all pulls, in inertial
coordinates by the same method.  The criterion is even in the velocities, so
a step and its reverse see the same flags.

Where the criterion is evaluated.  The map is the Wisdom-Holman map of
:mod:`.wisdom_holman`, ``K(h/2) [J(h/2) I(h) J(h/2)] K(h/2)`` a step, with the
closing drift deferred into the next step's opening one.  Regrouped, the
chain is a sequence of kick-drift-kick *segments*
``I(h/2) J(h/2) K(h) J(h/2) I(h/2)`` whose ends lie in the middle of the
perturbation steps (positions after the first half jump, velocities after
half the kick): the segment is the unit TRACE switches, and these ends are
where the criterion is evaluated.  A segment takes the flags of its start;
if its end flags a pair (or a pericentre) the start did not, it is redone
from its start with the union flagged, as in [1], so that a step and its
reverse (``-h`` from the end) take the same flags: time reversible, up to
the adaptive integrator's tolerance.  Outputs lie in the middle of a
segment's drift: they are synchronised (on a copy) with the flags of the
segment's start.  The stopping conditions are checked at the criterion
points, whose states are synchronised already (the kick-drift-kick form of
the map, half a step before the step's end), and at the end of the last
step of each call; so that they cost no synchronisation (a Kepler drift of
every body, or an inner integration during an encounter) a step.  The
checks' windows (from one check to the next) still cover the whole run.
When neither of two successive segments has a flag, the
two half kicks between them are the single kick ``I(h)`` of the
Wisdom-Holman map, with its arithmetic: far from encounters ``trace`` is
bit for bit ``wh`` with ``coordinates="democratic-heliocentric"``.  The
loop's copy with the lanes (:func:`trace_loop` with ``lanes``) makes such
steps with the planets in vector lanes (:mod:`.trace_lanes`) between its
outputs, and takes with this loop's own code every step whose criterion
point may flag.

References
----------
.. [1] Lu, T., Hernandez, D. M. & Rein, H. 2024, "TRACE: a time-reversible
   hybrid integrator for close encounters", MNRAS 533, 3708.
.. [2] Duncan, M. J., Levison, H. F. & Lee, M. H. 1998, AJ 116, 2067.
.. [3] Hairer, E., Nørsett, S. P. & Wanner, G. 1993, "Solving Ordinary
   Differential Equations I", section II.10 (DOP853).
"""

import functools
import math
from typing import NamedTuple

import numpy as np

from ._jit import called, njit, slots, specialize
from .coordinates import (from_democratic_heliocentric, row_difference,
                          to_democratic_heliocentric)
from .gravity import pair_accelerations, pull_pair, zero_rows
from .status import Status
from .stepping import (GO, _record, accept_fsal, dop853_error, epilogue, first_record,
                       stage_errors)
from .trace_lanes import FAR_WAIT, criterion_scales, far_steps
from .terms import table_rows
from .wisdom_holman import _heliocentric_term_kick, jump, kepler_drift_all, plain_drift_call

# the names the templates below are written against, bound by specialize
has_terms, step_end, term_kick, LANES, far_run = slots(
    "has_terms", "step_end", "term_kick", "LANES", "far_run")

__all__ = ["trace_loop", "trace_synchronize", "criterion", "inner_drift", "exact_flow",
           "inner_arrays",
           "SAFETY", "FAC_MIN", "FAC_MAX", "MAX_REDO", "MODE_GROUP", "MODE_ALL"]

SAFETY = 0.9        # inner step-size safety factor (HNW II.4)
FAC_MIN = 0.2       # a rejected inner step shrinks by at most 5
FAC_MAX = 6.0       # an accepted inner step grows by at most 6
#: a segment is redone at most this many times with more flags (each redo
#: adds at least one pair; the criterion rarely changes twice)
MAX_REDO = 8
#: the inner integrator's force: a group of flagged bodies about the star
#: (relative to the group's first body), or every body and every pull.
#: Floats: numba would compile the inner integrator once for each integer
#: constant passed (a literal type), and it is compiled once for both
MODE_GROUP = 0.0
MODE_ALL = 1.0
_TINY = 1e-300
_EPS = 2.220446049250313e-16


@njit(inline="always")
def criterion(xh, vb, gm, hill, r2, n_active, k_hill, k_speed, h, k_peri, enc):
    """Flag the pairs in a close encounter and say whether a pericentre is close.

    ``enc`` (uint8, shape (N, N)) gets 1 at ``[i, j]`` (``i > j >= 1``) for a
    flagged pair, 0 elsewhere below the diagonal; ``hill[i] = (m_i / 3
    m_0)^(1/3)``; ``r2`` (N,) is scratch (the squared heliocentric
    distances).  Returns ``(pairs flagged, 1 if a body's step is long
    against its time scale about the central one)``: ``k_peri^2 h^2 ((v^2 +
    3 rdot^2) / r^2 + G m_0 / r^3) > 1`` (see the module notes; ``k_peri``
    0 flags none).  Square roots and cube roots are taken only
    for the pairs that a bound on the switching radius leaves in doubt, so
    that a system far from encounters pays a few multiplications a pair.
    """
    n = xh.shape[0]
    peri = 0
    kp2, kg2, kv2, kh2 = criterion_scales(h, gm[0], k_hill, k_speed, k_peri)
    vmax2 = 0.0
    for i in range(1, n):
        ri2 = xh[i, 0] * xh[i, 0] + xh[i, 1] * xh[i, 1] + xh[i, 2] * xh[i, 2]
        r2[i] = ri2
        vi2 = vb[i, 0] * vb[i, 0] + vb[i, 1] * vb[i, 1] + vb[i, 2] * vb[i, 2]
        rv = xh[i, 0] * vb[i, 0] + xh[i, 1] * vb[i, 1] + xh[i, 2] * vb[i, 2]
        # kp2 ((v^2 + 3 rdot^2) / r^2 + G m_0 / r^3) > 1 with rdot = x . v / r,
        # times r^4 and without a root: d = r^4 - kp2 (v^2 r^2 + 3 (x . v)^2)
        # <= 0, or kp2 G m_0 r > d, that is (kp2 G m_0)^2 r^2 > d^2
        d = ri2 * ri2 - kp2 * (vi2 * ri2 + 3.0 * rv * rv)
        if d <= 0.0 or kg2 * ri2 > d * d:
            peri = 1
        vmax2 = max(vmax2, vi2)
    count = 0
    # |V_i - V_j| <= 2 max |V|: pairs farther apart than that many steps of
    # it skip the relative speed
    reach2 = 4.0 * kv2 * vmax2
    third = 1.0 / 3.0
    g3 = 3.0 * gm[0]
    for i in range(2, n):
        ri2 = r2[i]
        hi = hill[i]
        for j in range(1, min(i, n_active)):
            dx, dy, dz = row_difference(xh, i, j)
            d2 = dx * dx + dy * dy + dz * dz
            # (r_i + r_j) / 2 <= max(r_i, r_j) and ((m_i + m_j) / 3 m_0)^(1/3)
            # <= 2^(1/3) max(hill_i, hill_j): the exact radius only inside
            hmax = max(hi, hill[j])
            bound = kh2 * hmax * hmax * max(ri2, r2[j])
            flag = 0
            if d2 < reach2:
                ux, uy, uz = row_difference(vb, i, j)
                if d2 < kv2 * (ux * ux + uy * uy + uz * uz):
                    flag = 1
            if flag == 0 and d2 < bound:
                rh = (k_hill * ((gm[i] + gm[j]) / g3) ** third
                      * 0.5 * (math.sqrt(ri2) + math.sqrt(r2[j])))
                if d2 < rh * rh:
                    flag = 1
            enc[i, j] = flag
            count += flag
    return count, peri


@njit
def _new_flags(enc, enc_new, n, n_active):
    # whether enc_new flags a pair enc does not; enc becomes their union
    grew = False
    for i in range(2, n):
        for j in range(1, min(i, n_active)):
            if enc_new[i, j] and not enc[i, j]:
                enc[i, j] = 1
                grew = True
    return grew


@njit
def _kick_unflagged(xh, vb, acc, gm, n_active, enc, h):
    """``V_i += h`` times the pull of the other non-central bodies, leaving out
    the flagged pairs (their pull is in the drift); ``acc`` is scratch."""
    n = xh.shape[0]
    zero_rows(acc, 0, n)
    for i in range(2, n):
        for j in range(1, min(i, n_active)):
            if enc[i, j]:
                continue
            dx, dy, dz = row_difference(xh, i, j)
            pull_pair(acc, i, j, gm[i], gm[j], dx, dy, dz)
    for i in range(1, n):
        vb[i, 0] += h * acc[i, 0]
        vb[i, 1] += h * acc[i, 1]
        vb[i, 2] += h * acc[i, 2]


@njit(inline="always")
def _interaction_kick(xh, vb, acc, gm, n_active, enc, flagged, h):
    """``V_i += h`` times the pull of the other non-central bodies, the
    flagged pairs left out where ``flagged`` (:func:`_kick_unflagged`);
    the kick of a step that an encounter begins or that is redone."""
    if flagged:
        _kick_unflagged(xh, vb, acc, gm, n_active, enc, h)
    else:
        _pair_accelerations_call(xh, gm, n_active, 0.0, acc, 1, False)
        for i in range(xh.shape[0]):
            vb[i, 0] += h * acc[i, 0]
            vb[i, 1] += h * acc[i, 1]
            vb[i, 2] += h * acc[i, 2]


# -- the inner integrator ---------------------------------------------------------------

@njit
def _accel(mode, y, ns, idx, gm, n_active, enc, out):
    """Accelerations of the inner integrator's state ``y[:ns]``.

    MODE_GROUP: row 0 is the group's first body's heliocentric position, row
    k > 0 body ``idx[k]``'s position relative to it; the bodies feel the
    central body and their flagged partners in the group; ``out`` gets row 0's
    acceleration and the others' relative to it.  MODE_ALL: ``y`` holds every
    body's inertial position; every pull.
    """
    if mode == MODE_GROUP:
        x0 = y[0, 0]
        y0 = y[0, 1]
        z0 = y[0, 2]
        for k in range(ns):
            qx = x0
            qy = y0
            qz = z0
            if k > 0:
                qx += y[k, 0]
                qy += y[k, 1]
                qz += y[k, 2]
            r2 = qx * qx + qy * qy + qz * qz
            s = gm[0] / (r2 * math.sqrt(r2))
            out[k, 0] = -s * qx
            out[k, 1] = -s * qy
            out[k, 2] = -s * qz
        for k in range(1, ns):
            bk = idx[k]
            for m in range(k):
                bm = idx[m]
                if bk > bm:
                    flagged = enc[bk, bm]
                else:
                    flagged = enc[bm, bk]
                if not flagged:
                    continue
                # the separation from the relative rows alone (row 0 is 0)
                dx = y[k, 0]
                dy = y[k, 1]
                dz = y[k, 2]
                if m > 0:
                    dx -= y[m, 0]
                    dy -= y[m, 1]
                    dz -= y[m, 2]
                pull_pair(out, k, m, gm[bk], gm[bm], dx, dy, dz)
        for k in range(1, ns):
            out[k, 0] -= out[0, 0]
            out[k, 1] -= out[0, 1]
            out[k, 2] -= out[0, 2]
    else:
        zero_rows(out, 0, ns)
        for i in range(1, ns):
            for j in range(min(i, n_active)):
                dx, dy, dz = row_difference(y, i, j)
                pull_pair(out, i, j, gm[i], gm[j], dx, dy, dz)


@njit
def _row_norm(a, k):
    return math.sqrt(a[k, 0] ** 2 + a[k, 1] ** 2 + a[k, 2] ** 2)


@njit
def _dop853(mode, y, u, ns, idx, gm, n_active, enc, span, rtol, A, b, c, e5, e3, ky, ku,
            y1, u1, ys, us, hbox, counts):
    """Integrate ``y' = u, u' = a(y)`` (:func:`_accel`) over ``span`` (either
    sign) with DOP853, in place on rows ``[:ns]``; True on success.

    The error of a step is measured per row, against ``rtol`` times the
    row's position and velocity sizes (in MODE_GROUP the relative rows are
    the separations within the group, so the tolerance is relative to the
    encounter, not to the orbit).  ``hbox[0]`` keeps the last step size
    proposed, tried first next time; ``counts[2]`` counts accepted steps.
    """
    if span == 0.0 or ns == 0:
        return True
    s = b.shape[0]
    direction = 1.0 if span > 0.0 else -1.0
    _accel(mode, y, ns, idx, gm, n_active, enc, ku[0])
    for i in range(ns):
        for d in range(3):
            ky[0, i, d] = u[i, d]
    h = abs(hbox[0])
    if h == 0.0:
        # a first step from the shortest time scale of the rows
        tau = abs(span)
        for i in range(ns):
            rn = _row_norm(y, i)
            un = _row_norm(u, i)
            an = _row_norm(ku[0], i)
            if un > 0.0:
                tau = min(tau, rn / un)
            if an > 0.0:
                tau = min(tau, math.sqrt(rn / an))
        h = 0.01 * tau
    t = 0.0
    total = abs(span)
    ncomp = 6.0 * ns
    while t < total:
        last = False
        if t + 1.01 * h >= total:
            hs = total - t
            last = True
        else:
            hs = h
        hh = direction * hs
        for st in range(1, s):
            for i in range(ns):
                for d in range(3):
                    yi = y[i, d]
                    ui = u[i, d]
                    for j in range(st):
                        a = A[st, j]
                        if a != 0.0:
                            yi += hh * a * ky[j, i, d]
                            ui += hh * a * ku[j, i, d]
                    ys[i, d] = yi
                    us[i, d] = ui
                    ky[st, i, d] = ui
            _accel(mode, ys, ns, idx, gm, n_active, enc, ku[st])
        for i in range(ns):
            for d in range(3):
                dy = 0.0
                du = 0.0
                for j in range(s):
                    dy += b[j] * ky[j, i, d]
                    du += b[j] * ku[j, i, d]
                y1[i, d] = y[i, d] + hh * dy
                u1[i, d] = u[i, d] + hh * du
                ky[s, i, d] = u1[i, d]
        _accel(mode, y1, ns, idx, gm, n_active, enc, ku[s])
        err5 = 0.0
        err3 = 0.0
        for i in range(ns):
            sy = rtol * max(_row_norm(y, i), _row_norm(y1, i)) + _TINY
            su = rtol * max(_row_norm(u, i), _row_norm(u1, i)) + _TINY
            for d in range(3):
                ey, eu, fy, fu = stage_errors(ky, ku, e5, e3, s + 1, i, d)
                err5 += (ey / sy) ** 2 + (eu / su) ** 2
                err3 += (fy / sy) ** 2 + (fu / su) ** 2
        err = dop853_error(err5, err3, hs, ncomp)
        if not math.isfinite(err):
            err = math.inf
        if err == 0.0:
            fac = FAC_MAX
        elif err == math.inf:
            fac = FAC_MIN
        else:
            fac = min(FAC_MAX, max(FAC_MIN, SAFETY * err ** (-1.0 / 8.0)))
        if err <= 1.0:
            accept_fsal(y, u, y1, u1, ky, ku, s, ns)
            counts[2] += 1
            if last:
                break
            t += hs
            h = hs * fac
        else:
            h = hs * fac
            if h <= 4.0 * _EPS * total:
                return False
    hbox[0] = h
    return True


@njit
def _groups(enc, n, n_active, label):
    """Label the connected groups of flagged pairs: ``label[i]`` is the group
    of body i (-1: in none); returns the number of groups."""
    for i in range(n):
        label[i] = -1
    groups = 0
    changed = True
    for i in range(2, n):
        for j in range(1, min(i, n_active)):
            if enc[i, j]:
                if label[i] < 0 and label[j] < 0:
                    label[i] = groups
                    label[j] = groups
                    groups += 1
                elif label[i] < 0:
                    label[i] = label[j]
                elif label[j] < 0:
                    label[j] = label[i]
    # merge groups joined by a pair found after both were labelled
    while changed:
        changed = False
        for i in range(2, n):
            for j in range(1, min(i, n_active)):
                if enc[i, j] and label[i] != label[j]:
                    lo = min(label[i], label[j])
                    hi = max(label[i], label[j])
                    for k in range(n):
                        if label[k] == hi:
                            label[k] = lo
                    changed = True
    return groups


@njit
def inner_drift(xh, vb, gm, eta, n_active, enc, h, w1, w2, inner, tabs, rtol):
    """The drift of a segment with flagged pairs: every body on its Kepler orbit
    about ``G m_0``, then the bodies of each group of flagged pairs replaced by
    their integration with the group's pulls.  Returns False if the inner
    integrator failed (step-size underflow)."""
    A, b, c, e5, e3 = tabs
    label, idx, ky, ku, y, u, y1, u1, ys, us, hbox, counts = inner
    n = xh.shape[0]
    groups = _groups(enc, n, n_active, label)
    # the groups' starting rows, before the Kepler drift moves them
    for i in range(n):
        for d in range(3):
            ys[i, d] = xh[i, d]
            us[i, d] = vb[i, d]
    _kepler_drift_all_call(xh, vb, eta, h, w1, w2)
    ok = True
    for g in range(groups):
        ns = np.int64(0)   # not a constant: _dop853 is compiled for one type of it
        for i in range(1, n):
            if label[i] == g:
                idx[ns] = i
                ns += 1
        if ns == 0:
            continue
        c0 = idx[0]
        for d in range(3):
            y[0, d] = ys[c0, d]
            u[0, d] = us[c0, d]
        for k in range(1, ns):
            bk = idx[k]
            for d in range(3):
                y[k, d] = ys[bk, d] - ys[c0, d]
                u[k, d] = us[bk, d] - us[c0, d]
        if not _dop853(MODE_GROUP, y, u, ns, idx, gm, n_active, enc, h, rtol, A, b, c, e5,
                       e3, ky, ku, y1, u1, w1, w2, hbox, counts):
            ok = False
        for d in range(3):
            xh[c0, d] = y[0, d]
            vb[c0, d] = u[0, d]
        for k in range(1, ns):
            bk = idx[k]
            for d in range(3):
                xh[bk, d] = y[0, d] + y[k, d]
                vb[bk, d] = u[0, d] + u[k, d]
    return ok


@njit
def exact_flow(xh, vb, gm, n_active, enc, h, x, v, inner, tabs, rtol):
    """Every body and every pull over ``h`` by the inner integrator, in inertial
    coordinates (a close pericentre passage); ``x``, ``v`` are scratch."""
    A, b, c, e5, e3 = tabs
    label, idx, ky, ku, y, u, y1, u1, ys, us, hbox, counts = inner
    n = xh.shape[0]
    from_democratic_heliocentric(xh, vb, gm, x, v)
    for i in range(n):
        for d in range(3):
            y[i, d] = x[i, d]
            u[i, d] = v[i, d]
    ok = _dop853(MODE_ALL, y, u, n, idx, gm, n_active, enc, h, rtol, A, b, c, e5, e3,
                 ky, ku, y1, u1, ys, us, hbox, counts)
    for i in range(n):
        for d in range(3):
            x[i, d] = y[i, d]
            v[i, d] = u[i, d]
    to_democratic_heliocentric(x, v, gm, xh, vb)
    return ok


@njit
def _drift(xh, vb, gm, eta, n_active, enc, flagged, peri, h, w1, w2, x, v, inner, tabs,
           rtol):
    # the segment's drift of h: Kepler drifts, with the flagged groups
    # integrated, or (peri) the exact flow of everything
    if peri:
        return exact_flow(xh, vb, gm, n_active, enc, h, x, v, inner, tabs, rtol)
    if flagged:
        return inner_drift(xh, vb, gm, eta, n_active, enc, h, w1, w2, inner, tabs, rtol)
    _kepler_drift_all_call(xh, vb, eta, h, w1, w2)
    return True


@njit(inline="always")
def _copy(a, b):
    for i in range(a.shape[0]):
        b[i, 0] = a[i, 0]
        b[i, 1] = a[i, 1]
        b[i, 2] = a[i, 2]


@njit
def trace_synchronize(xh, vb, gm, eta, n_active, enc, state, owed, xs, vs, x, v, w1, w2,
                      inner, tabs, rtol):
    """Inertial ``x``, ``v`` at the current time: the owed part of the current
    segment's drift, with its flags, applied to a copy of the internal state
    (the whole gravity if the segment integrates everything)."""
    n = xh.shape[0]
    _copy(xh, xs)
    _copy(vb, vs)
    if owed != 0.0:
        # the inner integrator's step memory and counts are the run's: kept
        # as they were, so that looking does not change the trajectory
        hbox = inner.hbox
        counts = inner.counts
        h_kept = hbox[0]
        steps_kept = counts[2]
        _drift(xs, vs, gm, eta, n_active, enc, state[4] != 0, state[3] != 0, owed, w1, w2,
               x, v, inner, tabs, rtol)
        hbox[0] = h_kept
        counts[2] = steps_kept
    from_democratic_heliocentric(xs, vs, gm, x, v)
    return n


# the loop's rare paths (a call's start, a step redone, the step an encounter
# begins) call these, compiled once, instead of inlining a copy each; the
# Kepler drift of every body too, from the drifts of segments with flags
# (_drift, inner_drift) and the synchronisation's, where the loop's own
# unflagged segment keeps its inlined copy.  The Kepler drift is the copy
# that Wisdom-Holman's plain loop calls (without numba's runtime: it
# allocates nothing), with its empty targs: one compilation for both
_criterion_call = called(criterion)
_pair_accelerations_call = called(pair_accelerations)
_jump_call = called(jump)


@njit(inline="always")
def _kepler_drift_all_call(xh, vb, eta, h, w1, w2):
    plain_drift_call(xh, vb, eta, h, w1, w2, ())


class Work(NamedTuple):
    """The ``trace`` loop's workspace (:meth:`orbits.integrators.trace.Trace.workspace`):
    the democratic heliocentric state ``xh``, ``vb`` and the segment's start
    ``xc``, ``vc``; each body's ``gm``, Kepler ``eta``, Hill radius and
    squared criterion radius ``r2``; ``n_active[0]``; scratch ``acc``,
    ``xs``, ``vs``, ``w1``, ``w2``; the flags ``state``, the owed drift
    ``owed[0]``, ``checked``, and the pairs flagged (``enc``, ``enc_new``)."""
    xh: np.ndarray
    vb: np.ndarray
    xc: np.ndarray
    vc: np.ndarray
    gm: np.ndarray
    eta: np.ndarray
    hill: np.ndarray
    r2: np.ndarray
    n_active: np.ndarray
    acc: np.ndarray
    xs: np.ndarray
    vs: np.ndarray
    w1: np.ndarray
    w2: np.ndarray
    state: np.ndarray
    owed: np.ndarray
    checked: np.ndarray
    enc: np.ndarray
    enc_new: np.ndarray


class Criteria(NamedTuple):
    """The switching criteria: the Hill radii's factor, the close
    approach's speed factor, the pericentre factor, and the inner
    integrator's relative tolerance."""
    hill: float
    speed: float
    pericentre: float
    rtol: float


class Inner(NamedTuple):
    """The inner integrator's arrays (:func:`inner_arrays`): each body's
    group ``label``, a group's rows ``idx``, the DOP853 stages ``ky``,
    ``ku``, the group's state ``y``, ``u`` and step result ``y1``, ``u1``,
    the rows at the segment's start ``ys``, ``us``, the step memory
    ``hbox[0]`` and ``counts`` (segments with flags, redos, inner steps)."""
    label: np.ndarray
    idx: np.ndarray
    ky: np.ndarray
    ku: np.ndarray
    y: np.ndarray
    u: np.ndarray
    y1: np.ndarray
    u1: np.ndarray
    ys: np.ndarray
    us: np.ndarray
    hbox: np.ndarray
    counts: np.ndarray


def _trace_loop(x, v, t, dt, nsteps, work, criteria, inner, tabs, outputs, checks, check, ahead,
                targs):
    # work: a Work record, whose
    # state: [0] internal state current, [1] system checked, [2] the segment
    # started at a criterion point (else at a synchronised state: no opening
    # kick), [3] the segment integrates everything (a close pericentre),
    # [4] the segment has flagged pairs.  xc, vc: the segment's start.
    # owed_box[0]: the part of the segment's drift before the current time.
    # checked: [time, 1] when the epilogue last checked the stopping
    # conditions at a criterion point (x, v then hold that state), [., 0]
    # when at the end of the step.
    # criteria: a Criteria record; inner: the inner integrator's arrays
    # (Inner), whose counts (segments with flags, redos, inner steps) add up.
    # targs: the table of added terms (kicked with gravity's interaction where
    # it has rows: has_terms and term_kick bound by specialize), or the
    # lanes' scratch.  checks, check: the
    # Checks record (orbits._kernels.records) and the stopping conditions'
    # pointer (orbits._kernels.stopping.stop_record); ahead: the pointer of
    # orbits._kernels.stopping.ahead_pointer.
    (xh, vb, xc, vc, gm, eta, hill, r2, n_active_box, acc, xs, vs, w1, w2, state, owed_box,
     checked, enc, enc_new) = work
    n_active = n_active_box[0]
    mon, step0, mon_t, mon_out = outputs
    check_every, sargs = checks
    stopping = (sargs, check)
    k_hill, k_speed, k_peri, rtol = criteria
    conditions = sargs[0] != 0
    counts = inner.counts
    n = xh.shape[0]
    kick_terms = has_terms(targs)
    every = mon[0]
    n_mon = 0
    if state[0] == 0:
        to_democratic_heliocentric(x, v, gm, xh, vb)
        _copy(xh, xc)
        _copy(vb, vc)
        state[0] = 1
        state[2] = 0
        owed_box[0] = 0.0
        npairs, peri = _criterion_call(xh, vb, gm, hill, r2, n_active, k_hill, k_speed,
                                 dt, k_peri, enc)
        state[3] = peri
        state[4] = 1 if npairs > 0 else 0
    owed = owed_box[0]
    half = 0.5 * dt
    until_check = check_every
    until_record = first_record(every, step0, mon_t)
    far_wait = 0
    k = 0
    while k < nsteps:
        if LANES:
            if far_wait > 0:
                far_wait -= 1
            elif (not conditions and owed == half and state[2] != 0 and state[3] == 0
                  and state[4] == 0):
                # far from encounters: the steps before the next output and the
                # call's last step in the lanes (orbits._kernels.trace_lanes),
                # until a criterion point may flag; this step then as below
                m = nsteps - k - 1
                if 0 < until_record <= m:
                    m = until_record - 1
                if m > 0:
                    done, until_check, why = far_run(xh, vb, xc, vc, gm, eta, hill, n_active,
                                                     dt, k_hill, k_speed, k_peri, m,
                                                     until_check, check_every, targs)
                    k += done
                    until_record -= done
                    if why == 2:
                        owed_box[0] = owed
                        return Status.NON_FINITE, k - 1, n_mon
                    if why == 1:
                        far_wait = FAR_WAIT
        seg = owed + half
        flagged = state[4] != 0
        peri = state[3] != 0
        redo = 0
        ok = True
        while True:
            # the segment from its start (xc, vc) or from the opening kick
            # already applied (xh, vb)
            if flagged or peri:
                ok = _drift(xh, vb, gm, eta, n_active, enc, flagged, peri, seg, w1, w2, x, v,
                            inner, tabs, rtol)
                if not ok:
                    break
            else:
                kepler_drift_all(xh, vb, eta, seg, w1, w2)
            if peri:
                # the exact flow of gravity ends on the criterion point, less
                # the added terms' half kick
                _copy(vb, vs)
                if kick_terms:
                    term_kick(xh, vs, w1, w2, gm, eta, n_active, half, targs)
            else:
                jump(xh, vb, gm, n_active, half)
                if flagged:
                    _copy(vb, vs)
                    _kick_unflagged(xh, vs, acc, gm, n_active, enc, half)
                else:
                    pair_accelerations(xh, gm, n_active, 0.0, acc, 1, False)
                    for i in range(n):
                        vs[i, 0] = vb[i, 0] + half * acc[i, 0]
                        vs[i, 1] = vb[i, 1] + half * acc[i, 1]
                        vs[i, 2] = vb[i, 2] + half * acc[i, 2]
                if kick_terms:
                    term_kick(xh, vs, w1, w2, gm, eta, n_active, half, targs)
            npairs, peri_end = criterion(xh, vs, gm, hill, r2, n_active, k_hill,
                                         k_speed, dt, k_peri, enc_new)
            grew = npairs > 0 and _new_flags(enc, enc_new, n, n_active)
            if (grew or (peri_end and not peri)) and redo < MAX_REDO:
                # the end flags what the start did not: the segment again from
                # its start with the union flagged
                redo += 1
                counts[1] += 1
                if grew:
                    flagged = True
                if peri_end:
                    peri = True
                _copy(xc, xh)
                _copy(vc, vb)
                if state[2] and kick_terms:
                    term_kick(xh, vb, w1, w2, gm, eta, n_active, owed, targs)
                if state[2] and not peri:
                    _interaction_kick(xh, vb, acc, gm, n_active, enc, flagged, owed)
                    _jump_call(xh, vb, gm, n_active, owed)
                continue
            break
        if not ok:
            # the inner integrator's step collapsed (bodies meeting head-on:
            # no step goes through a point mass); the state goes back to the
            # segment's start, the last the run reached whole, as a
            # synchronised state that the next call starts from (state[0] =
            # 0), owed_box[0] before the steps done (Trace.behind).  With
            # collisions asked for, the pair whose two-body orbits touch
            # within the segment is the collision that stopped it.
            t_start = t + k * dt - owed
            from_democratic_heliocentric(xc, vc, gm, x, v)
            state[0] = 0
            checked[1] = 0.0
            if conditions and ahead(x, v, t_start, seg, sargs):
                return Status.COLLISION, k, n_mon
            return Status.STEP_UNDERFLOW, k, n_mon
        if flagged or peri:
            counts[0] += 1
        # the criterion point: the next segment's start and flags
        new_flagged = npairs > 0
        if new_flagged:
            for i in range(2, n):
                for j in range(1, min(i, n_active)):
                    enc[i, j] = enc_new[i, j]
        elif flagged:
            for i in range(2, n):
                for j in range(1, min(i, n_active)):
                    enc[i, j] = 0
        _copy(xh, xc)
        _copy(vs, vc)
        state[2] = 1
        state[3] = peri_end
        state[4] = 1 if new_flagged else 0
        if peri_end:
            # the next segment integrates gravity whole from the criterion
            # point, after the added terms' half kick
            _copy(vs, vb)
            if kick_terms:
                term_kick(xh, vb, w1, w2, gm, eta, n_active, half, targs)
        else:
            if not flagged and not peri and not new_flagged:
                # no flags either side: the Wisdom-Holman kick I(h), its arithmetic
                for i in range(1, n):
                    vb[i, 0] += dt * acc[i, 0]
                    vb[i, 1] += dt * acc[i, 1]
                    vb[i, 2] += dt * acc[i, 2]
                if kick_terms:
                    term_kick(xh, vb, w1, w2, gm, eta, n_active, dt, targs)
            else:
                _copy(vs, vb)
                _interaction_kick(xh, vb, acc, gm, n_active, enc, new_flagged, half)
                if kick_terms:
                    term_kick(xh, vb, w1, w2, gm, eta, n_active, half, targs)
            jump(xh, vb, gm, n_active, half)
        owed = half
        owed_box[0] = owed
        # the epilogue sees the inertial state when it records, and at the
        # last step of the call when it checks the stopping conditions;
        # otherwise these are checked at the criterion point, where the state
        # is synchronised already (xc, vc: a kick-drift-kick state at the
        # step's end less the owed half drift), without synchronising a copy
        # (a Kepler drift of every body, or an inner integration in an
        # encounter, every step); else the epilogue sees the internal state
        # (the finite check)
        seen_x, seen_v, t_seen = xh, vb, t + (k + 1) * dt
        if until_record == 1 or (conditions and k + 1 == nsteps):
            trace_synchronize(xh, vb, gm, eta, n_active, enc, state, owed, xs, vs, x, v, w1,
                              w2, inner, tabs, rtol)
            checked[1] = 0.0
            seen_x, seen_v = x, v
        elif conditions:
            from_democratic_heliocentric(xc, vc, gm, x, v)
            t_seen -= owed
            checked[0] = t_seen
            checked[1] = 1.0
            seen_x, seen_v = x, v
        status, done, until_check, until_record, n_mon = step_end(
            seen_x, seen_v, t_seen, k, nsteps, True, until_check, check_every, until_record,
            every, mon, n_mon, mon_t, mon_out, stopping, ())
        if status != GO:
            return status, done, n_mon
        k += 1
    return Status.OK, nsteps, n_mon


@njit(inline="always")
def _no_term_kick(xh, vb, x, acc, gm, eta, n_active, h, targs):
    pass


@njit(inline="always")
def _no_terms(targs):
    return False


@njit(inline="always")
def _table_has_rows(targs):
    return table_rows(targs) > 0


@njit(inline="always")
def _no_far(xh, vb, xc, vc, gm, eta, hill, n_active, dt, k_hill, k_speed, k_peri, m,
            until_check, check_every, targs):
    return 0, until_check, 0


_far_steps_call = called(far_steps, nrt=False)


@njit(inline="always")
def _far(xh, vb, xc, vc, gm, eta, hill, n_active, dt, k_hill, k_speed, k_peri, m,
         until_check, check_every, targs):
    # the lanes' loop: targs holds the lanes' scratch
    return _far_steps_call(xh, vb, xc, vc, gm, eta, hill, n_active, dt, k_hill, k_speed,
                           k_peri, m, until_check, check_every, targs[0])


# asked at every call of the loop and where the lanes may be compiled (twice
# a run's call): each answer is kept, as wh's loops are
@functools.lru_cache(maxsize=None)
def trace_loop(record=_record, terms=None, lanes=False):
    """The ``trace`` loop, ``record`` recording the monitors, and ``terms`` (the
    :class:`~orbits._kernels.terms.TermKernel` of a table of position-only
    terms, or None) kicked with the interaction, as ``wh`` kicks them; the
    loop with terms serves runs without them too, given an empty table.  It takes
    ``(x, v, t, dt, nsteps, work, criteria, inner, tabs, outputs, checks,
    check, ahead, targs)``: a :class:`Work`, a :class:`Criteria`, an
    :class:`Inner`, the DOP853 tables, the records of :mod:`.records`, the
    stopping conditions' pointer (:func:`~.stopping.stop_record`),
    :func:`~.stopping.ahead_pointer`'s pointer and the terms' arguments, or
    with ``lanes`` (no terms) a tuple of the lanes' scratch
    (:func:`~.trace_lanes.far_scratch_shape`): the loop whose steps far from
    encounters go through :func:`~.trace_lanes.far_steps`, the same results
    bit for bit."""
    key = "trace"
    if terms is None:
        kick, cache = _no_term_kick, True
    else:
        if lanes:
            raise ValueError("the lanes' trace loop takes no added terms")
        key = f"{key}_{terms.key}"
        cache = terms.cache
        kick = specialize(_heliocentric_term_kick, f"trace_{terms.key}", cache=cache,
                          inline=True, nrt=not cache, extra=terms.accel)
    step = epilogue(record, key, cache=cache, runtime=not cache)
    if lanes:
        key = f"{key}_lanes"
    # the terms' kick is called, where it runs (a table with rows): inlined
    # at the two sites where every step far from encounters kicks, it made
    # the loop's first compile some 10 s longer for no time a step that
    # shows (benchmarks/RESULTS.md)
    if terms is not None:
        kick = called(kick, nrt=not cache)
    return specialize(_trace_loop, key, cache=cache, nrt=not cache,
                      has_terms=_no_terms if terms is None else _table_has_rows,
                      term_kick=kick,
                      LANES=lanes,
                      far_run=_far if lanes else _no_far, step_end=step)


def inner_arrays(n, stages):
    """The inner integrator's arrays (:class:`Inner`) for ``n`` bodies and a
    method of ``stages`` stages."""
    return Inner(np.zeros(n, dtype=np.int64), np.zeros(n, dtype=np.int64),
                 np.zeros((stages + 1, n, 3)), np.zeros((stages + 1, n, 3)),
                 np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3)),
                 np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(1), np.zeros(3, dtype=np.int64))
