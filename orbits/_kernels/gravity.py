"""Pairwise Newtonian gravity on plain float64 arrays.

Bodies are ordered so that the ``n_active`` massive ones come first; the
others are test particles, which feel the massive bodies but cost no pair work
among themselves.  ``gm[i] = G * m[i]`` is precomputed by the caller.
Softening replaces ``r**2`` by ``r**2 + eps2``.

The kernels, and which one a simulation takes (:func:`serial_kind`):

* :func:`accelerate_pairwise_small`, the plain double loop: each pair once
  (j < i), Newton's third law; up to six massive bodies.
* :func:`accelerate_pairwise_lanes`: every body's pulls from each source in
  one vector pass over all bodies (each pair computed from both sides),
  summed in the double loop's order, so bit for bit its numbers; from seven
  massive bodies on one thread (:data:`LANES_FROM`).
* :func:`accelerate_pairwise`: each pair once, the separations gathered in
  batches whose square roots and divisions vectorise; bit for bit the
  double loop too, but slower than the lanes (kept for comparison).
* :func:`accelerate_pairwise_parallel` also visits each pair once, in blocks
  of rows spread over threads, each block adding into its own accumulator so
  that threads never write the same element; its inner loops vectorise.
  From ``orbits.simulation.PARALLEL_THRESHOLD`` bodies.
"""

import math

import numpy as np
import numba

from ._jit import cpu_name, njit, njit_parallel

__all__ = ["accelerate_pairwise", "accelerate_pairwise_parallel", "accelerate_reference",
           "pair_workspace", "gravity_args", "PAIR_BATCH", "SMALL_N", "N_BLOCKS",
           "accelerate_pairwise_small", "accelerate_pairwise_rebound", "pair_accelerations",
           "aligned_zeros", "zero_rows", "pull_with_sums", "pull_pair", "add_pulls",
           "accelerate_pairwise_lanes", "pair_accelerations_lanes", "lane_columns",
           "LANE_WIDTH", "LANE_ROWS", "LANES_FROM", "serial_kind", "pull_rows", "vector_doubles",
           "pull_factors", "pull_rows_factored", "pull_column"]


#: Up to this many massive bodies the plain double loop
#: (:func:`accelerate_pairwise_small`) is used; from here on gathering pairs
#: into vectorised batches (:func:`accelerate_pairwise`) pays
#: (benchmarks/bench_gravity.py; the figures in benchmarks/RESULTS.md).
SMALL_N = 8

#: Massive bodies from which the pairs' pulls are summed in vector lanes
#: (:func:`accelerate_pairwise_lanes`) on one thread.  It evaluates each pair
#: twice (once per body), one vector pass per source, so it pays where the
#: lanes are full: from seven massive bodies on it is quicker than the plain
#: double loop and the batched kernel, and its pair rate on one thread is
#: several times the batched kernel's (benchmarks/bench_gravity.py; the
#: figures in benchmarks/RESULTS.md).  So the batched kernel is left to
#: where it is asked for.
LANES_FROM = 7

#: Pairs handled per batch by the serial kernel: enough to fill the vector
#: units, small enough that the batch stays in L1 cache (4 arrays x 8 bytes).
PAIR_BATCH = 1024


def gravity_args(G, m, n_active, eps2, parallel=False):
    """The ``fargs`` tuple of the gravity forces: ``(G m, n_active, eps2, work, G, m)``.

    ``m`` is in the internal order (massive bodies first).  Both ``G m`` and
    ``G`` with ``m`` are carried: the batched and threaded kernels use the
    product, the few-body kernel REBOUND's rounding, which needs the factors.
    """
    m = np.ascontiguousarray(m, dtype=np.float64)
    return (G * m, int(n_active), float(eps2), pair_workspace(len(m), n_active, parallel),
            float(G), m)


