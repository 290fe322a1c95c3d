"""Ready-made body sets, each with the reference it comes from.

Every scene is a function that returns a fresh :class:`~orbits.bodies.BodySet`
and appends a record ``{"scene": name, ...parameters}`` to its ``history``,
so that results say where their initial conditions came from.  Scenes are
moved to the centre-of-mass frame unless their docstring says otherwise.

:data:`SCENES` maps the command-line names (lowercase, with hyphens) to the
functions; :func:`get` builds a scene by name and :func:`describe` lists them.

Masses of solar-system bodies are given through their GM values, which are
known far better than the masses themselves: a body's mass is stored as
``GM / G`` in the set's unit system, so that ``G * m`` equals the published
GM exactly.

Examples
--------
>>> from orbits import scenes
>>> bodies = scenes.get("outer-solar-system")
>>> bodies.names
['Sun', 'Jupiter', 'Saturn', 'Uranus', 'Neptune', 'Pluto']
>>> [name for name, _ in scenes.describe()][:3]
['earth-moon', 'sun-earth-moon', 'kepler']
"""

import math

import astropy.units as u
import numpy as np

from . import epochs as _epochs
from .bodies import BodySet
from .units import UnitSystem

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

#: Period of the figure-eight choreography in N-body units (G = m = 1), from
#: Simó's computation quoted by Chenciner & Montgomery (2000).
FIGURE_EIGHT_PERIOD = 6.32591398

#: The gravitational constant of the Hairer-Lubich-Wanner outer solar system,
#: in au^3 / (Msun day^2) (Hairer, Lubich & Wanner 2006, sect. I.2.4).
HLW_G = 2.95912208286e-4

#: Mean obliquity of the ecliptic at J2000.0 (IAU 2006 precession, Capitaine
#: et al. 2003, adopted by IAU 2006 Resolution B1).
J2000_OBLIQUITY = 84381.406 * u.arcsec

#: The Moon's mean distance and orbital eccentricity used by the Earth-Moon
#: scenes (NASA NSSDCA Moon Fact Sheet, D. R. Williams).
MOON_SEMI_MAJOR_AXIS = 384_400 * u.km
MOON_ECCENTRICITY = 0.0549

#: Mean inclination of the Moon's orbit to the ecliptic (same source).
_MOON_INCLINATION = 5.145 * u.deg

