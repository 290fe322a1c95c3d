"""Simulation.run: outputs, continuation, failures and bad input."""


import astropy.units as u
import numpy as np
import pytest

import orbits
from orbits.errors import (BodyUnitsError, IntegratorOptionError, NonFiniteState,
                           UnknownIntegratorError)

from helpers import kepler_bodies


def sun_jupiter_probe():
    b = orbits.BodySet()
    b.add("Sun", mass=1 * u.Msun)
    b.add("Jupiter", mass=1 * u.Mjup, primary="Sun", a=5.2 * u.au, e=0.048, inc=1.3 * u.deg)
    b.add("probe", mass=0 * u.kg, position=[1, 0, 0] * u.au, velocity=[0, 30, 0] * u.km / u.s)
    b.move_to_com()
    return b


def test_issue_example():
    sim = orbits.Simulation(sun_jupiter_probe(), integrator="verlet", dt=5 * u.day)
    result = sim.run(until=1000 * u.yr, outputs=500, progress=False)
    assert result.times.shape == (500,) and result.times.unit == u.day
    assert result.positions.shape == (500, 3, 3) and result.velocities.shape == (500, 3, 3)
    assert result.energy_error.shape == (500,)
    assert result.angular_momentum_error.shape == (500,)
    assert result.times[0] == 0 * u.day and result.times[-1] == 1000 * u.yr
    # 1000 yr / 5 d = 73050 steps exactly, and every output is on a step boundary
    assert result.steps == 73050
    steps_at = (result.times / (5 * u.day)).decompose().value
    np.testing.assert_array_equal(steps_at, np.round(steps_at))
    # velocity Verlet at dt = P_J/865 keeps Jupiter's energy to ~(2 pi / 865)^2 ~ 5e-5;
    # the probe is massless and does not enter
    assert result.energy_error.max() < 5e-5
    text = result.summary()
    assert "verlet" in text and "73050" in text and "energy" in text
    assert sim.time == 1000 * u.yr
    later = sim.run(until=1010 * u.yr, outputs=3, progress=False)
    assert later.times[0] == 1000 * u.yr and later.times[-1] == 1010 * u.yr
    # errors stay relative to the start of the simulation, not of each run
    assert later.energy_error[0] == pytest.approx(result.energy_error[-1], rel=1e-12)


def test_run_in_pieces_is_identical_to_one_run():
    # outputs only read the state; stopping and continuing must change nothing
    b = kepler_bodies(e=0.7, m_orbiter=1e-3)
    one = orbits.Simulation(b, integrator="leapfrog", dt=0.01).run(until=10.0, outputs=2,
                                                                   progress=False)
    sim = orbits.Simulation(b, integrator="leapfrog", dt=0.01)
    for t in (2.5, 5.0, 7.5, 10.0):
        r = sim.run(until=t, outputs=7, progress=False)
    assert np.array_equal(r.positions.value[-1], one.positions.value[-1])


def test_last_step_is_shortened_to_reach_until():
    b = kepler_bodies()
    sim = orbits.Simulation(b, integrator="rk4", dt=0.3)
    r = sim.run(until=1.0, outputs=2, progress=False)
    assert r.steps == 4 and r.times[-1].value == 1.0
    assert sim.time.value == 1.0


def test_plain_numbers_in_body_set_units():
    b = kepler_bodies()
    r = orbits.Simulation(b, integrator="rk4", dt=1.0).run(until=10.0, progress=False,
                                                         outputs=11)
    assert r.times.unit == u.dimensionless_unscaled


def test_integrator_instance_and_registry():
    integ = orbits.integrators.get("rk4")
    sim = orbits.Simulation(kepler_bodies(), integrator=integ, dt=0.1)
    assert sim.integrator is integ
    names = [i.name for i in orbits.integrators.available()]
    assert names[:6] == ["euler", "symplectic-euler", "verlet", "leapfrog", "rk2", "rk4"]


def test_monitor_cadence_inside_loop():
    b = kepler_bodies(e=0.5, m_orbiter=1e-3)
    sim = orbits.Simulation(b, integrator="verlet", dt=0.01, monitor_every=10,
                            monitors=("energy", "angular_momentum", "momentum",
                                      "center_of_mass"))
    r = sim.run(until=10.0, outputs=3, progress=False)
    assert r.monitor["times"].shape == (100,)
    np.testing.assert_allclose(r.monitor["times"].value, np.arange(1, 101) * 0.1, rtol=1e-12)
    # the in-loop series agrees with the values at outputs where they coincide
    assert r.monitor["energy_error"][-1] == pytest.approx(r.energy_error[-1], rel=1e-12)
    assert r.momentum.shape == (3, 3) and r.center_of_mass.shape == (3, 3)
    assert r.max_energy_error() >= r.energy_error.max()


