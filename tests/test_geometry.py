"""Geometry of a set of orbits: the invariable plane, mutual inclinations, and
elements about the barycentre (:mod:`orbits.geometry`)."""

import math

import astropy.units as u
import numpy as np
import pytest

import orbits
from orbits import geometry
from orbits.errors import BodyError, NoMassiveBodyError, UnknownBodyError

EPS = np.finfo(float).eps


def _energy_parts(b):
    """Kinetic and potential energy of a body set (internal units)."""
    m, x, v, G = b._m, b._x, b._v, b.units.G
    kinetic = 0.5 * np.sum(m * np.sum(v * v, axis=1))
    i, j = np.triu_indices(len(m), 1)
    potential = -G * np.sum(m[i] * m[j] / np.linalg.norm(x[i] - x[j], axis=1))
    return kinetic, potential


def _L_about_origin(b):
    return np.sum(b._m[:, None] * np.cross(b._x, b._v), axis=0)


def _tilted_system():
    # planets on orbits inclined up to 30 deg to the x-y plane, with nodes all
    # round: the invariable plane is far from x-y
    b = orbits.BodySet()
    b.add("Sun", mass=1 * u.Msun)
    for k, (a, inc, node) in enumerate([(1, 30, 10), (2.5, 12, 200), (6, 25, 95),
                                        (11, 5, 300)]):
        b.add(f"p{k}", mass=(k + 1) * 1e-4 * u.Msun, primary="Sun", a=a * u.au,
              e=0.05 * k, inc=inc * u.deg, Omega=node * u.deg, omega=40 * k * u.deg,
              f=1.1 * k * u.rad)
    b.move_to_com()
    return b


# -- to_invariable_plane ----------------------------------------------------------------

def test_the_invariable_plane_puts_L_on_plus_z_and_keeps_E_and_the_size_of_L():
    b = _tilted_system()
    L0 = _L_about_origin(b)
    K0, U0 = _energy_parts(b)
    tilt0 = math.atan2(np.hypot(L0[0], L0[1]), L0[2])
    assert tilt0 > 0.05                                # far from the x-y plane to start
    b.to_invariable_plane()
    L = _L_about_origin(b)
    # each component is a sum of the bodies' m x × v, each rounded to a few
    # eps of its size: 16 eps of the sum of their sizes bounds the x, y that
    # rounding leaves
    terms = np.sum(b._m * np.linalg.norm(b._x, axis=1) * np.linalg.norm(b._v, axis=1))
    assert np.hypot(L[0], L[1]) < 16 * EPS * terms
    assert L[2] > 0
    assert np.linalg.norm(L) == pytest.approx(np.linalg.norm(L0), rel=16 * EPS * terms
                                              / np.linalg.norm(L0))
    # a rotation keeps every distance and speed: the energy changes by the
    # rounding of the rotated components, a few eps of its parts' sizes
    K, U = _energy_parts(b)
    assert abs((K + U) - (K0 + U0)) < 16 * EPS * (K0 + abs(U0))
    assert b.history[-1] == {"from": "to_invariable_plane"}


def test_the_invariable_plane_follows_rebounds_rotation_to_new_axes():
    rebound = pytest.importorskip("rebound")
    b = _tilted_system()
    sim = b.to_rebound()
    sim.rotate(rebound.Rotation.to_new_axes(newz=sim.angular_momentum()))
    b.to_invariable_plane()
    theirs = np.array([p.xyz for p in sim.particles])
    scale = np.abs(b._x).max()
    # the same axes (new x along z × L, the ascending node), from the same
    # floats by other arithmetic (REBOUND rotates with a quaternion): a few
    # eps of the largest coordinate
    assert np.abs(b._x - theirs).max() < 64 * EPS * scale
    vtheirs = np.array([p.vxyz for p in sim.particles])
    assert np.abs(b._v - vtheirs).max() < 64 * EPS * np.abs(b._v).max()


def test_the_node_of_the_invariable_plane_is_the_new_x_axis():
    b = _tilted_system()
    L0 = geometry.angular_momentum(b._m, b._x, b._v)
    node = np.cross([0, 0, 1.0], L0)
    x_before = b._x.copy()
    b.to_invariable_plane()
    # a point on the node line (in both planes) lands on the new +x axis
    R = geometry.invariable_plane_rotation(L0)
    assert np.allclose(R @ (node / np.linalg.norm(node)), [1, 0, 0], rtol=0, atol=4 * EPS)
    assert np.allclose(b._x, x_before @ R.T, rtol=0, atol=0)


def test_the_invariable_plane_is_reached_once():
    b = _tilted_system()
    b.to_invariable_plane()
    once = b._x.copy()
    b.to_invariable_plane()
    # L is along z to rounding, so the node is not defined and x is kept:
    # the second rotation moves nothing beyond a few eps
    assert np.abs(b._x - once).max() < 16 * EPS * np.abs(once).max()


