"""Tests of the ready-made scenes: each builds, and each has the numbers of its source."""

import math
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import astropy.units as u
import numpy as np
import pytest
from astropy.time import Time
from scipy.integrate import solve_ivp
from scipy.spatial.distance import pdist

from orbits import scenes
from orbits.bodies import BodySet
from orbits.errors import EpochError
from orbits.errors import ElementsError
from orbits.units import UnitSystem

REPO = Path(__file__).resolve().parents[1]


def energy(bodies):
    """Total energy in the set's units, by a plain O(N^2) sum."""
    m = bodies.masses.value
    x = bodies.positions.value
    v = bodies.velocities.value
    kinetic = 0.5 * np.sum(m * np.sum(v * v, axis=1))
    i, j = np.triu_indices(len(m), k=1)
    potential = -bodies.units.G * np.sum(m[i] * m[j] / pdist(x))
    return kinetic, potential


def momentum(bodies):
    return (bodies.masses.value[:, None] * bodies.velocities.value).sum(axis=0)


def angular_momentum(bodies):
    m = bodies.masses.value[:, None]
    return (m * np.cross(bodies.positions.value, bodies.velocities.value)).sum(axis=0)


# -- the registry ------------------------------------------------------------------
@pytest.mark.parametrize("name", sorted(scenes.SCENES))
def test_every_scene_builds_checks_and_records_itself(name):
    bodies = scenes.get(name)
    assert isinstance(bodies, BodySet)
    bodies.check()
    assert bodies.history[-1]["scene"] == name


@pytest.mark.parametrize("name", sorted(scenes.SCENES))
def test_every_scene_is_a_fresh_set(name):
    first = scenes.get(name)
    first.add("visitor", mass=first.masses[0], position=first.positions[0] + 1 * first.units.length)
    first.move_to_com()
    second = scenes.get(name)
    assert "visitor" not in second
    assert not np.array_equal(first.positions.value[0], second.positions.value[0])


def test_every_scene_function_has_source_units_and_example():
    for function in scenes.SCENES.values():
        doc = function.__doc__
        assert "References" in doc and "Examples" in doc and "Returns" in doc
    assert {f.__name__ for f in scenes.SCENES.values()} <= set(scenes.__all__)


def test_get_unknown_name_lists_the_valid_ones():
    with pytest.raises(ValueError) as info:
        scenes.get("inner-solar-system")
    for name in scenes.SCENES:
        assert name in str(info.value)


def test_get_reads_underscores_as_hyphens_and_passes_options():
    assert scenes.get("outer_solar_system").names[1] == "Jupiter"
    assert len(scenes.get("plummer", n=50, seed=3)) == 50


def test_describe_gives_one_line_per_scene():
    pairs = scenes.describe()
    assert [name for name, _ in pairs] == list(scenes.SCENES)
    for _, line in pairs:
        assert line and "\n" not in line


# -- Earth and Moon ------------------------------------------------------------------
# The elements go through elements -> state -> elements in float64 with
# numbers of order 1e5 km; 1e-12 relative leaves a factor of ~100 over the
# rounding of the round trip.
ROUND_TRIP = 1e-12


def test_earth_moon_elements_and_masses():
    bodies = scenes.earth_moon()
    assert bodies.names == ["Earth", "Moon"]
    el = bodies.elements("Moon", primary="Earth")
    assert el["a"].to_value(u.km) == pytest.approx(384_400, rel=ROUND_TRIP)
    assert el["e"].value == pytest.approx(0.0549, rel=ROUND_TRIP)
    # G * m equals the DE440 GM values (gm_de440.tpc) to rounding.
    gm = (bodies.units.G * bodies.masses.value) << (u.km ** 3 / u.day ** 2)
    assert gm.to_value(u.km ** 3 / u.s ** 2) == pytest.approx(
        [398600.43550702266, 4902.8001184575496], rel=1e-14)
    assert bodies.masses[0] == 1 * u.Mearth
    assert np.allclose(momentum(bodies), 0, atol=1e-12)  # ~1e5 km/day * 1e-16
    assert np.allclose(bodies.center_of_mass()[0].value, 0, atol=1e-9)


