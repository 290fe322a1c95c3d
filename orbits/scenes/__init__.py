"""Ready-made body sets, each with the reference it comes from.

Every scene is a function that returns a fresh :class:`~orbits.bodies.BodySet`
and appends a record ``{"scene": name, ...parameters}`` to its ``history``,
so that results say where their initial conditions came from.  Scenes are
moved to the centre-of-mass frame unless their docstring says otherwise.

:data:`SCENES` maps the command-line names (lowercase, with hyphens) to the
functions; :func:`get` builds a scene by name and :func:`describe` lists them.

The scenes come in families, each in a module of this package: Keplerian
orbits (:mod:`orbits.scenes.keplerian`), initial conditions from the
literature (:mod:`orbits.scenes.published`), the solar system from an
ephemeris (:mod:`orbits.scenes.ephemerides`) and random samples
(:mod:`orbits.scenes.sampled`).

Masses of solar-system bodies are given through their GM values, which are
known far better than the masses themselves: a body's mass is stored as
``GM / G`` in the set's unit system, so that ``G * m`` equals the published
GM exactly (the DE440 values are in the private ``_provenance``).

Examples
--------
>>> from orbits import scenes
>>> bodies = scenes.get("outer-solar-system")
>>> bodies.names
['Sun', 'Jupiter', 'Saturn', 'Uranus', 'Neptune', 'Pluto']
>>> [name for name, _ in scenes.describe()][:3]
['earth-moon', 'sun-earth-moon', 'kepler']
"""

from .ephemerides import DE421_AU, J2000_OBLIQUITY, de421, de421_states, solar_system
from .keplerian import (MOON_ECCENTRICITY, MOON_SEMI_MAJOR_AXIS, earth_moon, kepler,
                        sun_earth_moon)
from .published import FIGURE_EIGHT_PERIOD, HLW_G, figure_eight, outer_solar_system, pythagorean
from .sampled import planetesimal_ring, plummer

__all__ = [
    "earth_moon",
    "sun_earth_moon",
    "kepler",
    "outer_solar_system",
    "solar_system",
    "de421",
    "de421_states",
    "pythagorean",
    "figure_eight",
    "plummer",
    "planetesimal_ring",
    "SCENES",
    "get",
    "describe",
    "FIGURE_EIGHT_PERIOD",
    "HLW_G",
    "DE421_AU",
    "J2000_OBLIQUITY",
    "MOON_SEMI_MAJOR_AXIS",
    "MOON_ECCENTRICITY",
]

#: Scene names, as the command line spells them, and the functions that build them.
SCENES = {
    "earth-moon": earth_moon,
    "sun-earth-moon": sun_earth_moon,
    "kepler": kepler,
    "outer-solar-system": outer_solar_system,
    "solar-system": solar_system,
    "de421": de421,
    "pythagorean": pythagorean,
    "figure-eight": figure_eight,
    "plummer": plummer,
    "planetesimal-ring": planetesimal_ring,
}


def get(name, **kwargs):
    """Build the scene called ``name`` (underscores are read as hyphens).

    Parameters
    ----------
    name : str
        A key of :data:`SCENES`, such as ``"outer-solar-system"``.
    **kwargs
        Passed to the scene's function.

    Returns
    -------
    BodySet

    Raises
    ------
    ValueError
        Unknown name; the message lists the valid ones.

    Examples
    --------
    >>> from orbits import scenes
    >>> len(scenes.get("plummer", n=100, seed=1))
    100
    """
    key = name.strip().lower().replace("_", "-") if isinstance(name, str) else name
    try:
        function = SCENES[key]
    except (KeyError, TypeError):
        raise ValueError(f"unknown scene {name!r}; valid scenes: "
                         f"{', '.join(SCENES)}") from None
    return function(**kwargs)


def describe():
    """The scenes' names with one-line descriptions: a list of (name, line) pairs.

    Examples
    --------
    >>> from orbits import scenes
    >>> dict(scenes.describe())["kepler"]
    'A two-body Kepler problem: one orbiter about a central mass.'
    """
    return [(name, function.__doc__.strip().splitlines()[0].strip())
            for name, function in SCENES.items()]
