"""BodySet: construction, elements, frames, REBOUND round trip, and every bad input."""

import astropy.units as u
import numpy as np
import pytest

import orbits
from orbits.errors import (BodyError, BodyUnitsError, CoincidentBodiesError,
                           DuplicateBodyError, ElementsError, NoMassiveBodyError,
                           UnknownBodyError)


def sun_jupiter():
    b = orbits.BodySet()
    b.add("Sun", mass=1 * u.Msun)
    b.add("Jupiter", mass=1 * u.Mjup, primary="Sun", a=5.2 * u.au, e=0.048, inc=1.3 * u.deg)
    return b


def test_issue_example_builds():
    b = sun_jupiter()
    b.add("probe", mass=0 * u.kg, position=[1, 0, 0] * u.au, velocity=[0, 30, 0] * u.km / u.s)
    b.move_to_com()
    assert b.names == ["Sun", "Jupiter", "probe"]
    assert b.positions.unit == u.au and b.velocities.unit == u.au / u.day
    # probe's velocity converted once: 30 km/s in au/day
    np.testing.assert_allclose(b.velocities[2, 1] - b.velocities[0, 1] * 0,
                               b.velocities[2, 1])
    x, v = b.center_of_mass()
    # after move_to_com the centre of mass is at the origin to rounding (|x| ~ 5 au)
    assert np.all(np.abs(x.to_value(u.au)) < 1e-15 * 10)
    assert np.all(np.abs(v.to_value(u.au / u.day)) < 1e-18)
    assert b.total_mass.to_value(u.Msun) == pytest.approx(1 + (1 * u.Mjup).to_value(u.Msun),
                                                         rel=1e-15)


def test_elements_round_trip_through_bodyset():
    b = sun_jupiter()
    el = b.elements("Jupiter", primary="Sun")
    # elements -> state -> elements: ~50 flops each way, so 1e-12 is generous
    assert el["a"].to_value(u.au) == pytest.approx(5.2, rel=1e-12)
    assert el["e"].value == pytest.approx(0.048, abs=1e-12)
    assert el["inc"].to_value(u.deg) == pytest.approx(1.3, rel=1e-12)


def test_hyperbolic_orbit_by_elements():
    b = orbits.BodySet()
    b.add("Sun", mass=1 * u.Msun)
    b.add("comet", mass=0 * u.kg, primary="Sun", a=-2 * u.au, e=1.5, f=30 * u.deg)
    el = b.elements("comet", primary="Sun")
    assert el["a"].to_value(u.au) == pytest.approx(-2, rel=1e-12)
    assert el["e"].value == pytest.approx(1.5, rel=1e-12)
    assert el["f"].to_value(u.deg) == pytest.approx(30, rel=1e-12)


def test_mean_anomaly_and_default_primary():
    b = orbits.BodySet()
    b.add("Sun", mass=1 * u.Msun)
    b.add("p", mass=1e-3 * u.Msun, a=1 * u.au, e=0.3, M=2 * u.rad)   # primary: the Sun
    el = b.elements("p", primary="Sun")
    assert el["M"].to_value(u.rad) == pytest.approx(2.0, rel=1e-12)


def test_from_arrays_with_explicit_units():
    hlw = orbits.UnitSystem(length=u.au, mass=u.Msun, time=u.day, G=2.95912208286e-4)
    b = orbits.BodySet.from_arrays([1.0, 1e-3], [[0, 0, 0], [5, 0, 0]],
                                   [[0, 0, 0], [0, 0.0075, 0]], names=["a", "b"], units=hlw)
    assert b.units.G == 2.95912208286e-4
    assert b.positions[1, 0] == 5 * u.au


def test_rebound_round_trip():
    import rebound
    b = sun_jupiter()
    sim = b.to_rebound()
    assert sim.G == b.units.G
    back = orbits.BodySet.from_rebound(sim, units=b.units, names=b.names)
    # plain float copies: exact
    assert np.array_equal(back.positions.value, b.positions.value)
    assert np.array_equal(back.velocities.value, b.velocities.value)
    assert isinstance(sim, rebound.Simulation)


# -- physical radii ------------------------------------------------------------------

