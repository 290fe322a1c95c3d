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
