"""Classic explicit Runge-Kutta methods of fixed step."""

from . import tableaux
from .base import ExplicitRungeKutta

__all__ = ["RK2", "RK4"]


class RK2(ExplicitRungeKutta):
    """The explicit midpoint rule, second order.

    Notes
    -----
    ``k1 = f(t, y)``, ``k2 = f(t + h/2, y + (h/2) k1)``, ``y1 = y + h k2``.

    References
    ----------
    Hairer, Nørsett & Wanner (1993), *Solving ODEs I*, section II.1.

    Examples
    --------
    Second order: halving the step quarters the error (the final position
    after a year, at steps of 4, 2 and 1 days).

    >>> def final(dt):
    ...     sim = orbits.Simulation(orbits.scenes.kepler(e=0.1), "rk2", dt=dt)
    ...     return sim.run(until=1 * u.yr, outputs=2, progress=False).positions[-1, 1]
    >>> x4, x2, x1 = final(4 * u.day), final(2 * u.day), final(1 * u.day)
    >>> round(float(np.linalg.norm(x4 - x2) / np.linalg.norm(x2 - x1)))
    4
    """

    name = "rk2"
    order = 2
    summary = "explicit midpoint rule"
    A, B, C = tableaux.MIDPOINT


class RK4(ExplicitRungeKutta):
    """The classic fourth-order Runge-Kutta method.

    Notes
    -----
    Four force evaluations a step; not symplectic, so the energy error of an
    orbit grows linearly in time, but slowly (as h^4).

    References
    ----------
    Kutta (1901); Hairer, Nørsett & Wanner (1993), *Solving ODEs I*, Table II.1.2.

    Examples
    --------
    Its weights, Simpson's rule's over the four stages:

    >>> [round(b, 6) for b in orbits.integrators.get("rk4").B.tolist()]
    [0.166667, 0.333333, 0.333333, 0.166667]
    """

    name = "rk4"
    order = 4
    summary = "classic fourth-order Runge-Kutta"
    A, B, C = tableaux.RK4
