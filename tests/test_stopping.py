"""Stopping conditions: close encounters and escapes, inside the compiled loop."""

import re

import astropy.units as u
import numpy as np
import pytest

import orbits
from orbits.errors import CloseEncounter, Escape


def head_on(**kw):
    # two light bodies flying at each other at 1 length/time each, G = 1
    b = orbits.BodySet(units=orbits.UnitSystem.nbody())
    b.add("a", mass=1e-9, position=[5, 0, 0], velocity=[-1, 0, 0])
    b.add("b", mass=1e-9, position=[-5, 0.1, 0], velocity=[1, 0, 0])
    return orbits.Simulation(b, integrator="leapfrog", dt=0.01, **kw)


def separation(sim, i=0, j=1):
    x = sim.bodies.positions.value
    return np.linalg.norm(x[i] - x[j])


def test_encounter_distance_stops_at_the_first_step_inside():
    sim = head_on(encounter_distance=1.0)
    with pytest.raises(CloseEncounter) as exc:
        sim.run(until=10.0, outputs=11, progress=False)
    err = exc.value
    assert set(err.bodies) == {"a", "b"} and "'a'" in str(err) and "'b'" in str(err)
    # they close at 2 per unit time from 10 apart: inside 1 after t = 4.5
    assert 4.49 < err.time.value < 4.52 and separation(sim) < 1.0
    assert err.result.status == "close encounter"
    assert err.result.times[-1] == err.time
    # one step fewer is still outside: the check runs every step
    again = head_on()
    again.run(until=(err.step - 1) * 0.01, outputs=2, progress=False)
    assert separation(again) >= 1.0


def test_hill_criterion():
    b = orbits.BodySet()
    b.add("Sun", mass=1 * u.Msun)
    b.add("Jupiter", mass=1 * u.Mjup, primary="Sun", a=5.2 * u.au)
    b.add("Saturnino", mass=1e-4 * u.Msun, primary="Sun", a=5.9 * u.au, f=0.4 * u.rad)
    sim = orbits.Simulation(b, integrator="verlet", dt=10 * u.day, encounter_hill=3.0)
    with pytest.raises(CloseEncounter) as exc:
        sim.run(until=2000 * u.yr, outputs=2, progress=False)
    assert set(exc.value.bodies) == {"Jupiter", "Saturnino"}

    def hill_ratio(s):
        x = s.bodies.positions.to_value(u.au)
        m = s.bodies.masses.to_value(u.Msun)
        r1, r2 = np.linalg.norm(x[1] - x[0]), np.linalg.norm(x[2] - x[0])
        rh = ((m[1] + m[2]) / (3 * m[0])) ** (1 / 3) * (r1 + r2) / 2
        return np.linalg.norm(x[1] - x[2]) / rh
    assert hill_ratio(sim) < 3.0
    before = orbits.Simulation(b, integrator="verlet", dt=10 * u.day)
    before.run(until=(exc.value.step - 1) * 10 * u.day, outputs=2, progress=False)
    assert hill_ratio(before) >= 3.0


def comet(e):
    b = orbits.BodySet()
    b.add("Sun", mass=1 * u.Msun)
    a = (-3 if e > 1 else 30) * u.au
    b.add("comet", mass=0 * u.kg, primary="Sun", a=a, e=e, f=0 * u.rad)
    return b


def test_escape_distance_and_unbound():
    sim = orbits.Simulation(comet(1.5), integrator="leapfrog", dt=1 * u.day,
                            escape_distance=50 * u.au, escape_unbound=True)
    with pytest.raises(Escape) as exc:
        sim.run(until=100 * u.yr, outputs=2, progress=False)
    assert exc.value.bodies == ("comet",)
    assert np.linalg.norm(sim.bodies.positions[1].to_value(u.au)) > 50
    # a bound comet with apocentre 30 (1 + 0.9) = 57 au passes 50 au: an escape
    # by distance alone, but not when the body must also be unbound
    bound = comet(0.9)
    with pytest.raises(Escape):
        orbits.Simulation(bound, integrator="leapfrog", dt=5 * u.day,
                          escape_distance=50 * u.au).run(until=200 * u.yr, outputs=2,
                                                         progress=False)
    r = orbits.Simulation(bound, integrator="leapfrog", dt=5 * u.day, escape_distance=50 * u.au,
                          escape_unbound=True).run(until=200 * u.yr, outputs=2,
                                                   progress=False)
    assert r.status == "completed"