def test_a_set_away_from_its_barycentre_uses_the_angular_momentum_about_it():
    b = _tilted_system()
    moved = b.copy()
    moved._x += [3.0, -7.0, 2.0]
    moved._v += [0.01, 0.002, -0.004]
    b.to_invariable_plane()
    moved.to_invariable_plane()
    Lb = geometry.angular_momentum(moved._m, moved._x, moved._v)
    terms = np.sum(b._m * np.linalg.norm(b._x, axis=1) * np.linalg.norm(b._v, axis=1))
    # the barycentre's offset and motion add nothing to L about the barycentre;
    # the rounding of the offset (~7 au) sets the scale of what is left
    assert np.hypot(Lb[0], Lb[1]) < 1e3 * EPS * terms
    assert np.allclose(moved.elements("p2", "Sun")["inc"], b.elements("p2", "Sun")["inc"],
                       rtol=0, atol=1e-12 * u.rad)


def test_the_invariable_plane_needs_mass_and_angular_momentum():
    empty = orbits.BodySet()
    empty.add("a", mass=0 * u.kg, position=[1, 0, 0] * u.au, velocity=[0, 1, 0] * u.au / u.d)
    with pytest.raises(NoMassiveBodyError):
        empty.to_invariable_plane()
    radial = orbits.BodySet()
    radial.add("a", mass=1 * u.Msun)
    radial.add("b", mass=1 * u.Msun, position=[1, 0, 0] * u.au,
               velocity=[0.01, 0, 0] * u.au / u.d)
    with pytest.raises(BodyError, match="no angular momentum") as exc:
        radial.to_invariable_plane()
    assert exc.value.field == "angular_momentum"
    with pytest.raises(ValueError, match="finite non-zero"):
        geometry.invariable_plane_rotation([0.0, 0.0, 0.0])


# -- mutual inclinations ------------------------------------------------------------------

def test_mutual_inclination_of_two_orbits_about_one_primary_is_the_spherical_formula():
    b = orbits.BodySet()
    b.add("Star", mass=1 * u.Msun)
    i1, i2, n1, n2 = 0.3, 1.1, 0.7, 2.9            # rad
    b.add("b", mass=1e-3 * u.Msun, primary="Star", a=1 * u.au, e=0.2, inc=i1 * u.rad,
          Omega=n1 * u.rad, omega=1.0 * u.rad)
    b.add("c", mass=0 * u.Msun, primary="Star", a=3 * u.au, e=0.4, inc=i2 * u.rad,
          Omega=n2 * u.rad, f=2.0 * u.rad)
    expect = math.acos(math.cos(i1) * math.cos(i2)
                       + math.sin(i1) * math.sin(i2) * math.cos(n1 - n2))
    got = b.mutual_inclination("b", "c", primary="Star")
    assert got.unit == u.rad
    # elements to state and back through the kernels, and acos of a cosine
    # near 0.6 (no loss of digits there): a few 1e-16 rad; 1e-14 allows ~50
    assert got.value == pytest.approx(expect, abs=1e-14)
    assert b.mutual_inclination("c", "b", primary="Star") == got          # symmetric
    assert b.mutual_inclination("b", "b", primary="Star") == 0 * u.rad


def test_two_planets_in_their_invariable_plane_have_opposite_nodes():
    # three bodies: the total angular momentum about the barycentre is the sum
    # of the two Jacobi orbits' (reduced mass times r x v); with it along z,
    # the two orbit normals and z lie in one plane, on either side of z.  So,
    # about the default (Jacobi) primaries: Omega_b - Omega_c = pi and the
    # mutual inclination is inc_b + inc_c, at every output of a run.
    b = orbits.BodySet()
    b.add("Star", mass=1 * u.Msun)
    b.add("b", mass=1e-3 * u.Msun, primary="Star", a=1 * u.au, e=0.1, inc=8 * u.deg,
          Omega=30 * u.deg)
    b.add("c", mass=3e-3 * u.Msun, a=4 * u.au, e=0.2, inc=20 * u.deg, Omega=250 * u.deg,
          f=1 * u.rad)
    b.move_to_com()
    b.to_invariable_plane()
    sim = orbits.Simulation(b, "ias15")
    result = sim.run(until=2000 * u.yr, outputs=21, progress=False)
    eb, ec = result.elements("b"), result.elements("c")
    mutual = result.mutual_inclination("b", "c")
    assert mutual.shape == (21,) and mutual.unit == u.rad
    # the inclinations exchange over the secular cycle (a check that it moves)
    assert np.ptp(eb["inc"].to_value(u.deg)) > 0.1
    # ias15 keeps L to ~1e-15 relative over this run (its angular momentum
    # error); the identity then holds to the rounding of the elements: 1e-12 rad
    assert np.abs(mutual - (eb["inc"] + ec["inc"])).max() < 1e-12 * u.rad
    dnode = ((eb["Omega"] - ec["Omega"]).to_value(u.rad)) % (2 * math.pi)
    assert np.abs(dnode - math.pi).max() < 1e-11
    # and the angle is the one between the orbits' planes at each output
    for k in (0, 10, 20):
        state = orbits.BodySet.from_arrays(result.masses, result.positions[k],
                                           result.velocities[k], names=result.names)
        assert state.mutual_inclination("b", "c").value == pytest.approx(
            mutual[k].value, abs=1e-15)


