"""Gravity kernels against a short numpy reference, and serial against parallel."""

import numpy as np
import pytest

from orbits._kernels import gravity
from orbits._kernels.gravity import accelerate_reference, pair_workspace


def accelerate_pairwise(x, gm, n_active, eps2, acc):
    return gravity.accelerate_pairwise(x, gm, n_active, eps2, acc,
                                       pair_workspace(len(x), n_active))


def accelerate_pairwise_small(x, gm, n_active, eps2, acc):
    return gravity.accelerate_pairwise_small(x, gm, n_active, eps2, acc,
                                             pair_workspace(len(x), n_active))


def accelerate_pairwise_lanes(x, gm, n_active, eps2, acc):
    return gravity.accelerate_pairwise_lanes(x, gm, n_active, eps2, acc,
                                             pair_workspace(len(x), n_active))


def accelerate_pairwise_parallel(x, gm, n_active, eps2, acc):
    return gravity.accelerate_pairwise_parallel(x, gm, n_active, eps2, acc,
                                                pair_workspace(len(x), n_active, True))


def random_system(rng, n, n_massless=0):
    x = rng.normal(size=(n, 3))
    gm = rng.uniform(0.1, 1.0, size=n)
    gm[n - n_massless:] = 0.0
    return np.ascontiguousarray(x), gm, n - n_massless


@pytest.mark.parametrize("n, n_massless", [(2, 0), (5, 0), (9, 3), (200, 50)])
@pytest.mark.parametrize("kernel", [accelerate_pairwise_small, accelerate_pairwise,
                                    accelerate_pairwise_lanes, accelerate_pairwise_parallel])
@pytest.mark.parametrize("eps2", [0.0, 0.01])
def test_against_numpy_reference(rng, n, n_massless, kernel, eps2):
    x, gm, n_active = random_system(rng, n, n_massless)
    acc = np.full((n, 3), np.nan)
    assert kernel(x, gm, n_active, eps2, acc) == 0
    ref = accelerate_reference(x, gm, eps2)
    # sums of n terms of size ~|a|: relative rounding ~ n eps; 1e-13 holds to n ~ 500
    np.testing.assert_allclose(acc, ref, rtol=0, atol=1e-13 * np.abs(ref).max())


def test_small_batched_and_lanes_serial_kernels_agree_bit_for_bit(rng):
    # the same j < i pair terms summed in the same order: identical results
    for n, massless in ((2, 0), (8, 2), (30, 5)):
        x, gm, n_active = random_system(rng, n, massless)
        a1 = np.empty_like(x)
        a2 = np.empty_like(x)
        a3 = np.empty_like(x)
        accelerate_pairwise_small(x, gm, n_active, 0.0, a1)
        accelerate_pairwise(x, gm, n_active, 0.0, a2)
        accelerate_pairwise_lanes(x, gm, n_active, 0.0, a3)
        np.testing.assert_array_equal(a1, a2)
        np.testing.assert_array_equal(a1, a3)


def test_serial_and_parallel_agree_for_large_n(rng):
    x, gm, n_active = random_system(rng, 1500, 300)
    a1 = np.empty_like(x)
    a2 = np.empty_like(x)
    accelerate_pairwise(x, gm, n_active, 0.0, a1)
    accelerate_pairwise_parallel(x, gm, n_active, 0.0, a2)
    # same sums in a different order: agreement to ~sqrt(n) eps relative to the
    # largest term; 1e-12 of the largest acceleration is ample
    np.testing.assert_allclose(a1, a2, rtol=0, atol=1e-12 * np.abs(a1).max())


def test_massless_bodies_exert_nothing(rng):
    x, gm, n_active = random_system(rng, 6, 3)
    acc = np.empty_like(x)
    accelerate_pairwise(x, gm, n_active, 0.0, acc)
    acc_massive_only = np.empty((3, 3))
    accelerate_pairwise(x[:3].copy(), gm[:3].copy(), 3, 0.0, acc_massive_only)
    np.testing.assert_array_equal(acc[:3], acc_massive_only)
    assert np.all(np.abs(acc[3:]) > 0)


def test_newtons_third_law_momentum(rng):
    # sum m_i a_i = 0 for the serial kernel up to rounding of the pair terms
    x, gm, n_active = random_system(rng, 50)
    acc = np.empty_like(x)
    accelerate_pairwise(x, gm, n_active, 0.0, acc)
    total = (gm[:, None] * acc).sum(axis=0)
    assert np.all(np.abs(total) < 1e-13 * np.abs(gm[:, None] * acc).sum(axis=0))


def test_two_body_value():
    x = np.array([[0.0, 0, 0], [2.0, 0, 0]])
    gm = np.array([4.0, 1.0])
    acc = np.empty((2, 3))
    accelerate_pairwise(x, gm, 2, 0.0, acc)
    # |a_0| = G m_1 / r^2 = 1/4 towards body 1, |a_1| = 4/4 towards body 0: exact in binary
    np.testing.assert_array_equal(acc, [[0.25, 0, 0], [-1.0, 0, 0]])


@pytest.mark.parametrize("batch", [7, 50, 10_000])
def test_batching_does_not_change_the_result(rng, batch):
    # the serial kernel gathers pairs in batches; any batch size (at least one
    # row of n_active pairs) must give bit-identical accelerations
    x, gm, n_active = random_system(rng, 40, 10)
    ref = np.empty_like(x)
    accelerate_pairwise(x, gm, n_active, 0.0, ref)
    acc = np.empty_like(x)
    work = np.zeros((4, max(batch, n_active)))
    gravity.accelerate_pairwise(x, gm, n_active, 0.0, acc, work)
    np.testing.assert_array_equal(acc, ref)


