"""The encounter log (``Simulation(..., encounter_log=...)``): every close
approach inside the threshold, with its time, bodies, distance and speed,
without stopping the run; checked against a dense reference integration."""

import astropy.units as u
import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar

import orbits
from orbits.errors import IntegratorOptionError, SimulationOptionError

G = orbits.UnitSystem().G          # au^3 / (Msun day^2)
M_JUP = 9.547919e-4                # Msun


def _rhs(t, y, gm):
    x = y[:9].reshape(3, 3)
    a = np.zeros((3, 3))
    for i in range(3):
        for j in range(3):
            if i != j and gm[j] > 0:
                d = x[i] - x[j]
                a[i] -= gm[j] * d / np.linalg.norm(d) ** 3
    return np.r_[y[9:], a.ravel()]


def _system(offsets):
    """Sun, Jupiter on a circular 5.2 au orbit and a massless probe that passes
    Jupiter at about each of ``offsets`` (au) at t = 200 d (one pass per
    probe: the probes are separate systems, see _runs)."""
    gm = np.array([G, G * M_JUP, 0.0])
    n = np.sqrt(G * (1 + M_JUP) / 5.2 ** 3)
    out = []
    for off in offsets:
        # at t = 200 d: Jupiter at (5.2, 0, 0) (heliocentric, in the
        # barycentric frame below), the probe off it by `off` in z, crossing
        # at 3 km/s relative speed in the plane
        xj = np.array([5.2, 0, 0]) * (1 / (1 + M_JUP))
        vj = np.array([0, 5.2 * n, 0]) * (1 / (1 + M_JUP))
        xs, vs = -M_JUP * xj, -M_JUP * vj
        xp = xj + np.array([0.0, 0.0, off])
        vp = vj + np.array([2e-2, 0.0, 0.0])
        y = np.r_[xs, xj, xp, vs, vj, vp]
        back = solve_ivp(_rhs, (200.0, 0.0), y, args=(gm,), method="DOP853", rtol=1e-13,
                         atol=1e-16)
        out.append(back.y[:, -1])
    return gm, out


def _reference_minimum(gm, y0):
    # closest approach of the probe to Jupiter on a DOP853 run at rtol 1e-13,
    # its dense output minimised around the pass
    sol = solve_ivp(_rhs, (0.0, 400.0), y0, args=(gm,), method="DOP853", rtol=1e-13,
                    atol=1e-16, dense_output=True)

    def dist(t):
        y = sol.sol(t)
        return np.linalg.norm(y[6:9] - y[3:6])
    ts = np.linspace(0, 400, 4001)
    k = int(np.argmin([dist(t) for t in ts]))
    res = minimize_scalar(dist, bracket=(ts[k - 1], ts[k], ts[k + 1]), method="brent",
                          options={"xtol": 1e-14})
    return res.x, res.fun


def _bodies(y0):
    x = y0[:9].reshape(3, 3)
    v = y0[9:].reshape(3, 3)
    return orbits.BodySet.from_arrays(np.array([1.0, M_JUP, 0.0]) * u.Msun, x * u.au,
                                      v * u.au / u.day, names=["Sun", "Jupiter", "probe"])


@pytest.mark.parametrize("off", [0.02, 2e-3])
def test_the_log_finds_the_pass_with_its_minimum_distance(off):
    gm, (y0,) = _system([off])
    t_ref, d_ref = _reference_minimum(gm, y0)
    sim = orbits.Simulation(_bodies(y0), "ias15", encounter_log=0.1 * u.au, monitors=())
    res = sim.run(until=400 * u.day, outputs=2, progress=False)
    log = res.encounters
    assert len(log) == 1, log
    row = log[0]
    assert {row["body_1"], row["body_2"]} == {"Jupiter", "probe"}
    # the goal: the minimum distance to 1e-6 relative of a dense
    # reference; ias15's own trajectory differs from DOP853's by ~1e-12
    assert abs(row["distance"].to_value(u.au) / d_ref - 1) < 1e-6
    # the time to a small fraction of the pass's duration (d / v ~ 0.1-1 d)
    assert abs(row["time"].to_value(u.day) - t_ref) < 1e-4
    assert res.times[-1] == 400 * u.day         # the run did not stop


