"""REBOUND's ways to give an orbit in BodySet.add: P, pomega, l, theta, E, T."""

import math

import astropy.units as u
import numpy as np
import pytest

import orbits
from orbits.errors import BodyUnitsError, ElementsError

rebound = pytest.importorskip("rebound")

SUN, PLANET = 1.0, 1e-3      # masses, Msun
UNITS = orbits.UnitSystem()  # au, Msun, day: plain numbers accepted, angles in rad


def with_sun():
    b = orbits.BodySet(UNITS)
    b.add("Sun", mass=SUN)
    return b


def state(b, name="planet"):
    i = b.index(name)
    return b._x[i].copy(), b._v[i].copy()


def same_state(b1, b2, rtol):
    (x1, v1), (x2, v2) = state(b1), state(b2)
    np.testing.assert_allclose(x1, x2, rtol=0, atol=rtol * np.linalg.norm(x1))
    np.testing.assert_allclose(v1, v2, rtol=0, atol=rtol * np.linalg.norm(v1))


def added(**fields):
    b = with_sun()
    b.add("planet", mass=PLANET, primary="Sun", **fields)
    return b


def mu():
    return UNITS.G * (SUN + PLANET)


# the angles of one orbit, in rad
E_, INC, OMEGA_NODE, OMEGA_PERI = 0.3, 0.2, 1.1, 2.5
POMEGA = OMEGA_NODE + OMEGA_PERI


def test_period_in_place_of_a():
    P = 400.0
    a = (mu() * (P / (2 * math.pi)) ** 2) ** (1 / 3)
    # the cube root rounds once more than a given directly: a few ulps
    same_state(added(P=P, e=E_, f=1.0), added(a=a, e=E_, f=1.0), rtol=1e-15)
    # the two-body GM of primary and body, as REBOUND's: another mass, another a
    b = added(P=P, e=E_)
    a_back = float(b.elements("planet", primary="Sun")["a"].to_value(u.au))
    assert 2 * math.pi * math.sqrt(a_back ** 3 / mu()) == pytest.approx(P, rel=1e-14)
    light = with_sun()
    light.add("planet", mass=0.0, primary="Sun", P=P, e=E_)
    assert light.elements("planet", primary="Sun")["a"].to_value(u.au) < a_back
    # a Quantity in any unit of time
    same_state(added(P=P * u.day, e=E_), added(P=(P / 365.25) * u.yr, e=E_), rtol=1e-15)


def test_pomega_in_place_of_omega():
    base = added(a=1.3, e=E_, inc=INC, Omega=OMEGA_NODE, omega=OMEGA_PERI, f=0.4)
    same_state(added(a=1.3, e=E_, inc=INC, Omega=OMEGA_NODE, pomega=POMEGA, f=0.4), base,
               rtol=1e-15)
    # without Omega, pomega is omega (Omega = 0): the planar case it is made for
    same_state(added(a=1.3, e=E_, pomega=OMEGA_PERI), added(a=1.3, e=E_, omega=OMEGA_PERI),
               rtol=0)
    # all three given and agreeing (to a whole turn) are accepted
    same_state(added(a=1.3, e=E_, inc=INC, Omega=OMEGA_NODE, omega=OMEGA_PERI,
                     pomega=POMEGA + 2 * math.pi, f=0.4), base, rtol=0)


def test_mean_and_true_longitudes():
    common = dict(a=1.3, e=E_, inc=INC, Omega=OMEGA_NODE, omega=OMEGA_PERI)
    # l = pomega + M, theta = pomega + f: one subtraction rounded
    same_state(added(**common, l=POMEGA + 0.7), added(**common, M=0.7), rtol=1e-14)
    same_state(added(**common, theta=POMEGA + 0.7), added(**common, f=0.7), rtol=1e-14)
    # with pomega given instead of omega
    same_state(added(a=1.3, e=E_, inc=INC, Omega=OMEGA_NODE, pomega=POMEGA, l=POMEGA + 0.7),
               added(**common, M=0.7), rtol=1e-14)


