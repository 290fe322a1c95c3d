"""Drift-law fits of orbits.monitors on synthetic errors whose law is known, and the
monitor fields' errors."""

import astropy.units as u
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


# -- test particles' energies ------------------------------------------------------------

def _star_and_comet(e=0.999999):
    """A star (G = 1, mass 1) and a massless comet of a = 1 starting at perihelion."""
    b = orbits.BodySet(orbits.UnitSystem.nbody())
    b.add("Star", mass=1.0)
    b.add("comet", mass=0.0, primary="Star", a=1.0, e=e)
    return b


def _kepler_energy(result, body, about):
    x = (result.positions[:, body] - result.positions[:, about]).value
    v = (result.velocities[:, body] - result.velocities[:, about]).value
    mu = result.masses[about].value          # G = 1
    return 0.5 * np.sum(v * v, axis=1) - mu / np.linalg.norm(x, axis=1)


@pytest.mark.parametrize("integrator, dt, low, high", [
    # three orbits from perihelion at e = 0.999999 (perihelion at 1e-6, speed
    # 1.4e3).  The leapfrog at P/1000 unbinds the comet at the first perihelion
    # (measured 2.0e6: the energy goes from -0.5 to +1e6); dop853 at its default
    # tolerances keeps it bound but loses 1.2e-3 of its energy (measured); ias15
    # keeps it to round-off, which at perihelion is that of the energy's two
    # terms, each 2e6 times the energy: 2e6 * 2.2e-16 * a few ~ 1e-9 (measured
    # 2.1e-10 from the first output on, the rounding of the reference at the
    # start, and 3.0e-10 at most)
    ("leapfrog", 2 * np.pi / 1000, 1.0, None),
    ("dop853", None, 1e-4, 1e-1),
    ("ias15", None, None, 1e-8),
])
def test_test_particle_energy_error_sees_a_massless_orbit(integrator, dt, low, high):
    sim = orbits.Simulation(_star_and_comet(), integrator, dt=dt)
    res = sim.run(until=3 * 2 * np.pi, outputs=31, progress=False)
    # the energy monitor sums m E: blind to the comet
    assert res.energy_error.max() == 0.0
    err = res.test_particle_energy_error
    assert err.shape == (31,) and err[0] == 0.0
    # the Kepler energy about the star, written out
    eps = _kepler_energy(res, 1, 0)
    np.testing.assert_allclose(err, np.abs(eps - eps[0]) / abs(eps[0]), rtol=1e-12, atol=0)
    if low is not None:
        assert err.max() > low
    if high is not None:
        assert err.max() < high
    line = [s for s in res.summary().splitlines() if s.startswith("test particles")]
    assert line == [f"test particles  largest relative energy error {err.max():.3e} "
                    "(comet; Kepler energy about Star)"]


def test_test_particle_energy_error_is_none_without_test_particles_or_energy_monitor():
    sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
    res = sim.run(until=10 * u.day, outputs=3, progress=False)
    assert res.test_particle_energy_error is None
    assert not any(s.startswith("test particles") for s in res.summary().splitlines())
    quiet = orbits.Simulation(_star_and_comet(e=0.5), "ias15", monitors=())
    res = quiet.run(until=1.0, outputs=3, progress=False)
    assert res.test_particle_energy_error is None


def test_test_particle_energy_error_keeps_the_jacobi_integral_of_a_circular_binary():
    # the circular restricted three-body problem (mass ratio 0.01, the binary
    # circular to rounding): a massless body at 1.8 times the binary's
    # separation keeps its Jacobi integral, which ias15 conserves to round-off
    # (measured 9.5e-16 over five binary orbits); the planet's pull changes its
    # Kepler energy about the star by 5.5e-2 of itself (measured), so a Kepler
    # measure would not show the integration
    b = orbits.BodySet(orbits.UnitSystem.nbody())
    b.add("Star", mass=1.0)
    b.add("Planet", mass=0.01, primary="Star", a=1.0, e=0.0)
    b.add("dust", mass=0.0, primary="Star", a=1.8, e=0.1, f=2.0)
    b.move_to_com()
    res = orbits.Simulation(b, "ias15").run(until=5 * 2 * np.pi, outputs=50, progress=False)
    assert res.test_particle_energy_error.max() < 1e-13
    assert "(dust; Jacobi integral)" in res.summary()
    eps = _kepler_energy(res, 2, 0)
    assert np.abs(eps / eps[0] - 1).max() > 1e-3


def test_load_gives_the_test_particle_energy_error_of_the_outputs(tmp_path):
    # a run written to a file returns its last output only (no series); the
    # file holds every output, and load() gives the same series as the run in
    # memory
    path = tmp_path / "comet.h5"
    b = orbits.scenes.kepler(e=0.3)
    b.add("comet", mass=0 * u.Msun, primary="Star", a=2 * u.au, e=0.9)
    args = dict(until=3 * u.yr, outputs=11, progress=False)
    mem = orbits.Simulation(b, "ias15").run(**args)
    written = orbits.Simulation(b, "ias15").run(output=path, **args)
    assert written.test_particle_energy_error is None
    loaded = orbits.load(path).test_particle_energy_error
    np.testing.assert_array_equal(loaded, mem.test_particle_energy_error)
