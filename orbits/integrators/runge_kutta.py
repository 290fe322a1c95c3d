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
    >>> import orbits
    >>> orbits.integrators.get("rk2").order
    2
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
    >>> import orbits
    >>> orbits.integrators.get("rk4").order
    4
    """

    name = "rk4"
    order = 4
    summary = "classic fourth-order Runge-Kutta"
    A, B, C = tableaux.RK4