def test_a_pass_outside_the_threshold_is_not_logged_and_hill_radii_work():
    gm, (y0,) = _system([0.3])
    # Jupiter's Hill radius at 5.2 au: 0.355 au; 0.5 of it is 0.18 au < 0.3
    sim = orbits.Simulation(_bodies(y0), "ias15", encounter_log=0.5, monitors=())
    assert len(sim.run(until=400 * u.day, outputs=2, progress=False).encounters) == 0
    # 1.5 Hill radii (0.53 au) takes it
    sim = orbits.Simulation(_bodies(y0), "ias15", encounter_log=1.5, monitors=())
    log = sim.run(until=400 * u.day, outputs=2, progress=False).encounters
    assert len(log) == 1 and abs(log[0]["distance"].to_value(u.au) - 0.3) < 0.05


def _two_planets():
    # two planets on circular orbits at 1 and 1.2 au, starting in conjunction,
    # meet 0.2 au apart once a synodic period (4.18 yr), logged within 0.3 au
    b = orbits.BodySet()
    b.add("Sun", mass=1 * u.Msun)
    b.add("A", mass=1e-6 * u.Msun, primary="Sun", a=1.0 * u.au, e=0.0)
    b.add("B", mass=1e-6 * u.Msun, primary="Sun", a=1.2 * u.au, e=0.0)
    return orbits.Simulation(b, "leapfrog", dt=2 * u.day, encounter_log=0.3 * u.au,
                             monitors=())


def test_a_full_log_is_emptied_and_the_run_goes_on():
    # a log of 5 rows for 3 pairs is handed back to the driver after every
    # 3rd row, emptied, and the run goes on: every pass is there, once
    sim = _two_planets()
    sim._log = np.zeros((5, 5))
    sim._stop = sim._stop[:14] + (sim._log, sim._log_n)
    res = sim.run(until=200 * u.yr, outputs=2, progress=False)
    n_a = np.sqrt(G * (1 + 1e-6) / 1.0 ** 3)
    n_b = np.sqrt(G * (1 + 1e-6) / 1.2 ** 3)
    synodic = 2 * np.pi / (n_a - n_b) / 365.25          # 4.18 yr
    t = res.encounters["time"].to_value(u.yr)
    assert len(t) == int(200 / synodic)                  # 47
    # one a conjunction, a synodic period apart (the two-body periods give
    # 4.1794 yr; leapfrog at 2 d, the barycentre's wobble and the planets'
    # pull give 4.1821 yr, measured: 6.5e-4 longer)
    assert np.allclose(np.diff(t), synodic, rtol=2e-3)
    assert np.allclose(res.encounters["distance"].to_value(u.au), 0.2, atol=2e-3)


def test_bad_encounter_log_input_is_refused_by_name():
    with pytest.raises(SimulationOptionError):
        orbits.Simulation(orbits.scenes.kepler(), "ias15", encounter_log=-1)
    with pytest.raises(IntegratorOptionError):
        orbits.Simulation(orbits.scenes.kepler(), "wh", dt=1 * u.day, encounter_log=3)


def test_the_log_goes_into_the_output_file(tmp_path):
    gm, (y0,) = _system([0.02])
    path = tmp_path / "flyby.h5"
    sim = orbits.Simulation(_bodies(y0), "ias15", encounter_log=0.1 * u.au, monitors=())
    res = sim.run(until=400 * u.day, outputs=5, progress=False, output=path)
    back = orbits.load(path).encounters
    assert len(back) == 1 == len(res.encounters)
    for name in ("time", "distance", "speed"):
        assert back[name][0] == res.encounters[name][0]
    assert (back["body_1"][0], back["body_2"][0]) == ("Jupiter", "probe")
    # a file without encounter_log has no log
    plain = orbits.Simulation(_bodies(y0), "ias15", monitors=())
    plain.run(until=10 * u.day, outputs=2, progress=False, output=tmp_path / "plain.h5")
    assert orbits.load(tmp_path / "plain.h5").encounters is None


