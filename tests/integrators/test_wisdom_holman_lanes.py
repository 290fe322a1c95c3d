"""The Wisdom-Holman loop with the planets in vector lanes
(orbits._kernels.wh_lanes) against the same loop with the scalar drift: the
same trajectory bit for bit.

The comparisons are exact (tolerance zero): the lanes compute each planet's
drift by the scalar code's operations in its order, or hand it to the scalar
drift (see tests/kernels/test_wh_lanes.py), so nothing may differ by even an
ulp; from seven bodies on (``PAIRS_LANES_FROM_BODIES``; the odd orbits'
scene has eight) the kick's pulls are also summed in the lanes, in the scalar
order (tests/kernels/test_wh_lanes.py).  Which loop a run takes is chosen by
the number of bodies (``LANES_FROM_BODIES``), set here to force one or the
other.
"""

import astropy.units as u
import numpy as np
import pytest

import orbits
from orbits._kernels import wh_lanes as _lanes
from orbits.integrators import wisdom_holman as IW

DH = "democratic-heliocentric"


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
    monkeypatch.setattr(IW, "LANES_FROM_BODIES", 4 if lanes else 10 ** 9)
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
    # 400 days: a long step for Jupiter, Saturn and Uranus (the lanes decline
    # them), a short one for Neptune and Pluto; with more than a quarter declined
    # the loop drifts by the scalar code for a while and tries the lanes again
    bodies = orbits.scenes.outer_solar_system()
    until = 300 * 400 * u.day
    x0, v0, _ = final_state(monkeypatch, bodies, False, spec, until, dt=400 * u.day)
    x1, v1, ws = final_state(monkeypatch, bodies, True, spec, until, dt=400 * u.day)
    assert np.array_equal(x0, x1)
    assert np.array_equal(v0, v1)
    assert ws["lanes"][0][_lanes.MEMO, 0] > 0


def test_lanes_are_chosen_by_the_number_of_bodies(monkeypatch):
    # the loop records its scratch in the workspace when it runs with lanes
    for bodies, lanes in ((orbits.scenes.outer_solar_system(), True),
                          (orbits.scenes.kepler(e=0.1), False)):
        sim = orbits.Simulation(bodies, integrator="wh", dt=1 * u.day, monitors=())
        sim.run(until=10 * u.day, outputs=2, progress=False)
        assert ("lanes" in sim._ws) == lanes