def serial_kind(n, n_active):
    """The one-thread pair kernel for ``n`` bodies of which ``n_active`` are
    massive: ``"small"`` (:func:`accelerate_pairwise_small`), ``"lanes"``
    (:func:`accelerate_pairwise_lanes`) or ``"serial"``
    (:func:`accelerate_pairwise`); all three give the same numbers bit for
    bit.  See :data:`LANES_FROM`."""
    if n_active >= LANES_FROM:
        return "lanes"
    return "small" if n_active <= SMALL_N else "serial"


def pair_workspace(n, n_active, parallel=False):
    """Scratch array for :func:`accelerate_pairwise`, shape (4, batch), and
    :func:`accelerate_pairwise_lanes` (rows :data:`LANE_ROWS`, columns
    :func:`lane_columns`), or for :func:`accelerate_pairwise_parallel`
    (``parallel=True``), shape (3 * N_BLOCKS, n)."""
    if parallel:
        return np.zeros((3 * N_BLOCKS, n))
    pairs = n_active * (n_active - 1) // 2 + (n - n_active) * n_active
    return np.zeros((LANE_ROWS, max(n_active, min(pairs, PAIR_BATCH), lane_columns(n), 1)))


@njit(inline="always")  # tens of bodies: the call costs a few % of a step
def accelerate_pairwise(x, gm, n_active, eps2, acc, work):
    """Accelerations by the serial j < i pair loop.

    Parameters
    ----------
    x : ndarray, shape (N, 3)
        Positions.
    gm : ndarray, shape (N,)
        G times the masses; zero for test particles.
    n_active : int
        Number of massive bodies, which come first.
    eps2 : float
        Softening length squared (0 for none).
    acc : ndarray, shape (N, 3)
        Output.
    work : ndarray, shape (4, B)
        Scratch from :func:`pair_workspace`.

    Notes
    -----
    ``a_i = - sum_j G m_j (x_i - x_j) / (|x_i - x_j|^2 + eps2)^(3/2)``.

    Each pair (i, j < i) is visited once and its term added to both bodies
    (Newton's third law); test particles (i >= n_active) pair only with the
    massive bodies.  The pairs' separations are first gathered into ``work``
    in batches, so that the square roots and divisions, which dominate the
    cost, run as one vectorised loop over many pairs instead of row by row;
    vector square root and division are correctly rounded like the scalar
    ones, so the result is the same as a plain double loop's.
    """
    n = x.shape[0]
    zero_rows(acc, 0, n)
    cap = work.shape[1]
    k = 0
    first = 1
    for i in range(1, n):
        m = min(i, n_active)
        if k + m > cap:
            _apply_batch(gm, n_active, eps2, acc, work, first, i, k)
            k = 0
            first = i
        xi = x[i, 0]
        yi = x[i, 1]
        zi = x[i, 2]
        for j in range(m):
            work[0, k] = xi - x[j, 0]
            work[1, k] = yi - x[j, 1]
            work[2, k] = zi - x[j, 2]
            k += 1
    _apply_batch(gm, n_active, eps2, acc, work, first, n, k)
    return 0


# A loop that LLVM vectorises over the lanes' columns runs its vector body
# over whole registers and the rest in scalar code, so the columns are padded
# to a multiple of the register's doubles.  How wide a register LLVM fills
# depends on the processor it compiles for: 512 bits (8 doubles) on AMD's
# Zen 4 with AVX-512, but 256 bits (4) on Intel's AVX-512 processors, where LLVM
# prefers them, and on AVX2 machines.  A width narrower than the register's
# leaves loops partly or wholly in scalar code; a wider one spends work on
# padding (both measured: benchmarks/RESULTS.md).  So the width is asked of
# LLVM itself, for the processor and features numba compiles for: a one-line
# loop vectorised as numba would (10 ms at import).  The results do not depend
# on it: each lane's arithmetic is its own, and the padding's is never read.