def test_monitors_off():
    r = orbits.Simulation(kepler_bodies(), dt=0.1, monitors=()).run(until=1.0, outputs=2,
                                                                    progress=False)
    assert r.energy_error is None and r.angular_momentum_error is None
    assert "energy" not in r.summary().split("status")[0].split("units")[1]


def collision_course():
    # two bodies of negligible mass flying straight at each other: the drift
    # of leapfrog's third step puts both exactly at the origin, where the
    # force is 0/0.  (The mass is small enough that gravity changes no bit
    # of the velocities before that.)
    b = orbits.BodySet(units=orbits.UnitSystem.nbody())
    b.add("a", mass=1e-300, position=[5, 0, 0], velocity=[-2, 0, 0])
    b.add("b", mass=1e-300, position=[-5, 0, 0], velocity=[2, 0, 0])
    return b


def test_non_finite_state_keeps_last_good_state():
    sim = orbits.Simulation(collision_course(), integrator="leapfrog", dt=1.0)
    with pytest.raises(NonFiniteState) as exc:
        sim.run(until=10.0, outputs=11, progress=False)
    err = exc.value
    assert err.step == 2 and err.time.value == 2.0
    assert "step 3" in str(err)
    r = err.result
    assert r.status == "non-finite state"
    np.testing.assert_array_equal(r.positions.value[-1], [[1, 0, 0], [-1, 0, 0]])
    assert np.all(np.isfinite(r.positions.value))
    # the simulation itself was left at the last good state
    assert sim.time.value == 2.0
    np.testing.assert_array_equal(sim.bodies.positions.value, [[1, 0, 0], [-1, 0, 0]])


@pytest.mark.parametrize("dt, exc", [
    (0 * u.day, IntegratorOptionError), (-1 * u.day, IntegratorOptionError),
    (1 * u.au, BodyUnitsError), (1.0, BodyUnitsError), (None, IntegratorOptionError),
    (np.nan * u.day, IntegratorOptionError),
])
def test_bad_dt(dt, exc):
    with pytest.raises(exc, match="dt"):
        orbits.Simulation(sun_jupiter_probe(), "verlet", dt=dt)


def test_bad_until_and_outputs():
    sim = orbits.Simulation(sun_jupiter_probe(), "verlet", dt=5 * u.day)
    sim.run(until=1 * u.yr, outputs=2, progress=False)
    with pytest.raises(ValueError, match="is the current time"):
        sim.run(until=1 * u.yr)
    with pytest.raises(BodyUnitsError, match="until"):
        sim.run(until=2 * u.au)
    with pytest.raises(ValueError, match="at most 3 outputs"):
        sim.run(until=1 * u.yr + 10 * u.day, outputs=10)


def test_unknown_integrator_and_option():
    with pytest.raises(UnknownIntegratorError, match="valid names: euler, symplectic-euler"):
        orbits.Simulation(sun_jupiter_probe(), integrator="verlett", dt=1 * u.day)
    with pytest.raises(IntegratorOptionError, match="no option 'epsilon'; valid options: none"):
        orbits.integrators.get("rk4", epsilon=1e-9)


def test_progress_bar_can_be_silenced(capsys):
    orbits.Simulation(kepler_bodies(), "verlet", dt=0.01).run(until=1.0, outputs=2,
                                                              progress=False)
    assert capsys.readouterr().err == ""
    orbits.Simulation(kepler_bodies(), "verlet", dt=0.01).run(until=1.0, outputs=2,
                                                              progress=True)
    assert "step" in capsys.readouterr().err


def test_parallel_and_serial_runs_agree():
    b = orbits.scenes.plummer(150, seed=3)
    runs = [orbits.Simulation(b, integrator="leapfrog", dt=1e-3, parallel=p, monitors=())
            .run(until=0.05, outputs=2, progress=False) for p in (False, True)]
    # the two kernels sum in different orders: rounding differences of ~1e-16
    # grow over 50 steps of a cluster (Lyapunov time ~ crossing time = 2.8) by
    # far less than 1e3
    np.testing.assert_allclose(runs[0].positions.value, runs[1].positions.value,
                               rtol=0, atol=1e-12)


def test_softening_changes_the_force():
    b = kepler_bodies(m_orbiter=1e-3)
    r0 = orbits.Simulation(b, dt=0.01).run(until=1.0, outputs=2, progress=False)
    r1 = orbits.Simulation(b, dt=0.01, softening=0.1).run(until=1.0, outputs=2,
                                                           progress=False)
    assert not np.allclose(r0.positions.value[-1], r1.positions.value[-1], atol=1e-6)
    with pytest.raises(IntegratorOptionError, match="softening"):
        orbits.Simulation(b, dt=0.01, softening=-1.0)