def test_retrograde_longitudes_are_measured_the_other_way_round():
    retro = dict(a=1.3, e=E_, inc=2.5, Omega=OMEGA_NODE)
    # pomega = Omega - omega, l = pomega - M, theta = pomega - f (REBOUND's)
    base = added(**retro, omega=OMEGA_PERI, M=0.7)
    pomega = OMEGA_NODE - OMEGA_PERI
    same_state(added(**retro, pomega=pomega, l=pomega - 0.7), base, rtol=1e-14)
    same_state(added(**retro, omega=OMEGA_PERI, theta=pomega - 0.7),
               added(**retro, omega=OMEGA_PERI, f=0.7), rtol=1e-14)
    same_state(added(**retro, omega=OMEGA_PERI, pomega=pomega, M=0.7), base, rtol=0)
    with pytest.raises(ElementsError, match=r"Omega - omega \(a retrograde orbit\)"):
        added(**retro, omega=OMEGA_PERI, pomega=OMEGA_NODE + OMEGA_PERI)
    # a planar retrograde orbit: pomega is where the pericentre is
    b = added(a=1.0, e=0.5, inc=math.pi, pomega=0.5)
    x, _ = state(b)
    assert math.atan2(x[1], x[0]) == pytest.approx(0.5, abs=1e-14)


@pytest.mark.parametrize("E", [0.0, 1.0, 3.0, -2.0, 7.5])
def test_eccentric_anomaly(E):
    b = added(a=1.3, e=0.6, E=E)
    M = float(b.elements("planet", primary="Sun")["M"].to_value(u.rad))
    # Kepler's equation M = E - e sin E, modulo a turn; the round trip
    # through the state costs a few ulps times 1 / (1 - e)
    assert math.remainder(M - (E - 0.6 * math.sin(E)), 2 * math.pi) == pytest.approx(
        0, abs=1e-13)


def test_time_of_pericentre_passage_is_on_the_simulations_clock():
    a, e = 1.0, 0.5
    P = 2 * math.pi * math.sqrt(a ** 3 / mu())
    b = added(a=a, e=e, T=0.25 * P)
    M = float(b.elements("planet", primary="Sun")["M"].to_value(u.rad))
    assert math.remainder(M + math.pi / 2, 2 * math.pi) == pytest.approx(0, abs=1e-14)
    same_state(added(a=a, e=e, T=0.0), added(a=a, e=e, f=0.0), rtol=0)
    # run to t = T: the body is at its pericentre a (1 - e) (ias15 on a
    # Kepler orbit holds the phase to ~1e-14 over a quarter orbit; the
    # distance's minimum is flat, so the check is of the phase to ~1e-7)
    sim = orbits.Simulation(b)
    sim.run(until=0.25 * P * u.day, outputs=2, progress=False)
    x = sim.bodies.positions.to_value(u.au)
    assert np.linalg.norm(x[1] - x[0]) == pytest.approx(a * (1 - e), rel=1e-13)
    # hyperbolic orbits have a time of pericentre too
    hyp = added(a=-2.0, e=1.5, T=-30.0)
    assert float(hyp.elements("planet", primary="Sun")["M"].to_value(u.rad)) == pytest.approx(
        30 * math.sqrt(mu() / 8), rel=1e-13)


@pytest.mark.parametrize("fields, field, words", [
    (dict(a=1.0, P=365.0), "P", ["a or the period P, not both"]),
    (dict(e=0.1), "a", ["semi-major axis a or the period P"]),
    (dict(P=-3.0), "P", ["period must be positive"]),
    (dict(P=0.0), "P", ["period must be positive"]),
    (dict(P=300.0, e=1.2), "P", ["bound orbit", "e = 1.2"]),
    (dict(a=-1.0, e=1.2, E=0.3), "E", ["bound orbit", "give f or M"]),
    (dict(a=1.0, f=0.1, M=0.2), "f", ["one of f, M, E, l, theta, T", "got f, M"]),
    (dict(a=1.0, l=0.1, theta=0.2, T=3.0), "l", ["got l, theta, T"]),
    (dict(a=1.0, E=0.1, M=0.2), "M", ["got M, E"]),
    (dict(a=1.0, Omega=1.0, omega=2.0, pomega=3.5), "pomega",
     ["Omega, omega and pomega disagree", "differs from it by 0.5 rad"]),
    (dict(a=1.0, omega=2.0, pomega=3.0), "pomega", ["omega and pomega (Omega = 0) disagree"]),
    (dict(a=1.0, l=math.inf), "l", ["must be finite"]),
    (dict(P=math.nan), "P", ["must be finite"]),
    (dict(P=300.0, e=-0.1), "e", ["eccentricity must be >= 0"]),
])
def test_conflicting_and_missing_fields_name_the_body_and_fields(fields, field, words):
    with pytest.raises(ElementsError) as exc:
        added(**fields)
    assert exc.value.body == "planet" and exc.value.field == field
    text = str(exc.value)
    assert text.startswith(f"body 'planet', field '{field}'")
    for word in words:
        assert word in text