_PROBE = """
define void @probe({p} noalias nocapture %a, {p} noalias nocapture readonly %b, i64 %n) {{
entry:
  %c = icmp sgt i64 %n, 0
  br i1 %c, label %loop, label %exit
loop:
  %i = phi i64 [ 0, %entry ], [ %next, %loop ]
  %pa = getelementptr inbounds double, {p} %a, i64 %i
  %pb = getelementptr inbounds double, {p} %b, i64 %i
  %va = load double, {p} %pa
  %vb = load double, {p} %pb
  %m = fmul double %vb, 2.0
  %s = fadd double %va, %m
  store double %s, {p} %pa
  %next = add nuw nsw i64 %i, 1
  %done = icmp eq i64 %next, %n
  br i1 %done, label %exit, label %loop
exit:
  ret void
}}
"""


def vector_doubles():
    """Doubles in the vector registers that LLVM fills when it vectorises a
    loop of doubles for the processor numba compiles for: 8 or 4 (4 also
    where the registers are narrower; 8 if LLVM cannot be asked)."""
    try:
        import llvmlite.binding as llvm
        from numba.core import config
        from numba.core.codegen import get_host_cpu_features
        llvm.initialize_native_target()
        llvm.initialize_native_asmprinter()
        target = llvm.Target.from_default_triple()
        cpu = cpu_name()
        features = (config.CPU_FEATURES if config.CPU_FEATURES is not None
                    else get_host_cpu_features())
        machine = target.create_target_machine(cpu=cpu, features=features, opt=3)
        try:
            module = llvm.parse_assembly(_PROBE.format(p="ptr"))
        except RuntimeError:                  # an LLVM with typed pointers
            module = llvm.parse_assembly(_PROBE.format(p="double*"))
        options = llvm.create_pipeline_tuning_options(speed_level=3)
        options.loop_vectorization = True
        passes = llvm.create_pass_builder(machine, options)
        passes.getModulePassManager().run(module, passes)
        return 8 if "<8 x double>" in str(module) else 4
    except Exception:      # noqa: BLE001 - any failure: the wider padding, safe everywhere
        return 8


#: the lanes' columns (:func:`pair_accelerations_lanes`, and the planets of
#: :mod:`orbits._kernels.wh_lanes`) are padded to a multiple of it: the
#: doubles of the vector registers LLVM fills on this machine
#: (:func:`vector_doubles`)
LANE_WIDTH = vector_doubles()

#: rows of the lanes' scratch: positions (0 to 2), sums (3 to 5) and the
#: central body's factors 1 / r^3 (6)
LANE_ROWS = 7

#: bytes of a cache line, where the lanes' scratch starts
_LINE = 64


