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
                                    accelerate_pairwise_parallel])
@pytest.mark.parametrize("eps2", [0.0, 0.01])
def test_against_numpy_reference(rng, n, n_massless, kernel, eps2):
    x, gm, n_active = random_system(rng, n, n_massless)
    acc = np.full((n, 3), np.nan)
    assert kernel(x, gm, n_active, eps2, acc) == 0
    ref = accelerate_reference(x, gm, eps2)
    # sums of n terms of size ~|a|: relative rounding ~ n eps; 1e-13 holds to n ~ 500
    np.testing.assert_allclose(acc, ref, rtol=0, atol=1e-13 * np.abs(ref).max())


def test_small_and_batched_serial_kernels_agree_bit_for_bit(rng):
    # the same j < i pair terms in the same order: identical results
    for n, massless in ((2, 0), (8, 2), (30, 5)):
        x, gm, n_active = random_system(rng, n, massless)
        a1 = np.empty_like(x)
        a2 = np.empty_like(x)
        accelerate_pairwise_small(x, gm, n_active, 0.0, a1)
        accelerate_pairwise(x, gm, n_active, 0.0, a2)
        np.testing.assert_array_equal(a1, a2)


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