def test_sun_earth_moon_orbits():
    bodies = scenes.sun_earth_moon()
    assert bodies.names == ["Sun", "Earth", "Moon"]
    moon = bodies.elements("Moon", primary="Earth")
    assert moon["a"].to_value(u.km) == pytest.approx(384_400, rel=ROUND_TRIP)
    assert moon["e"].value == pytest.approx(0.0549, rel=ROUND_TRIP)
    assert moon["inc"].to_value(u.deg) == pytest.approx(5.145, rel=ROUND_TRIP)
    # The Earth-Moon barycentre, not the Earth, is on the 1 au ellipse.
    m = bodies.masses.value
    x, v = bodies.positions.value, bodies.velocities.value
    emb = BodySet.from_arrays(
        [m[0], m[1] + m[2]], [x[0], (m[1] * x[1] + m[2] * x[2]) / (m[1] + m[2])],
        [v[0], (m[1] * v[1] + m[2] * v[2]) / (m[1] + m[2])], names=["Sun", "EMB"],
        units=bodies.units)
    el = emb.elements("EMB", primary="Sun")
    assert el["a"].to_value(u.au) == pytest.approx(1.0, rel=ROUND_TRIP)
    assert el["e"].value == pytest.approx(0.0167, rel=1e-10)  # e from a difference of O(1) terms
    assert np.allclose(momentum(bodies), 0, atol=1e-18)  # Msun au/day; masses ~1, v ~0.02


# -- Kepler ----------------------------------------------------------------------------
def test_kepler_defaults_start_away_from_apsis():
    bodies = scenes.kepler(e=0.3)
    el = bodies.elements("Planet", primary="Star")
    assert el["f"].to_value(u.rad) == pytest.approx(1.0, rel=1e-12)
    assert el["a"].to_value(u.au) == pytest.approx(1.0, rel=1e-12)
    assert el["e"].value == pytest.approx(0.3, rel=1e-12)
    assert bodies.masses.to_value(u.Msun) == pytest.approx([1.0, 1e-3])
    assert np.allclose(momentum(bodies), 0, atol=1e-18)


@pytest.mark.parametrize("e, a", [(0.0, 1.0), (0.9, 2.0), (1.5, -1.0), (3.0, -0.5)])
def test_kepler_energy_is_the_two_body_value(e, a):
    bodies = scenes.kepler(e=e, a=a * u.au)
    kinetic, potential = energy(bodies)
    G = bodies.units.G
    expected = -G * 1.0 * 1e-3 / (2 * a)  # E = -G m1 m2 / (2a), hyperbolic too
    # Two terms of size ~G m1 m2 / r cancel to the result; 1e-12 relative is ~100 ulps.
    assert kinetic + potential == pytest.approx(expected, rel=1e-12)


def test_kepler_rejects_elements_that_describe_no_orbit():
    with pytest.raises(ElementsError):
        scenes.kepler(e=1.5)  # a > 0 with e > 1
    with pytest.raises(ElementsError):
        scenes.kepler(e=-0.1)
    with pytest.raises(ElementsError):
        scenes.kepler(e=1.0)


def test_kepler_accepts_plain_numbers_with_explicit_units():
    bodies = scenes.kepler(e=0.1, a=2.0, f=0.5, m_central=1.0, m_orbiter=0.0, inc=0.2,
                           units=UnitSystem.nbody())
    el = bodies.elements("Planet", primary="Star")
    assert el["a"].value == pytest.approx(2.0, rel=1e-12)
    assert el["inc"].value == pytest.approx(0.2, rel=1e-12)


