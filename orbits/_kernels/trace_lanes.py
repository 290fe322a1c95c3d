"""``trace``'s steps far from encounters, with the planets in vector lanes.

A segment of ``trace`` (:mod:`orbits._kernels.trace`) that neither its
start nor its end flags, between two such segments, is the step of ``wh``
in democratic heliocentric coordinates bit for bit: the Kepler drift of a
whole step, the half jump, the planets' mutual kick, the half jump.
:func:`far_steps` makes a run of such steps on the state kept in the lanes
of :mod:`orbits._kernels.wh_lanes` (its drift, jumps and pulls, each bit for
bit the scalar kernel), as ``wh``'s loop does between outputs, and
evaluates the switching criterion at each step's criterion point (after the
first half jump, with the velocities half kicked) in the lanes too.

The lanes' criterion (:func:`may_flag`) is a bound, not the criterion: it
stops the run of steps wherever :func:`~orbits._kernels.trace.criterion`
could flag something.  It makes the scalar criterion's own operations on the
same numbers (squared distances and speeds, the bound on the Hill radius
that the scalar criterion starts from) and takes, with a relative margin of
:data:`MARGIN`, a pair within the speed radius or within that bound, or a
body within the pericentre threshold; the Hill radius itself (a cube root
and two square roots) is left to the scalar criterion.  The step where it
stops is taken by the scalar loop from that step's start and the criterion
point before it, both kept in the lanes: it evaluates the criterion and
flags, redoes or goes on as it would have.  So the run is the scalar loop's
bit for bit, whatever the lanes' criterion says; only the time differs.

The pairs go first through a looser test, ``max(SP_i + SP_j, bound on the
Hill radius)`` with ``SP = k_speed |h| |V|`` in place of the relative
speed, made inside the pass that sums the planets' pulls
(:func:`pulls_tested`): that pass already has each pair's squared
separation, and its square roots and divisions leave room for the test's
few operations.  Its speeds are taken before the kick that makes the
criterion point's velocities (the kick needs the pulls), widened by a
margin (:data:`_GROW`) far above what a half kick far from encounters
changes; :func:`criterion_end` checks that no kicked speed outgrew its
reach.  Only where a pair passes the looser test, or a speed outgrew its
reach, are the pairs tested again with the relative speeds.  Each pair is
tested once per source body in the lanes (both orders, the same squared
numbers), and only the pairs that the scalar criterion tests (an active
source); the padding columns are left out.
"""

import math

import numpy as np

from ._jit import njit
from .gravity import LANE_WIDTH, lane_columns, pull_column
from .wh_lanes import (SCRATCH_ROWS, STATE, SUMS, jump_rows, jump_shift, kick_rows,
                       resident_drift_into, resident_finite, resident_load, resident_store,
                       zero_sums)

__all__ = ["far_steps", "may_flag", "may_flag_at", "load_hill", "load_point", "criterion_scales",
           "criterion_start", "pulls_tested", "criterion_end", "far_scratch_shape", "MARGIN",
           "FAR_WAIT", "FAR_STEPS"]

#: 2^(1/3): ((m_i + m_j) / 3 m_0)^(1/3) <= 2^(1/3) max(hill_i, hill_j)
_CBRT2 = 1.2599210498948732

#: The lanes' criterion's relative margin on each threshold (see the module
#: notes): it takes the same operations as the scalar criterion, so the
#: margin only guards the bound against a difference of rounding.
MARGIN = 1.0 + 1e-12

# A speed reach of criterion_start's, taken before the kick of the
# criterion point, widened for it: a half kick of the planets' pulls changes
# a speed far from encounters by a millionth or less (Venus's on Mercury at
# the users' step), and criterion_end checks the widened reach held.
_GROW = 1.0 + 1.0 / 1024.0

#: Steps the scalar loop takes after the lanes' criterion stopped a run of
#: steps, before it tries the lanes again: a pair near its switching radius
#: stops the lanes at every step, and each try costs a step's drift and kick
#: in the lanes on top of the scalar step.
FAR_WAIT = 16

# the rows of the scratch after the lanes' state's (wh_lanes.SCRATCH_ROWS):
# each column's squared Hill factor, squared distance and half-kicked
# velocity (3), the step's drifted state (6), which holds its criterion
# point's positions, the last criterion point (6), each column's scaled
# speed, and a count of the steps made in the lanes (row FAR_STEPS, column 0)
_HILL2 = SCRATCH_ROWS
_R2 = _HILL2 + 1
_VS = _R2 + 1
_DRIFTED = _VS + 3
_POINT = _DRIFTED + 6
# each column's speed reach k_speed |h| |V| (with the margin, widened)
_SP = _POINT + 6
#: the scratch's row whose column 0 counts the steps made in the lanes
FAR_STEPS = _SP + 1


