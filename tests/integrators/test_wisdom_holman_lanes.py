"""The Wisdom-Holman loop with the planets in vector lanes
(orbits._kernels.wh_lanes) against the same loop with the scalar drift: the
same trajectory bit for bit.

The comparisons are exact (tolerance zero): the lanes compute each planet's
drift by the scalar code's operations in its order, or hand it to the scalar
drift (see tests/kernels/test_wh_lanes.py), so nothing may differ by even an
ulp; the kick's pulls are summed in the lanes in the scalar order, and the
state stays in the lanes between outputs (tests/kernels/test_wh_lanes.py).
Which loop a run takes is chosen by the number of bodies
(``LANES_FROM_BODIES``), of planets outside the lanes' domain
(``LANES_COST_OF_DECLINED``) and, with the ``lanes`` option's "auto", the
run's length (``LANES_FROM_STEPS``), set here to force one or the other.
"""

import astropy.units as u
import numpy as np
import pytest

import orbits
from orbits._kernels import wh_lanes as _lanes
from orbits.integrators import wisdom_holman as IW

DH = "democratic-heliocentric"


def take_lanes(monkeypatch, lanes):
    """Make the runs that follow take the lanes' loop, or the scalar one (the
    ``lanes`` option's "auto", whatever the runs' length)."""
    monkeypatch.setattr(IW, "LANES_FROM_BODIES", 4 if lanes else 10 ** 9)
    monkeypatch.setattr(IW, "LANES_COST_OF_DECLINED", 0)
    monkeypatch.setattr(IW, "LANES_FROM_STEPS", 0 if lanes else 10 ** 18)


def with_odd_orbits():
    """The outer solar system with two massless bodies: one on an orbit of
    eccentricity 0.99 (pericentre 0.3 au, where a 10-day step is long
    against the orbit and the scalar drift's bracketed solver takes it), 1.2
    au from the Sun and falling towards pericentre, and one on a hyperbola
    (pericentre 4 au), coming in from 33 au."""
    b = orbits.scenes.outer_solar_system()
    b.add("comet", 0 * u.Msun, primary="Sun", a=30 * u.au, e=0.99, inc=10 * u.deg,
          f=-120 * u.deg)
    b.add("interstellar", 0 * u.Msun, primary="Sun", a=-2 * u.au, e=3.0, inc=40 * u.deg,
          f=-100 * u.deg)
    return b


def final_state(monkeypatch, bodies, lanes, spec, until, dt=10 * u.day, **options):
    take_lanes(monkeypatch, lanes)
    name, _, coords = spec.partition(":")
    integ = orbits.integrators.get(name, coordinates=coords or "jacobi", **options)
    sim = orbits.Simulation(bodies, integrator=integ, dt=dt, monitors=())
    r = sim.run(until=until, outputs=5, progress=False)
    return r.positions.to_value(u.au), r.velocities.to_value(u.au / u.day), sim._ws


@pytest.mark.parametrize("spec, options", [("wh", {}), (f"wh:{DH}", {}),
                                           ("wh", {"corrector": 5}), ("saba2", {})])
def test_lanes_are_the_scalar_loop_bit_for_bit(monkeypatch, spec, options):
    bodies = with_odd_orbits()
    # long enough for the comet to pass its pericentre (in months) and the
    # hyperbolic body its own (in about 7 years)
    until = 20 * u.yr
    x0, v0, _ = final_state(monkeypatch, bodies, False, spec, until, **options)
    x1, v1, _ = final_state(monkeypatch, bodies, True, spec, until, **options)
    assert np.array_equal(x0, x1)
    assert np.array_equal(v0, v1)


@pytest.mark.parametrize("spec", ["wh", f"wh:{DH}"])
def test_long_steps_left_to_the_scalar_drift_bit_for_bit(monkeypatch, spec):
    # 1200 days: a long step for Jupiter (1.7 rad of its orbit: the lanes
    # decline it and hand it to the scalar drift), a step people take for
    # Saturn (0.7 rad: the lanes' medium passes) and a short one for the rest
    bodies = orbits.scenes.outer_solar_system()
    until = 100 * 1200 * u.day
    x0, v0, _ = final_state(monkeypatch, bodies, False, spec, until, dt=1200 * u.day)
    x1, v1, ws = final_state(monkeypatch, bodies, True, spec, until, dt=1200 * u.day)
    assert np.array_equal(x0, x1)
    assert np.array_equal(v0, v1)
    took = ws["lanes"][0][_lanes._RTAKE, :5]
    assert np.array_equal(took, [0, 1, 1, 1, 1])