# -- Hairer, Lubich & Wanner ------------------------------------------------------------
def test_outer_solar_system_has_the_book_numbers():
    bodies = scenes.outer_solar_system()
    assert bodies.names == ["Sun", "Jupiter", "Saturn", "Uranus", "Neptune", "Pluto"]
    assert bodies.units.G == 2.95912208286e-4
    assert bodies.units.length == u.au and bodies.units.time == u.day
    m = bodies.masses.to_value(u.Msun)
    assert list(m) == [1.00000597682, 0.000954786104043, 0.000285583733151,
                       0.0000437273164546, 0.0000517759138449, 1 / 1.3e8]
    # Spot checks against Hairer, Lubich & Wanner (2006), table I.2.1, exactly.
    x = bodies.positions.to_value(u.au)
    v = bodies.velocities.to_value(u.au / u.day)
    assert list(x[1]) == [-3.5023653, -3.8169847, -1.5507963]
    assert list(v[1]) == [0.00565429, -0.00412490, -0.00190589]
    assert list(x[4]) == [11.4707666, -25.7294829, -10.8169456]
    assert list(x[5]) == [-15.5387357, -25.2225594, -3.1902382]
    assert list(v[5]) == [0.00276725, -0.00170702, -0.00136504]
    assert list(x[0]) == [0.0, 0.0, 0.0] and list(v[0]) == [0.0, 0.0, 0.0]


def test_outer_solar_system_com_option():
    bodies = scenes.outer_solar_system(com=True)
    assert np.allclose(momentum(bodies), 0, atol=1e-19)  # ~1e-5 Msun au/day * 1e-16
    assert np.allclose(bodies.center_of_mass()[0].value, 0, atol=1e-15)
    # The move keeps the relative configuration.
    published = scenes.outer_solar_system()
    rel = bodies.positions[1:] - bodies.positions[0]
    assert np.allclose(rel.value, published.positions[1:].value, rtol=0, atol=1e-14)


# -- the solar system from astropy's built-in ephemeris -------------------------------------
@pytest.fixture(scope="module")
def j2000():
    return scenes.solar_system()


def _distance(bodies, a, b):
    return np.linalg.norm(bodies.positions[bodies.index(a)] - bodies.positions[bodies.index(b)])


def test_solar_system_bodies_and_frame(j2000):
    assert j2000.names == ["Sun", "Mercury", "Venus", "Earth", "Moon", "Mars", "Jupiter",
                           "Saturn", "Uranus", "Neptune"]
    assert np.allclose(momentum(j2000), 0, atol=1e-19)  # ~1e-5 Msun au/day * 1e-14
    assert np.allclose(j2000.center_of_mass()[0].value, 0, atol=1e-15)


def test_solar_system_distances_at_j2000(j2000):
    # The Earth's perihelion was on 2000 January 3 at 0.98328 au (Astronomical
    # Almanac); at J2000, 1.5 days before, the distance differs by < 1e-5 au.
    assert _distance(j2000, "Earth", "Sun").to_value(u.au) == pytest.approx(0.98333,
                                                                           abs=1e-3)
    # The Moon is always between perigee and apogee extremes.
    assert 356_000 < _distance(j2000, "Moon", "Earth").to_value(u.km) < 407_000


# J2000 mean elements of Standish, "Keplerian elements for approximate positions of
# the major planets" (JPL SSD, table 1): a in au, inclination to the ecliptic in deg.
STANDISH = {"Mercury": (0.38709927, 7.00497902), "Venus": (0.72333566, 3.39467605),
            "Earth": (1.00000261, 0.0), "Mars": (1.52371034, 1.84969142),
            "Jupiter": (5.20288700, 1.30439695), "Saturn": (9.53667594, 2.48599187),
            "Uranus": (19.18916464, 0.77263783), "Neptune": (30.06992276, 1.77004347)}