def test_times_and_angles_need_their_units():
    b = orbits.BodySet()        # the default: Quantities only
    b.add("Sun", mass=1 * u.Msun)
    with pytest.raises(BodyUnitsError, match="field 'P'"):
        b.add("planet", mass=0 * u.kg, primary="Sun", P=1 * u.au)
    with pytest.raises(BodyUnitsError, match="field 'T'"):
        b.add("planet", mass=0 * u.kg, primary="Sun", a=1 * u.au, T=3.0)
    with pytest.raises(BodyUnitsError, match="field 'pomega'"):
        b.add("planet", mass=0 * u.kg, primary="Sun", a=1 * u.au, pomega=1 * u.day)
    b.add("planet", mass=0 * u.kg, primary="Sun", P=1 * u.yr, l=90 * u.deg, e=0.1,
          pomega=10 * u.deg)
    assert b.history[-1]["P"] == "1.0 yr" and b.history[-1]["l"] == "90.0 deg"


# -- against REBOUND -------------------------------------------------------------

#: One system, each body given a different way (REBOUND's keywords, its units
#: au, Msun, day with our G); primary None: the centre of mass of the bodies
#: before it, in both packages.
REBOUND_CASES = [
    ("b", 3e-6, "Sun", dict(P=365.25, e=0.0167, inc=0.01, Omega=0.3, pomega=1.8, l=2.0)),
    ("c", 1e-3, "Sun", dict(P=4332.6, e=0.048, inc=0.02, Omega=1.75, omega=4.8, T=-1200.0)),
    ("d", 3e-4, None, dict(a=9.5, e=0.056, inc=0.04, Omega=1.98, pomega=1.6, theta=5.0)),
    ("e", 0.0, "Sun", dict(P=1700.0, e=0.7, inc=1.1, Omega=0.4, omega=0.2, E=2.4)),
    ("f", 0.0, "c", dict(a=0.01, e=0.2, inc=0.5, Omega=2.0, pomega=0.3, T=3.0)),
    ("g", 5e-5, None, dict(P=60000.0, e=0.3, inc=2.5, Omega=5.0, pomega=0.7, l=-1.0)),
    ("h", 0.0, "Sun", dict(a=3.0, e=0.4, inc=3.0, Omega=1.0, omega=2.0, theta=0.5)),
    ("i", 0.0, "Sun", dict(a=-3.0, e=1.4, inc=0.3, Omega=1.0, omega=2.0, T=40.0)),
]


def test_the_same_orbits_given_to_rebound_give_the_same_state():
    ours = orbits.BodySet(UNITS)
    ours.add("Sun", mass=1.0)
    sim = rebound.Simulation()
    sim.G = UNITS.G
    sim.add(m=1.0)
    names = ["Sun"]
    for name, m, primary, fields in REBOUND_CASES:
        ours.add(name, mass=m, primary=primary, **fields)
        where = {} if primary is None else {"primary": sim.particles[names.index(primary)]}
        sim.add(m=m, **where, **fields)
        names.append(name)
    for i, name in enumerate(names):
        p = sim.particles[i]
        x, v = state(ours, name)
        # both evaluate the same formulas in float64, in other orders and with
        # other Kepler solvers: rounding of a few ulps, amplified by the
        # conversion's conditioning (1 / (1 - e) = 3.3 at e = 0.7, and the
        # phase M = n T of a T far from pericentre); measured at most 1.4e-15
        # of |x| and |v| (REBOUND 5.2.2).  1e-13 leaves a factor 70 for other
        # libms and fails on any wrong formula, sense or GM (the GM of the
        # primary alone moves b by 1e-6)
        np.testing.assert_allclose(x, [p.x, p.y, p.z], rtol=0,
                                   atol=1e-13 * np.linalg.norm(x))
        np.testing.assert_allclose(v, [p.vx, p.vy, p.vz], rtol=0,
                                   atol=1e-13 * np.linalg.norm(v))