def test_escapes_alone_take_the_escapes_check():
    # a record of escape conditions alone is checked by check_escapes, whose
    # C callable compiles in about 1.6 s where check_stop's takes 19-25 s on a
    # 2-core AMD EPYC (benchmarks/RESULTS.md); the stops it finds are those
    # of the tests above (the same code, inlined in both checks)
    import numba
    from orbits._kernels import stopping as ks
    sim = orbits.Simulation(comet(1.5), integrator="leapfrog", dt=1 * u.day,
                            escape_distance=50 * u.au, escape_unbound=True)
    sargs, check = ks.stop_record(sim._stop)
    assert ks.check_kind(int(sargs[0])) == "escapes"
    assert check.cfunc._pyfunc.__code__ is ks.check_escapes.py_func.__code__
    assert ks.check_kind(ks.ESCAPE | ks.ENCOUNTER_HILL) == "all"
    assert ks.check_kind(0) == "none" and ks.check_kind(True) == "all"
    # no conditions: a pointer of the check's type that compiles nothing (the
    # loops call the check only where the mask is not 0)
    none = ks.stop_record(None)[1]
    assert none.cfunc is None and none._numba_type_ == numba.typeof(check)


@pytest.mark.parametrize("integrator", ["dop853", "rk4-doubling", "ias15"])
def test_adaptive_methods_name_the_body(integrator):
    # the last of three bodies leaves: the error names the body the
    # condition found (not row 0), in each adaptive loop (dopri5 runs
    # dop853's)
    b = orbits.BodySet(units=orbits.UnitSystem.nbody())
    b.add("star", mass=1.0, position=[0, 0, 0], velocity=[0, 0, 0])
    b.add("planet", mass=1e-6, position=[1, 0, 0], velocity=[0, 1, 0])
    b.add("comet", mass=0.0, position=[0, 3, 0], velocity=[0, 2, 0])
    sim = orbits.Simulation(b, integrator=integrator, escape_distance=20.0)
    with pytest.raises(Escape) as exc:
        sim.run(until=100.0, outputs=2, progress=False)
    assert exc.value.bodies == ("comet",)


def test_rk_methods_check_too():
    with pytest.raises(CloseEncounter):
        head_on(encounter_distance=1.0).run(until=10.0, progress=False, outputs=2)
    sim = orbits.Simulation(head_on().bodies, integrator="rk4", dt=0.01,
                            encounter_distance=1.0)
    with pytest.raises(CloseEncounter):
        sim.run(until=10.0, outputs=2, progress=False)


def test_conditions_survive_a_restart(tmp_path):
    path = tmp_path / "stop.h5"
    head_on(encounter_distance=1.0).run(until=2.0, outputs=3, output=path, progress=False)
    sim = orbits.Simulation.from_file(path)
    with pytest.raises(CloseEncounter):
        sim.run(until=10.0, outputs=2, output=path, progress=False)
    assert orbits.load(path).status == "close encounter"
    assert "close encounter" in orbits.io.describe(path)


@pytest.mark.parametrize("kwargs, match", [
    (dict(encounter_distance=-1.0), "encounter_distance"),
    (dict(encounter_hill=0), "encounter_hill"),
    (dict(escape_distance=0.0), "escape_distance"),
    (dict(escape_unbound=True), "escape_unbound needs escape_distance"),
])
def test_bad_conditions(kwargs, match):
    with pytest.raises(ValueError, match=match):
        head_on(**kwargs)


def test_wrong_unit_for_a_distance():
    with pytest.raises(orbits.BodyUnitsError, match="escape_distance"):
        orbits.Simulation(comet(1.5), dt=1 * u.day, escape_distance=3 * u.day)


def test_the_collision_filter_never_passes_over_a_contact():
    # a pair on its exact two-body orbit (the filter's own model, with its
    # factor two for the other bodies' tides unused): whenever the true
    # closest approach inside the step (2000 samples of the exact orbit) is
    # below r, the filter must examine the pair.  Relative states from
    # grazing flybys to a planet about its star, steps from a small to a
    # large part of the orbit.
    from orbits._kernels.kepler import kepler_drift
    from orbits._kernels.stopping import _may_reach, _within_reach
    rng = np.random.default_rng(7)
    examined = 0
    for _ in range(300):
        mu = 10 ** rng.uniform(-9, 0)
        d = 10 ** rng.uniform(-4, 0.5)
        x0 = rng.normal(size=3)
        x0 *= d / np.linalg.norm(x0)
        v_circ = np.sqrt(mu / d)
        v0 = rng.normal(size=3) * v_circ * 10 ** rng.uniform(-1, 1)
        h = d / np.linalg.norm(v0) * 10 ** rng.uniform(-2, 0.3)
        xs = np.repeat(x0[None], 2000, axis=0)
        vs = np.repeat(v0[None], 2000, axis=0)
        for k, tk in enumerate(np.linspace(0.0, h, 2000)):
            kepler_drift(mu, xs, vs, k, tk)
        dist = np.linalg.norm(xs, axis=1)
        r = dist.min() * rng.uniform(1.0001, 1.5)
        work = np.array([x0, v0, xs[-1], vs[-1]])
        assert _within_reach(work, mu, h, r)
        # the first bound, from the end of the step alone
        assert _may_reach(xs[-1] @ xs[-1], vs[-1] @ vs[-1], mu, h, r * r)
        examined += 1
    assert examined == 300