def sized():
    # a massless body first, so that a simulation's internal order (massive
    # bodies first) differs from the set's and a radius put back in the wrong
    # row shows
    b = orbits.BodySet()
    b.add("probe", mass=0 * u.kg, position=[3, 0, 0] * u.au,
          velocity=[0, 0.01, 0] * u.au / u.day, radius=10 * u.m)
    b.add("Sun", mass=1 * u.Msun, radius=1 * u.Rsun)
    b.add("Jupiter", mass=1 * u.Mjup, primary="Sun", a=5.2 * u.au, e=0.048,
          radius=71492 * u.km)
    return b


def test_radii_given_in_any_length_unit_come_back_in_the_sets_unit():
    b = sized()
    assert b.radii.unit == u.au and b.radii.shape == (3,)
    assert b._r.dtype == np.float64
    np.testing.assert_allclose(b.radii.to_value(u.km), [0.01, 695700, 71492], rtol=1e-14)
    b.add("rock", mass=0 * u.kg, position=[7, 0, 0] * u.au)        # no radius: a point
    assert b.radii[-1] == 0 * u.au
    r = [0.5, 0.002] * u.km
    a = orbits.BodySet.from_arrays([1, 1e-3] * u.Msun, [[0, 0, 0], [1, 0, 0]] * u.au,
                                   np.zeros((2, 3)) * u.au / u.day, radii=r)
    np.testing.assert_allclose(a.radii.to_value(u.km), [0.5, 0.002], rtol=1e-14)
    default = orbits.BodySet.from_arrays([1, 1e-3] * u.Msun, [[0, 0, 0], [1, 0, 0]] * u.au,
                                         np.zeros((2, 3)) * u.au / u.day)
    assert np.array_equal(default.radii.value, [0.0, 0.0])
    # plain numbers with an explicit unit system are read in it, as masses are
    U = orbits.UnitSystem.nbody()
    n = orbits.BodySet.from_arrays([1.0, 1.0], [[0, 0, 0], [1, 0, 0]], np.zeros((2, 3)),
                                   units=U, radii=[0.25, 0.125])
    assert n.radii.value.tolist() == [0.25, 0.125]


@pytest.mark.parametrize("radius, error", [
    (-1 * u.km, BodyError), (np.nan * u.km, BodyError), (np.inf * u.au, BodyError),
    (1 * u.kg, BodyUnitsError), (1.0, BodyUnitsError), ([1, 2] * u.km, BodyError),
])
def test_bad_radius_names_the_body_and_the_field(radius, error):
    b = orbits.BodySet()
    with pytest.raises(error) as exc:
        b.add("X", mass=1 * u.Msun, radius=radius)
    assert exc.value.body == "X" and exc.value.field == "radius"
    assert "'X'" in str(exc.value) and "radius" in str(exc.value)
    assert len(b) == 0 and len(b._r) == 0  # nothing half-added


def test_bad_radii_in_arrays():
    U = orbits.UnitSystem.nbody()
    m, x, v = [1.0, 1.0], [[0, 0, 0], [1, 0, 0]], np.zeros((2, 3))
    with pytest.raises(BodyError, match="radii.*shape") as exc:
        orbits.BodySet.from_arrays(m, x, v, units=U, radii=[1.0, 2.0, 3.0])
    assert exc.value.field == "radii"
    with pytest.raises(BodyError) as exc:
        orbits.BodySet.from_arrays(m, x, v, names=["a", "b"], units=U, radii=[0.1, -0.1])
    assert exc.value.body == "b" and exc.value.field == "radius"
    with pytest.raises(BodyError) as exc:
        orbits.BodySet.from_arrays(m, x, v, names=["a", "b"], units=U, radii=[np.nan, 0.1])
    assert exc.value.body == "a" and exc.value.field == "radius"
    with pytest.raises(BodyUnitsError) as exc:
        orbits.BodySet.from_arrays([1, 1] * u.Msun, x * u.au, v * u.au / u.day,
                                   radii=[1, 2] * u.s)
    assert exc.value.field == "radii"


