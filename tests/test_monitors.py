"""Drift-law fits of orbits.monitors on synthetic errors whose law is known."""

import numpy as np

from orbits.monitors import ensemble_growth_exponent


def _walks(members, steps, rng):
    return np.cumsum(rng.standard_normal((members, steps)), axis=1)


def test_random_walks_give_one_half_within_the_stated_spread():
    rng = np.random.default_rng(3)
    steps = 100_000
    t = np.unique(np.geomspace(1, steps, 120).astype(int))
    fits = []
    for _ in range(20):
        e = _walks(16, steps, rng)[:, t - 1]
        fits.append(ensemble_growth_exponent(t, e, t_from=t[-1] / 250, boots=100))
    p = np.array([f[0] for f in fits])
    spread = np.array([f[1] for f in fits])
    # the docstring's estimate 1 / (sqrt(16) ln 250) = 0.045; the bootstrap and the
    # scatter of 20 independent ensembles agree with it to within a factor 2
    assert abs(p.mean() - 0.5) < 3 * 0.045 / np.sqrt(20)
    assert 0.5 * 0.045 < p.std() < 2 * 0.045
    assert 0.5 * 0.045 < np.median(spread) < 2 * 0.045


def test_a_common_drift_gives_one():
    rng = np.random.default_rng(4)
    steps = 100_000
    t = np.unique(np.geomspace(1, steps, 120).astype(int))
    walks = _walks(16, steps, rng)[:, t - 1]
    drift = 0.05 * t                       # as large as the walks after 400 steps
    p, spread = ensemble_growth_exponent(t, walks + drift, t_from=t[-1] / 250)
    assert abs(p - 1.0) < 0.1 and spread < 0.05
    p, spread = ensemble_growth_exponent(t, walks, t_from=t[-1] / 250)
    assert abs(p - 0.5) < 3 * spread