def test_wall_limit_stops_with_the_state_kept():
    import astropy.units as u
    sim = orbits.Simulation(orbits.scenes.outer_solar_system(), "leapfrog", dt=1 * u.day)
    sim.run(until=10 * u.day, outputs=2, progress=False)          # compiled before timing
    with pytest.raises(orbits.WallTimeExceeded, match="wall-time limit of 0.2 s") as info:
        sim.run(until=1e9 * u.yr, outputs=5, wall_limit=0.2, progress=False)
    exc = info.value
    assert exc.result.status == "wall-time limit"
    assert sim.steps == exc.step > 10
    # the result ends with the state the simulation was left at, and it goes on
    assert np.array_equal(exc.result.positions[-1].value, sim.bodies.positions.value)
    sim.run(until=sim.time + 10 * u.day, outputs=2, progress=False)


def test_wall_limit_must_be_positive():
    sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
    with pytest.raises(ValueError, match="wall_limit"):
        sim.run(until=10 * u.day, outputs=2, wall_limit=0)


def _dated_outer():
    from astropy.time import Time
    b = orbits.scenes.outer_solar_system()
    b.epoch = Time(2451545.0, format="jd", scale="tdb")
    return b


def _crossing(r2=1.0):
    # two planets on circles of 1 and r2 au, one prograde, one retrograde,
    # 0.1 rad apart: they meet head on after about 2.9 d
    # (tests/test_collision_resolution.py), or pass r2 - 1 au apart
    b = orbits.BodySet()
    b.add("Star", mass=1 * u.Msun, radius=0.005 * u.au)
    vc = float(np.sqrt(orbits.UnitSystem().G))
    b.add("P1", mass=2e-3 * u.Msun, position=[1, 0, 0] * u.au,
          velocity=[0, vc, 0] * u.au / u.day, radius=0.01 * u.au)
    c, s = np.cos(0.1), np.sin(0.1)
    v2 = vc / np.sqrt(r2)
    b.add("P2", mass=1e-3 * u.Msun, position=[r2 * c, r2 * s, 0] * u.au,
          velocity=[v2 * s, -v2 * c, 0] * u.au / u.day, radius=0.01 * u.au)
    b.move_to_com()
    return b


#: simulations whose state is more than positions and velocities: wh's owed
#: drift, IAS15's step predictor and a term's work, the tangent vectors and
#: MEGNO's sums, a merger that changed the bodies, a date, and trace's
#: flags through a close encounter (0.03 au, inside the Hill radius, 0.087 au)
PICKLED = {
    "wh": (lambda: orbits.Simulation(_dated_outer(), "wh", dt=100 * u.day),
           3000 * u.day, 6000 * u.day),
    "ias15 GR migration": (
        lambda: orbits.Simulation(orbits.scenes.outer_solar_system(), "ias15",
                                  forces=[orbits.forces.GR("Sun"),
                                          orbits.forces.Migration("Saturn", tau_a=1e5 * u.yr)]),
        3000 * u.day, 6000 * u.day),
    "leapfrog megno": (
        lambda: orbits.Simulation(orbits.scenes.outer_solar_system(), "leapfrog",
                                  dt=30 * u.day, monitors=["energy", "megno"], seed=2),
        3000 * u.day, 6000 * u.day),
    "ias15 merge": (lambda: orbits.Simulation(_crossing(), "ias15", collisions="merge"),
                    5 * u.day, 10 * u.day),
    "trace encounter": (lambda: orbits.Simulation(_crossing(1.03), "trace", dt=0.05 * u.day),
                        2 * u.day, 4 * u.day),
}


@pytest.mark.parametrize("case", PICKLED)
def test_a_simulation_pickles_and_deep_copies_to_the_same_numbers(case):
    # a pickled or deep-copied simulation is made again from its configuration
    # with its exact state, as a restart from a file is: it runs on to the
    # bits of the original, and of a simulation that was never copied
    import copy
    import pickle
    make, first, second = PICKLED[case]
    sims = [make(), make()]
    for s in sims:
        s.run(until=first, outputs=2, progress=False)
    sims += [pickle.loads(pickle.dumps(sims[1])), copy.deepcopy(sims[1])]
    results = [s.run(until=second, outputs=5, progress=False) for s in sims]
    ref = results[0]
    for s, r in zip(sims[1:], results[1:]):
        assert s.bodies.names == sims[0].bodies.names
        assert s.steps == sims[0].steps and s.time == sims[0].time
        assert (s.epoch is None) == (sims[0].epoch is None)
        if s.epoch is not None:
            assert (s.epoch + s.time).jd == (sims[0].epoch + sims[0].time).jd
        assert s.work == sims[0].work
        assert len(r.collisions if r.collisions is not None else []) == \
            len(ref.collisions if ref.collisions is not None else [])
        for name in ("positions", "velocities", "energy"):
            assert np.array_equal(getattr(r, name).value, getattr(ref, name).value,
                                  equal_nan=True), name
        if case == "leapfrog megno":
            assert np.array_equal(r.megno, ref.megno)
