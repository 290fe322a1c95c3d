"""Bodies by name: ``bodies["Jupiter"]`` (a read-only view), ``body.orbit()``
as REBOUND's ``particle.orbit()``, ``result["Jupiter"]`` (a track through the
outputs), and the errors for names that are not there."""

import math

import astropy.units as u
import numpy as np
import pytest

import orbits
from orbits.body import Body, Orbit, Track
from orbits.errors import BodyError, ElementsError, NoMassiveBodyError, UnknownBodyError

rebound = pytest.importorskip("rebound")

TWO_PI = 2.0 * math.pi


def _wrapped(a, b):
    """|a - b| for angles, the difference taken into (-pi, pi]."""
    return abs((a - b + math.pi) % TWO_PI - math.pi)


def _system():
    # an outer solar system with a retrograde, inclined comet and a body on a
    # hyperbolic orbit, every body with a radius
    b = orbits.scenes.outer_solar_system(com=True)
    b.add("comet", mass=1e-12 * u.Msun, primary="Sun", a=18 * u.au, e=0.6,
          inc=150 * u.deg, Omega=40 * u.deg, omega=250 * u.deg, f=2.0 * u.rad,
          radius=5 * u.km)
    b.add("visitor", mass=0 * u.Msun, primary="Sun", a=-3 * u.au, e=1.5,
          inc=20 * u.deg, Omega=100 * u.deg, omega=30 * u.deg, f=-0.5 * u.rad)
    return b


# -- the body view ---------------------------------------------------------------------

def test_a_view_gives_the_sets_values_in_its_units():
    b = _system()
    for i, name in enumerate(b.names):
        body = b[name]
        assert isinstance(body, Body) and body.name == name and body.index == i
        assert body.mass == b.masses[i] and body.radius == b.radii[i]
        assert np.array_equal(body.position, b.positions[i])
        assert np.array_equal(body.velocity, b.velocities[i])
        assert body.position.unit == u.au and body.velocity.unit == u.au / u.day
    assert b["comet"].radius.to_value(u.km) == pytest.approx(5.0, rel=1e-12)


def test_integer_indexes_count_from_either_end():
    b = _system()
    assert b[0].name == "Sun" and b[1].name == "Jupiter"
    assert b[-1].name == "visitor" and b[np.int64(2)].name == "Saturn"
    with pytest.raises(IndexError, match="out of range for 8 bodies"):
        b[8]
    with pytest.raises(IndexError):
        b[-9]
    for key in (1.0, True, slice(0, 2), None):
        with pytest.raises(TypeError, match="by name .str. or index .int."):
            b[key]


def test_an_unknown_name_suggests_the_nearest():
    b = _system()
    with pytest.raises(UnknownBodyError, match=r"'Jupyter'.*did you mean 'Jupiter'\?"):
        b["Jupyter"]
    # a name that differs in case only is found as the suggestion
    with pytest.raises(UnknownBodyError, match=r"did you mean 'Saturn'\?.*known: Sun,"):
        b["saturn"]
    # nothing close: no suggestion, the known names
    with pytest.raises(UnknownBodyError) as exc:
        b["Vulcan"]
    assert "did you mean" not in str(exc.value) and "known: Sun, Jupiter" in str(exc.value)
    assert isinstance(exc.value, KeyError) and exc.value.body == "Vulcan"
    # the same for every lookup by name: index, elements, and an unknown primary
    with pytest.raises(UnknownBodyError, match="did you mean 'Neptune'"):
        b.elements("Neptun", primary="Sun")
    with pytest.raises(UnknownBodyError, match="unknown primary 'Son' .did you mean 'Sun'"):
        b["Jupiter"].orbit(primary="Son")


def test_iteration_and_membership():
    b = _system()
    views = list(b)
    assert [v.name for v in views] == b.names and all(isinstance(v, Body) for v in views)
    assert "Jupiter" in b and "Vulcan" not in b and b["Saturn"] in b
    assert 1 not in b


def test_a_view_is_read_only_and_follows_its_set():
    b = orbits.scenes.outer_solar_system()
    jupiter = b["Jupiter"]
    with pytest.raises(AttributeError, match="read-only view"):
        jupiter.mass = 1 * u.Msun
    before = jupiter.position
    b.move_to_com()
    shift = b.positions[1] - before
    assert np.abs(shift).max() > 1e-4 * u.au                 # the set moved ...
    assert np.array_equal(jupiter.position, b.positions[1])  # ... and the view with it
    jupiter.position[0] = 99 * u.au                          # a copy: the set keeps its own
    assert b.positions[1, 0] != 99 * u.au


def test_a_view_kept_over_a_change_of_the_set_finds_its_body_again():
    b = orbits.scenes.kepler()
    planet = b["Planet"]
    b.add("Moon", mass=0 * u.kg, position=[2, 0, 0] * u.au)
    assert planet.index == 1 and b["Moon"].index == 2
    assert planet.name == "Planet" and np.array_equal(planet.position, b.positions[1])