def every_output(monkeypatch, bodies, lanes, spec, until, dt, **options):
    take_lanes(monkeypatch, lanes)
    name, _, coords = spec.partition(":")
    integ = orbits.integrators.get(name, coordinates=coords or "jacobi", **options)
    sim = orbits.Simulation(bodies, integrator=integ, dt=dt)
    steps = int(round((until / dt).to_value(u.one)))
    return sim.run(until=until, outputs=steps + 1, progress=False)


@pytest.mark.parametrize("scene, dt", [("outer", 10 * u.day), ("sun8", 0.5 * u.day),
                                       ("twelve", 5 * u.day)])
@pytest.mark.parametrize("spec, options", [("wh", {}), (f"wh:{DH}", {}),
                                           ("wh", {"corrector": 5})])
def test_an_output_every_step_with_monitors_bit_for_bit(monkeypatch, scene, dt, spec, options):
    # the state kept in the lanes is written back for every output and its
    # monitors, and loaded again after the output's drift; three lane
    # layouts: padded (6 bodies), full (9), two groups of eight (12)
    if scene == "outer":
        bodies = with_odd_orbits()
    elif scene == "sun8":
        bodies = orbits.scenes.solar_system(moon=False)
    else:
        bodies = orbits.scenes.solar_system(moon=False)
        for k in range(3):
            bodies.add(f"p{k}", 1e-9 * u.Msun, primary="Sun", a=(12 + 7 * k) * u.au,
                       e=0.05 * k, inc=k * u.deg, f=k * u.rad)
    a = every_output(monkeypatch, bodies, False, spec, 60 * dt, dt, **options)
    b = every_output(monkeypatch, bodies, True, spec, 60 * dt, dt, **options)
    assert len(a.times) == 61
    for name in ("times", "positions", "velocities"):
        assert np.array_equal(getattr(a, name).value, getattr(b, name).value), name
    assert a.energy is not None and a.angular_momentum is not None
    for name in ("energy", "angular_momentum"):
        assert np.array_equal(getattr(a, name).value, getattr(b, name).value), name


@pytest.mark.filterwarnings("ignore:overflow encountered:RuntimeWarning")
@pytest.mark.parametrize("coordinates, scale, step", [("jacobi", 1e160, 0), (DH, 1e160, 0),
                                                      (DH, 1e100, 1)])
def test_a_state_that_turns_non_finite_stops_as_the_scalar_loop_does(
        monkeypatch, coordinates, scale, step):
    # Saturn at an absurd speed: its state overflows in the first step or
    # the second; the lanes' finite check stops the run where the scalar
    # loop's does, with the same outputs and last state (NaN where the
    # output's synchronisation overflowed, as it does in both)
    from orbits.errors import NonFiniteState
    got = []
    for lanes in (False, True):
        take_lanes(monkeypatch, lanes)
        sim = orbits.Simulation(orbits.scenes.outer_solar_system(),
                                integrator=orbits.integrators.get("wh", coordinates=coordinates),
                                dt=10 * u.day)
        state = sim.state
        v = state.v.copy()
        v[2] *= scale
        sim.set_state(state._replace(v=v))
        with pytest.raises(NonFiniteState) as info:
            sim.run(until=100 * u.day, outputs=11, progress=False)
        got.append((info.value, sim.state))
    (e0, s0), (e1, s1) = got
    assert e0.step == e1.step
    assert e1.step == step
    assert e0.time == e1.time
    for name in ("times", "positions", "velocities"):
        assert np.array_equal(getattr(e0.result, name).value, getattr(e1.result, name).value,
                              equal_nan=True), name
    assert np.array_equal(s0.x, s1.x, equal_nan=True)
    assert np.array_equal(s0.v, s1.v, equal_nan=True)