@pytest.mark.parametrize("planet", list(STANDISH))
def test_solar_system_planets_osculating_elements(j2000, planet):
    a_mean, inc_mean = STANDISH[planet]
    el = j2000.elements(planet, primary="Sun")
    # Osculating heliocentric elements differ from mean ones by planetary
    # perturbations: up to 0.3% in a (Saturn, Uranus) and ~0.01 deg in inc.
    assert el["a"].to_value(u.au) == pytest.approx(a_mean, rel=0.01)
    # 0.05 deg would fail for a wrong obliquity by far (it is 23.4 deg).
    assert el["inc"].to_value(u.deg) == pytest.approx(inc_mean, abs=0.05)


def test_solar_system_icrs_frame_is_the_equatorial_one(j2000):
    icrs = scenes.solar_system(frame="icrs")
    eps = (84381.406 * u.arcsec).to_value(u.rad)
    y, z = icrs.positions.value[:, 1], icrs.positions.value[:, 2]
    rotated = np.column_stack([icrs.positions.value[:, 0],
                               math.cos(eps) * y + math.sin(eps) * z,
                               -math.sin(eps) * y + math.cos(eps) * z])
    assert np.allclose(rotated, j2000.positions.value, rtol=0, atol=1e-14)
    # The Earth is ~0.38 au out of the ICRS xy plane at J2000, and in the ecliptic.
    assert abs(icrs.positions.value[3, 2]) > 0.3
    assert abs(j2000.positions.value[3, 2]) < 1e-3
    with pytest.raises(ValueError, match="frame"):
        scenes.solar_system(frame="galactic")


def test_solar_system_without_moon_uses_the_barycentre(j2000):
    bodies = scenes.solar_system(moon=False)
    assert "Moon" not in bodies and len(bodies) == 9
    m_earth = bodies.masses[bodies.index("Earth")]
    assert m_earth.value == pytest.approx(j2000.masses[3].value + j2000.masses[4].value,
                                          rel=1e-15)
    emb = (j2000.masses[3] * j2000.positions[3] + j2000.masses[4] * j2000.positions[4]) \
        / (j2000.masses[3] + j2000.masses[4])
    # Both sets have the same mass and momentum, so the same COM shift.
    assert np.allclose(bodies.positions[3].value, emb.value, rtol=0, atol=1e-15)
    # The builtin "earth-moon-barycenter" is plan94's, quoted good to 1000 km
    # (ERFA's plan94 notes); ours, from epv00 and moon98, to ~10 km.  Weighting
    # the pair the wrong way round would put it ~380,000 km off.
    from astropy.coordinates import get_body_barycentric
    plan94 = get_body_barycentric("earth-moon-barycenter",
                                  Time("2000-01-01 12:00:00", scale="tdb"), "builtin")
    icrs = scenes.solar_system(moon=False, frame="icrs")
    shift = icrs.positions[0] - (get_body_barycentric(
        "sun", Time("2000-01-01 12:00:00", scale="tdb"), "builtin").xyz)
    assert np.linalg.norm(icrs.positions[3] - shift - plan94.xyz).to_value(u.km) < 1500


def test_solar_system_epoch_as_string_or_time(j2000):
    same = scenes.solar_system(Time("2000-01-01 12:00:00", scale="tdb"))
    assert np.array_equal(same.positions.value, j2000.positions.value)
    # TT and TDB differ by < 2 ms; the Moon moves 2 m in that time.
    tt = scenes.solar_system(Time("2000-01-01 12:00:00", scale="tt"))
    assert np.allclose(tt.positions.value, j2000.positions.value, rtol=0, atol=1e-10)
    # a number is a Julian date in TDB, as de421 and de421_states read it
    assert np.array_equal(scenes.solar_system(2451545.0).positions.value,
                          j2000.positions.value)
    with pytest.raises(EpochError):
        scenes.solar_system([2451545.0])


# Run in a fresh interpreter after this, so that nothing cached by other tests
# (leap seconds, IERS tables, ephemeris files) can hide a download.
NO_NETWORK = textwrap.dedent("""
    import socket
    def refuse(*args, **kwargs):
        raise OSError("network access attempted")
    class NoNetwork(socket.socket):
        connect = connect_ex = sendto = refuse
    socket.socket = NoNetwork
    socket.create_connection = socket.getaddrinfo = refuse
""")


