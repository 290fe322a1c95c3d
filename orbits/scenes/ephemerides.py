"""Scenes of the solar system at a date, from an ephemeris: astropy's built-in
one (:func:`solar_system`) and JPL's DE421 (:func:`de421`, :func:`de421_states`).

Neither touches the network: the built-in ephemeris is ERFA's analytic
theories, and DE421's Chebyshev series come with the ``de421`` package.
"""

import math

import astropy.units as u
import numpy as np

from .. import epochs as _epochs
from ..bodies import BodySet
from ..units import UnitSystem
from ._provenance import DE440_REFERENCE, de440_mass, record

__all__ = ["solar_system", "de421", "de421_states", "J2000_OBLIQUITY", "DE421_AU"]

#: Mean obliquity of the ecliptic at J2000.0 (IAU 2006 precession, Capitaine
#: et al. 2003, adopted by IAU 2006 Resolution B1).
J2000_OBLIQUITY = 84381.406 * u.arcsec

_PLANETS = ("Mercury", "Venus", "Earth", "Mars", "Jupiter", "Saturn", "Uranus",
            "Neptune")
_FRAMES = ("ecliptic", "icrs")


def _rotate_to_ecliptic(vectors, obliquity):
    """Rotate (N, 3) equatorial vectors about the x axis into the ecliptic."""
    c, s = math.cos(obliquity), math.sin(obliquity)
    out = np.empty_like(vectors)
    out[:, 0] = vectors[:, 0]
    out[:, 1] = c * vectors[:, 1] + s * vectors[:, 2]
    out[:, 2] = -s * vectors[:, 1] + c * vectors[:, 2]
    return out


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
    >>> from orbits import scenes
    >>> bodies = scenes.solar_system()
    >>> len(bodies)
    10
    >>> r = bodies.positions[3] - bodies.positions[0]     # Earth - Sun, near perihelion
    >>> print(np.round(np.linalg.norm(r), 3))
    0.983 AU
    """
    # astropy.coordinates takes about a second to import; only this scene needs it
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
    m = np.array([1.0] + [de440_mass(name, units).value for name in names[1:]])
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
    return record(bodies, "solar-system", epoch=f"{time.isot} TDB", moon=bool(moon),
                  frame=frame, ephemeris="astropy builtin (ERFA epv00, plan94, moon98)",
                  gm=DE440_REFERENCE)


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
    >>> from orbits import scenes
    >>> x, v = scenes.de421_states(2451545.0)
    >>> bool(np.all(x == scenes.de421().positions))
    True
    >>> x, v = scenes.de421_states([2451545.0 + 365.25, 2451545.0 + 3652.5])
    >>> x.shape
    (2, 11, 3)
    """
    if _epochs.is_time(epoch):
        epoch = _epochs.to_tdb(epoch)
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
        1 DE421 au = :data:`~orbits.scenes.ephemerides.DE421_AU`) per solar mass, so the Sun's mass is
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
    return record(bodies, "de421", com=bool(com), epoch=f"{time.isot} TDB",
                  frame="icrs", ephemeris="JPL DE421 (jplephem, de421 package)",
                  gm="JPL DE421 header (Folkner, Williams & Boggs 2008)")