def test_parallel_result_does_not_depend_on_thread_count(rng):
    # blocks, not threads, own the accumulators: bit-identical for 1 and 2 threads
    import numba
    x, gm, n_active = random_system(rng, 300, 40)
    out = []
    before = numba.get_num_threads()
    try:
        for threads in (1, min(2, numba.config.NUMBA_NUM_THREADS)):
            numba.set_num_threads(threads)
            acc = np.empty_like(x)
            accelerate_pairwise_parallel(x, gm, n_active, 0.0, acc)
            out.append(acc)
    finally:
        numba.set_num_threads(before)
    np.testing.assert_array_equal(out[0], out[1])


def scattered(n, seed, planar=False):
    """Positions of ``n`` bodies 0.3 to 30 apart in every direction (in a
    plane with signed zeros in z if ``planar``) and their G m over six
    decades."""
    rng = np.random.default_rng(seed)
    x = rng.standard_normal((n, 3)) * 10 ** rng.uniform(-0.5, 1.5, (n, 1))
    if planar:
        x[:, 2] = np.where(rng.random(n) < 0.5, 0.0, -0.0)
    return x, 10 ** rng.uniform(-9, -3, n)


@pytest.mark.parametrize("n", [2, 3, 4, 5, 7, 8, 9, 12, 17])
@pytest.mark.parametrize("first, skip", [(0, True), (1, False), (0, False)])
@pytest.mark.parametrize("test_particles", [0, 2])
@pytest.mark.parametrize("planar", [False, True])
@pytest.mark.parametrize("eps2", [0.0, 1e-4])
def test_pairs_in_lanes_are_the_scalar_sums_bit_for_bit(n, first, skip, test_particles, planar,
                                                        eps2):
    # each source's pull on every lane, summed over the sources in ascending
    # order, must be pair_accelerations's sums exactly: the same pulls (the
    # scalar -(G m / r^3) (x_i - x_j) is exactly (G m / r^3) (x_j - x_i)) in
    # the same order; the lanes' own source and a pair left out (the
    # Wisdom-Holman kick in Jacobi coordinates: (0, 1)) add an exact zero;
    # padding columns (n - 1 not a multiple of the lane width) and test
    # particles (sources of nothing) change nothing.  The three forms: the
    # Jacobi kick, the democratic heliocentric one, and gravity
    x, gm = scattered(n, seed=n + 100 * first + 10 * test_particles, planar=planar)
    n_active = max(1, n - test_particles)
    gm[n_active:] = 0.0
    want = np.full_like(x, np.nan)
    got = np.full_like(x, np.nan)
    gravity.pair_accelerations(x, gm, n_active, eps2, want, first, skip)
    gravity.pair_accelerations_lanes(x, gm, n_active, eps2, got, first, skip,
                                     np.full((gravity.LANE_ROWS, gravity.lane_columns(n)),
                                             np.nan))
    assert np.array_equal(got, want)
    assert np.all(np.isfinite(got))
    assert np.array_equal(np.signbit(got), np.signbit(want))


@pytest.mark.parametrize("own, real", [(3, 8), (0, 5), (8, 8), (2, 3)])
@pytest.mark.parametrize("eps2", [0.0, 1e-4])
def test_a_pass_with_kept_factors_is_the_plain_pass_bit_for_bit(own, real, eps2):
    # pull_factors then pull_rows_factored (the central body's pass, whose
    # factors 1 / r^3 its own sums read back) must add exactly what
    # pull_rows adds, the skipped columns (own, padding from real on) an
    # exact zero; the factors must be the scalar pair loop's 1 / (r2 sqrt(r2))
    x, gm = scattered(9, seed=own + 10 * real, planar=own == 0)
    P = np.uint64(8)
    X, Y, Z = (np.ascontiguousarray(x[1:, d]) for d in range(3))
    start = np.random.default_rng(own).standard_normal((3, 8))
    want = start.copy()
    got = start.copy()
    F = np.full(8, np.nan)
    xs, ys, zs = x[0]
    gravity.pull_rows(X, Y, Z, want[0], want[1], want[2], P, xs, ys, zs, gm[0],
                      np.uint64(own), eps2, np.uint64(real))
    gravity.pull_factors(X, Y, Z, F, P, xs, ys, zs, np.uint64(own), eps2, np.uint64(real))
    gravity.pull_rows_factored(X, Y, Z, got[0], got[1], got[2], P, xs, ys, zs, gm[0],
                               np.uint64(own), F, np.uint64(real))
    assert np.array_equal(got, want)
    for k in range(8):
        if k == own or k >= real:
            assert F[k] == 1.0
        else:
            d = x[k + 1] - x[0]
            r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + eps2
            assert F[k] == 1.0 / (r2 * np.sqrt(r2))


def test_the_lane_width_is_the_vector_width_llvm_fills_for_the_processor(monkeypatch):
    # the lanes' padding (gravity.LANE_WIDTH) is the doubles of the vector
    # registers LLVM fills for the processor numba compiles for: 512-bit
    # registers on AMD's Zen 4, 256-bit ones on Intel's AVX-512 processors
    # (where LLVM prefers them) and on AVX2-only ones (LLVM's processor tables)
    from numba.core import config

    from orbits._kernels import gravity as G
    assert G.LANE_WIDTH == G.vector_doubles() and G.LANE_WIDTH in (4, 8)
    avx512 = "+avx,+avx2,+fma,+avx512f,+avx512dq,+avx512vl,+avx512bw,+avx512cd"
    for cpu, features, width in [("znver4", avx512, 8), ("sapphirerapids", avx512, 4),
                                 ("haswell", "+avx,+avx2,+fma", 4)]:
        monkeypatch.setattr(config, "CPU_NAME", cpu)
        monkeypatch.setattr(config, "CPU_FEATURES", features)
        assert G.vector_doubles() == width, cpu
