"""Planetesimals that collide and merge
=====================================

A ring of planetesimals between 0.9 and 1.1 au about a Sun-mass star, two
Earth masses in all, on nearly circular and nearly coplanar orbits (Rayleigh
distributed eccentricities and inclinations, 0.01 and 0.005 rad): the scene
``orbits.scenes.planetesimal_ring``.  Their
radii are inflated to 5e-4 au (75 000 km) so that collisions, rare for real
sizes, come within a few hundred orbits; the run is a picture of the
bookkeeping, not a model of planet formation.  ``ias15`` with
``collisions="merge"``: every pair that touches, at the end of a step or
inside it, becomes one body (mass, momentum and volume conserved).

::

    python examples/planetesimal_accretion.py                  # 80 bodies, 400 years
    python examples/planetesimal_accretion.py --n 40 --years 100

The figure shows the number of bodies and the largest mass over time (left),
and the eccentricities and semi-major axes at the start (grey) and at the
end (sized by mass, right).  The run prints the collisions table and the
largest energy error, which stays at round-off: what the mergers take out
of the energy is booked as work (see the guide on collisions).

.. image:: planetesimal_accretion.png
   :alt: Left: the number of bodies falls and the largest mass grows over 400
         years.  Right: eccentricity against semi-major axis at the start and
         at the end.
"""

import argparse
import pathlib

import astropy.units as u
import numpy as np

import orbits

# beside this script (the current folder where there is no __file__: the docs' gallery)
HERE = pathlib.Path(globals().get("__file__", "planetesimal_accretion.py")).resolve().parent
EARTH_MASS = (1 * u.Mearth).to_value(u.Msun)


def main(n=80, years=400, outputs=201, png=None, show=True):
    bodies = orbits.scenes.planetesimal_ring(n)
    sim = orbits.Simulation(bodies, "ias15", collisions="merge")
    result = sim.run(until=years * u.yr, outputs=outputs, progress=False)
    print(result.summary())
    print(result.collisions["time", "body_1", "body_2", "survivor"][:10])
    print(f"bodies left: {len(sim.bodies.names)} of {n + 1}; "
          f"largest energy error (E + W): {result.energy_error.max():.2e}")
    if png is not False:
        draw(bodies, sim.bodies, result, png)
    return result, sim


def draw(start, end, result, png=None):
    import matplotlib.pyplot as plt

    t = result.times.to_value(u.yr)
    m = result.masses_at_outputs.to_value(u.Msun) / EARTH_MASS
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    left.plot(t, np.sum(np.isfinite(m[:, 1:]), axis=1), color="C0")
    left.set_xlabel("time [yr]")
    left.set_ylabel("planetesimals left", color="C0")
    twin = left.twinx()
    twin.plot(t, np.nanmax(m[:, 1:], axis=1), color="C3")
    twin.set_ylabel("largest mass [Earth masses]", color="C3")
    left.set_title("mergers")
    for bodies, style in ((start, dict(color="0.7", s=8, label="start")),
                          (end, dict(color="C0", label="end"))):
        els = [bodies.elements(name, primary="Sun") for name in bodies.names[1:]]
        mass = bodies.masses.to_value(u.Msun)[1:] / EARTH_MASS
        size = style.pop("s", None) or 200 * mass
        right.scatter([el["a"].to_value(u.au) for el in els], [float(el["e"]) for el in els],
                      s=size, **style)
    right.set_xlabel("a [au]")
    right.set_ylabel("e")
    right.set_title("orbits (size: mass)")
    right.legend(loc="upper right")
    fig.tight_layout()
    if png:
        fig.savefig(png, dpi=120)
    return fig


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--n", type=int, default=80, help="number of planetesimals")
    parser.add_argument("--years", type=float, default=400)
    parser.add_argument("--outputs", type=int, default=201)
    parser.add_argument("--png", default=str(HERE / "planetesimal_accretion.png"))
    args = parser.parse_args()
    main(args.n, args.years, args.outputs, args.png)