def test_elements_through_the_view_are_the_sets():
    b = _system()
    for primary in (None, "Sun", "barycentre"):
        ours = b["Saturn"].elements(primary=primary)
        theirs = b.elements("Saturn", primary=primary)
        assert all(np.array_equal(ours[k], theirs[k]) for k in theirs)


# -- orbit() against REBOUND --------------------------------------------------------------

# Both sides turn the same float64 state into elements with formulas of a
# different order; each element's rounding is a few 1e-16 of its size,
# amplified by the conditioning of the conversion: ~1/e for omega and f
# (e >= 0.009 here, so ~1e-14) and ~1/sin(inc) for Omega (inc >= 0.3 deg:
# ~4e-14); the largest difference on this system is 3.7e-14 rad (omega and
# f).  1e-12 (relative, or in rad for angles) keeps a margin of ~25 over it
# without letting a wrong formula or primary through: the three primaries
# differ by 1e-3 of a planet's distance, mu = G M against G (M + m) by 1e-3.
REL = 1e-12


def _compare(ours, theirs, body):
    for key in ("a", "e", "d", "v", "h", "P"):
        mine = getattr(ours, key).value
        if key == "P" and np.isnan(mine):
            assert theirs.a < 0, body           # REBOUND: a negative period
            continue
        assert mine == pytest.approx(getattr(theirs, key), rel=REL), (body, key)
    assert ours.n.value == pytest.approx(abs(theirs.n), rel=REL), body
    for key in ("inc", "Omega", "omega", "f", "M", "pomega", "l", "theta"):
        assert _wrapped(getattr(ours, key).value, getattr(theirs, key)) < REL, (body, key)
    hvec, evec = ([w.x, w.y, w.z] for w in (theirs.hvec, theirs.evec))
    assert np.abs(ours.hvec.value - hvec).max() < REL * np.linalg.norm(hvec), body
    assert np.abs(ours.evec.value - evec).max() < REL * max(ours.e.value, 1), body


@pytest.mark.parametrize("primary", [None, "Sun", "barycentre", "barycenter"])
def test_orbit_matches_rebounds_particle_orbit(primary):
    b = _system()
    sim = b.to_rebound()
    for i, name in enumerate(b.names[1:], start=1):
        p = sim.particles[i]
        if primary is None:
            theirs = p.orbit()                          # REBOUND's default: Jacobi
        elif primary == "Sun":
            theirs = p.orbit(primary=sim.particles[0])
        else:
            theirs = p.orbit(primary=sim.com())
        ours = b[name].orbit(primary=primary)
        assert isinstance(ours, Orbit) and ours.primary == primary
        _compare(ours, theirs, name)


def test_orbit_units_and_repr():
    o = _system()["Jupiter"].orbit(primary="Sun")
    assert o.a.unit == u.au and o.P.unit == u.day and o.n.unit == u.rad / u.day
    assert o.h.unit == u.au ** 2 / u.day and o.hvec.shape == (3,)
    assert o.P.to_value(u.yr) == pytest.approx(11.86, rel=1e-3)
    assert repr(o).startswith("<Orbit a=5.2") and "inc=23.2" in repr(o)  # equatorial


def test_orbit_errors_are_named():
    b = _system()
    with pytest.raises(BodyError, match="orbital elements need a primary"):
        b["Sun"].orbit()
    with pytest.raises(BodyError, match="no orbit about itself"):
        b["Jupiter"].orbit(primary="Jupiter")
    b.add("twin", mass=0 * u.Msun, position=b["Jupiter"].position,
          velocity=b["Jupiter"].velocity)
    with pytest.raises(ElementsError):
        b["twin"].orbit(primary="Jupiter")
    massless = orbits.BodySet()
    massless.add("a", mass=0 * u.kg, position=[1, 0, 0] * u.au)
    massless.add("b", mass=0 * u.kg, position=[2, 0, 0] * u.au)
    with pytest.raises(NoMassiveBodyError):
        massless["b"].orbit(primary="barycentre")


def test_barycentric_elements_use_all_bodies_and_mu_of_rebounds_com():
    # mu = G (M + m): a massless body's barycentric orbit about M alone, as
    # a body about a single star of the total mass
    b = orbits.BodySet(units=orbits.UnitSystem.nbody())
    b.add("A", mass=0.6, position=[-0.4, 0, 0], velocity=[0, -0.3, 0])
    b.add("B", mass=0.4, position=[0.6, 0, 0], velocity=[0, 0.45, 0])
    b.add("probe", mass=0.0, position=[30, 0, 0], velocity=[0, math.sqrt(1 / 30), 0])
    o = b["probe"].orbit(primary="barycentre")
    # a circle of radius 30 about the barycentre (at rest at the origin)
    assert o.a.value == pytest.approx(30, rel=1e-14) and o.e.value < 1e-13


# -- sim.bodies: the current state ------------------------------------------------------