def test_a_simulation_reserves_no_room_for_every_pair():
    # 3000 bodies have 4.5e6 pairs: a table of a row each (5 floats) would be
    # 180 MB.  What a simulation allocates is O(N) (the state, a pair kernel's
    # scratch), with a stopping condition too, and with the log a table of a
    # fixed number of rows
    import tracemalloc
    n = 3000
    rng = np.random.default_rng(3)
    b = orbits.BodySet.from_arrays(np.full(n, 1e-9) * u.Msun, rng.normal(size=(n, 3)) * u.au,
                                   np.zeros((n, 3)) * u.au / u.day)
    for kw in ({}, {"escape_distance": 100 * u.au}, {"encounter_log": 0.01 * u.au}):
        tracemalloc.start()
        sim = orbits.Simulation(b, "leapfrog", dt=1 * u.day, monitors=(), parallel=False, **kw)
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        assert peak < 20e6, (kw, peak)
        assert sim._log.shape[0] <= orbits.simulation.LOG_ROWS


def _crossing_pairs(k):
    # k pairs of massless bodies 100 apart in z, each pair's bodies flying at
    # each other along x at 1 (G = 1) and passing 0.1 apart at t = 1.5, half
    # way through the step from 1 to 2 (dt = 1): k approaches in one step
    b = orbits.BodySet(units=orbits.UnitSystem.nbody())
    b.add("star", mass=1.0, position=[0, 0, -1e4], velocity=[0, 0, 0])
    for i in range(k):
        b.add(f"a{i}", mass=0.0, position=[-1.5, 0, 100 * i], velocity=[1, 0, 0])
        b.add(f"b{i}", mass=0.0, position=[1.5, 0.1, 100 * i], velocity=[-1, 0, 0])
    return b


def test_more_approaches_in_one_step_than_the_log_holds_are_all_logged(monkeypatch):
    # a log of 4 rows and 10 approaches in one step: the step's look is cut
    # short when the log is full, the driver empties and enlarges it, and the
    # look goes on where it stopped; every approach is logged, once
    monkeypatch.setattr(orbits.simulation, "LOG_ROWS", 4)
    sim = orbits.Simulation(_crossing_pairs(10), "leapfrog", dt=1.0,
                            encounter_log=0.3 * u.dimensionless_unscaled, monitors=())
    assert sim._log.shape[0] == 4
    res = sim.run(until=4.0, outputs=2, progress=False)
    log = res.encounters
    assert len(log) == 10
    assert sorted(zip(log["body_1"], log["body_2"])) == sorted(
        (f"a{i}", f"b{i}") for i in range(10))
    # straight lines (the star's pull from 1e4 away moves them by 1e-8):
    # the Hermite interpolant is exact for them
    assert np.allclose(log["time"].value, 1.5, atol=1e-6)
    assert np.allclose(log["distance"].value, 0.1, atol=1e-6)
    assert sim._log.shape[0] >= 10 // 2


def test_a_result_keeps_its_log_when_the_simulation_runs_on():
    # the log's table is made where result.encounters is first read: it holds
    # the passes of its run, as they were at the run's end, whatever later
    # runs log
    sim = _two_planets()
    first = sim.run(until=20 * u.yr, outputs=2, progress=False)
    second = sim.run(until=40 * u.yr, outputs=2, progress=False)
    # a conjunction every 4.18 yr (the test above): 4 by 20 yr, 5 more by 40 yr
    assert len(second.encounters) == 5
    assert len(first.encounters) == 4
    assert first.encounters["time"].max() < 20 * u.yr < second.encounters["time"].min()
