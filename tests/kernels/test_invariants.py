"""Invariant kernels against plain numpy."""

import numpy as np

from orbits._kernels import invariants as inv


def numpy_energy(x, v, m, G, eps2=0.0):
    kin = 0.5 * np.sum(m * np.sum(v * v, axis=1))
    d = x[:, None, :] - x[None, :, :]
    r = np.sqrt(np.sum(d * d, axis=-1) + eps2)
    iu = np.triu_indices(len(m), 1)
    return kin - G * np.sum((m[:, None] * m[None, :])[iu] / r[iu])


def test_invariants_match_numpy(rng):
    n = 40
    x, v = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    m = rng.uniform(size=n)
    # n^2 terms of size ~1: agreement to ~n^2 eps relative is the numpy side's own error
    assert abs(inv.energy(x, v, m, 1.3, n, 0.0) / numpy_energy(x, v, m, 1.3) - 1) < 1e-13
    L = np.empty(3)
    inv.angular_momentum(x, v, m, L)
    np.testing.assert_allclose(L, np.sum(m[:, None] * np.cross(x, v), axis=0), rtol=1e-13)
    p = np.empty(3)
    inv.momentum(v, m, p)
    np.testing.assert_allclose(p, m @ v, rtol=1e-13)
    c = np.empty(3)
    inv.center_of_mass(x, m, c)
    np.testing.assert_allclose(c, m @ x / m.sum(), rtol=1e-13)


def test_compensated_energy_beats_naive_sum():
    # many equal small terms added to a large one: naive summation loses them
    # all, Neumaier's sum keeps them (the exact sum is 1 + 1e4 * 1e-17 ... kinetic
    # terms 0.5 * m v^2 with m = 2, v^2 = 1e-17 each)
    n = 10_001
    x = np.zeros((n, 3))
    x[:, 0] = np.arange(n) * 1e6  # far apart: potential negligible with G = 0
    v = np.zeros((n, 3))
    v[0, 0] = 1.0
    v[1:, 0] = np.sqrt(1e-17)
    m = np.full(n, 2.0)
    e = inv.energy(x, v, m, 0.0, n, 0.0)
    exact = 1.0 + (n - 1) * 1e-17
    assert abs(e - exact) < 2e-16
    naive = 0.0
    for i in range(n):
        naive += 0.5 * m[i] * v[i, 0] ** 2
    assert abs(naive - exact) > 5e-14


def _row_by_row(rows, m, G, n_active, eps2, which):
    # monitor_row on each row's own state, the row's column 0 added to the energy
    w, n = inv.MONITOR_WIDTH, len(m)
    for row in rows:
        x = row[w:w + 3 * n].reshape(n, 3).copy()
        v = row[w + 3 * n:w + 6 * n].reshape(n, 3).copy()
        e0 = row[0]
        inv.monitor_row(x, v, m, G, n_active, eps2, which, row)
        if which & inv.ENERGY:
            row[0] += e0


def test_fill_monitors_gives_monitor_rows_values_to_the_bit(rng):
    # outputs recorded in a loop get their energy and angular momentum after
    # it, a block of rows at a time: the same sums in the same order, so the
    # same bits, on rows fewer than a block, a block, one more, with test
    # particles (n_active < N), softening, and rows with NaN and inf; the
    # other monitors' bits (made in the loop) leave their columns alone
    w = inv.MONITOR_WIDTH
    B = inv.FILL_BLOCK
    cases = [(6, 6, 0.0, inv.ENERGY | inv.ANGULAR_MOMENTUM),
             (9, 9, 0.0, inv.ENERGY | inv.ANGULAR_MOMENTUM),
             (5, 3, 1e-4, inv.ENERGY | inv.ANGULAR_MOMENTUM | inv.MOMENTUM | inv.CENTER_OF_MASS),
             (1, 1, 0.0, inv.ENERGY | inv.MOMENTUM | inv.CENTER_OF_MASS),
             (4, 4, 0.0, inv.ANGULAR_MOMENTUM)]
    for n, n_active, eps2, which in cases:
        for k in (1, B - 1, B, B + 1, 3 * B + 5):
            rows = np.zeros((k, w + 6 * n))
            scale = rng.choice([1e-3, 1.0, 30.0], size=(k, 6 * n))
            rows[:, w:] = rng.normal(size=(k, 6 * n)) * scale
            rows[:, 0] = rng.normal(size=k) * 1e-7      # the terms' energy
            rows[:, inv.WORK_COLUMN] = rng.normal(size=k)
            if k > 3:
                rows[1, w] = np.nan
                rows[2, w + 3 * n] = np.inf
            m = rng.uniform(1e-6, 1e-3, size=n)
            m[0] = 1.0
            expected = rows.copy()
            _row_by_row(expected, m, 0.3, n_active, eps2, which & inv.FILLED)
            inv.fill_kernel()(rows, m, 0.3, n_active, eps2, which)
            np.testing.assert_array_equal(rows, expected, err_msg=f"{(n, k, which)}")


def test_fill_monitors_leaves_what_it_does_not_monitor(rng):
    # without the energy bit, column 0 (the terms' energy) stays as it was;
    # the momentum and centre of mass are the loop's
    w, n = inv.MONITOR_WIDTH, 3
    rows = rng.normal(size=(5, w + 6 * n))
    before = rows.copy()
    inv.fill_kernel()(rows, np.ones(n), 1.0, n, 0.0,
                      inv.ANGULAR_MOMENTUM | inv.MOMENTUM | inv.CENTER_OF_MASS)
    np.testing.assert_array_equal(rows[:, 0], before[:, 0])
    np.testing.assert_array_equal(rows[:, 4:], before[:, 4:])
    assert not np.array_equal(rows[:, 1:4], before[:, 1:4])