def test_sim_bodies_by_name_is_the_current_state_and_a_kept_view_a_snapshot():
    sim = orbits.Simulation(orbits.scenes.outer_solar_system(), "leapfrog", dt=10 * u.day)
    kept = sim.bodies["Jupiter"]
    start = kept.position
    result = sim.run(until=10 * u.yr, outputs=2, progress=False)
    now = sim.bodies["Jupiter"]
    assert np.array_equal(now.position, result.positions[-1, 1])
    assert np.array_equal(now.velocity, result.velocities[-1, 1])
    assert np.array_equal(kept.position, start)          # read before the run
    el = now.elements(primary="Sun")
    assert np.array_equal(el["a"], result.elements("Jupiter", primary="Sun")["a"][-1])


# -- result["name"] -----------------------------------------------------------------------

def test_a_track_is_the_bodys_column_of_the_outputs():
    # the outer solar system (six massive bodies): ias15's loop for small
    # systems, which other tests compile too; _system's seven massive bodies
    # would take the loop with gravity in vector lanes (18 s to compile)
    sim = orbits.Simulation(orbits.scenes.outer_solar_system(com=True), "ias15")
    result = sim.run(until=20 * u.yr, outputs=5, progress=False)
    track = result["Saturn"]
    assert isinstance(track, Track) and track.name == "Saturn" and track.index == 2
    assert len(track) == 5 and repr(track) == "<Track 'Saturn': 5 outputs>"
    assert np.array_equal(track.times, result.times)
    assert np.array_equal(track.positions, result.positions[:, 2])
    assert np.array_equal(track.velocities, result.velocities[:, 2])
    assert track.positions.unit == u.au and track.positions.shape == (5, 3)
    assert np.array_equal(track.masses, np.full(5, result.masses[2].value) << u.Msun)
    assert track.radius == result.radii[2]
    for primary in (None, "Sun", "barycentre"):
        ours = track.elements(primary=primary)
        theirs = result.elements("Saturn", primary=primary)
        assert all(np.array_equal(ours[k], theirs[k]) for k in theirs)
    assert np.array_equal(track.mutual_inclination("Jupiter"),
                          result.mutual_inclination("Saturn", "Jupiter"))
    assert "Saturn" in result and "Vulcan" not in result and 2 not in result


def test_a_result_is_indexed_by_name_only():
    result = orbits.Simulation(orbits.scenes.kepler(), "ias15").run(
        until=1 * u.yr, outputs=3, progress=False)
    with pytest.raises(TypeError, match="looked up by name"):
        result[0]
    with pytest.raises(TypeError, match="not iterable"):
        iter(result)
    with pytest.raises(UnknownBodyError, match="did you mean 'Planet'"):
        result["planet"]
    with pytest.raises(UnknownBodyError, match="did you mean 'Planet'"):
        result.elements("Plane")


def _crossing():
    # two planets on the circle of 1 au, one prograde and one retrograde,
    # 0.1 rad apart: they meet head on after about 2.9 d (as in
    # test_collision_resolution)
    b = orbits.BodySet()
    b.add("Star", mass=1 * u.Msun, radius=0.005 * u.au)
    vc = math.sqrt(orbits.UnitSystem().G)
    b.add("P1", mass=2e-3 * u.Msun, position=[1, 0, 0] * u.au,
          velocity=[0, vc, 0] * u.au / u.day, radius=0.01 * u.au)
    c, s = math.cos(0.1), math.sin(0.1)
    b.add("P2", mass=1e-3 * u.Msun, position=[c, s, 0] * u.au,
          velocity=[vc * s, -vc * c, 0] * u.au / u.day, radius=0.01 * u.au)
    b.move_to_com()
    return b


def test_a_track_is_nan_after_its_body_merged_away():
    sim = orbits.Simulation(_crossing(), "ias15", collisions="merge")
    res = sim.run(until=10 * u.day, outputs=11, progress=False)
    (row,) = res.collisions
    gone = res.times > row["step_time"]
    assert gone.any() and not gone.all()
    p2 = res["P2"]
    assert np.isnan(p2.positions[gone].value).all() and np.isnan(p2.masses[gone]).all()
    assert np.isfinite(p2.positions[~gone].value).all()
    assert np.isfinite(res["P1"].positions.value).all()
    el = p2.elements(primary="Star")
    assert np.isnan(el["a"][gone]).all() and np.isfinite(el["a"][~gone]).all()
    # P1 prograde, P2 retrograde on one circle: planes opposite until the merger
    incl = res.mutual_inclination("P1", "P2", primary="Star")
    assert np.isnan(incl[gone]).all()
    # the angle from atan2 keeps its accuracy at pi: the orbits stay in the
    # x-y plane to round-off (their z components are exactly zero)
    assert np.all(incl[~gone].value == math.pi)
    bary = res["P1"].elements(primary="barycentre")
    assert np.isfinite(bary["a"]).all()