def test_mutual_inclination_over_a_run_matches_the_elements_at_each_output():
    sim = orbits.Simulation(orbits.scenes.outer_solar_system(), "leapfrog", dt=10 * u.day)
    result = sim.run(until=500 * u.yr, outputs=6, progress=False)
    for primary in ("Sun", "barycentre"):
        ej = result.elements("Jupiter", primary=primary)
        es = result.elements("Saturn", primary=primary)
        ij, isat = ej["inc"].value, es["inc"].value
        expect = np.arccos(np.cos(ij) * np.cos(isat) + np.sin(ij) * np.sin(isat)
                           * np.cos(ej["Omega"].value - es["Omega"].value))
        got = result.mutual_inclination("Jupiter", "Saturn", primary=primary)
        # acos of a cosine within 2.4e-4 of 1 (I ~ 1.25 deg): its rounding of
        # 1e-16 becomes 1e-16 / sin(I) ~ 5e-15 rad; 1e-13 allows twenty times that
        assert np.abs(got.value - expect).max() < 1e-13


def test_mutual_inclination_errors_are_named():
    b = orbits.scenes.outer_solar_system()
    with pytest.raises(UnknownBodyError, match="did you mean 'Saturn'"):
        b.mutual_inclination("Jupiter", "Saturm")
    with pytest.raises(BodyError, match="no orbit about itself"):
        b.mutual_inclination("Sun", "Jupiter", primary="Sun")
    result = orbits.Simulation(b, "leapfrog", dt=10 * u.day).run(
        until=1 * u.yr, outputs=2, progress=False)
    with pytest.raises(UnknownBodyError, match="did you mean 'Jupiter'"):
        result.mutual_inclination("jupiter ", "Saturn")
    with pytest.raises(UnknownBodyError, match="unknown primary 'Son'"):
        result.mutual_inclination("Jupiter", "Saturn", primary="Son")
    with pytest.raises(BodyError, match="no orbit about itself"):
        result.mutual_inclination("Jupiter", "Saturn", primary="Jupiter")


# -- elements about the barycentre over a run ----------------------------------------------

def test_barycentric_elements_of_a_run_match_rebound_at_each_output():
    rebound = pytest.importorskip("rebound")
    sim = orbits.Simulation(orbits.scenes.outer_solar_system(), "ias15")
    result = sim.run(until=200 * u.yr, outputs=5, progress=False)
    U = result.units
    for k in range(len(result)):
        state = orbits.BodySet.from_arrays(result.masses, result.positions[k],
                                           result.velocities[k], names=result.names,
                                           units=U)
        reb = state.to_rebound()
        for i, name in enumerate(result.names):
            theirs = reb.particles[i].orbit(primary=reb.com())
            ours = result.elements(name, primary="barycenter")
            # as in tests/test_body.py: the same floats through formulas of a
            # different order, conditioned by 1/e (e >= 0.009): 1e-12
            assert ours["a"][k].value == pytest.approx(theirs.a, rel=1e-12), (k, name)
            assert ours["e"][k].value == pytest.approx(theirs.e, rel=1e-12), (k, name)
            d = (ours["omega"][k].value - theirs.omega + math.pi) % (2 * math.pi) - math.pi
            assert abs(d) < 1e-12, (k, name)


def test_barycentric_elements_of_the_set_and_the_run_agree_at_the_start():
    b = orbits.scenes.outer_solar_system()
    result = orbits.Simulation(b, "leapfrog", dt=10 * u.day).run(
        until=10 * u.yr, outputs=2, progress=False)
    for name in b.names:
        ours = result.elements(name, primary="barycentre")
        theirs = b.elements(name, primary="barycentre")
        # the same state; the barycentre from einsum against a matrix product:
        # a few eps apart, turned into elements conditioned by 1/e
        for key in ("a", "e", "inc"):
            assert ours[key][0].value == pytest.approx(theirs[key].value, rel=1e-13)


def test_the_barycentre_is_a_word_not_a_body():
    assert geometry.is_barycentre("barycentre") and geometry.is_barycentre("barycenter")
    assert not geometry.is_barycentre("Barycentre") and not geometry.is_barycentre(None)
    b = orbits.scenes.kepler()
    # the Sun about the barycentre: the reflex orbit of a two-body system, with
    # mu = G (M + m) as REBOUND's primary=sim.com() gives it
    el = b.elements("Star", primary="barycentre")
    r_star = np.linalg.norm(b._x[0] - b._com()[0])
    assert el["a"].value > 0 and r_star > 0
    with pytest.raises(UnknownBodyError, match="unknown primary 'barycentric'"):
        b.elements("Planet", primary="barycentric")
