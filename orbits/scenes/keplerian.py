"""Scenes given by Keplerian orbits: the two-body problem, the Earth and the
Moon, and the Sun, the Earth and the Moon."""

import astropy.units as u
import numpy as np

from ..bodies import BodySet
from ..units import UnitSystem
from ._provenance import DE440_REFERENCE, GM_DE440, GM_UNIT, de440_mass, record

__all__ = ["kepler", "earth_moon", "sun_earth_moon", "MOON_SEMI_MAJOR_AXIS",
           "MOON_ECCENTRICITY"]

#: The Moon's mean distance and orbital eccentricity used by the Earth-Moon
#: scenes (NASA NSSDCA Moon Fact Sheet, D. R. Williams).
MOON_SEMI_MAJOR_AXIS = 384_400 * u.km
MOON_ECCENTRICITY = 0.0549

#: Mean inclination of the Moon's orbit to the ecliptic (same source).
_MOON_INCLINATION = 5.145 * u.deg


def _earth_moon_units():
    # Taking G from the Earth's GM makes the Earth's mass exactly 1 Mearth and
    # the Moon's GM_moon / GM_earth = 0.0123000371.
    G = (GM_DE440["Earth"] * GM_UNIT / (1 * u.Mearth))
    return UnitSystem(length=u.km, mass=u.Mearth, time=u.day, G=G,
                      name="km-Mearth-day (DE440 GM_earth)",
                      G_source=f"GM of the Earth from {DE440_REFERENCE}")


def kepler(e=0.0, a=1.0 * u.au, f=1.0 * u.rad, m_central=1.0 * u.Msun,
           m_orbiter=1e-3 * u.Msun, inc=0.0 * u.rad, units=None):
    """A two-body Kepler problem: one orbiter about a central mass.

    Parameters
    ----------
    e : float
        Eccentricity, ``>= 0``.  ``e > 1`` (hyperbolic) needs ``a < 0``; the
        parabola ``e = 1`` cannot be given by ``a`` and is refused.
    a : Quantity, scalar, length
        Semi-major axis of the relative orbit.  Default 1 au.
    f : Quantity, scalar, angle
        True anomaly at the start.  Default 1 rad (57.3 deg): away from both
        apsides, so that an integrator's error shows in the radial and the
        tangential direction at once, as convergence tests need; it is also
        inside the asymptotes of every hyperbola (``|f| < pi/2 < arccos(-1/e)``).
    m_central, m_orbiter : Quantity, scalar, mass
        Default 1 Msun and 1e-3 Msun (about Jupiter's mass).  The orbiter has
        mass by default so that the total energy and angular momentum are not
        those of the central body alone: with a massless orbiter the energy of
        the COM-frame pair is exactly zero and a relative energy error has no
        meaning.  ``m_orbiter = 0`` is allowed.
    inc : Quantity, scalar, angle
        Inclination of the orbit to the xy plane.  Default 0.
    units : UnitSystem, optional
        Default au, solar masses and days.  When given, plain numbers are read
        in it.

    Returns
    -------
    BodySet
        Bodies ``"Star"`` and ``"Planet"`` in the centre-of-mass frame.  The
        relative orbit has ``mu = G (m_central + m_orbiter)`` and period
        ``2 pi sqrt(a^3 / mu)``, and has its pericentre on the +x axis.

    Raises
    ------
    orbits.errors.ElementsError
        Elements that describe no orbit (``e < 0``, ``e >= 1`` with ``a > 0``, a
        hyperbolic ``f`` beyond the asymptote...).

    References
    ----------
    .. [1] Murray, C. D. & Dermott, S. F. 1999, *Solar System Dynamics*,
       Cambridge University Press, ch. 2.

    Examples
    --------
    >>> from orbits import scenes
    >>> bodies = scenes.kepler(e=0.5)
    >>> round(float(bodies.elements("Planet", primary="Star")["e"]), 12)
    0.5
    >>> hyperbola = scenes.kepler(e=1.5, a=-1 * u.au)
    """
    bodies = BodySet(units)
    bodies.add("Star", mass=m_central, position=np.zeros(3) << bodies.units.length)
    bodies.add("Planet", mass=m_orbiter, primary="Star", a=a, e=e, f=f, inc=inc)
    bodies.move_to_com()
    return record(bodies, "kepler", e=float(e), a=str(a), f=str(f), inc=str(inc),
                  m_central=str(m_central), m_orbiter=str(m_orbiter))