def far_scratch_shape(n):
    """The shape of the scratch of :func:`far_steps` for ``n`` bodies: the
    lanes' state's (:func:`~orbits._kernels.wh_lanes.lanes_scratch_shape`)
    and the rows above."""
    return (FAR_STEPS + 1, 2 * lane_columns(n))


@njit(inline="always")
def criterion_scales(h, gm0, k_hill, k_speed, k_peri):
    """The squared scales of the switching criterion at the step ``h``:
    ``(k_peri h)^2``, ``((k_peri h)^2 G m_0)^2``, ``(k_speed |h|)^2`` and
    ``(2^(1/3) k_hill)^2``."""
    kp2 = (k_peri * h) ** 2
    kg2 = (kp2 * gm0) ** 2
    kv = k_speed * abs(h)
    kh2 = (k_hill * _CBRT2) ** 2
    return kp2, kg2, kv * kv, kh2


@njit(inline="always")
def load_hill(S, hill, n):
    """Each column's squared Hill factor ``hill[i]^2`` into its row (the
    padding repeats body 1's)."""
    H2 = S[_HILL2]
    for k in range(lane_columns(n)):
        i = k + 1 if k + 1 < n else 1
        H2[k] = hill[i] * hill[i]


@njit(inline="always")
def load_point(S, xh, vs, gm, hill):
    """A criterion point into the lanes as :func:`far_steps` has it: the
    positions ``xh`` and the velocities ``vs`` (half kicked) of the
    planets, and the Hill factors; what :func:`may_flag` reads."""
    n = xh.shape[0]
    resident_load(xh, vs, gm, gm, S)
    load_hill(S, hill, n)
    for k in range(lane_columns(n)):
        i = k + 1 if k + 1 < n else 1
        for d in range(3):
            S[_VS + d, k] = vs[i, d]


@njit(inline="always")
def _rows(S, r):
    # the three rows from r (x, y, z of positions or velocities)
    return S[r], S[r + 1], S[r + 2]


@njit(inline="always")
def _hill_bound(khm, H2, R2, k, aj, rj2):
    # the bound on the squared Hill switching radius of column k and a source
    # whose squared Hill factor and distance are aj, rj2 (see criterion)
    return khm * max(H2[k], aj) * max(R2[k], rj2)


@njit(inline="always")
def _paired(k, j, n):
    # whether column k (unsigned) pairs with the source body j (column j -
    # 1): after it and not padding; compared as signed integers, which the
    # vector instructions compare directly (unsigned ones take three more
    # operations a comparison)
    kk = np.int64(k)
    return (kk >= j) & (kk < n - 1)


@njit(inline="always")
def may_flag(S, gm, n_active, n, h, k_hill, k_speed, k_peri):
    """Whether :func:`~orbits._kernels.trace.criterion` could flag a pair or
    a pericentre at the lanes' criterion point of the step ``h``: the
    positions in the lanes' state, the velocities in the rows ``_VS`` (see
    the module notes); the pulls' sums (:data:`SUMS`) are overwritten."""
    return may_flag_at(S, STATE, _VS, gm, n_active, n, h, k_hill, k_speed, k_peri)


@njit(inline="always")
def may_flag_at(S, pos, vel, gm, n_active, n, h, k_hill, k_speed, k_peri):
    """:func:`may_flag` of the positions in the three rows from ``pos`` and
    the velocities in those from ``vel``: :func:`criterion_start`,
    :func:`pulls_tested` and :func:`criterion_end` with no kick between."""
    criterion_start(S, pos, vel, n, k_speed * abs(h))
    hits = pulls_tested(S, gm, n_active, n, pos, k_hill)
    return criterion_end(S, pos, vel, gm, n_active, n, h, k_hill, k_speed, k_peri, hits)


@njit(inline="always")
def criterion_start(S, pos, vel, n, kv):
    """What :func:`pulls_tested` reads besides the positions in the three
    rows from ``pos``: each column's squared heliocentric distance, and its
    speed reach ``kv |V|`` (``kv = k_speed |h|``, with the margin) from the
    velocities in the three rows from ``vel`` (before the kick that makes
    the criterion point's), widened by :data:`_GROW` for that kick."""
    P = np.uint64(lane_columns(n))
    X, Y, Z = _rows(S, pos)
    U, V, W = _rows(S, vel)
    R2 = S[_R2]
    SP = S[_SP]
    kvm = MARGIN * kv * kv
    for k in range(P):
        R2[k] = X[k] * X[k] + Y[k] * Y[k] + Z[k] * Z[k]
        SP[k] = _GROW * math.sqrt(kvm * (U[k] * U[k] + V[k] * V[k] + W[k] * W[k]))