def test_solar_system_never_touches_the_network():
    script = NO_NETWORK + textwrap.dedent("""
        from astropy.time import Time
        from orbits import scenes
        a = scenes.solar_system("2024-03-01 00:00:00")
        b = scenes.solar_system(Time("2024-03-01 00:00:00", scale="utc"))
        print(len(a), len(b))
    """)
    out = subprocess.run([sys.executable, "-c", script], cwd=REPO, capture_output=True,
                         text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["10", "10"]


# -- the solar system from JPL DE421 --------------------------------------------------------
DE421_NAMES = ["Sun", "Mercury", "Venus", "Earth", "Moon", "Mars", "Jupiter", "Saturn",
               "Uranus", "Neptune", "Pluto"]


@pytest.fixture(scope="module")
def de421():
    pytest.importorskip("jplephem")
    pytest.importorskip("de421")
    return scenes.de421()


def test_de421_bodies_and_units(de421):
    assert de421.names == DE421_NAMES
    assert de421.units.length == u.au and de421.units.time == u.day
    assert de421.masses[0] == 1 * u.Msun
    # G m gives back DE421's GM values in km^3/s^2, which the header stores in
    # (DE421 au)^3/day^2: these round decimals come back to ~1e-15, so the
    # 7.5e-12 of using the IAU au for DE421's would show.
    gm = ((de421.units.G * de421.masses.value) << (u.au ** 3 / u.day ** 2)).to_value(
        u.km ** 3 / u.s ** 2)
    published = {0: 132712440040.944, 1: 22032.09, 2: 324858.592, 5: 42828.375214,
                 6: 126712764.8, 7: 37940585.2, 8: 5794548.6, 9: 6836535.0, 10: 977.0}
    for i, value in published.items():
        assert gm[i] == pytest.approx(value, rel=1e-13), de421.names[i]
    assert gm[3] / gm[4] == pytest.approx(81.3005690699153, rel=1e-14)  # EMRAT


def test_de421_constants_are_the_ephemeris_header():
    pytest.importorskip("jplephem")
    de421_package = pytest.importorskip("de421")
    from jplephem.ephem import Ephemeris

    header = Ephemeris(de421_package)
    assert header.DENUM == 421
    from orbits.scenes import ephemerides
    for key, value in ephemerides._GM_DE421.items():
        assert value == getattr(header, key), key
    assert ephemerides._EMRAT_DE421 == header.EMRAT
    assert scenes.DE421_AU.to_value(u.km) == header.AU


def test_de421_geometry_at_j2000(de421):
    # Perihelion was on 2000 January 3 at 0.98329 au; 1.5 days before it the
    # distance differs by < 1e-5 au.
    assert _distance(de421, "Earth", "Sun").to_value(u.au) == pytest.approx(0.98329,
                                                                           abs=1e-4)
    # The Sun's barycentric wobble is ~0.01 au; at J2000 it was 0.0077 au.
    assert np.linalg.norm(de421.positions[0]).to_value(u.au) < 0.01
    assert 356_000 < _distance(de421, "Moon", "Earth").to_value(u.km) < 407_000
    # The xy plane is the equator: the Earth is ~0.38 au north of it at J2000.
    assert de421.positions[3, 2].to_value(u.au) == pytest.approx(0.384, abs=1e-3)


def test_de421_agrees_with_astropy_builtin_earth(de421):
    # ERFA's epv00 gives the Earth to ~5 km (its documentation, against DE405);
    # DE421 and epv00 differed by 4.2 km and 1 cm/s at J2000.  A km/au or
    # day/second slip, or a wrong Earth-Moon split (~4,700 km), would be far off.
    icrs = scenes.solar_system(frame="icrs")
    earth = icrs.index("Earth")
    r = de421.positions[3] - de421.positions[0]
    w = de421.velocities[3] - de421.velocities[0]
    assert np.linalg.norm(r - (icrs.positions[earth] - icrs.positions[0])).to_value(u.km) < 20
    assert np.linalg.norm(w - (icrs.velocities[earth] - icrs.velocities[0])).to_value(
        u.m / u.s) < 0.1


def test_de421_momentum_is_that_of_the_barycentre(de421):
    m = de421.masses.value
    v = de421.velocities.value
    # DE421's barycentre also holds 343 asteroids, ~1e-9 Msun at ~0.01 au/day:
    # ~1e-11 Msun au/day against sum m|v| = 1.9e-5, so 3.6e-7 remains.  A
    # mass or velocity wrong by 1% for any planet would give > 1e-4.
    assert np.linalg.norm(momentum(de421)) / np.sum(m * np.linalg.norm(v, axis=1)) < 1e-6
    assert np.linalg.norm(de421.center_of_mass()[0].to_value(u.au)) < 1e-8
    moved = scenes.de421(com=True)
    assert np.allclose(momentum(moved), 0, atol=1e-19)  # ~1e-5 Msun au/day * 1e-14
    assert moved.history[-1] == {**de421.history[-1], "com": True}


def test_de421_never_touches_the_network():
    pytest.importorskip("jplephem")
    pytest.importorskip("de421")
    script = NO_NETWORK + textwrap.dedent("""
        from orbits import scenes
        print(len(scenes.de421()))
    """)
    out = subprocess.run([sys.executable, "-c", script], cwd=REPO, capture_output=True,
                         text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["11"]


@pytest.mark.parametrize("missing", ["jplephem", "de421"])
def test_de421_without_its_packages_names_the_extra(monkeypatch, missing):
    monkeypatch.setitem(sys.modules, missing, None)
    monkeypatch.delitem(sys.modules, "jplephem.ephem", raising=False)
    with pytest.raises(ImportError, match=r'pip install "orbits\[ephemeris\]"'):
        scenes.de421()


# -- N-body units ------------------------------------------------------------------------
def test_pythagorean_energy_by_hand():
    bodies = scenes.pythagorean()
    assert bodies.units.G == 1.0
    assert list(bodies.masses.value) == [3.0, 4.0, 5.0]
    assert not np.any(bodies.velocities.value)
    kinetic, potential = energy(bodies)
    # Sides 5 (3-4), 4 (3-5) and 3 (4-5): -(12/5 + 15/4 + 20/3) = -769/60.
    assert kinetic == 0.0
    assert potential == pytest.approx(-769 / 60, rel=1e-15)
    assert list(bodies.positions.value[:, :2].ravel()) == [1, 3, -2, -1, 1, -1]


def test_figure_eight_invariants():
    bodies = scenes.figure_eight()
    assert np.array_equal(momentum(bodies), np.zeros(3))
    assert np.allclose(angular_momentum(bodies), 0, atol=1e-15)
    kinetic, potential = energy(bodies)
    v3 = math.hypot(0.93240737, 0.86473146)
    r = math.hypot(0.97000436, 0.24308753)
    # By hand: T = (|v3|^2 + 2 |v3/2|^2) / 2; U = -(1/r + 1/r + 1/(2r)).
    assert kinetic + potential == pytest.approx(0.75 * v3 ** 2 - 2.5 / r, rel=1e-14)
    assert kinetic + potential == pytest.approx(-1.28714, abs=1e-5)


def test_figure_eight_is_periodic_and_a_choreography():
    bodies = scenes.figure_eight()
    m, x0, v0 = bodies.masses.value, bodies.positions.value, bodies.velocities.value

    def rhs(t, y):
        x = y[:9].reshape(3, 3)
        d = x[None, :, :] - x[:, None, :]
        r3 = np.sum(d * d, axis=2) ** 1.5
        np.fill_diagonal(r3, np.inf)
        return np.concatenate([y[9:], (m[None, :, None] * d / r3[:, :, None]).sum(1).ravel()])

    y0 = np.concatenate([x0.ravel(), v0.ravel()])
    T = scenes.FIGURE_EIGHT_PERIOD
    sol = solve_ivp(rhs, (0, T), y0, method="DOP853", rtol=1e-12, atol=1e-12,
                    dense_output=True)
    # The initial conditions have 8 digits; the orbit closes to 4e-8.  A period
    # wrong in its 6th digit would miss by > 1e-5.
    assert np.max(np.abs(sol.y[:, -1] - y0)) < 1e-6
    # After T/3 each body is where the next one started.
    third = sol.sol(T / 3)[:9].reshape(3, 3)
    assert np.allclose(third, x0[[2, 0, 1]], atol=1e-6)


PLUMMER_N = 2000


def test_plummer_energy_and_virial_ratio():
    # Over 200 seeds at n = 2000 the energy scattered by 0.0077 (0.35/sqrt(n))
    # about -0.2513 and 2T/|W| by 0.017 (0.77/sqrt(n)) about 0.997 (the 0.1%
    # mass cut moves them by -7e-4 and -1e-3); the bounds are ~4 sigma.
    for seed in (0, 1, 2):
        bodies = scenes.plummer(PLUMMER_N, seed=seed)
        kinetic, potential = energy(bodies)
        assert kinetic + potential == pytest.approx(-0.25, abs=1.5 / math.sqrt(PLUMMER_N))
        assert 2 * kinetic / -potential == pytest.approx(1.0, abs=3 / math.sqrt(PLUMMER_N))


def test_plummer_structure():
    bodies = scenes.plummer(PLUMMER_N, seed=7)
    assert bodies.units.G == 1.0
    assert bodies.masses.value == pytest.approx(np.full(PLUMMER_N, 1 / PLUMMER_N))
    assert bodies.total_mass.value == pytest.approx(1.0, rel=1e-13)
    assert np.allclose(momentum(bodies), 0, atol=1e-15)
    assert np.allclose(bodies.center_of_mass()[0].value, 0, atol=1e-14)
    r = np.linalg.norm(bodies.positions.value, axis=1)
    # Half-mass radius of a Hénon-units Plummer sphere: (3 pi / 16) / sqrt(2^(2/3) - 1)
    # = 0.769; the sample median scatters by ~2% at n = 2000.
    assert np.median(r) == pytest.approx(3 * math.pi / 16 / math.sqrt(2 ** (2 / 3) - 1),
                                         rel=0.06)
    # The 0.999 mass cut puts every star inside 22.8 (plus the COM shift).
    assert r.max() < 23.0


def test_plummer_seed_reproducibility():
    a = scenes.plummer(500, seed=12)
    b = scenes.plummer(500, seed=12)
    c = scenes.plummer(500, seed=13)
    assert np.array_equal(a.positions.value, b.positions.value)
    assert np.array_equal(a.velocities.value, b.velocities.value)
    assert not np.array_equal(a.positions.value, c.positions.value)
    rng = np.random.default_rng(12)
    assert np.array_equal(scenes.plummer(500, seed=rng).positions.value, a.positions.value)


@pytest.mark.parametrize("n", [1, 0, -5, 2.5, "10", True, None])
def test_plummer_rejects_bad_n(n):
    with pytest.raises(ValueError):
        scenes.plummer(n)


def test_plummer_large_n_is_quick():
    start = time.perf_counter()
    bodies = scenes.plummer(100_000, seed=1)
    elapsed = time.perf_counter() - start
    assert len(bodies) == 100_000
    bodies.check()
    # Measured at 0.05 s; appending one body at a time took minutes at this size.
    assert elapsed < 5.0


@pytest.mark.parametrize("mass_cut", [0.0, 1.0, 1.5, -0.1])
def test_plummer_rejects_bad_mass_cut(mass_cut):
    with pytest.raises(ValueError, match="mass_cut"):
        scenes.plummer(10, mass_cut=mass_cut)
