"""The registry of integrators: name -> class, and REBOUND's names for the same methods.

>>> [i.name for i in orbits.integrators.available()][:3]
['euler', 'symplectic-euler', 'verlet']
>>> orbits.integrators.get("rk4")
RK4()
>>> orbits.integrators.get("whfast").name       # REBOUND's name for the same method
'wh'
"""

import difflib
import importlib
from typing import NamedTuple

from ..errors import UnknownIntegratorError
from .base import ExplicitRungeKutta, Integrator, Option, SplittingMethod

__all__ = ["get", "available", "aliases", "register", "adaptive_names", "Integrator",
           "IntegratorInfo", "Option", "SplittingMethod", "ExplicitRungeKutta", "ALIASES",
           "DEFAULT"]

#: The built-in integrators in the registry's order: name -> (module, class).
#: A module (with its kernels) is imported when its integrator is first
#: asked for: importing all of them costs 0.1 s a process, and a run needs
#: one (benchmarks/RESULTS.md).
_BUILT_IN = {
    "euler": ("euler", "Euler"), "symplectic-euler": ("euler", "SymplecticEuler"),
    "verlet": ("leapfrog", "Verlet"), "leapfrog": ("leapfrog", "Leapfrog"),
    "rk2": ("runge_kutta", "RK2"), "rk4": ("runge_kutta", "RK4"),
    "yoshida4": ("composition", "Yoshida4"), "yoshida6": ("composition", "Yoshida6"),
    "yoshida8": ("composition", "Yoshida8"),
    "wh": ("wisdom_holman", "WisdomHolman"), "saba2": ("wisdom_holman", "SABA2"),
    "saba3": ("wisdom_holman", "SABA3"), "saba4": ("wisdom_holman", "SABA4"),
    "dopri5": ("embedded", "Dopri5"), "dop853": ("embedded", "DOP853"),
    "rk4-doubling": ("doubling", "RK4Doubling"),
    "radau": ("scipy_ivp", "Radau"), "lsoda": ("scipy_ivp", "LSODA"),
    "ias15": ("ias15", "IAS15"), "taylor": ("taylor", "Taylor"),
    "implicit-euler": ("implicit", "ImplicitEuler"),
    "implicit-midpoint": ("implicit", "ImplicitMidpoint"),
    "trace": ("trace", "Trace"),
}

#: name -> class: the built-in integrators imported so far, and those
#: registered (:func:`register`)
_REGISTRY = {}

#: The integrator of ``Simulation(bodies)`` and ``orbits run``: adaptive, so
#: that it needs no step, and accurate to round-off at its default tolerance
#: (REBOUND's default too).
DEFAULT = "ias15"

#: Other names -> registry name, where the other name means the same method:
#: REBOUND's ``"whfast"`` is the Wisdom-Holman map in Jacobi coordinates
#: without a corrector by default, with the same ``corrector`` and
#: ``coordinates`` choices as ``wh`` (its ``"wh"`` is the same map too).
ALIASES = {"whfast": "wh"}

#: REBOUND's names for methods that are not here, with what to use instead.
#: Not aliases: the methods differ (see the integrators guide).
_ELSEWHERE = {
    "mercurius": ("REBOUND's MERCURIUS (a Wisdom-Holman map whose interaction is split "
                  "by a smooth changeover function, IAS15 inside it) is not here; 'trace' "
                  "is the hybrid method here (the same democratic heliocentric map, "
                  "switching time-reversibly to DOP853 for close encounters)", "trace"),
    "saba": ("REBOUND's 'saba' is SABA(10,6,4) unless its type is set; that method is not "
             "here, but 'saba2', 'saba3' and 'saba4' are (Laskar & Robutel 2001, as "
             "REBOUND's 'saba2' to 'saba4')", "saba2"),
    "whfast512": ("WHFast512 is the Wisdom-Holman map in democratic heliocentric "
                  "coordinates: 'wh' with coordinates='democratic-heliocentric'", "wh"),
    "whc": ("REBOUND's 'whc' is WHFast with the 17th-order corrector: 'wh' with "
            "corrector=17", "wh"),
}