@njit(inline="always")
def pulls_tested(S, gm, n_active, n, pos, k_hill):
    """:func:`~orbits._kernels.wh_lanes.pulls_rows` of the positions in the
    three rows from ``pos`` (the same sums, bit for bit), and in the same
    passes each pair's looser test: the pairs within ``max(SP_i + SP_j,
    bound on the Hill radius)`` (rows from :func:`criterion_start`), counted
    (see the module notes)."""
    P = np.uint64(lane_columns(n))
    zero_sums(S, P)
    X, Y, Z = _rows(S, pos)
    AX, AY, AZ = _rows(S, SUMS)
    R2 = S[_R2]
    H2 = S[_HILL2]
    SP = S[_SP]
    khm = MARGIN * (k_hill * _CBRT2) ** 2
    real = np.uint64(n - 1)
    hits = 0
    # each source's pull on every column, and its test of the columns it
    # pairs with (those after its own, but padding), on the same separation
    for j in range(1, n_active):
        c = np.uint64(j - 1)
        xs = X[c]
        ys = Y[c]
        zs = Z[c]
        sj = SP[c]
        aj = H2[c]
        rj2 = R2[c]
        ms = gm[j]
        for k in range(P):
            d2 = pull_column(X, Y, Z, AX, AY, AZ, k, xs, ys, zs, ms, c, 0.0, real)
            s = SP[k] + sj
            reach = max(s * s, _hill_bound(khm, H2, R2, k, aj, rj2))
            hits += _paired(k, j, n) & (d2 < reach)
    return hits


