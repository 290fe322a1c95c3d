"""Explicit Euler and semi-implicit (symplectic) Euler."""

from . import tableaux
from .base import ExplicitRungeKutta, SplittingMethod

__all__ = ["Euler", "SymplecticEuler"]


class Euler(ExplicitRungeKutta):
    """Explicit (forward) Euler, the first-order baseline.

    Notes
    -----
    Both position and velocity are advanced from the old state::

        x_{n+1} = x_n + h v_n
        v_{n+1} = v_n + h a(x_n)

    The energy of an orbit grows secularly (the map expands phase space);
    use it to see why the other methods exist.

    References
    ----------
    Hairer, Nørsett & Wanner (1993), *Solving ODEs I*, section I.7.

    Examples
    --------
    The energy error of a circular orbit at a step of a day, after 5 and 10
    years: it only grows.

    >>> sim = orbits.Simulation(orbits.scenes.kepler(), "euler", dt=1 * u.day)
    >>> error = sim.run(until=10 * u.yr, outputs=3, progress=False).energy_error
    >>> bool(0 < error[1] < error[2])
    True
    """

    name = "euler"
    order = 1
    summary = "explicit Euler, x and v from the old state (baseline)"
    A, B, C = tableaux.EULER


class SymplecticEuler(SplittingMethod):
    """Semi-implicit (symplectic) Euler: kick, then drift with the new velocity.

    Notes
    -----
    ::

        v_{n+1} = v_n + h a(x_n)
        x_{n+1} = x_n + h v_{n+1}

    First order, but symplectic: the energy error stays bounded.

    References
    ----------
    Hairer, Lubich & Wanner (2006), *Geometric Numerical Integration*, section I.1.2.

    Examples
    --------
    >>> orbits.integrators.get("symplectic-euler").symplectic
    True
    """

    name = "symplectic-euler"
    order = 1
    summary = "semi-implicit Euler: kick, then drift with the new velocity"
    operators = tableaux.SYMPLECTIC_EULER