class IntegratorInfo(NamedTuple):
    """What :func:`available` lists about each integrator.

    Examples
    --------
    >>> info = next(i for i in orbits.integrators.available() if i.name == "wh")
    >>> info.name, info.order, info.symplectic, info.adaptive
    ('wh', 2, True, False)
    """

    name: str
    order: int
    symplectic: bool
    adaptive: bool
    summary: str
    #: other names that :func:`get` accepts for it (REBOUND's)
    aliases: tuple = ()


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


def _names():
    # every name in the registry's order: the built-in ones, then those
    # registered
    return [*_BUILT_IN, *(n for n in _REGISTRY if n not in _BUILT_IN)]


def _class(name):
    # the class of a name of _names(), its module imported on first use
    cls = _REGISTRY.get(name)
    if cls is None:
        module, attr = _BUILT_IN[name]
        cls = _REGISTRY[name] = getattr(importlib.import_module(f"{__name__}.{module}"),
                                        attr)
    return cls


def _classes():
    # every class of the registry, in its order (every module imported)
    return [_class(name) for name in _names()]


def __getattr__(attr):
    # the built-in classes as attributes of the package (orbits.integrators.IAS15)
    for module, cls in _BUILT_IN.values():
        if cls == attr:
            return getattr(importlib.import_module(f"{__name__}.{module}"), attr)
    raise AttributeError(f"module {__name__!r} has no attribute {attr!r}")


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
        The name is not registered; the message suggests the nearest one and
        lists the valid ones.
    IntegratorOptionError
        An option the integrator does not have; the message lists the ones
        it has.

    Returns
    -------
    Integrator
        An instance with its options in ``config``; an instance given as
        ``name`` is returned as it is, or copied with ``options`` changed.

    Examples
    --------
    >>> orbits.integrators.get("ias15", epsilon=1e-10)
    IAS15(epsilon=1e-10, min_dt=0.0, adaptive_mode='global')
    >>> orbits.integrators.get("dopri5").config
    {'rtol': 1e-09, 'atol': 1e-12}
    >>> orbits.integrators.get("whfast", corrector=17)   # an alias (ALIASES)
    WisdomHolman(coordinates='jacobi', corrector=17, lanes='auto')
    """
    if isinstance(name, Integrator):
        if options:
            return type(name)(**{**name.config, **options})
        return name
    return _lookup(name)(**options)


def _lookup(name):
    """The class registered under ``name`` or one of its aliases."""
    if isinstance(name, str):
        names = _names()
        for key in (ALIASES.get(name.lower(), name), name.lower()):
            if key in names:
                return _class(key)
    raise UnknownIntegratorError(_unknown_message(name))


def _unknown_message(name):
    text = f"unknown integrator {name!r}"
    valid = f"valid names: {', '.join(_names())}; aliases: " + ", ".join(
        f"{a} -> {n}" for a, n in ALIASES.items())
    if not isinstance(name, str):
        return f"{text}: a name is a string; {valid}"
    note, nearest = _ELSEWHERE.get(name.lower(), (None, None))
    if note is None:
        close = difflib.get_close_matches(name.lower(), [*_names(), *ALIASES], n=1,
                                          cutoff=0.6)
        nearest = ALIASES.get(close[0], close[0]) if close else None
    else:
        text += f"; {note}"
    if nearest is not None:
        text += f"; did you mean {nearest!r}?"
    return f"{text}; {valid}"


def aliases():
    """Other names :func:`get` accepts, each with the registry name it means.

    Returns
    -------
    dict of str to str

    Examples
    --------
    >>> orbits.integrators.aliases()
    {'whfast': 'wh'}
    """
    return dict(ALIASES)


def adaptive_names():
    """The registry names of the adaptive integrators, which choose their own steps.

    Returns
    -------
    list of str

    Examples
    --------
    >>> orbits.integrators.adaptive_names()[-2:]
    ['ias15', 'taylor']
    """
    return [name for name in _names() if _class(name).adaptive]


def available():
    """Registered integrators with their order and properties, in registry order.

    Returns
    -------
    list of IntegratorInfo

    Examples
    --------
    >>> [(i.name, i.order) for i in orbits.integrators.available() if i.symplectic][:3]
    [('symplectic-euler', 1), ('verlet', 2), ('leapfrog', 2)]
    """
    return [IntegratorInfo(c.name, c.order, c.symplectic, c.adaptive, c.summary,
                           tuple(a for a, n in ALIASES.items() if n == c.name))
            for c in map(_class, _names())]