def test_copy_and_subset_keep_radii():
    b = sized()
    c = b.copy()
    assert np.array_equal(c.radii.value, b.radii.value)
    c.add("moon", mass=0 * u.kg, position=[9, 0, 0] * u.au, radius=1737 * u.km)
    assert len(b.radii) == 3 and len(c.radii) == 4          # independent
    keep = [2, 0]
    sub = orbits.BodySet.from_arrays(b.masses[keep], b.positions[keep], b.velocities[keep],
                                     names=[b.names[k] for k in keep], radii=b.radii[keep])
    assert np.array_equal(sub.radii.value, b.radii.value[keep])
    b.move_to_com()                                          # moves states, not radii
    assert np.array_equal(b.radii.value, c.radii.value[:3])


def test_simulation_keeps_radii_in_the_sets_order():
    b = sized()
    sim = orbits.Simulation(b, integrator="leapfrog", dt=1 * u.day)
    sim.run(until=20 * u.day, outputs=3, progress=False)
    after = sim.bodies
    assert after.names == b.names
    assert np.array_equal(after.radii.value, b.radii.value)
    assert after.radii.unit == u.au
    assert np.array_equal(sim.description().radii, b.radii.value)
    result = sim.run(until=30 * u.day, outputs=2, progress=False)
    assert np.array_equal(result.radii.value, b.radii.value) and result.radii.unit == u.au


def test_rebound_round_trip_keeps_radii():
    b = sized()
    sim = b.to_rebound()
    assert [p.r for p in sim.particles] == b.radii.value.tolist()
    sim.particles[1].r = 0.125
    back = orbits.BodySet.from_rebound(sim, units=b.units, names=b.names)
    assert back.radii.value.tolist() == [b.radii.value[0], 0.125, b.radii.value[2]]


# -- bad input: each names the body and the field -------------------------------------

@pytest.mark.parametrize("kwargs, field", [
    (dict(mass=np.nan * u.Msun), "mass"),
    (dict(mass=np.inf * u.Msun), "mass"),
    (dict(mass=-1 * u.Msun), "mass"),
    (dict(mass=1 * u.Msun, position=[np.nan, 0, 0] * u.au), "position"),
    (dict(mass=1 * u.Msun, position=[1, 0, 0] * u.au, velocity=[np.inf, 0, 0] * u.km / u.s),
     "velocity"),
    (dict(mass=1 * u.Msun, position=[1, 0] * u.au), "position"),
])
def test_bad_values(kwargs, field):
    b = orbits.BodySet()
    with pytest.raises(BodyError) as exc:
        b.add("X", **kwargs)
    assert exc.value.body == "X" and exc.value.field == field
    assert "'X'" in str(exc.value) and field in str(exc.value)
    assert len(b) == 0  # nothing half-added


@pytest.mark.parametrize("kwargs, field", [
    (dict(mass=1 * u.m), "mass"),
    (dict(mass=1.0), "mass"),                                          # bare number
    (dict(mass=1 * u.Msun, position=[1, 0, 0] * u.s), "position"),
    (dict(mass=1 * u.Msun, position=[1, 0, 0] * u.au, velocity=[1, 0, 0] * u.au), "velocity"),
])
def test_wrong_physical_type_or_bare_number(kwargs, field):
    b = orbits.BodySet()
    with pytest.raises(BodyUnitsError) as exc:
        b.add("X", **kwargs)
    assert exc.value.field == field
    assert isinstance(exc.value, u.UnitsError)


def test_bare_numbers_allowed_with_explicit_units():
    b = orbits.BodySet(units=orbits.UnitSystem.nbody())
    b.add("a", mass=1.0, position=[0, 0, 0], velocity=[0, 0, 0])
    assert b.masses[0].value == 1.0


@pytest.mark.parametrize("a, e, field", [
    (1.0, 1.0, "e"), (1.0, 1.5, "e"), (-1.0, 0.5, "e"), (1.0, -0.1, "e"),
    (0.0, 0.1, "a"), (np.nan, 0.1, "a"),
])
def test_bad_elements(a, e, field):
    b = orbits.BodySet()
    b.add("Sun", mass=1 * u.Msun)
    with pytest.raises(ElementsError) as exc:
        b.add("p", mass=0 * u.kg, primary="Sun", a=a * u.au, e=e)
    assert exc.value.body == "p" and exc.value.field == field


def test_hyperbola_beyond_asymptote():
    b = orbits.BodySet()
    b.add("Sun", mass=1 * u.Msun)
    with pytest.raises(ElementsError, match="'p'"):
        b.add("p", mass=0 * u.kg, primary="Sun", a=-1 * u.au, e=1.5, f=170 * u.deg)


