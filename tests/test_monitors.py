"""Drift-law fits of orbits.monitors on synthetic errors whose law is known, and the
monitor fields' errors."""

import numpy as np
import pytest

import orbits
from orbits._kernels.invariants import MONITOR_WIDTH, WORK_COLUMN
from orbits.monitors import ensemble_growth_exponent, monitor_fields


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


@pytest.mark.parametrize("zero_reference", [False, True])
@pytest.mark.filterwarnings("ignore:overflow encountered:RuntimeWarning")
def test_monitor_fields_errors_are_numpys_expressions_bit_for_bit(zero_reference):
    # the errors of a run's rows (a slice of rows wide with the bodies'
    # columns, as the recorder keeps them) are computed in one compiled pass
    # over the rows; they must be the floats of the plain numpy expressions
    # of relative_error and vector_relative_error, over values spanning 600
    # decades, with a work column, and against the scales where the
    # reference is zero
    # (the extreme values overflow to inf in both computations: numpy's
    # warnings about it are silenced, the comparison takes infs and NaNs)
    rng = np.random.default_rng(11)
    wide = rng.standard_normal((2000, 44)) * 10.0 ** rng.uniform(-300, 300, (2000, 44))
    rows = wide[:, :MONITOR_WIDTH]
    ref = rows[0].copy()
    if zero_reference:
        ref[[0, WORK_COLUMN]] = 0.0
        ref[1:4] = 0.0
    scales = (2.5, 3.5)
    out = monitor_fields(rows, ("energy", "angular_momentum"), ref, scales,
                         orbits.UnitSystem())
    e_ref = ref[0] + ref[WORK_COLUMN]
    denom = abs(e_ref) if e_ref != 0 else scales[0]
    expected = np.abs((rows[:, 0] + rows[:, WORK_COLUMN]) - e_ref) / denom
    assert np.array_equal(out["energy_error"], expected, equal_nan=True)
    norm = np.linalg.norm(ref[1:4])
    ldenom = norm if norm > 1e-14 * scales[1] else scales[1]
    d = rows[:, 1:4] - ref[1:4]
    lexpected = np.sqrt(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] + d[:, 2] * d[:, 2]) / ldenom
    assert np.array_equal(out["angular_momentum_error"], lexpected, equal_nan=True)
    # rows written before the work column was kept: the same without it
    old = monitor_fields(rows[:, :10], ("energy",), ref[:10], scales, orbits.UnitSystem())
    d0 = abs(ref[0]) if ref[0] != 0 else scales[0]
    assert np.array_equal(old["energy_error"], np.abs(rows[:, 0] - ref[0]) / d0,
                          equal_nan=True)
