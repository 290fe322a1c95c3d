"""Where a scene's numbers come from: the published GM values its masses are made
from (a mass is ``GM / G``, so that ``G * m`` is the published GM exactly), and
the record of the scene that a body set keeps in its ``history``."""

import astropy.units as u

__all__ = ["GM_DE440", "GM_UNIT", "DE440_REFERENCE", "de440_mass", "record"]

#: GM values in km^3 / s^2 from the JPL DE440 planetary ephemeris, as published
#: in NAIF's gm_de440.tpc (Park et al. 2021).  Planets other than the Earth are
# planet-plus-satellites systems, which is what a point mass at a planet's
# ephemeris position stands for.
GM_DE440 = {
    "Sun": 1.3271244004127942e11,
    "Mercury": 2.2031868551400003e04,
    "Venus": 3.2485859200000000e05,
    "Earth": 3.9860043550702266e05,
    "Moon": 4.9028001184575496e03,
    "Mars": 4.2828375815756102e04,
    "Jupiter": 1.2671276409999998e08,
    "Saturn": 3.7940584841799997e07,
    "Uranus": 5.7945563999999985e06,
    "Neptune": 6.8365271005803989e06,
}
GM_UNIT = u.km ** 3 / u.s ** 2
DE440_REFERENCE = ("JPL DE440 GM values (NAIF gm_de440.tpc; Park et al. 2021, "
                    "AJ 161, 105)")


def de440_mass(name, units):
    """The mass of body ``name`` in ``units`` whose ``G * m`` is its DE440 GM.

    Examples
    --------
    >>> from orbits import UnitSystem
    >>> from orbits.scenes._provenance import de440_mass
    >>> de440_mass("Jupiter", UnitSystem()).round(8)
    <Quantity 0.00095479 solMass>
    """
    gm_internal = (GM_DE440[name] * GM_UNIT).to_value(units.length ** 3 / units.time ** 2)
    return (gm_internal / units.G) << units.mass


def record(bodies, scene, **params):
    """Append ``{"scene": scene, **params}`` to the set's history; the set."""
    bodies.history.append({"scene": scene, **params})
    return bodies