def aligned_zeros(shape):
    """``np.zeros(shape)`` whose first element starts a cache line (numpy
    aligns a small array to 16 bytes only).  The lanes' rows then start where
    their vector loads do not straddle two lines, whatever address a run's
    scratch gets (a scratch that straddles lines slows the Wisdom-Holman
    lanes' drift and kick: benchmarks/RESULTS.md)."""
    size = int(np.prod(shape))
    buf = np.zeros(size + _LINE // 8)
    start = (-buf.ctypes.data % _LINE) // 8
    return buf[start:start + size].reshape(shape)


@njit(inline="always")
def lane_columns(n):
    """Lane columns for ``n`` bodies: one per body after the first
    (``n - 1``), padded to a multiple of :data:`LANE_WIDTH`."""
    return LANE_WIDTH * max(1, (n - 1 + LANE_WIDTH - 1) // LANE_WIDTH)


# The pairs' pulls with the bodies in vector lanes.  Each source body's pull
# on every lane at once: the source broadcast, the lanes its receivers, one
# pass over the columns per source (8 sources over 8 lanes: 64 pulls, of
# which 28 pairs are needed, but in 8 vector passes instead of 28 chains of
# scalar operations).  A body's pulls are summed over the sources in
# ascending order, which is pair_accelerations's order (the pulls of the
# bodies before it, then those after), and each pull is the same
# expression: the scalar code's ``-(G m_j / r^3) (x_i - x_j)`` is exactly
# ``(G m_j / r^3) (x_j - x_i)``, subtraction being the addition of the
# negation; so the accelerations are the scalar loop's bit for bit.  A
# lane's own source (and a pair left out) adds a zero that leaves its sum as
# it is: its mass is replaced by 0 and its distance by 1 (a sum started at
# +0 is never -0, so adding +0 or -0 changes nothing).  Two things decide
# the speed of a pass: its sums must not go through masked stores (a masked
# store cannot be forwarded to the next pass's load), and the pass must
# store nothing but its sums (LLVM keeps the scalar form of a pass that
# writes a further row).

@njit(inline="always")
def _separation(X, Y, Z, k, xs, ys, zs, own, real):
    # a source's separation from column k, and whether the column adds an
    # exact zero (its own, or padding from real on)
    return xs - X[k], ys - Y[k], zs - Z[k], (k == own) | (k >= real)


@njit(inline="always")
def _factor(dx, dy, dz, skip, eps2):
    # 1 / r^3 of a separation, as the scalar pair loop computes it; 1 where
    # the column is skipped
    r2 = dx * dx + dy * dy + dz * dz + eps2
    r2 = 1.0 if skip else r2
    return 1.0 / (r2 * math.sqrt(r2))


@njit(inline="always")
def pull_column(X, Y, Z, AX, AY, AZ, k, xs, ys, zs, ms, own, eps2, real):
    """The pull of :func:`pull_rows` on the column ``k`` alone, added to its
    sums; returns the squared separation (without ``eps2``), so that a pass
    that also tests the pair's distance shares its arithmetic."""
    dx, dy, dz, skip = _separation(X, Y, Z, k, xs, ys, zs, own, real)
    s = (0.0 if skip else ms) * _factor(dx, dy, dz, skip, eps2)
    AX[k] = AX[k] + s * dx
    AY[k] = AY[k] + s * dy
    AZ[k] = AZ[k] + s * dz
    return dx * dx + dy * dy + dz * dz


@njit(inline="always")
def pull_rows(X, Y, Z, AX, AY, AZ, P, xs, ys, zs, ms, own, eps2, real):
    """The pull of a source at ``(xs, ys, zs)`` of ``G m = ms`` on the
    columns ``k < P`` of the rows ``X``, ``Y``, ``Z``, added to the sums
    ``AX``, ``AY``, ``AZ``; the column ``own`` and those from ``real`` on
    (padding) add an exact zero (see the notes above)."""
    for k in range(P):
        pull_column(X, Y, Z, AX, AY, AZ, k, xs, ys, zs, ms, own, eps2, real)


@njit(inline="always")
def pull_factors(X, Y, Z, F, P, xs, ys, zs, own, eps2, real):
    """The factors ``1 / r^3`` of :func:`pull_rows` for a source at ``(xs,
    ys, zs)`` into ``F[k]``, ``k < P`` (1 for the column ``own`` and those
    from ``real`` on), the same operations in the same order.  A source
    whose own sums also need these factors (the central body, whose sums
    the scalar loop adds pair by pair) then takes them from ``F`` instead of
    a square root and a division a pair, and pulls the lanes with
    :func:`pull_rows_factored`."""
    for k in range(P):
        dx, dy, dz, skip = _separation(X, Y, Z, k, xs, ys, zs, own, real)
        F[k] = _factor(dx, dy, dz, skip, eps2)


@njit(inline="always")
def pull_rows_factored(X, Y, Z, AX, AY, AZ, P, xs, ys, zs, ms, own, F, real):
    """:func:`pull_rows` with its factors ``1 / r^3`` from ``F``
    (:func:`pull_factors` of the same source), bit for bit."""
    for k in range(P):
        dx, dy, dz, skip = _separation(X, Y, Z, k, xs, ys, zs, own, real)
        s = (0.0 if skip else ms) * F[k]
        AX[k] = AX[k] + s * dx
        AY[k] = AY[k] + s * dy
        AZ[k] = AZ[k] + s * dz


@njit(inline="always")
def _pull(S, P, xs, ys, zs, ms, own, eps2):
    # the pull of a source on every column of the scratch's rows (positions
    # 0 to 2, sums 3 to 5) but ``own``
    pull_rows(S[0], S[1], S[2], S[3], S[4], S[5], P, xs, ys, zs, ms, own, eps2, P)


@njit(inline="always")
def _columns_from(R, x, d, n):
    # component d of bodies 1 .. n - 1 into R[0 .. n - 2], the padding after
    # them a copy of body 1 (its sums are never read)
    for k in range(np.uint64(n - 1)):
        R[k] = x[k + 1, d]
    for k in range(np.uint64(n - 1), np.uint64(lane_columns(n))):
        R[k] = x[1, d]


@njit(inline="always")
def pair_accelerations_lanes(x, gm, n_active, eps2, acc, first, skip_first_pair, S):
    """:func:`pair_accelerations` with the bodies after the first in vector
    lanes, bit for bit, for ``first`` 0 or 1.  ``S`` is scratch of at least
    :data:`LANE_ROWS` rows and :func:`lane_columns` ``(N)`` columns."""
    n = x.shape[0]
    P = lane_columns(n)
    Pu = np.uint64(P)
    # the positions and the zeroed sums, each in a loop of its own without a
    # select on the index, so that LLVM stores them as vectors: the passes'
    # vector loads then take them from the store buffer, where scalar stores
    # would make each wait until they reach the cache
    _columns_from(S[0], x, 0, n)
    _columns_from(S[1], x, 1, n)
    _columns_from(S[2], x, 2, n)
    for r in range(3, 6):
        A = S[r]
        for k in range(Pu):
            A[k] = 0.0
    real = np.uint64(P)
    if first == 0:
        # the central body (column none; body 1's where the pair (0, 1) is left
        # out), its factors 1 / r^3 kept in row 6 for its own sums below
        own = np.uint64(0 if skip_first_pair else P)
        pull_factors(S[0], S[1], S[2], S[6], Pu, x[0, 0], x[0, 1], x[0, 2], own, eps2, real)
        pull_rows_factored(S[0], S[1], S[2], S[3], S[4], S[5], Pu, x[0, 0], x[0, 1], x[0, 2],
                           gm[0], own, S[6], real)
    for j in range(max(first, 1), n_active):
        # body j's column is j - 1
        _pull(S, Pu, x[j, 0], x[j, 1], x[j, 2], gm[j], np.uint64(j - 1), eps2)
    ax = 0.0
    ay = 0.0
    az = 0.0
    if first == 0:
        # the central body's sums, pulled by the bodies after it in order, as
        # the scalar loop adds them (a pair's r^2 is the same whichever body
        # its separation starts from)
        F = S[6]
        for i in range(2 if skip_first_pair else 1, n_active):
            dx = x[i, 0] - x[0, 0]
            dy = x[i, 1] - x[0, 1]
            dz = x[i, 2] - x[0, 2]
            s = gm[i] * F[i - 1]
            ax += s * dx
            ay += s * dy
            az += s * dz
    acc[0, 0] = ax
    acc[0, 1] = ay
    acc[0, 2] = az
    for i in range(1, n):
        acc[i, 0] = S[3, i - 1]
        acc[i, 1] = S[4, i - 1]
        acc[i, 2] = S[5, i - 1]


@njit(inline="always")
def accelerate_pairwise_lanes(x, gm, n_active, eps2, acc, work):
    """The pairs' pulls with the bodies in vector lanes
    (:func:`pair_accelerations_lanes`), bit for bit the plain double loop;
    arguments as :func:`accelerate_pairwise`."""
    pair_accelerations_lanes(x, gm, n_active, eps2, acc, 0, False, work)
    return 0


@njit(inline="always")  # a few bodies: the call itself would cost ~10 % of a step
def accelerate_pairwise_small(x, gm, n_active, eps2, acc, work):
    """The plain j < i double loop, fastest for a few bodies; arguments as
    :func:`accelerate_pairwise` (``work`` is not used)."""
    pair_accelerations(x, gm, n_active, eps2, acc, 0, False)
    return 0


@njit(inline="always")
def zero_rows(a, first, end):
    """Rows ``first <= i < end`` of ``a`` (shape (N, 3)) set to zero."""
    for i in range(first, end):
        a[i, 0] = 0.0
        a[i, 1] = 0.0
        a[i, 2] = 0.0


@njit(inline="always")
def pull_with_sums(acc, j, gmi, gmj, inv_r3, dx, dy, dz, axi, ayi, azi, react):
    """The pulls within a pair ``i > j``, with ``d = x_i - x_j`` and ``inv_r3 =
    1 / r^3``: body i's sums ``(axi, ayi, azi)``, kept by the caller and
    returned, less ``G m_j d / r^3``, and with ``react`` (body i massive)
    row j of ``acc`` plus ``G m_i d / r^3``."""
    sj = gmj * inv_r3
    axi -= sj * dx
    ayi -= sj * dy
    azi -= sj * dz
    if react:
        si = gmi * inv_r3
        acc[j, 0] += si * dx
        acc[j, 1] += si * dy
        acc[j, 2] += si * dz
    return axi, ayi, azi


@njit(inline="always")
def pull_pair(acc, i, j, gmi, gmj, dx, dy, dz):
    """Both pulls within the pair ``(i, j)`` into the rows of ``acc``, with
    ``d = x_i - x_j`` (no softening): row i less ``G m_j d / r^3``, row j plus
    ``G m_i d / r^3``."""
    r2 = dx * dx + dy * dy + dz * dz
    inv_r3 = 1.0 / (r2 * math.sqrt(r2))
    add_pulls(acc, i, j, gmj * inv_r3, gmi * inv_r3, dx, dy, dz)


@njit(inline="always")
def add_pulls(acc, i, j, sj, si, dx, dy, dz):
    """Row i of ``acc`` less ``sj d``, row j plus ``si d``: the pulls within a
    pair, ``d = x_i - x_j`` and ``s`` each the other body's ``G m / r^3``."""
    acc[i, 0] -= sj * dx
    acc[i, 1] -= sj * dy
    acc[i, 2] -= sj * dz
    acc[j, 0] += si * dx
    acc[j, 1] += si * dy
    acc[j, 2] += si * dz


@njit(inline="always")
def pair_accelerations(x, gm, n_active, eps2, acc, first, skip_first_pair):
    """``acc`` = the pull within every pair ``first <= j < i`` (j active), each
    pair once (Newton's third law); bodies before ``first`` feel and exert
    none, and ``skip_first_pair`` leaves out the pair ``(first, first + 1)``
    too.  The plain double loop of :func:`accelerate_pairwise_small`, and the
    interaction kicks of the Wisdom-Holman maps, which leave out the central
    body's pulls (democratic heliocentric) or the innermost pair (Jacobi)."""
    n = x.shape[0]
    zero_rows(acc, 0, n)
    for i in range(first + 1, n):
        xi = x[i, 0]
        yi = x[i, 1]
        zi = x[i, 2]
        gmi = gm[i]
        axi = 0.0
        ayi = 0.0
        azi = 0.0
        for j in range(first + 1 if (skip_first_pair and i == first + 1) else first,
                       min(i, n_active)):
            dx = xi - x[j, 0]
            dy = yi - x[j, 1]
            dz = zi - x[j, 2]
            r2 = dx * dx + dy * dy + dz * dz + eps2
            inv_r3 = 1.0 / (r2 * math.sqrt(r2))
            axi, ayi, azi = pull_with_sums(acc, j, gmi, gm[j], inv_r3, dx, dy, dz, axi, ayi,
                                           azi, i < n_active)
        acc[i, 0] += axi
        acc[i, 1] += ayi
        acc[i, 2] += azi


@njit(inline="always")
def accelerate_pairwise_rebound(x, G, m, n_active, eps2, acc):
    """The j < i pair loop in REBOUND's floating-point operations, for bit-for-bit
    agreement with its ``leapfrog`` (basic gravity, serial build).

    Parameters
    ----------
    x : ndarray, shape (N, 3)
        Positions.
    G : float
        The gravitational constant.
    m : ndarray, shape (N,)
        Masses (not ``G m``: the rounding of ``G m`` differs).
    n_active, eps2, acc
        As :func:`accelerate_pairwise`.

    Notes
    -----
    Per pair, in this order and with no fused multiply-add (fastmath is off
    in every kernel, so LLVM does not contract)::

        d = x_i - x_j,   r = sqrt(dx dx + dy dy + dz dz + eps2)
        p = G / (r r r),   a_i += (-p m_j) d,   a_j += (p m_i) d

    with row i's terms summed in order from zero before the later rows add
    their reactions to it, as in REBOUND.  :func:`accelerate_pairwise_small` rounds differently
    (``G m_j / (r^2 sqrt(r^2))``), by an ulp or so per pair; the two agree to
    rounding.  Test particles pull nothing back, as REBOUND's default
    ``testparticle_type = 0``.

    References
    ----------
    REBOUND's documentation of ``gravity = "basic"`` (Rein & Liu 2012, A&A
    537, A128, sect. 4.1: direct summation over pairs).
    """
    n = x.shape[0]
    zero_rows(acc, 0, n)
    # Row i's own sum can be kept in registers: nothing has been added to
    # acc[i] before row i (earlier rows only reach j < their own index), so
    # 0 + a_1 + a_2 ... in a register rounds exactly as in memory.
    for i in range(1, n):
        mi = m[i]
        axi = 0.0
        ayi = 0.0
        azi = 0.0
        # a test particle (i >= n_active) feels the active bodies and pulls none
        for j in range(min(i, n_active)):
            dx = x[i, 0] - x[j, 0]
            dy = x[i, 1] - x[j, 1]
            dz = x[i, 2] - x[j, 2]
            r = math.sqrt(dx * dx + dy * dy + dz * dz + eps2)
            p = G / (r * r * r)
            pj = -p * m[j]
            axi += pj * dx
            ayi += pj * dy
            azi += pj * dz
            if i < n_active:
                pi = p * mi
                acc[j, 0] += pi * dx
                acc[j, 1] += pi * dy
                acc[j, 2] += pi * dz
        acc[i, 0] = axi
        acc[i, 1] = ayi
        acc[i, 2] = azi
    return 0


@njit(inline="always")
def _apply_batch(gm, n_active, eps2, acc, work, first, stop, npairs):
    dxs = work[0]
    dys = work[1]
    dzs = work[2]
    inv = work[3]
    for k in range(npairs):  # the vectorised part
        r2 = dxs[k] * dxs[k] + dys[k] * dys[k] + dzs[k] * dzs[k] + eps2
        inv[k] = 1.0 / (r2 * math.sqrt(r2))
    k = 0
    for i in range(first, stop):
        axi = 0.0
        ayi = 0.0
        azi = 0.0
        if i < n_active:
            gmi = gm[i]
            for j in range(i):
                dx = dxs[k]
                dy = dys[k]
                dz = dzs[k]
                sj = gm[j] * inv[k]
                si = gmi * inv[k]
                axi -= sj * dx
                ayi -= sj * dy
                azi -= sj * dz
                acc[j, 0] += si * dx
                acc[j, 1] += si * dy
                acc[j, 2] += si * dz
                k += 1
        else:
            for j in range(n_active):
                sj = gm[j] * inv[k]
                axi -= sj * dxs[k]
                ayi -= sj * dys[k]
                azi -= sj * dzs[k]
                k += 1
        acc[i, 0] += axi
        acc[i, 1] += ayi
        acc[i, 2] += azi


#: Blocks of rows the threaded kernel splits the pairs into.  Each block owns a
#: private accumulator, so a fixed number (not the number of threads) keeps
#: the result the same whatever the thread count; 16 balances two to sixteen
#: threads.
N_BLOCKS = 16


# Not cached on disk: a cached serial loop that calls a cached parallel
# function can crash when loaded (numba issue #8578).  The loops that call this
# kernel are cached themselves and carry its compiled code, so nothing is lost.
# Re-association lets LLVM vectorise the row sums; the result differs from the
# serial kernel only by rounding (tested to 1e-13 relative).
@njit_parallel(cache=False, fastmath={"reassoc", "contract"})
def accelerate_pairwise_parallel(x, gm, n_active, eps2, acc, work):
    """Accelerations with threads; same arguments as :func:`accelerate_pairwise`.

    ``work`` has shape (3 * N_BLOCKS, N) (:func:`pair_workspace` with
    ``parallel=True``).

    Notes
    -----
    Each pair is computed once, as in the serial kernel (Newton's third law):
    the rows i are cut into :data:`N_BLOCKS` blocks of equal pair counts, and
    the threads take whole blocks.  A block adds its terms, for row i and for
    the reaction on every j < i, into its own slice of ``work``, so no two
    threads ever write the same element; the slices are then summed in block
    order, so the result does not depend on how blocks were given to threads.
    The inner loops run over separate x, y, z arrays and vectorise.  Filling
    only row i per thread (no reaction terms) would also be race-free but does
    every pair twice, which is slower (benchmarks/RESULTS.md).
    """
    n = x.shape[0]
    xs = np.empty(n)
    ys = np.empty(n)
    zs = np.empty(n)
    for j in range(n):
        xs[j] = x[j, 0]
        ys[j] = x[j, 1]
        zs[j] = x[j, 2]
    # block boundaries with equal numbers of pairs: row i has min(i, n_active)
    bounds = np.empty(N_BLOCKS + 1, dtype=np.int64)
    total = 0.0
    for i in range(n):
        total += min(i, n_active)
    bounds[0] = 0
    b = 1
    acc_pairs = 0.0
    for i in range(n):
        while b < N_BLOCKS and acc_pairs >= total * b / N_BLOCKS:
            bounds[b] = i
            b += 1
        acc_pairs += min(i, n_active)
    while b <= N_BLOCKS:
        bounds[b] = n
        b += 1
    for blk in numba.prange(N_BLOCKS):
        bx = work[3 * blk]
        by = work[3 * blk + 1]
        bz = work[3 * blk + 2]
        for j in range(n):
            bx[j] = 0.0
            by[j] = 0.0
            bz[j] = 0.0
        for i in range(bounds[blk], bounds[blk + 1]):
            xi = xs[i]
            yi = ys[i]
            zi = zs[i]
            gmi = gm[i]
            ax = 0.0
            ay = 0.0
            az = 0.0
            if i < n_active:
                for j in range(i):
                    dx = xs[j] - xi
                    dy = ys[j] - yi
                    dz = zs[j] - zi
                    r2 = dx * dx + dy * dy + dz * dz + eps2
                    inv_r3 = 1.0 / (r2 * math.sqrt(r2))
                    sj = gm[j] * inv_r3
                    ax += sj * dx
                    ay += sj * dy
                    az += sj * dz
                    si = gmi * inv_r3
                    bx[j] -= si * dx
                    by[j] -= si * dy
                    bz[j] -= si * dz
            else:
                for j in range(n_active):
                    dx = xs[j] - xi
                    dy = ys[j] - yi
                    dz = zs[j] - zi
                    r2 = dx * dx + dy * dy + dz * dz + eps2
                    sj = gm[j] / (r2 * math.sqrt(r2))
                    ax += sj * dx
                    ay += sj * dy
                    az += sj * dz
            bx[i] += ax
            by[i] += ay
            bz[i] += az
    for i in numba.prange(n):
        sx = 0.0
        sy = 0.0
        sz = 0.0
        for blk in range(N_BLOCKS):
            sx += work[3 * blk, i]
            sy += work[3 * blk + 1, i]
            sz += work[3 * blk + 2, i]
        acc[i, 0] = sx
        acc[i, 1] = sy
        acc[i, 2] = sz
    return 0


def accelerate_reference(x, gm, eps2=0.0):
    """Plain numpy version for tests: O(N^2) memory, no tricks."""
    d = x[:, None, :] - x[None, :, :]
    r2 = np.sum(d * d, axis=-1) + eps2
    np.fill_diagonal(r2, np.inf)
    return -np.sum(gm[None, :, None] * d / r2[..., None] ** 1.5, axis=1)