def test_lanes_are_chosen_by_the_number_of_bodies(monkeypatch):
    # the loop records its scratch in the workspace when it runs with lanes;
    # lanes="on" asks for them, and still not below LANES_FROM_BODIES (the
    # default "auto" also depends on whether an earlier test compiled them)
    for bodies, lanes in ((orbits.scenes.outer_solar_system(), True),
                          (orbits.scenes.kepler(e=0.1), False)):
        sim = orbits.Simulation(bodies, integrator=orbits.integrators.get("wh", lanes="on"),
                                dt=1 * u.day, monitors=())
        sim.run(until=10 * u.day, outputs=2, progress=False)
        assert ("lanes" in sim._ws) == lanes


@pytest.mark.parametrize("scene, step_days, lanes", [
    # the estimate's Stumpff argument z, the square of a step's eccentric
    # anomaly, against the lanes' 1 and |dt| |v| against r: Jupiter out from
    # about 750 days, Saturn from 1800, Uranus from 5200 and Neptune and
    # Pluto at 12000, so 9 * 3 = 27 < 6**2 at 6000 days and 9 * 5 = 45 is not
    # at 12000 (RESULTS: lanes 0.587 against scalar 0.604 us a step at 6000
    # days, 0.472 against 0.479 at 12000)
    ("outer", 10, True), ("outer", 216.6, True), ("outer", 1000, True), ("outer", 6000, True),
    ("outer", 12000, False),
    # Mercury and Venus out at 40 days: 18 < 81
    ("inner", 4.398, True), ("inner", 0.5, True), ("inner", 40, True)])
def test_the_lanes_are_taken_where_few_planets_leave_their_domain(scene, step_days, lanes):
    bodies = (orbits.scenes.outer_solar_system() if scene == "outer"
              else orbits.scenes.solar_system(moon=False))
    sim = orbits.Simulation(bodies, integrator="wh", dt=step_days * u.day, monitors=())
    sim.run(until=2 * step_days * u.day, progress=False)
    assert sim._ws["lanes_pay"] is lanes


def test_auto_takes_the_lanes_for_long_runs_and_once_they_are_compiled(monkeypatch, tmp_path):
    # lanes="auto" (the default): the scalar loop for a run that ends before
    # LANES_FROM_STEPS steps on a machine that never compiled the lanes' loop
    # (its compilation would cost more than the run saves), the lanes' loop
    # for one that reaches it, and for any run once that loop is compiled:
    # in this process, or in an earlier one, which left a marker beside the
    # cache (here a folder of the test's own).  Bit for bit the same states.
    from orbits import _compiling
    monkeypatch.setattr(_compiling, "cache_dir", lambda: str(tmp_path))
    monkeypatch.setattr(IW, "_LANES_READY", set())
    monkeypatch.setattr(IW, "LANES_FROM_STEPS", 100)
    bodies = orbits.scenes.outer_solar_system()

    def run(steps, **options):
        integ = orbits.integrators.get("wh", **options)
        sim = orbits.Simulation(bodies, integ, dt=10 * u.day, monitors=())
        r = sim.run(until=steps * 10 * u.day, outputs=3, progress=False)
        return sim._ws["lanes_taken"], r.positions.value, r.velocities.value

    short = run(60)
    assert not short[0] and list(tmp_path.iterdir()) == []
    assert run(120)[0]                                  # reaches 100 steps
    markers = list(tmp_path.glob("*.ready"))
    assert len(markers) == 1 and "lanes" in markers[0].name
    again = run(60)                                     # compiled in this process
    assert again[0]
    assert np.array_equal(again[1], short[1]) and np.array_equal(again[2], short[2])
    monkeypatch.setattr(IW, "_LANES_READY", set())      # a new process: the marker
    assert run(60)[0]
    markers[0].unlink()
    monkeypatch.setattr(IW, "_LANES_READY", set())
    assert not run(60)[0]
    # "on" and "off" whatever the length; and too few bodies, or added terms, never
    assert run(60, lanes="on")[0] and not run(120, lanes="off")[0]
    monkeypatch.setattr(IW, "LANES_FROM_STEPS", 0)
    three = orbits.Simulation(orbits.scenes.kepler(), "wh", dt=1 * u.day)
    three.run(until=10 * u.day, progress=False)
    assert not three._ws["lanes_taken"]
    gr = orbits.Simulation(bodies, "wh", dt=10 * u.day, forces=[orbits.forces.GRPotential("Sun")])
    gr.run(until=100 * u.day, progress=False)
    assert not gr._ws["lanes_taken"]