def test_unknown_primary_and_duplicate_name():
    b = sun_jupiter()
    with pytest.raises(UnknownBodyError, match="Saturn.*known bodies: Sun, Jupiter"):
        b.add("Io", mass=0 * u.kg, primary="Saturn", a=0.003 * u.au)
    with pytest.raises(DuplicateBodyError, match="'Jupiter'"):
        b.add("Jupiter", mass=1 * u.Mjup, position=[1, 2, 3] * u.au)


@pytest.mark.parametrize("name, what", [("Pla\0net", "NUL"), ("Pla\ud800net", "surrogate")])
def test_a_name_an_output_file_cannot_hold_is_refused_where_it_enters(name, what):
    # an HDF5 file holds neither a NUL nor a lone surrogate: without this check
    # the set is made, and a run writing a file fails at its first write
    b = sun_jupiter()
    with pytest.raises(BodyError, match=what) as exc:
        b.add(name, mass=0 * u.kg, position=[1, 0, 0] * u.au)
    assert exc.value.body == name and exc.value.field == "name"
    assert b.names == ["Sun", "Jupiter"]
    U = orbits.UnitSystem.nbody()
    with pytest.raises(BodyError, match=what):
        orbits.BodySet.from_arrays([1, 0], [[0, 0, 0], [1, 0, 0]], np.zeros((2, 3)),
                                   names=["Sun", name], units=U)


def test_wrong_array_shapes():
    U = orbits.UnitSystem.nbody()
    with pytest.raises(BodyError, match="positions.*shape \\(2, 3\\)"):
        orbits.BodySet.from_arrays([1, 1], [[0, 0, 0]], [[0, 0, 0], [0, 0, 0]], units=U)
    with pytest.raises(BodyError, match="velocities"):
        orbits.BodySet.from_arrays([1, 1], np.zeros((2, 3)), np.zeros((2, 2)), units=U)
    with pytest.raises(BodyError, match="names"):
        orbits.BodySet.from_arrays([1, 1], np.zeros((2, 3)), np.zeros((2, 3)),
                                   names=["a"], units=U)
    with pytest.raises(BodyError, match="body '1'.*mass"):
        orbits.BodySet.from_arrays([1, -1], [[0, 0, 0], [1, 0, 0]], np.zeros((2, 3)), units=U)


def test_no_massive_body_and_coincident_bodies():
    U = orbits.UnitSystem.nbody()
    b = orbits.BodySet(units=U)
    b.add("a", mass=0.0, position=[1, 0, 0])
    with pytest.raises(NoMassiveBodyError):
        b.check()
    with pytest.raises(NoMassiveBodyError):
        orbits.Simulation(b, dt=0.1)
    b.add("b", mass=1.0, position=[0, 0, 0])
    b.add("c", mass=1.0, position=[1, 0, 0])
    with pytest.raises(CoincidentBodiesError, match="'a'.*'c'"):
        orbits.Simulation(b, dt=0.1)


def test_history_describes_quantities_as_str_does():
    # the record of how bodies were made writes each element as str() would
    # (with each unit's string formatted once, not at every add)
    from orbits.bodies._input import describe as _describe
    for value in (12.0 * u.au, 0.1 * u.one, 180 * u.deg, np.array([1.0, 2.0]) * u.au / u.day,
                  0 * u.kg, 0.1, 5, 1e-300 * u.au, 3.0 * u.au ** 3 / u.yr ** 2):
        assert _describe(value) == str(value)


@pytest.mark.parametrize("n", [3, 100])
def test_coincident_bodies_are_named_for_few_and_many(n):
    # a few bodies are compared pair by pair, many through np.unique: the
    # same error, naming the first of the pair and the other
    x = np.arange(3.0 * n).reshape(n, 3)
    x[n - 1] = x[1]
    b = orbits.BodySet.from_arrays(np.ones(n) * u.Msun, x * u.au, np.zeros((n, 3)) * u.au / u.day,
                                   names=[f"b{k}" for k in range(n)])
    with pytest.raises(CoincidentBodiesError) as exc:
        b.check()
    assert exc.value.body == "b1" and f"'b{n - 1}'" in str(exc.value)