@njit(inline="always")
def criterion_end(S, pos, vel, gm, n_active, n, h, k_hill, k_speed, k_peri, hits):
    """The rest of :func:`may_flag_at` once the velocities in the three rows
    from ``vel`` are the criterion point's: the pericentre test, the check
    that no speed outgrew its reach in :func:`pulls_tested` (whose count is
    ``hits``), and the pairs again with their relative speeds where the
    looser test may flag."""
    kp2, kg2, kv2, kh2 = criterion_scales(h, gm[0], k_hill, k_speed, k_peri)
    P = np.uint64(lane_columns(n))
    X, Y, Z = _rows(S, pos)
    U, V, W = _rows(S, vel)
    R2 = S[_R2]
    H2 = S[_HILL2]
    SP = S[_SP]
    lo = MARGIN - 1.0
    kgm = MARGIN * kg2
    kvm = MARGIN * kv2
    peri = 0
    grown = 0
    # (whole rows of lanes, the padding masked: loops that LLVM vectorises)
    for k in range(P):
        ri2 = R2[k]
        vi2 = U[k] * U[k] + V[k] * V[k] + W[k] * W[k]
        rv = X[k] * U[k] + Y[k] * V[k] + Z[k] * W[k]
        d = ri2 * ri2 - kp2 * (vi2 * ri2 + 3.0 * rv * rv)
        real = np.int64(k) < n - 1
        peri += real & ((d <= lo * ri2 * ri2) | (kgm * ri2 > d * d))
        grown += real & (kvm * vi2 > SP[k] * SP[k])
    if peri:
        return True
    if hits == 0 and grown == 0:
        return False
    khm = MARGIN * kh2
    L = np.uint64(LANE_WIDTH)
    # the sources with a pair after them: column c = j - 1 pairs with the
    # columns c < k < n - 1 (the last planet's column has none), the pairs
    # (i, j), i > j, as the scalar criterion takes them: the lanes after
    # column c, from the vector register that holds it on
    sources = min(n_active, n - 1)
    hits = 0
    for j in range(1, sources):
        c = np.uint64(j - 1)
        xj = X[c]
        yj = Y[c]
        zj = Z[c]
        uj = U[c]
        vj = V[c]
        wj = W[c]
        aj = H2[c]
        rj2 = R2[c]
        for k in range((c + np.uint64(1)) // L * L, P):
            dx = X[k] - xj
            dy = Y[k] - yj
            dz = Z[k] - zj
            d2 = dx * dx + dy * dy + dz * dz
            ux = U[k] - uj
            uy = V[k] - vj
            uz = W[k] - wj
            bound = _hill_bound(khm, H2, R2, k, aj, rj2)
            hits += (_paired(k, j, n)
                     & ((d2 < kvm * (ux * ux + uy * uy + uz * uz)) | (d2 < bound)))
    return hits != 0


@njit(inline="always")
def _close_step(S, gm, n_active, dt, half, P):
    # the kick by dt and the closing half jump of a step from its drifted
    # rows into the state's (wh_lanes.kick_rows, jump_rows: the same
    # operations), the criterion point (the drifted positions, the
    # half-kicked velocities) copied into _POINT in the same passes
    for r in range(3):
        V = S[_DRIFTED + 3 + r]
        U = S[STATE + 3 + r]
        A = S[SUMS + r]
        Vs = S[_VS + r]
        Pv = S[_POINT + 3 + r]
        for k in range(P):
            U[k] = V[k] + dt * A[k]
            Pv[k] = Vs[k]
    px, py, pz = jump_shift(S, gm, n_active, half, STATE + 3)
    X = S[_DRIFTED]
    Y = S[_DRIFTED + 1]
    Z = S[_DRIFTED + 2]
    U = S[STATE]
    V = S[STATE + 1]
    W = S[STATE + 2]
    PX = S[_POINT]
    PY = S[_POINT + 1]
    PZ = S[_POINT + 2]
    for k in range(P):
        x = X[k]
        y = Y[k]
        z = Z[k]
        U[k] = x + px
        V[k] = y + py
        W[k] = z + pz
        PX[k] = x
        PY[k] = y
        PZ[k] = z


@njit(inline="always")
def far_steps(xh, vb, xc, vc, gm, eta, hill, n_active, dt, k_hill, k_speed, k_peri, m,
              until_check, check_every, S):
    """Up to ``m`` unflagged steps of ``trace`` in the lanes, from a state
    ``xh``, ``vb`` (democratic heliocentric) that owes half a step's drift,
    whose last segment had no flags (see the module notes); ``xc``, ``vc``
    get the last criterion point, as the scalar loop keeps it.  The
    epilogue's finite check every ``check_every`` steps (``until_check``
    counting down), on the lanes.  Returns ``(steps made, until_check,
    why)``: ``why`` 0 when ``m`` were made, 1 when the next step's criterion
    point may flag (the state is that step's start), 2 when the state is not
    finite after the last step made."""
    n = xh.shape[0]
    P = np.uint64(lane_columns(n))
    half = 0.5 * dt
    seg = half + half
    kv = k_speed * abs(dt)
    resident_load(xh, vb, gm, eta, S)
    load_hill(S, hill, n)
    done = 0
    why = 0
    # a step drifts the state into rows of its own and makes its criterion
    # point there, so that a step that may flag leaves the state at its
    # start; the closing kick and half jump write the state's rows from
    # them, and keep the criterion point in the same passes (_close_step)
    while done < m:
        b0 = xh[0, 0]
        b1 = xh[0, 1]
        b2 = xh[0, 2]
        resident_drift_into(xh, vb, eta, seg, S, _DRIFTED)
        jump_rows(S, gm, n_active, half, P, _DRIFTED, _DRIFTED)
        criterion_start(S, _DRIFTED, _DRIFTED + 3, n, kv)
        hits = pulls_tested(S, gm, n_active, n, _DRIFTED, k_hill)
        kick_rows(S, half, P, _DRIFTED + 3, _VS)
        if criterion_end(S, _DRIFTED, _VS, gm, n_active, n, dt, k_hill, k_speed, k_peri,
                         hits):
            xh[0, 0] = b0
            xh[0, 1] = b1
            xh[0, 2] = b2
            why = 1
            break
        _close_step(S, gm, n_active, dt, half, P)
        done += 1
        until_check -= 1
        if until_check == 0:
            until_check = check_every
            if not resident_finite(xh, vb, S):
                why = 2
                break
    resident_store(S, xh, vb)
    if done > 0:
        # the last criterion point: the planets from the lanes, the central
        # row as the scalar loop has it there (its drift done, no pull)
        for i in range(1, n):
            for d in range(3):
                xc[i, d] = S[_POINT + d, i - 1]
                vc[i, d] = S[_POINT + 3 + d, i - 1]
        for d in range(3):
            xc[0, d] = xh[0, d]
            vc[0, d] = vb[0, d] + half * 0.0
        S[FAR_STEPS, 0] += done
    return done, until_check, why
