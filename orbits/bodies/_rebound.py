"""Conversion between a body set and a ``rebound.Simulation``: plain floats both
ways, in the set's unit system with REBOUND's ``G``.

REBOUND is optional: it is imported where a simulation is made.
"""

import math

import numpy as np

from ..units import UnitSystem

__all__ = ["arrays_from_simulation", "simulation_from"]


def arrays_from_simulation(sim, units=None):
    """Masses, positions, velocities and radii of a REBOUND simulation's
    particles, and the unit system to read them in.

    Returns
    -------
    m : ndarray, shape (N,)
    x, v : ndarray, shape (N, 3)
    r : ndarray, shape (N,)
    units : UnitSystem
        ``units``, or by default a dimensionless system with ``sim.G``.

    Raises
    ------
    ValueError
        ``units.G`` is not REBOUND's ``sim.G``.
    """
    n = sim.N
    m = np.array([sim.particles[i].m for i in range(n)])
    x = np.array([sim.particles[i].xyz for i in range(n)], dtype=float).reshape(n, 3)
    v = np.array([sim.particles[i].vxyz for i in range(n)], dtype=float).reshape(n, 3)
    r = np.array([sim.particles[i].r for i in range(n)], dtype=float)
    if units is None:
        units = UnitSystem.nbody(G=sim.G)
    elif not math.isclose(units.G, sim.G, rel_tol=1e-15):
        raise ValueError(f"units.G = {units.G!r} differs from the REBOUND "
                         f"simulation's G = {sim.G!r}")
    return m, x, v, r, units


def simulation_from(bodies):
    """A ``rebound.Simulation`` with the set's G, masses, radii and states, in order."""
    import rebound
    sim = rebound.Simulation()
    sim.G = bodies.units.G
    for i in range(len(bodies)):
        x, v = bodies._x[i], bodies._v[i]
        sim.add(m=float(bodies._m[i]), r=float(bodies._r[i]), x=x[0], y=x[1], z=x[2],
                vx=v[0], vy=v[1], vz=v[2])
    return sim