# GM values in km^3 / s^2 from the JPL DE440 planetary ephemeris, as published
# in NAIF's gm_de440.tpc (Park et al. 2021).  Planets other than the Earth are
# planet-plus-satellites systems, which is what a point mass at a planet's
# ephemeris position stands for.
_GM_DE440 = {
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
_GM_UNIT = u.km ** 3 / u.s ** 2
_DE440_REFERENCE = ("JPL DE440 GM values (NAIF gm_de440.tpc; Park et al. 2021, "
                    "AJ 161, 105)")

# Radii beyond this fraction of the Plummer mass are not sampled: the
# untruncated model has no outer edge, and one star at r ~ 1000 would set the
# size of every plot and the step of every integrator.
PLUMMER_MASS_CUT = 0.999

def planetesimal_ring(n=80, seed=1, radius=5e-4 * u.au, total_mass=2 * u.Mearth):
    """A ring of planetesimals with radii between 0.9 and 1.1 au about a Sun-mass star.

    ``n`` equal masses (``total_mass`` in all) on nearly circular, nearly
    coplanar orbits: semi-major axes uniform in [0.9, 1.1] au, eccentricities
    and inclinations Rayleigh distributed with scales 0.01 and 0.005 rad,
    the angles uniform.  The radii are inflated (5e-4 au by default, 75 000
    km) so that collisions come within a few hundred orbits: a scene for
    ``collisions="merge"`` (``examples/planetesimal_accretion.py``).

    Parameters
    ----------
    n : int
        Number of planetesimals, ``>= 1``.  Default 80.
    seed : int or None
        Passed to :func:`numpy.random.default_rng`; equal seeds give equal sets.
    radius : Quantity, length
        Each planetesimal's radius; the star's is the Sun's.
    total_mass : Quantity, mass

    Returns
    -------
    BodySet
        ``"Sun"`` and ``"p000"`` ... in au, Msun and days, moved to the
        centre-of-mass frame.

    References
    ----------
    Ida & Makino (1992), Icarus 96, 107: Rayleigh distributions of the
    planetesimals' eccentricities and inclinations.  Kokubo & Ida (1996),
    Icarus 123, 180: planetesimal radii enlarged so that collisions come
    within an affordable run.

    Examples
    --------
    >>> from orbits import scenes
    >>> ring = scenes.planetesimal_ring(n=20)
    >>> len(ring), ring.names[:2], ring.radii[1]
    (21, ['Sun', 'p000'], <Quantity 0.0005 AU>)
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise ValueError(f"n must be a whole number of planetesimals >= 1, got {n!r}")
    rng = np.random.default_rng(seed)
    b = BodySet()
    b.add("Sun", mass=1 * u.Msun, radius=1 * u.Rsun)
    for k in range(int(n)):
        b.add(f"p{k:03d}", mass=total_mass / n, primary="Sun",
              a=rng.uniform(0.9, 1.1) * u.au, e=rng.rayleigh(0.01),
              inc=rng.rayleigh(0.005) * u.rad, Omega=rng.uniform(0, 360) * u.deg,
              omega=rng.uniform(0, 360) * u.deg, M=rng.uniform(0, 360) * u.deg,
              radius=radius)
    b.move_to_com()
    return _record(b, "planetesimal-ring", n=int(n), seed=seed,
                   radius=float(radius.to_value(u.au)),
                   total_mass=float(total_mass.to_value(u.Mearth)))


# Bound on g(q) = q^2 (1 - q^2)^(7/2) for the rejection sampling of speeds;
# its maximum is 0.0922 at q^2 = 2/9 (Aarseth, Henon & Wielen 1974 use 0.1).
_PLUMMER_G_BOUND = 0.1


# -- helpers --------------------------------------------------------------------
def _mass_from_gm(gm, units):
    """The mass, in ``units``, whose ``G * m`` is ``gm`` (a Quantity)."""
    gm_internal = gm.to_value(units.length ** 3 / units.time ** 2)
    return (gm_internal / units.G) << units.mass


def _record(bodies, scene, **params):
    bodies.history.append({"scene": scene, **params})
    return bodies


def _earth_moon_units():
    # Taking G from the Earth's GM makes the Earth's mass exactly 1 Mearth and
    # the Moon's GM_moon / GM_earth = 0.0123000371.
    G = (_GM_DE440["Earth"] * _GM_UNIT / (1 * u.Mearth))
    return UnitSystem(length=u.km, mass=u.Mearth, time=u.day, G=G,
                      name="km-Mearth-day (DE440 GM_earth)",
                      G_source=f"GM of the Earth from {_DE440_REFERENCE}")


def _as_tdb(epoch):
    from astropy.time import Time

    if isinstance(epoch, Time):
        if epoch.scale == "tdb":
            return epoch
        # UTC needs the leap-second table and UT1 the IERS tables; the
        # conversion must not go to the network for fresher ones.
        from astropy.utils import iers
        with iers.conf.set_temp("auto_download", False):
            return epoch.tdb
    if isinstance(epoch, str):
        return Time(epoch, scale="tdb")
    raise TypeError(f"epoch must be a string or an astropy Time, got "
                    f"{type(epoch).__name__}")


def _rotate_to_ecliptic(vectors, obliquity):
    """Rotate (N, 3) equatorial vectors about the x axis into the ecliptic."""
    c, s = math.cos(obliquity), math.sin(obliquity)
    out = np.empty_like(vectors)
    out[:, 0] = vectors[:, 0]
    out[:, 1] = c * vectors[:, 1] + s * vectors[:, 2]
    out[:, 2] = -s * vectors[:, 1] + c * vectors[:, 2]
    return out


# -- scenes ---------------------------------------------------------------------
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
    :func:`sun_earth_moon` and :func:`solar_system`).

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
    bodies.add("Moon", mass=_mass_from_gm(_GM_DE440["Moon"] * _GM_UNIT, units),
               primary="Earth", a=MOON_SEMI_MAJOR_AXIS, e=MOON_ECCENTRICITY)
    bodies.move_to_com()
    return _record(bodies, "earth-moon", a=str(MOON_SEMI_MAJOR_AXIS),
                   e=MOON_ECCENTRICITY, gm=_DE440_REFERENCE)


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
    are not those of any date.  Use :func:`solar_system` for the real sky.

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
    m_earth = _mass_from_gm(_GM_DE440["Earth"] * _GM_UNIT, units)
    m_moon = _mass_from_gm(_GM_DE440["Moon"] * _GM_UNIT, units)
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
    return _record(bodies, "sun-earth-moon", a_earth=str(a_earth), e_earth=e_earth,
                   a_moon=str(MOON_SEMI_MAJOR_AXIS), e_moon=MOON_ECCENTRICITY,
                   inc_moon=str(_MOON_INCLINATION), gm=_DE440_REFERENCE)


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
    >>> import astropy.units as u
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
    return _record(bodies, "kepler", e=float(e), a=str(a), f=str(f), inc=str(inc),
                   m_central=str(m_central), m_orbiter=str(m_orbiter))


# Hairer, Lubich & Wanner (2006), Table I.2.1: masses relative to the Sun
# (the Sun's including the inner planets), positions in au and velocities in
# au/day, to the digits printed in the book.  The Sun is at rest at the origin.
_HLW_NAMES = ("Sun", "Jupiter", "Saturn", "Uranus", "Neptune", "Pluto")
_HLW_MASSES = (1.00000597682, 0.000954786104043, 0.000285583733151,
               0.0000437273164546, 0.0000517759138449, 1 / 1.3e8)
_HLW_POSITIONS = (
    (0.0, 0.0, 0.0),
    (-3.5023653, -3.8169847, -1.5507963),
    (9.0755314, -3.0458353, -1.6483708),
    (8.3101420, -16.2901086, -7.2521278),
    (11.4707666, -25.7294829, -10.8169456),
    (-15.5387357, -25.2225594, -3.1902382),
)
_HLW_VELOCITIES = (
    (0.0, 0.0, 0.0),
    (0.00565429, -0.00412490, -0.00190589),
    (0.00168318, 0.00483525, 0.00192462),
    (0.00354178, 0.00137102, 0.00055029),
    (0.00288930, 0.00114527, 0.00039677),
    (0.00276725, -0.00170702, -0.00136504),
)


def outer_solar_system(com=False):
    """The Hairer–Lubich–Wanner outer solar system: Sun, four giant planets and Pluto.

    The standard test problem of geometric numerical integration: the Sun
    (its mass including the inner planets), Jupiter, Saturn, Uranus, Neptune
    and Pluto, with the initial positions and velocities of 1994 September 5
    printed in the book, and its own value of G.

    Parameters
    ----------
    com : bool
        Move to the centre-of-mass frame.  Default False: keep the published
        frame, in which the Sun is at rest at the origin (heliocentric
        positions and velocities) and the axes are equatorial (the planets'
        orbits are inclined about 23 deg to the xy plane).  In that frame the
        centre of mass drifts at 6.8e-6 au/day (250 au in 1e5 years);
        integrators do not mind, but plots in that frame would.
        :meth:`orbits.Result.plot` and ``orbits plot`` draw about the Sun by
        default, and :meth:`orbits.Result.relative_to` or
        :meth:`orbits.Result.barycentric` change the frame of a result.

    Returns
    -------
    BodySet
        Bodies ``"Sun"``, ``"Jupiter"``, ``"Saturn"``, ``"Uranus"``,
        ``"Neptune"``, ``"Pluto"``, in au, solar masses and days with
        ``G = 2.95912208286e-4`` au^3/(Msun day^2) (:data:`HLW_G`; the book's
        value, 1.4e-12 relative from Gauss's constant squared).  Masses:
        ``m0 = 1.00000597682`` (Sun plus inner planets),
        ``m1 = 0.000954786104043``, ``m2 = 0.000285583733151``,
        ``m3 = 0.0000437273164546``, ``m4 = 0.0000517759138449``,
        ``m5 = 1 / 1.3e8``.

    References
    ----------
    .. [1] Hairer, E., Lubich, C. & Wanner, G. 2006, *Geometric Numerical
       Integration: Structure-Preserving Algorithms for Ordinary Differential
       Equations*, 2nd ed., Springer Series in Computational Mathematics 31,
       section I.2.4 and table 2.1.

    Examples
    --------
    >>> from orbits import scenes
    >>> bodies = scenes.outer_solar_system()
    >>> bodies.units.G
    0.000295912208286
    >>> bodies.positions[1].to_value(u.au).tolist()
    [-3.5023653, -3.8169847, -1.5507963]
    """
    units = UnitSystem(length=u.au, mass=u.Msun, time=u.day, G=HLW_G, name="hlw",
                       G_source="Hairer, Lubich & Wanner 2006, sect. I.2.4")
    bodies = BodySet.from_arrays(np.array(_HLW_MASSES), np.array(_HLW_POSITIONS),
                                 np.array(_HLW_VELOCITIES), names=_HLW_NAMES,
                                 units=units)
    if com:
        bodies.move_to_com()
    return _record(bodies, "outer-solar-system", com=bool(com),
                   epoch="1994-09-05",
                   source="Hairer, Lubich & Wanner 2006, table I.2.1")


_PLANETS = ("Mercury", "Venus", "Earth", "Mars", "Jupiter", "Saturn", "Uranus",
            "Neptune")
_FRAMES = ("ecliptic", "icrs")


def solar_system(epoch="2000-01-01 12:00:00", moon=True, frame="ecliptic"):
    """The Sun, the eight planets and the Moon at an epoch, from astropy's built-in ephemeris.

    Positions and velocities come from
    ``astropy.coordinates.get_body_barycentric_posvel(..., ephemeris="builtin")``,
    which needs no download: ERFA's ``epv00`` (the Earth and the Sun, from
    VSOP2000), ``plan94`` (the other planets, Simon et al. 1994) and
    ``moon98`` (the Moon, Meeus 1998, with analytic velocities).  Nothing
    here touches the network.

    Parameters
    ----------
    epoch : astropy.time.Time, str or float
        The date, as :func:`orbits.epochs.parse` reads it: a ``Time`` of any
        scale (converted to TDB with IERS downloads switched off), text (a
        date astropy reads, in TDB unless a scale follows it:
        ``"2024-03-01 UTC"``), or a Julian date in TDB; default J2000.0,
        ``"2000-01-01 12:00:00"`` TDB.  The set returned carries it as its
        :attr:`~orbits.BodySet.epoch`.
    moon : bool
        Include the Moon as its own body (the Earth is then the geocentre).
        With ``moon=False`` the body named ``"Earth"`` is the Earth-Moon
        barycentre with the pair's mass, made from the Earth and the Moon
        below (the builtin ephemeris's own "earth-moon-barycenter" comes from
        ``plan94`` and is about 100 times less accurate).
    frame : {"ecliptic", "icrs"}
        Orientation of the axes.  ``"icrs"``: the barycentric ICRS axes of the
        ephemeris (equatorial).  ``"ecliptic"`` (default, as planetary orbits
        are nearly flat in it): those axes rotated about x by the J2000 mean
        obliquity 84381.406 arcsec (IAU 2006), i.e. the mean ecliptic and
        equinox of J2000; the 23 mas frame bias between ICRS and the J2000
        mean equator is below the ephemeris's accuracy and is neglected.

    Returns
    -------
    BodySet
        ``"Sun"``, ``"Mercury"``, ``"Venus"``, ``"Earth"``, (``"Moon"``),
        ``"Mars"``, ``"Jupiter"``, ``"Saturn"``, ``"Uranus"``, ``"Neptune"``, in
        au, solar masses and days (the default unit system, with astropy's
        GM_sun), moved to the centre-of-mass frame (a shift of order 1e-7 au:
        the ephemeris is barycentric for the full solar system, which has more
        bodies than these).  The Sun's mass is 1 Msun; the others are their
        DE440 GM values divided by G: systems (planet and satellites) for Mars
        to Neptune, the Earth and the Moon separately.

    Notes
    -----
    Accuracy is that of the analytic theories, as quoted in ERFA's
    documentation: for the Earth about 5 km (epv00, 1900-2100); for the
    planets up to 300 km (Mercury) to 700,000 km (Uranus) over 1800-2050,
    degrading outside 1000-3000 AD (plan94); for the Moon 6 km RMS and
    36 mm/s RMS in velocity over 1950-2100 (moon98).  Good for realistic
    starting conditions, not for comparison with a numerical ephemeris.

    References
    ----------
    .. [1] Park, R. S., Folkner, W. M., Williams, J. G. & Boggs, D. H. 2021,
       "The JPL Planetary and Lunar Ephemerides DE440 and DE441", AJ 161, 105
       (GM values from NAIF's ``gm_de440.tpc``).
    .. [2] Simon, J. L. et al. 1994, "Numerical expressions for precession
       formulae and mean elements for the Moon and the planets", A&A 282, 663
       (ERFA ``plan94``).
    .. [3] Moisson, X. & Bretagnon, P. 2001, "Analytical planetary solution
       VSOP2000", Celest. Mech. Dyn. Astron. 80, 205 (ERFA ``epv00``).
    .. [4] Meeus, J. 1998, *Astronomical Algorithms*, 2nd ed., Willmann-Bell
       (ERFA ``moon98``).
    .. [5] Capitaine, N., Wallace, P. T. & Chapront, J. 2003, "Expressions for
       IAU 2000 precession quantities", A&A 412, 567 (obliquity 84381.406").

    Examples
    --------
    >>> import numpy as np
    >>> from orbits import scenes
    >>> bodies = scenes.solar_system()
    >>> len(bodies)
    10
    >>> r = bodies.positions[3] - bodies.positions[0]     # Earth - Sun, near perihelion
    >>> print(np.round(np.linalg.norm(r), 3))
    0.983 AU
    """
    from astropy.coordinates import get_body_barycentric_posvel

    if frame not in _FRAMES:
        raise ValueError(f"unknown frame {frame!r}; expected one of {_FRAMES}")
    time = _epochs.parse(epoch)
    units = UnitSystem.default()

    names = ["Sun", *_PLANETS[:3], "Moon", *_PLANETS[3:]]
    n = len(names)
    x = np.empty((n, 3))
    v = np.empty((n, 3))
    for i, name in enumerate(names):
        pos, vel = get_body_barycentric_posvel(name.lower(), time, ephemeris="builtin")
        x[i] = pos.xyz.to_value(units.length)
        v[i] = vel.xyz.to_value(units.unit("velocity"))
    m = np.array([1.0] + [_mass_from_gm(_GM_DE440[name] * _GM_UNIT, units).value
                          for name in names[1:]])
    if not moon:
        # The builtin "earth-moon-barycenter" is plan94's, good to ~1000 km;
        # epv00's Earth and moon98's Moon give it to ~10 km.
        e, k = names.index("Earth"), names.index("Moon")
        m_pair = m[e] + m[k]
        x[e] = (m[e] * x[e] + m[k] * x[k]) / m_pair
        v[e] = (m[e] * v[e] + m[k] * v[k]) / m_pair
        m[e] = m_pair
        keep = np.arange(n) != k
        names, m, x, v = [nm for nm in names if nm != "Moon"], m[keep], x[keep], v[keep]
    if frame == "ecliptic":
        eps = J2000_OBLIQUITY.to_value(u.rad)
        x, v = _rotate_to_ecliptic(x, eps), _rotate_to_ecliptic(v, eps)

    bodies = BodySet.from_arrays(m, x, v, names=names, units=units)
    bodies.move_to_com()
    bodies.epoch = time
    return _record(bodies, "solar-system", epoch=f"{time.isot} TDB", moon=bool(moon),
                   frame=frame, ephemeris="astropy builtin (ERFA epv00, plan94, moon98)",
                   gm=_DE440_REFERENCE)


# The constants of DE421 itself, from the ephemeris's header as the de421
# package ships it (de421/constants.npy: DENUM = 421, AU, EMRAT, GM1 ... GM9,
# GMB, GMS), and listed in Folkner, Williams & Boggs 2008 (IPN Progress Report
# 42-178).  GM values are in (DE421 au)^3 / day^2; the planets other than the
# Earth are planet-plus-satellites systems ("GMB" is the Earth and the Moon
# together, split by EMRAT = M_earth / M_moon).  tests/test_scenes.py checks
# that these equal the package's header to the last bit.
_GM_DE421 = {
    "GMS": 0.0002959122082855911,
    "GM1": 4.91254957186794e-11,
    "GM2": 7.243452332698441e-10,
    "GMB": 8.997011408268049e-10,
    "GM4": 9.54954869562239e-11,
    "GM5": 2.82534584085505e-07,
    "GM6": 8.459706073308477e-08,
    "GM7": 1.29202482579265e-08,
    "GM8": 1.52435910924974e-08,
    "GM9": 2.17844105199052e-12,
}
_EMRAT_DE421 = 81.3005690699153

#: The astronomical unit of DE421, an estimated parameter of the fit (the
#: header's "AU"); it is 0.37 m shorter than the IAU 2012 au that astropy's
#: ``u.au`` is (149,597,870.700 km exactly).
DE421_AU = 149_597_870.6996262 * u.km

#: The epoch of the :func:`de421` scene: J2000.0, JD 2451545.0 TDB.
_J2000_JD_TDB = 2451545.0

# Scene name -> (the de421 package's series, the header's GM key).  DE421's
# "mercury" and "venus" are the planets themselves (they have no moons) and
# "mars" ... "pluto" are the barycentres of the planet systems; "earthmoon" is
# the Earth-Moon barycentre and "moon" the geocentric Moon, from which the
# Earth and the Moon are made below.
_DE421_BODIES = {
    "Sun": ("sun", "GMS"), "Mercury": ("mercury", "GM1"), "Venus": ("venus", "GM2"),
    "Earth": (None, None), "Moon": (None, None), "Mars": ("mars", "GM4"),
    "Jupiter": ("jupiter", "GM5"), "Saturn": ("saturn", "GM6"),
    "Uranus": ("uranus", "GM7"), "Neptune": ("neptune", "GM8"), "Pluto": ("pluto", "GM9"),
}


def _de421_ephemeris():
    """The DE421 ephemeris of the ``de421`` package, read by ``jplephem``."""
    try:
        import de421 as package
        from jplephem.ephem import Ephemeris
    except ImportError as exc:
        raise ImportError(
            "the de421 scene reads the JPL DE421 ephemeris with the jplephem and de421 "
            'packages; install them with: pip install "orbits[ephemeris]"') from exc
    return Ephemeris(package)


def _de421_gm(name):
    """DE421's GM of one of the scene's bodies, in (DE421 au)^3 / day^2."""
    if name == "Earth":
        return _GM_DE421["GMB"] * (_EMRAT_DE421 / (1.0 + _EMRAT_DE421))
    if name == "Moon":
        return _GM_DE421["GMB"] * (1.0 / (1.0 + _EMRAT_DE421))
    return _GM_DE421[_DE421_BODIES[name][1]]


def _de421_arrays(ephemeris, tdb, tdb2):
    """Positions (n, 11, 3) in au and velocities in au/day of the de421
    scene's bodies at the ``n`` Julian dates ``tdb + tdb2`` (TDB)."""
    au_per_km = (1 * u.km).to_value(u.au)

    def state(series):
        # jplephem gives (3, n) arrays in km and km/day
        x, v = ephemeris.position_and_velocity(series, tdb, tdb2)
        return x.T * au_per_km, v.T * au_per_km

    x_emb, v_emb = state("earthmoon")
    x_moon, v_moon = state("moon")          # geocentric
    earth_share = 1.0 / (1.0 + _EMRAT_DE421)
    moon_share = _EMRAT_DE421 / (1.0 + _EMRAT_DE421)
    n = len(tdb)
    x = np.empty((n, len(_DE421_BODIES), 3))
    v = np.empty((n, len(_DE421_BODIES), 3))
    for i, (name, (series, _)) in enumerate(_DE421_BODIES.items()):
        if name == "Earth":
            x[:, i], v[:, i] = x_emb - earth_share * x_moon, v_emb - earth_share * v_moon
        elif name == "Moon":
            x[:, i], v[:, i] = x_emb + moon_share * x_moon, v_emb + moon_share * v_moon
        else:
            x[:, i], v[:, i] = state(series)
    return x, v


def de421_states(epoch):
    """The :func:`de421` scene's bodies at any epoch of DE421 (1900 to 2200).

    The same eleven bodies, in the same order, units and frame as
    :func:`de421` (barycentric ICRF, not moved to the centre of mass),
    evaluated from the ephemeris at other times: what a run from the
    :func:`de421` scene is compared with.

    Parameters
    ----------
    epoch : float, array_like or astropy.time.Time
        Julian date(s) in TDB, or a Time of any scale (converted to TDB
        without the network; its two-part date is kept).

    Returns
    -------
    positions, velocities : Quantity
        In au and au/day, of shape (11, 3) for one epoch and (n, 11, 3) for
        ``n`` epochs.

    Raises
    ------
    ValueError
        An epoch outside DE421's span, JD 2414992.5 to 2524624.5.
    ImportError
        ``jplephem`` or ``de421`` is not installed.

    Examples
    --------
    >>> import numpy as np
    >>> from orbits import scenes
    >>> x, v = scenes.de421_states(2451545.0)
    >>> bool(np.all(x == scenes.de421().positions))
    True
    >>> x, v = scenes.de421_states([2451545.0 + 365.25, 2451545.0 + 3652.5])
    >>> x.shape
    (2, 11, 3)
    """
    from astropy.time import Time

    if isinstance(epoch, Time):
        epoch = _as_tdb(epoch)
        tdb, tdb2 = np.atleast_1d(epoch.jd1), np.atleast_1d(epoch.jd2)
        scalar = epoch.isscalar
    else:
        tdb = np.asarray(epoch, dtype=float)
        scalar = tdb.ndim == 0
        tdb, tdb2 = np.atleast_1d(tdb), np.zeros(tdb.size)
    if tdb.ndim != 1:
        raise ValueError(f"epoch must be one date or a 1-d sequence of dates, got shape "
                         f"{np.shape(epoch)}")
    ephemeris = _de421_ephemeris()
    jd = tdb + tdb2
    if not np.all((jd >= ephemeris.jalpha) & (jd <= ephemeris.jomega)):
        raise ValueError(f"DE421 covers JD {ephemeris.jalpha} to {ephemeris.jomega} (TDB); "
                         f"got {jd.min()} to {jd.max()}")
    x, v = _de421_arrays(ephemeris, tdb, tdb2)
    if scalar:
        x, v = x[0], v[0]
    return x << u.au, v << (u.au / u.day)


def de421(com=False, epoch=None):
    """The Sun, the planets, the Moon and Pluto from the JPL DE421 ephemeris, at
    J2000.0 or another date.

    Positions and velocities at ``epoch`` (default JD 2451545.0 TDB, 2000
    January 1, 12:00 TDB) in the barycentric ICRF axes of DE421 (equatorial), evaluated from the
    Chebyshev series that the ``de421`` package installs with ``jplephem``:
    nothing is downloaded and nothing touches the network.  Masses and G are
    DE421's own GM values, so the set is the ephemeris's dynamical model
    restricted to these eleven bodies.

    Parameters
    ----------
    com : bool
        Move to the centre of mass of the eleven bodies.  Default False: keep
        the solar-system barycentre of DE421, whose model also has 343
        asteroids (about 1e-9 solar masses) that are not in this set; there
        the centre of mass of the set is 1.6e-9 au from the origin and its
        momentum is 3.6e-7 of ``sum m |v|``.
    epoch : astropy.time.Time, str or float, optional
        The date, as :func:`orbits.epochs.parse` reads it (a ``Time`` of any
        scale, text such as ``"2024-03-01T00:00:00 TDB"``, or a Julian date in
        TDB), within DE421's span, 1900 to 2200 (JD 2414992.5 to 2524624.5).
        Default: J2000.0.  The set returned carries it as its
        :attr:`~orbits.BodySet.epoch`, so that a run's ``result.epochs`` are
        dates, and :func:`de421_states` at those dates is the ephemeris to
        compare with.

    Returns
    -------
    BodySet
        ``"Sun"``, ``"Mercury"``, ``"Venus"``, ``"Earth"``, ``"Moon"``,
        ``"Mars"``, ``"Jupiter"``, ``"Saturn"``, ``"Uranus"``, ``"Neptune"``,
        ``"Pluto"``, in au (IAU 2012), solar masses and days.  G is DE421's
        GM_sun (``GMS = 2.959122082855911e-4`` (DE421 au)^3/day^2, with
        1 DE421 au = :data:`DE421_AU`) per solar mass, so the Sun's mass is
        exactly 1 Msun and each other mass is ``GM / GMS``.  Mars to Pluto are
        the barycentres of the planets' systems, with the systems' masses; the
        Earth and the Moon are separate bodies, their GMs split from DE421's
        Earth-Moon GM by ``EMRAT = 81.3005690699153``.

    Raises
    ------
    ImportError
        ``jplephem`` or ``de421`` is not installed; the message says
        ``pip install "orbits[ephemeris]"``.
    ValueError
        An epoch outside DE421's span.
    orbits.errors.EpochError
        An epoch that is no date.

    Notes
    -----
    The ``de421`` package (2008.1) holds the ephemeris as NumPy arrays of
    Chebyshev coefficients in the original JPL body order, not as an SPK
    ``de421.bsp`` file, and is read with ``jplephem.ephem.Ephemeris``, whose
    positions are in km and velocities in km/day.  The Earth and the Moon are
    ``EMB - moon / (1 + EMRAT)`` and ``EMB + moon EMRAT / (1 + EMRAT)``, as in
    SPK segments ``[3, 399]`` and ``[3, 301]``.  The ``de421`` package's
    description quotes DE421 as good to 200 m for Venus and 300 m for the
    Earth and Mars over the decade before 2008.

    References
    ----------
    .. [1] Folkner, W. M., Williams, J. G. & Boggs, D. H. 2008, "The Planetary
       and Lunar Ephemeris DE 421", IPN Progress Report 42-178 (GM values,
       EMRAT and AU from the ephemeris's header as distributed in the ``de421``
       package: ``GM1 ... GM9``, ``GMB``, ``GMS``).
    .. [2] Rhodes, B., ``jplephem`` and ``de421`` (PyPI), MIT licence.

    Examples
    --------
    >>> import numpy as np
    >>> from orbits import scenes
    >>> bodies = scenes.de421()
    >>> bodies.names[3:5]
    ['Earth', 'Moon']
    >>> r = bodies.positions[3] - bodies.positions[0]     # Earth - Sun, near perihelion
    >>> print(np.round(np.linalg.norm(r), 5))
    0.98333 AU
    >>> bodies.epoch.isot
    '2000-01-01T12:00:00.000'
    >>> later = scenes.de421(epoch="2024-03-01T00:00:00 TDB")
    >>> float(later.epoch.jd)
    2460370.5
    """
    time = _epochs.from_pair(_J2000_JD_TDB, 0.0) if epoch is None else _epochs.parse(epoch)
    ephemeris = _de421_ephemeris()
    jd1, jd2 = _epochs.to_pair(time)
    if not ephemeris.jalpha <= jd1 + jd2 <= ephemeris.jomega:
        raise ValueError(f"DE421 covers JD {ephemeris.jalpha} to {ephemeris.jomega} (TDB); "
                         f"got epoch JD {jd1 + jd2!r} ({time.isot} TDB)")
    x, v = _de421_arrays(ephemeris, np.array([jd1]), np.array([jd2]))
    gm = np.array([_de421_gm(name) for name in _DE421_BODIES])
    x, v = x[0], v[0]

    # G * (1 Msun) = GMS, carried from DE421's au to the IAU au of u.au
    # (a factor 1 - 7.5e-12) so that G m equals the header's GM in km^3/day^2.
    G = _GM_DE421["GMS"] * DE421_AU ** 3 / (u.day ** 2 * u.Msun)
    units = UnitSystem(length=u.au, mass=u.Msun, time=u.day, G=G,
                       name="au-Msun-day (DE421 GM_sun)",
                       G_source="GMS of JPL DE421 (Folkner, Williams & Boggs 2008)")
    bodies = BodySet.from_arrays(gm / _GM_DE421["GMS"], x, v, names=list(_DE421_BODIES),
                                 units=units)
    if com:
        bodies.move_to_com()
    bodies.epoch = time
    return _record(bodies, "de421", com=bool(com), epoch=f"{time.isot} TDB",
                   frame="icrs", ephemeris="JPL DE421 (jplephem, de421 package)",
                   gm="JPL DE421 header (Folkner, Williams & Boggs 2008)")


def pythagorean():
    """Burrau's Pythagorean three-body problem.

    Masses 3, 4 and 5 start at rest at the corners of a 3-4-5 right triangle,
    each opposite the side of its own length: at (1, 3), (-2, -1) and (1, -1),
    with ``G = 1``.  The motion is chaotic, with close encounters, and ends
    (near t = 60) with the two heavier bodies (4 and 5) leaving as a binary
    and the lightest (3) escaping the other way, as Szebehely & Peters found;
    a hard test of adaptive step control.

    Returns
    -------
    BodySet
        Bodies ``"1"`` (m = 3), ``"2"`` (m = 4) and ``"3"`` (m = 5) in the
        plane z = 0, in N-body units (:meth:`UnitSystem.nbody`, G = 1).  The
        centre of mass is at rest at the origin as given; the total energy is
        ``-769/60``.

    References
    ----------
    .. [1] Burrau, C. 1913, "Numerische Berechnung eines Spezialfalles des
       Dreikörperproblems", Astron. Nachr. 195, 113.
    .. [2] Szebehely, V. & Peters, C. F. 1967, "Complete solution of a general
       problem of three bodies", AJ 72, 876.

    Examples
    --------
    >>> from orbits import scenes
    >>> bodies = scenes.pythagorean()
    >>> bodies.masses
    <Quantity [3., 4., 5.]>
    """
    bodies = BodySet.from_arrays(
        np.array([3.0, 4.0, 5.0]),
        np.array([[1.0, 3.0, 0.0], [-2.0, -1.0, 0.0], [1.0, -1.0, 0.0]]),
        np.zeros((3, 3)), names=["1", "2", "3"], units=UnitSystem.nbody())
    bodies.move_to_com()
    return _record(bodies, "pythagorean", source="Burrau 1913; Szebehely & Peters 1967")


def figure_eight():
    """The figure-eight choreography of three equal masses.

    Three bodies of mass 1 chase one another around one figure-eight curve,
    with ``G = 1`` and period :data:`FIGURE_EIGHT_PERIOD` (6.32591398).  The
    initial conditions are Simó's, as given by Chenciner & Montgomery:
    ``x1 = -x2 = (0.97000436, -0.24308753, 0)``, ``x3 = 0``,
    ``v3 = (-0.93240737, -0.86473146, 0)``, ``v1 = v2 = -v3 / 2``.
    The total momentum and angular momentum are zero.

    Returns
    -------
    BodySet
        Bodies ``"1"``, ``"2"``, ``"3"`` in the plane z = 0, in N-body units
        (:meth:`UnitSystem.nbody`, G = 1), already in the centre-of-mass frame.

    References
    ----------
    .. [1] Chenciner, A. & Montgomery, R. 2000, "A remarkable periodic solution
       of the three-body problem in the case of equal masses", Annals of
       Mathematics 152, 881.
    .. [2] Moore, C. 1993, "Braids in classical dynamics", Phys. Rev. Lett. 70,
       3675 (first found numerically).

    Examples
    --------
    >>> from orbits import scenes
    >>> bodies = scenes.figure_eight()
    >>> bodies.velocities[0].value.tolist()
    [0.466203685, 0.43236573, -0.0]
    """
    x1 = np.array([0.97000436, -0.24308753, 0.0])
    v3 = np.array([-0.93240737, -0.86473146, 0.0])
    bodies = BodySet.from_arrays(
        np.ones(3), np.array([x1, -x1, np.zeros(3)]),
        np.array([-v3 / 2, -v3 / 2, v3]), names=["1", "2", "3"],
        units=UnitSystem.nbody())
    return _record(bodies, "figure-eight", period=FIGURE_EIGHT_PERIOD,
                   source="Chenciner & Montgomery 2000 (Simo's initial conditions)")


def plummer(n=1000, seed=None, mass_cut=PLUMMER_MASS_CUT):
    """A Plummer-sphere star cluster of ``n`` equal masses, in Hénon units.

    Sampled by the method of Aarseth, Hénon & Wielen (1974): the radius by
    inverting the cumulative mass ``M(r) = r^3 / (r^2 + b^2)^(3/2)``, isotropic
    directions for position and velocity, and the speed, as a fraction ``q``
    of the local escape speed, by von Neumann rejection on
    ``g(q) = q^2 (1 - q^2)^(7/2)``.

    Parameters
    ----------
    n : int
        Number of stars, ``>= 2``.  Default 1000.  Building takes linear time
        (10^5 stars in well under a second).
    seed : int, numpy.random.Generator or None
        Passed to :func:`numpy.random.default_rng`; equal seeds give equal sets.
    mass_cut : float
        Radii are drawn from the inner ``mass_cut`` of the mass,
        ``0 < mass_cut < 1``.  Default 0.999 (radii below ``38.7 b`` = 22.8
        Hénon length units); with the masses still summing to 1, the expected
        energy becomes -0.2507 and the virial ratio 0.999.

    Returns
    -------
    BodySet
        Bodies ``"0"`` ... ``"n-1"`` of mass ``1/n`` in N-body units
        (:meth:`UnitSystem.nbody`, G = 1), moved to the centre-of-mass frame.
        Hénon units (G = M = 1, E = -1/4) make the Plummer scale radius
        ``b = 3 pi / 16``; the sample's energy and virial ratio ``2T/|W|``
        scatter about -1/4 and 1 by a few times ``1/sqrt(n)``.

    Raises
    ------
    ValueError
        ``n`` is not an integer >= 2, or ``mass_cut`` is outside (0, 1).

    Notes
    -----
    With the radius ``r`` in units of ``b`` from ``X`` uniform in
    ``(0, mass_cut)``: ``r = (X^(-2/3) - 1)^(-1/2)``.  The escape speed at
    radius ``r`` (Hénon units) is ``sqrt(2) (r^2 + b^2)^(-1/4)``.

    References
    ----------
    .. [1] Aarseth, S. J., Hénon, M. & Wielen, R. 1974, "A comparison of
       numerical methods for the study of star cluster dynamics", A&A 37, 183.
    .. [2] Plummer, H. C. 1911, "On the problem of distribution in globular
       star clusters", MNRAS 71, 460.
    .. [3] Hénon, M. 1971, "The Monte Carlo method", Ap&SS 14, 151 (the units).

    Examples
    --------
    >>> from orbits import scenes
    >>> cluster = scenes.plummer(1000, seed=42)
    >>> len(cluster)
    1000
    >>> round(float(cluster.total_mass), 12)
    1.0
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)):
        raise ValueError(f"n must be an integer >= 2, got {n!r}")
    n = int(n)
    if n < 2:
        raise ValueError(f"n must be an integer >= 2, got {n}")
    mass_cut = float(mass_cut)
    if not 0.0 < mass_cut < 1.0:
        raise ValueError(f"mass_cut must be in (0, 1), got {mass_cut}")
    rng = np.random.default_rng(seed)
    b = 3.0 * math.pi / 16.0

    # 1 - uniform lies in (0, 1], so 0 < X <= mass_cut < 1 and r is finite.
    X = mass_cut * (1.0 - rng.random(n))
    r = b / np.sqrt(X ** (-2.0 / 3.0) - 1.0)
    positions = r[:, None] * _isotropic(rng, n)

    q = _plummer_speed_fractions(rng, n)
    speed = q * math.sqrt(2.0) * (r ** 2 + b ** 2) ** -0.25
    velocities = speed[:, None] * _isotropic(rng, n)

    bodies = BodySet.from_arrays(np.full(n, 1.0 / n), positions, velocities,
                                 units=UnitSystem.nbody())
    bodies.move_to_com()
    return _record(bodies, "plummer", n=n, seed=None if seed is None else repr(seed),
                   mass_cut=mass_cut, units="Henon (G = M = 1, E = -1/4)",
                   source="Aarseth, Henon & Wielen 1974")


def _isotropic(rng, n):
    """``n`` unit vectors uniformly distributed on the sphere."""
    z = 2.0 * rng.random(n) - 1.0
    phi = 2.0 * math.pi * rng.random(n)
    s = np.sqrt(1.0 - z ** 2)
    return np.column_stack([s * np.cos(phi), s * np.sin(phi), z])


def _plummer_speed_fractions(rng, n):
    """``n`` draws of q in [0, 1) with density proportional to q^2 (1 - q^2)^(7/2)."""
    out = np.empty(n)
    filled = 0
    while filled < n:
        # About 43% of the candidates are accepted; ask for enough at once.
        want = n - filled
        m = int(want / 0.4) + 16
        q = rng.random(m)
        y = _PLUMMER_G_BOUND * rng.random(m)
        keep = q[y < q ** 2 * (1.0 - q ** 2) ** 3.5][:want]
        out[filled:filled + keep.size] = keep
        filled += keep.size
    return out


# -- registry -------------------------------------------------------------------
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
