"""The registry of integrators: name -> class.

>>> import orbits
>>> [i.name for i in orbits.integrators.available()][:3]
['euler', 'symplectic-euler', 'verlet']
>>> orbits.integrators.get("rk4")
RK4()
"""

from typing import NamedTuple

from ..errors import UnknownIntegratorError
from .base import ExplicitRungeKutta, Integrator, SplittingMethod
from .composition import Yoshida4, Yoshida6, Yoshida8
from .doubling import RK4Doubling
from .embedded import DOP853, Dopri5
from .euler import Euler, SymplecticEuler
from .ias15 import IAS15
from .implicit import ImplicitEuler, ImplicitMidpoint
from .leapfrog import Leapfrog, Verlet
from .runge_kutta import RK2, RK4
from .scipy_ivp import LSODA, Radau
from .taylor import Taylor
from .trace import Trace
from .wisdom_holman import SABA2, SABA3, SABA4, WisdomHolman

__all__ = ["get", "available", "register", "Integrator", "IntegratorInfo",
           "SplittingMethod", "ExplicitRungeKutta"]

_REGISTRY = {}


class IntegratorInfo(NamedTuple):
    """What :func:`available` lists about each integrator.

    Examples
    --------
    >>> import orbits
    >>> info = next(i for i in orbits.integrators.available() if i.name == "wh")
    >>> info.name, info.order, info.symplectic, info.adaptive
    ('wh', 2, True, False)
    """

    name: str
    order: int
    symplectic: bool
    adaptive: bool
    summary: str


def register(cls):
    """Add an integrator class to the registry (usable as a decorator).

    Parameters
    ----------
    cls : type
        A subclass of :class:`~orbits.integrators.Integrator` with a ``name``.

    Returns
    -------
    type
        ``cls``, unchanged.

    Raises
    ------
    TypeError
        ``cls`` is not a named Integrator subclass.

    Examples
    --------
    >>> from orbits import integrators
    >>> @integrators.register
    ... class HalfLeapfrog(type(integrators.get("leapfrog"))):
    ...     name = "half-leapfrog-example"
    >>> type(integrators.get("half-leapfrog-example")).__name__
    'HalfLeapfrog'
    >>> del integrators._REGISTRY["half-leapfrog-example"]   # keep the registry as it was
    """
    if not (isinstance(cls, type) and issubclass(cls, Integrator) and cls.name):
        raise TypeError("only named Integrator subclasses can be registered")
    _REGISTRY[cls.name] = cls
    return cls


for _cls in (Euler, SymplecticEuler, Verlet, Leapfrog, RK2, RK4, Yoshida4, Yoshida6,
             Yoshida8, WisdomHolman, SABA2, SABA3, SABA4, Dopri5, DOP853,
             RK4Doubling, Radau, LSODA, IAS15, Taylor, ImplicitEuler, ImplicitMidpoint, Trace):
    register(_cls)


def get(name, **options):
    """A configured integrator instance.

    Parameters
    ----------
    name : str
        Registry name; see :func:`available`.
    **options
        The integrator's options; unknown ones are an error.

    Raises
    ------
    UnknownIntegratorError
        The name is not registered; the message lists the valid ones.

    Returns
    -------
    Integrator
        An instance with its options in ``config``; an instance given as
        ``name`` is returned as it is, or copied with ``options`` changed.

    Examples
    --------
    >>> import orbits
    >>> orbits.integrators.get("ias15", epsilon=1e-10)
    IAS15(epsilon=1e-10, min_dt=0.0, adaptive_mode='global')
    >>> orbits.integrators.get("dopri5").config
    {'rtol': 1e-09, 'atol': 1e-12}
    """
    if isinstance(name, Integrator):
        if options:
            return type(name)(**{**name.config, **options})
        return name
    try:
        cls = _REGISTRY[name]
    except (KeyError, TypeError):
        raise UnknownIntegratorError(
            f"unknown integrator {name!r}; valid names: {', '.join(_REGISTRY)}") from None
    return cls(**options)


def available():
    """Registered integrators with their order and properties, in registry order.

    Returns
    -------
    list of IntegratorInfo

    Examples
    --------
    >>> import orbits
    >>> [(i.name, i.order) for i in orbits.integrators.available() if i.symplectic][:3]
    [('symplectic-euler', 1), ('verlet', 2), ('leapfrog', 2)]
    """
    return [IntegratorInfo(c.name, c.order, c.symplectic, c.adaptive, c.summary)
            for c in _REGISTRY.values()]