def test_a_planet_about_its_star_is_passed_over():
    # Jupiter at 5.2 au about the Sun (radius 0.00465 au), a 20-day step: the
    # pull bound taken at half the separation leaves the pair out without
    # its two-body pericentre
    from orbits._kernels.stopping import _within_reach
    mu = 4 * np.pi ** 2 * (1 + 1e-3) / 365.25 ** 2          # au^3 / day^2
    x0 = np.array([5.2, 0.0, 0.0])
    v0 = np.array([0.0, np.sqrt(mu / 5.2), 0.0])
    h = 20.0
    work = np.array([x0, v0, x0 + h * v0, v0])
    assert not _within_reach(work, mu, h, 0.00465)


def _jupiter_probe():
    # Sun, Jupiter on a circular 5.2 au orbit and a massless probe that
    # passes it at 0.005 au and 0.05 au/day half way through the step from
    # 10 to 11 days (dt = 1 day): 0.025 au from it at both step ends.  The
    # probe starts 10.5 days before the pass on the straight line of the
    # pass; the Sun's tide over those days (2e-6 au/day^2) and Jupiter's
    # focusing (G m_J / v^2 = 1.1e-4 au) move the pass by ~1e-4 au.
    gm_sun = orbits.UnitSystem().G
    b = orbits.BodySet()
    b.add("Sun", mass=1 * u.Msun)
    xj = np.array([5.2, 0.0, 0.0])
    vj = np.array([0.0, np.sqrt(gm_sun / 5.2), 0.0])
    b.add("Jupiter", mass=1 * u.Mjup, position=xj * u.au, velocity=vj * u.au / u.day)
    w = np.array([0.05, 0.0, 0.0])
    b.add("probe", mass=0 * u.kg, position=(xj - 10.5 * w + [0, 0, 0.005]) * u.au,
          velocity=(vj + w) * u.au / u.day)
    return b


@pytest.mark.parametrize("integrator", ["leapfrog", "rk4"])
def test_an_encounter_between_step_ends_stops_a_fixed_step_run(integrator):
    # the closest approach along the step, as for collisions and the log:
    # the run stops at the end of the step that holds the pass
    sim = orbits.Simulation(_jupiter_probe(), integrator, dt=1 * u.day,
                            encounter_distance=0.02 * u.au)
    with pytest.raises(CloseEncounter) as info:
        sim.run(until=30 * u.day, outputs=2, progress=False)
    exc = info.value
    assert set(exc.bodies) == {"Jupiter", "probe"}
    assert exc.time == 11 * u.day and exc.step == 11
    # both ends of that step are outside the distance: only the look inside
    # the step sees the pass
    x = sim.bodies.positions.to_value(u.au)
    assert np.linalg.norm(x[2] - x[1]) > 0.02
    # the message names the pass: when it was closest and how close
    found = re.search(r"closest at t = ([-+.e0-9]+) .*separation ([-+.e0-9]+)", str(exc))
    assert found and 10 < float(found[1]) < 11 and float(found[2]) < 0.02


def test_conditions_are_data_of_one_type():
    # a loop is compiled for the numba types of its arguments: a stopping
    # record of one type for every simulation, with conditions or without,
    # is one compiled loop serving them all
    import numba
    from orbits._kernels import stopping as ks
    b = orbits.scenes.outer_solar_system()
    sized = orbits.BodySet.from_arrays(b.masses, b.positions, b.velocities, names=b.names,
                                       units=b.units, radii=[1e-3] * len(b) * u.au)
    none = ks.stop_record(None)
    assert numba.typeof(none[0]) == ks.SARGS
    cases = [(b, dict(encounter_distance=0.01 * u.au)),
             (b, dict(encounter_hill=1.0, escape_distance=1e3 * u.au, escape_unbound=True)),
             (sized, dict(collisions="merge")),
             (b, dict(encounter_log=0.1 * u.au)),
             (b, dict(encounter_log=3.0, monitors=("energy", "megno")))]
    for bodies, kw in cases:
        sim = orbits.Simulation(bodies.copy(), "ias15", **kw)
        record = ks.stop_record(sim._stop)
        assert record[0] is sim._stop, kw
        assert numba.typeof(record) == numba.typeof(none), kw
