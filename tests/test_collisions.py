"""Collisions (``Simulation(..., collisions="halt")``): bodies with radii that
touch, at the end of a step or inside it, stop the run with a named error
that keeps the state; bad input is refused by name."""

import astropy.units as u
import numpy as np
import pytest

import orbits
from orbits.errors import BodyError, Collision, IntegratorOptionError, SimulationOptionError


def _infall(star_radius=0.005):
    # a massless comet falling straight onto a star of radius star_radius au
    b = orbits.BodySet()
    b.add("Star", mass=1 * u.Msun, radius=star_radius * u.au)
    b.add("Comet", mass=0 * u.kg, position=[1, 0, 0] * u.au,
          velocity=[-0.001, 0, 0] * u.au / u.day, radius=1 * u.km)
    return b


def _flyby(y0, x0=-1.05):
    # a fast comet passing the star at about y0 au, its closest approach half
    # way through the step of 0.5 d from 5.0 to 5.5 d (x0 / 0.2 au/d = 5.25 d)
    b = orbits.BodySet()
    b.add("Star", mass=1 * u.Msun, radius=0.01 * u.au)
    b.add("Comet", mass=0 * u.kg, position=[x0, y0, 0] * u.au,
          velocity=[0.2, 0, 0] * u.au / u.day)
    return b


def test_a_radial_infall_halts_at_contact_and_keeps_the_state():
    sim = orbits.Simulation(_infall(), "ias15", collisions="halt")
    with pytest.raises(Collision) as info:
        sim.run(until=1 * u.yr, outputs=5, progress=False)
    exc = info.value
    assert exc.bodies == ("Star", "Comet")
    # ias15's steps are short against the fall's last stretch: the contact is
    # found at the end of the step in which the comet crossed the surface
    assert exc.distance < 0.005 * u.au
    assert exc.contact_time <= exc.time
    assert sim.time == exc.time and exc.result.times[-1] == exc.time
    x = sim.bodies.positions.to_value(u.au)
    assert np.linalg.norm(x[1] - x[0]) < 0.005 + 1e-9


def test_a_grazing_passage_inside_one_step_is_caught():
    # the comet passes within the star's radius between two step ends, at
    # both of which it is outside it (0.05 and 0.024 au, deflected): only the
    # look inside the step sees it
    sim = orbits.Simulation(_flyby(0.008), "leapfrog", dt=0.5 * u.day, collisions="halt")
    with pytest.raises(Collision) as info:
        sim.run(until=20 * u.day, outputs=2, progress=False)
    exc = info.value
    assert exc.time == 5.5 * u.day
    assert 5.0 * u.day < exc.contact_time < 5.5 * u.day
    assert exc.distance < 0.01 * u.au
    x = sim.bodies.positions.to_value(u.au)
    assert np.linalg.norm(x[1] - x[0]) > 0.01


def test_a_passage_outside_the_radii_does_not_stop_the_run():
    # closest approach about 0.03 au (gravitational focusing at 0.2 au/d
    # pulls it in by under 1e-3 au), three times the star's radius
    sim = orbits.Simulation(_flyby(0.03), "leapfrog", dt=0.5 * u.day, collisions="halt")
    res = sim.run(until=20 * u.day, outputs=2, progress=False)
    assert res.times[-1] == 20 * u.day


def test_collisions_travel_with_the_configuration():
    sim = orbits.Simulation(_infall(), "ias15", collisions="halt")
    assert sim.stop_conditions["collisions"] == "halt"
    twin = orbits.Simulation.from_config(_infall(), sim.config.to_dict())
    assert twin.stop_conditions["collisions"] == "halt"
    with pytest.raises(Collision):
        twin.run(until=1 * u.yr, outputs=2, progress=False)


def test_bad_collision_input_is_refused_by_name():
    with pytest.raises(SimulationOptionError, match="explode"):
        orbits.Simulation(_infall(), "ias15", collisions="explode")
    points = orbits.scenes.kepler()
    with pytest.raises(BodyError, match="radius") as info:
        orbits.Simulation(points, "ias15", collisions="halt")
    assert info.value.field == "radius"
    touching = _infall(star_radius=2.0)
    with pytest.raises(BodyError, match="touch at the start"):
        orbits.Simulation(touching, "ias15", collisions="halt")
    with pytest.raises(IntegratorOptionError, match="collisions"):
        orbits.Simulation(_infall(), "wh", dt=1 * u.day, collisions="halt")


def test_a_file_says_the_run_ended_in_a_collision(tmp_path):
    path = tmp_path / "infall.h5"
    sim = orbits.Simulation(_infall(), "ias15", collisions="halt")
    with pytest.raises(Collision) as info:
        sim.run(until=1 * u.yr, outputs=5, progress=False, output=path)
    back = orbits.load(path)
    assert back.status == "collision"
    assert back.times[-1] == info.value.time