def earth_moon():
    """The Earth and the Moon on a Keplerian orbit of the Moon's mean size and shape.

    The Earth is the central body and the Moon starts at perigee on the orbit
    ``a = 384,400 km``, ``e = 0.0549`` about it, in the orbit's own plane
    (``inc = 0``).  The pair is moved to the centre-of-mass frame.

    Returns
    -------
    BodySet
        Bodies ``"Earth"`` and ``"Moon"``, in km, Earth masses and days.  G is
        taken from the Earth's DE440 GM, so the Earth's mass is exactly
        1 Mearth and the Moon's is ``GM_moon / GM_earth = 0.0123000371``.

    Notes
    -----
    The orbit is a two-body Keplerian ellipse with ``mu = G (m_E + m_M)``; the
    real Moon's orbit is strongly perturbed by the Sun (see
    :func:`~orbits.scenes.sun_earth_moon` and :func:`~orbits.scenes.solar_system`).

    References
    ----------
    .. [1] Park, R. S., Folkner, W. M., Williams, J. G. & Boggs, D. H. 2021,
       "The JPL Planetary and Lunar Ephemerides DE440 and DE441", AJ 161, 105;
       GM values as distributed in NAIF's ``gm_de440.tpc``:
       GM_earth = 398600.435507, GM_moon = 4902.800118 km^3/s^2.
    .. [2] Williams, D. R., *Moon Fact Sheet*, NASA Space Science Data
       Coordinated Archive, https://nssdc.gsfc.nasa.gov/planetary/factsheet/
       (semi-major axis 0.3844e6 km, eccentricity 0.0549).

    Examples
    --------
    >>> from orbits import scenes
    >>> bodies = scenes.earth_moon()
    >>> bodies.names
    ['Earth', 'Moon']
    >>> round(float(bodies.elements("Moon", primary="Earth")["a"].value))
    384400
    """
    units = _earth_moon_units()
    bodies = BodySet(units)
    bodies.add("Earth", mass=1.0 * u.Mearth, position=[0.0, 0.0, 0.0] * u.km)
    bodies.add("Moon", mass=de440_mass("Moon", units),
               primary="Earth", a=MOON_SEMI_MAJOR_AXIS, e=MOON_ECCENTRICITY)
    bodies.move_to_com()
    return record(bodies, "earth-moon", a=str(MOON_SEMI_MAJOR_AXIS),
                  e=MOON_ECCENTRICITY, gm=DE440_REFERENCE)


def sun_earth_moon():
    """The Sun, the Earth and the Moon on idealised Keplerian orbits.

    The Earth-Moon barycentre starts at perihelion of the heliocentric orbit
    ``a = 1 au``, ``e = 0.0167`` in the xy plane (the ecliptic of this
    model); the Moon starts at perigee of the geocentric orbit
    ``a = 384,400 km``, ``e = 0.0549``, inclined 5.145 deg to the ecliptic.
    The Earth and the Moon are placed about their barycentre by their mass
    ratio, and the whole set is moved to the centre-of-mass frame.

    Returns
    -------
    BodySet
        Bodies ``"Sun"``, ``"Earth"``, ``"Moon"``, in au, solar masses and days
        (the default :class:`~orbits.units.UnitSystem`, with astropy's
        GM_sun).  The Sun's mass is 1 Msun; the Earth's and the Moon's come from
        their DE440 GM values.

    Notes
    -----
    A schematic configuration, not an ephemeris: the phases and orientations
    are not those of any date.  Use :func:`~orbits.scenes.solar_system` for the real sky.

    References
    ----------
    .. [1] Park, R. S. et al. 2021, "The JPL Planetary and Lunar Ephemerides
       DE440 and DE441", AJ 161, 105 (GM values from NAIF's ``gm_de440.tpc``).
    .. [2] Williams, D. R., *Earth Fact Sheet* and *Moon Fact Sheet*, NASA
       Space Science Data Coordinated Archive,
       https://nssdc.gsfc.nasa.gov/planetary/factsheet/ (Earth: e = 0.0167;
       Moon: a = 384,400 km, e = 0.0549, inclination 5.145 deg).

    Examples
    --------
    >>> from orbits import scenes
    >>> bodies = scenes.sun_earth_moon()
    >>> bodies.names
    ['Sun', 'Earth', 'Moon']
    """
    units = UnitSystem.default()
    m_sun = 1.0 * u.Msun
    m_earth = de440_mass("Earth", units)
    m_moon = de440_mass("Moon", units)
    a_earth, e_earth = 1.0 * u.au, 0.0167

    # The barycentre of the pair, not the Earth, follows the heliocentric ellipse.
    helio = BodySet(units)
    helio.add("Sun", mass=m_sun, position=[0.0, 0.0, 0.0] * u.au)
    helio.add("Earth-Moon", mass=m_earth + m_moon, primary="Sun", a=a_earth, e=e_earth)
    pair = BodySet(units)
    pair.add("Earth", mass=m_earth, position=[0.0, 0.0, 0.0] * u.au)
    pair.add("Moon", mass=m_moon, primary="Earth", a=MOON_SEMI_MAJOR_AXIS,
             e=MOON_ECCENTRICITY, inc=_MOON_INCLINATION)
    x_bary, v_bary = helio.positions[1], helio.velocities[1]
    x_rel, v_rel = pair.positions[1], pair.velocities[1]
    share_earth = float(m_moon / (m_earth + m_moon))
    share_moon = float(m_earth / (m_earth + m_moon))

    bodies = BodySet(units)
    bodies.add("Sun", mass=m_sun, position=helio.positions[0],
               velocity=helio.velocities[0])
    bodies.add("Earth", mass=m_earth, position=x_bary - share_earth * x_rel,
               velocity=v_bary - share_earth * v_rel)
    bodies.add("Moon", mass=m_moon, position=x_bary + share_moon * x_rel,
               velocity=v_bary + share_moon * v_rel)
    bodies.move_to_com()
    return record(bodies, "sun-earth-moon", a_earth=str(a_earth), e_earth=e_earth,
                  a_moon=str(MOON_SEMI_MAJOR_AXIS), e_moon=MOON_ECCENTRICITY,
                  inc_moon=str(_MOON_INCLINATION), gm=DE440_REFERENCE)
