"""Mercury's perihelion advance from general relativity, with each GR term.
==========================================================================

Sun and Mercury alone, so that every bit of the advance is relativistic:
the longitude of perihelion (from the Runge-Lenz vector) is fitted with a
straight line over a century and set beside 6 pi G M / (c^2 a (1 - e^2)) per
orbit, 42.98 arcseconds per century.  ::

    python examples/mercury_perihelion.py
"""

import math

import astropy.constants as const
import astropy.units as u
import numpy as np

import orbits
from orbits import forces

ARCSEC_PER_CENTURY = (1 * u.rad / u.day).to_value(u.arcsec / (100 * u.yr))


def sun_mercury():
    b = orbits.BodySet()
    b.add("Sun", mass=1 * u.Msun)
    b.add("Mercury", mass=1.6601e-7 * u.Msun, primary="Sun", a=0.38709893 * u.au,
          e=0.20563069, inc=7.00487 * u.deg)
    b.move_to_com()
    return b


def perihelion_rate(result):
    """Secular rate of the longitude of perihelion, rad/day, from a run's outputs."""
    x = (result.positions[:, 1] - result.positions[:, 0]).to_value(u.au)
    v = (result.velocities[:, 1] - result.velocities[:, 0]).to_value(u.au / u.day)
    mu = orbits.UnitSystem().G * float(result.masses.to_value(u.Msun).sum())
    h = np.cross(x, v)
    e = np.cross(v, h) / mu - x / np.linalg.norm(x, axis=1)[:, None]
    e0 = e[0] / np.linalg.norm(e[0])
    q = np.cross(h[0] / np.linalg.norm(h[0]), e0)
    angle = np.unwrap(np.arctan2(e @ q, e @ e0))
    return np.polyfit(result.times.to_value(u.day), angle, 1)[0]


def main(years=100):
    bodies = sun_mercury()
    el = bodies.elements("Mercury", primary="Sun")
    a, ecc = el["a"].to_value(u.au), float(el["e"])
    mu = orbits.UnitSystem().G * (1 + 1.6601e-7)
    c = const.c.to_value(u.au / u.day)
    period = 2 * math.pi * math.sqrt(a ** 3 / mu)
    theory = 6 * math.pi * mu / (c ** 2 * a * (1 - ecc ** 2)) / period * ARCSEC_PER_CENTURY
    print(f"theory                      {theory:.4f} arcsec per century")
    runs = [("no GR (wh)", "wh", 0.5, []),
            ("GR (ias15)", "ias15", None, [forces.GR("Sun")]),
            ("GRPotential (wh)", "wh", 0.5, [forces.GRPotential("Sun")]),
            ("GRFull (ias15)", "ias15", None, [forces.GRFull()])]
    out = {}
    for label, integrator, dt, terms in runs:
        sim = orbits.Simulation(bodies, integrator, dt=None if dt is None else dt * u.day,
                                forces=terms, monitors=())
        res = sim.run(until=years * u.yr, outputs=int(41.5 * years), progress=False)
        out[label] = perihelion_rate(res) * ARCSEC_PER_CENTURY
        print(f"{label:27s} {out[label]:.4f} arcsec per century")
    return theory, out


if __name__ == "__main__":
    import argparse
    p = argparse.ArgumentParser(description="Mercury's perihelion precession with each GR term")
    p.add_argument("--years", type=float, default=100,
                   help="length of each run in years (100; the documentation's build uses 20)")
    main(years=p.parse_args().years)