def test_a_restart_looks_inside_its_first_step(tmp_path):
    # the grazing passage falls inside the first step after a checkpoint at
    # 5.0 d: the file keeps the state the check compares with, so that the
    # restarted run finds it as the uninterrupted one does
    path = tmp_path / "graze.h5"
    whole = orbits.Simulation(_flyby(0.008), "leapfrog", dt=0.5 * u.day, collisions="halt")
    with pytest.raises(Collision) as first:
        whole.run(until=20 * u.day, outputs=2, progress=False)
    sim = orbits.Simulation(_flyby(0.008), "leapfrog", dt=0.5 * u.day, collisions="halt")
    sim.run(until=5 * u.day, outputs=2, progress=False, output=path)
    again = orbits.Simulation.from_file(path)
    with pytest.raises(Collision) as second:
        again.run(until=20 * u.day, outputs=2, progress=False)
    assert second.value.time == first.value.time == 5.5 * u.day
    assert second.value.contact_time == first.value.contact_time


def _line(x_b, radius=1.0):
    # two bodies of radius 1 on a line (G = 1, masses 1e-6): "b" at x_b moves
    # at -1 towards "a" at rest; they touch when 2 apart, at t = x_b - 2
    b = orbits.BodySet(units=orbits.UnitSystem.nbody())
    b.add("a", mass=1e-6, position=[0, 0, 0], velocity=[0, 0, 0], radius=radius)
    b.add("b", mass=1e-6, position=[x_b, 0, 0], velocity=[-1, 0, 0], radius=radius)
    return b


@pytest.mark.parametrize("integrator", ["leapfrog", "rk4"])
def test_a_collision_inside_the_first_step_halts(integrator):
    # from x = 3 the bodies touch at t = 1, inside the first step of 10 (at
    # its end they are 7 apart, passed through each other): the check looks
    # inside the first step as inside every other
    sim = orbits.Simulation(_line(3.0), integrator, dt=10, collisions="halt")
    with pytest.raises(Collision) as info:
        sim.run(until=40, outputs=2, progress=False)
    exc = info.value
    assert exc.bodies == ("a", "b") and exc.step == 1 and exc.time.value == 10
    # the pair's relative motion is a straight line (their pull, 1e-6 / 4,
    # moves them by < 1e-4 over the step), whose closest approach is 0 at
    # t = 3; the contact (separation 2) is at t = 1
    assert 0.0 <= exc.contact_time.value <= 3.0 + 1e-3
    assert exc.distance.value < 2.0


@pytest.mark.parametrize("integrator", ["leapfrog", "rk4"])
def test_a_collision_inside_the_first_step_merges(integrator):
    sim = orbits.Simulation(_line(3.0), integrator, dt=10, collisions="merge")
    res = sim.run(until=40, outputs=2, progress=False)
    assert len(sim.bodies) == 1 and len(res.collisions) == 1
    row = res.collisions[0]
    assert (row["body_1"], row["body_2"], row["resolution"]) == ("a", "b", "merge")
    assert row["step_time"].value == 10 and row["time"].value <= 10
    # mass and momentum: the merged body moves at the pair's mean velocity
    assert sim.bodies._m[0] == 2e-6
    assert np.allclose(sim.bodies._v[0], [-0.5, 0, 0], rtol=1e-12)


def test_bodies_overlapping_at_the_start_merge_there():
    # "b" inside "a" at t = 0: collisions="merge" asks for the merger, which
    # happens at the start (the table's first row, at t = 0)
    touching = _line(1.5)
    sim = orbits.Simulation(touching, "leapfrog", dt=10, collisions="merge")
    assert len(sim.bodies) == 1
    res = sim.run(until=20, outputs=2, progress=False)
    assert len(res.collisions) == 1
    row = res.collisions[0]
    assert row["time"].value == 0 and row["step_time"].value == 0
    assert (row["body_1"], row["body_2"], row["survivor"]) == ("a", "b", "a")
    assert row["distance"].value == 1.5
    # momentum 1e-6 * (-1), now of a body of 2e-6; E plus the merger's offset
    # stays the initial energy (a single body drifts: to rounding)
    assert np.allclose(sim.bodies._v[0], [-0.5, 0, 0], rtol=1e-12)
    assert abs(res.energy_error[-1]) < 1e-12


@pytest.mark.parametrize("how", ["halt", "bounce"])
def test_bodies_overlapping_at_the_start_are_refused_unless_merged(how):
    with pytest.raises(BodyError, match="'a' and 'b' touch at the start") as info:
        orbits.Simulation(_line(1.5), "leapfrog", dt=10, collisions=how)
    assert info.value.field == "radius" and "merge" in str(info.value)


def test_a_result_keeps_the_collisions_resolved_by_its_end():
    # result.collisions is made where it is first read (astropy.table's
    # import is not paid by a run that never reads it), from the collisions
    # as they were at the run's end: from x = 30 the bodies touch at t = 28,
    # in the third step, after the first run
    sim = orbits.Simulation(_line(30.0), "leapfrog", dt=10, collisions="merge")
    first = sim.run(until=10, outputs=2, progress=False)
    second = sim.run(until=40, outputs=2, progress=False)
    assert len(second.collisions) == 1 and second.collisions[0]["resolution"] == "merge"
    assert len(first.collisions) == 0
