"""The one place where astropy units meet plain floats.

A :class:`UnitSystem` fixes the units of length, mass and time in which a
body set's numbers are stored and integrated, and the value of the
gravitational constant ``G`` in those units, together with where that value
came from.  Everything inside the integrators is a float in this system;
quantities are converted once on the way in and once on the way out.
"""

import math

import astropy.constants as const
import astropy.units as u
import numpy as np

from .errors import BodyUnitsError

__all__ = ["UnitSystem", "GAUSSIAN_GRAVITATIONAL_CONSTANT", "time_unit", "format_time",
           "TIME_UNITS"]

#: Gauss's constant k in au^(3/2) / (day Msun^(1/2)) (IAU 1976).  k**2 is the
#: G that REBOUND's unit table and the Hairer-Lubich-Wanner data set use for
#: au, day and solar masses.
GAUSSIAN_GRAVITATIONAL_CONSTANT = 0.01720209895

# For a mass unit that is a body's mass, G * (1 mass unit) is that body's GM,
# which is known far better than G itself (1e-10 against 2e-5 relative).
_GM_FOR_MASS_UNIT = (
    (u.Msun, const.GM_sun, "astropy.constants.GM_sun"),
    (u.Mjup, const.GM_jup, "astropy.constants.GM_jup"),
    (u.Mearth, const.GM_earth, "astropy.constants.GM_earth"),
)

# REBOUND's own unit names for the units it knows.
_REBOUND_NAMES = {
    "length": {u.au: "AU", u.m: "m", u.km: "km", u.cm: "cm", u.pc: "pc"},
    "mass": {u.Msun: "Msun", u.kg: "kg", u.g: "g", u.Mearth: "Mearth", u.Mjup: "Mjupiter"},
    "time": {u.day: "day", u.s: "s", u.yr: "yr", u.hour: "hr"},
}

#: Units in which a person reads a time: the first whose bound (in years) is
#: above the span, so that a span reads as a number from 1 to 999 of its unit
#: (a day and a year excepted): 1e5 years in kyr, a month in days, an hour in
#: seconds.  The run summary, ``orbits info`` and the plots' time axes use it.
TIME_UNITS = ((1 / 365.25, u.s), (1.0, u.day), (1e3, u.yr), (1e6, u.kyr), (1e9, u.Myr),
              (math.inf, u.Gyr))

_KINDS = ("length", "mass", "time", "velocity", "acceleration", "energy",
          "angular_momentum", "momentum", "dimensionless", "angle")


class UnitSystem:
    """Units of length, mass and time, and the gravitational constant in them.

    Parameters
    ----------
    length, mass, time : astropy.units.Unit
        The units in which states are stored and integrated.
        Default: au, solar masses and days.
    G : float, astropy.units.Quantity or None
        The gravitational constant.  A float is taken to be in
        ``length**3 / (mass * time**2)``; a Quantity is converted to that; None
        takes it from astropy's constants (from the body's GM where the mass
        unit is the Sun, Jupiter or the Earth, else CODATA G).
    name : str, optional
        A short label recorded with results.

    Examples
    --------
    >>> from orbits import UnitSystem
    >>> round(UnitSystem().G, 15)
    0.000295912208192
    >>> hlw = UnitSystem(length=u.au, mass=u.Msun, time=u.day, G=2.95912208286e-4)
    >>> UnitSystem.nbody().G
    1.0
    """

    def __init__(self, length=u.au, mass=u.Msun, time=u.day, G=None, name=None,
                 G_source=None):
        self.length = u.Unit(length)
        self.mass = u.Unit(mass)
        self.time = u.Unit(time)
        dims = self._dimensionless = all(
            x == u.dimensionless_unscaled for x in (self.length, self.mass, self.time))
        for kind, unit, expected in (("length", self.length, "length"),
                                     ("mass", self.mass, "mass"),
                                     ("time", self.time, "time")):
            if not dims and unit.physical_type != expected:
                raise u.UnitsError(f"UnitSystem {kind} unit {unit} is not a {expected}")
        g_unit = self.length ** 3 / (self.mass * self.time ** 2)
        if G is None:
            if dims:
                raise ValueError("a dimensionless unit system needs an explicit G "
                                 "(UnitSystem.nbody() gives G = 1)")
            G, G_source = self._astropy_G(g_unit)
        elif isinstance(G, u.Quantity):
            G = G.to_value(g_unit)
            G_source = G_source or "given as a Quantity"
        else:
            G_source = G_source or "given"
        G = float(G)
        if not math.isfinite(G) or G <= 0:
            raise ValueError(f"G must be a positive finite number, got {G}")
        self.G = G
        self.G_source = G_source
        self.name = name or self._default_name()

    # -- constructors -----------------------------------------------------------
    @classmethod
    def default(cls):
        """au, solar masses and days, with G * Msun = astropy's GM_sun.

        Examples
        --------
        >>> from orbits import UnitSystem
        >>> U = UnitSystem.default()
        >>> U.name, str(U.length), str(U.mass), str(U.time)
        ('au-Msun-day', 'AU', 'solMass', 'd')
        >>> U == UnitSystem()
        True
        """
        return cls(name="au-Msun-day")

    @classmethod
    def nbody(cls, G=1.0):
        """Dimensionless N-body units with ``G = 1`` (Hénon units for a cluster).

        Examples
        --------
        >>> from orbits import UnitSystem
        >>> U = UnitSystem.nbody()
        >>> U.G, U.name, U.unit("length").is_equivalent(1)
        (1.0, 'nbody', True)
        """
        d = u.dimensionless_unscaled
        return cls(length=d, mass=d, time=d, G=G, name="nbody",
                   G_source="N-body units" if G == 1.0 else None)

    @classmethod
    def rebound(cls, length=u.au, mass=u.Msun, time=u.day):
        """The units with REBOUND's value of G, so that a comparison matches it exactly.

        REBOUND derives G from its own table of unit values; for au, solar
        masses and days that is the square of Gauss's constant.  Other units
        are looked up in REBOUND itself, which must then be installed.

        Examples
        --------
        >>> from orbits import UnitSystem
        >>> from orbits.units import GAUSSIAN_GRAVITATIONAL_CONSTANT as k
        >>> U = UnitSystem.rebound()
        >>> abs(U.G / k**2 - 1) < 1e-15
        True
        """
        length, mass, time = u.Unit(length), u.Unit(mass), u.Unit(time)
        try:
            import rebound
        except ImportError:  # pragma: no cover - rebound is a test dependency
            rebound = None
        if rebound is None:
            if (length, mass, time) == (u.au, u.Msun, u.day):
                # REBOUND's own table gives this to within one unit in the last place.
                return cls(length, mass, time, G=GAUSSIAN_GRAVITATIONAL_CONSTANT ** 2,
                           name="au-Msun-day (REBOUND G)",
                           G_source="Gauss's constant squared (rebound not installed)")
            raise ImportError("UnitSystem.rebound for these units needs the rebound "
                              "package (pip install rebound)")
        try:
            names = tuple(_REBOUND_NAMES[k][unit] for k, unit in
                          (("time", time), ("length", length), ("mass", mass)))
        except KeyError as exc:
            raise u.UnitsError(f"REBOUND has no unit for {exc.args[0]}") from None
        sim = rebound.Simulation()
        sim.units = names
        return cls(length, mass, time, G=sim.G, name=f"{'-'.join(names)} (REBOUND G)",
                   G_source=f"REBOUND {rebound.__version__} unit table")

    # -- conversion -------------------------------------------------------------
    def unit(self, kind):
        """The unit of a physical kind: ``"length"``, ``"velocity"``, ``"energy"``...

        Examples
        --------
        >>> from orbits import UnitSystem
        >>> U = UnitSystem()
        >>> U.unit("velocity"), U.unit("energy")
        (Unit("AU / d"), Unit("AU2 solMass / d2"))
        """
        try:
            return self._units[kind]
        except KeyError:
            raise ValueError(f"unknown kind {kind!r}; expected one of {_KINDS}") from None

    @property
    def _units(self):
        # composing astropy units costs ~10 us each: build the table once
        table = self.__dict__.get("_unit_table")
        if table is None:
            L, M, T = self.length, self.mass, self.time
            table = self.__dict__["_unit_table"] = {
                "length": L, "mass": M, "time": T, "velocity": L / T,
                "acceleration": L / T ** 2, "energy": M * L ** 2 / T ** 2,
                "angular_momentum": M * L ** 2 / T, "momentum": M * L / T,
                "dimensionless": u.dimensionless_unscaled, "angle": u.rad,
            }
        return table

    def to_internal(self, value, kind, *, bare_ok=False, body=None, field=None):
        """Convert ``value`` to a float64 array in this system.

        A Quantity is converted to the unit of ``kind``.  A bare number is
        accepted only where ``bare_ok`` (the caller was given this unit system
        explicitly) and is then taken to be in this system already; angles
        given as bare numbers are radians.

        Raises
        ------
        BodyUnitsError
            The value has the wrong physical type, or is a bare number where a
            Quantity is needed.

        Examples
        --------
        >>> from orbits import UnitSystem
        >>> U = UnitSystem()
        >>> float(U.to_internal(1 * u.yr, "time"))
        365.25
        >>> U.to_internal(2.0, "length", bare_ok=True).dtype
        dtype('float64')
        >>> try:
        ...     U.to_internal(2.0, "length")
        ... except orbits.BodyUnitsError as exc:
        ...     print(str(exc).split(";")[0])
        expected a Quantity with a unit of length (e.g. AU), got the bare number 2.0
        """
        target = self.unit(kind)
        if isinstance(value, u.Quantity):
            try:
                return np.asarray(value.to_value(target), dtype=np.float64)
            except u.UnitConversionError:
                expected = ("a dimensionless number" if target == u.dimensionless_unscaled
                            else f"a {target.physical_type} (e.g. in {target})")
                raise BodyUnitsError(
                    f"expected {expected}, got {value.unit.physical_type} "
                    f"({value.unit})", body=body, field=field) from None
        if kind == "dimensionless" or bare_ok or (self._dimensionless and kind != "angle"):
            try:
                return np.asarray(value, dtype=np.float64)
            except (TypeError, ValueError):
                raise BodyUnitsError(f"expected a number, got {value!r}",
                                     body=body, field=field) from None
        raise BodyUnitsError(
            f"expected a Quantity with a unit of {target.physical_type} (e.g. "
            f"{target}), got the bare number {value!r}; pass a unit, or give the "
            f"unit system explicitly to use plain numbers", body=body, field=field)

    def quantity(self, value, kind):
        """Attach the unit of ``kind`` to a float array, without copying.

        Examples
        --------
        >>> from orbits import UnitSystem
        >>> UnitSystem().quantity(np.array([1.0, 2.0]), "velocity")
        <Quantity [1., 2.] AU / d>
        """
        # the constructor without a copy: the same view as ``<<``, in half
        # its time (a run's result attaches units to a dozen arrays)
        return u.Quantity(np.asarray(value), self.unit(kind), copy=False)

    # -- bookkeeping ------------------------------------------------------------
    def to_dict(self):
        """Plain description, for results and files.

        Examples
        --------
        >>> from orbits import UnitSystem
        >>> d = UnitSystem().to_dict()
        >>> d["length"], d["mass"], d["time"], round(d["G"], 15)
        ('AU', 'solMass', 'd', 0.000295912208192)
        """
        d = self.__dict__.get("_description")
        if d is None:
            d = self.__dict__["_description"] = {
                "name": self.name, "length": self.length.to_string(),
                "mass": self.mass.to_string(), "time": self.time.to_string(),
                "G": self.G, "G_source": self.G_source}
        return dict(d)

    def __getitem__(self, key):
        """A field of :meth:`to_dict` by its name (``U["G"]`` is ``U.G``), as a
        result's ``units`` gave them when it was that dictionary.

        Examples
        --------
        >>> from orbits import UnitSystem
        >>> U = UnitSystem.default()
        >>> U["name"], U["G"] == U.G
        ('au-Msun-day', True)
        """
        d = self.to_dict()
        if key not in d:
            raise KeyError(f"{key!r}; a UnitSystem's fields are {', '.join(map(repr, d))}")
        return d[key]

    @classmethod
    def from_dict(cls, d):
        """Inverse of :meth:`to_dict`.

        Examples
        --------
        >>> from orbits import UnitSystem
        >>> U = UnitSystem.nbody()
        >>> UnitSystem.from_dict(U.to_dict()) == U
        True
        """
        return cls(u.Unit(d["length"]), u.Unit(d["mass"]), u.Unit(d["time"]),
                   G=d["G"], name=d["name"], G_source=d["G_source"])

    def __eq__(self, other):
        if not isinstance(other, UnitSystem):
            return NotImplemented
        return ((self.length, self.mass, self.time, self.G)
                == (other.length, other.mass, other.time, other.G))

    def __hash__(self):
        return hash((self.length.to_string(), self.mass.to_string(),
                     self.time.to_string(), self.G))

    def __repr__(self):
        return (f"UnitSystem(length={self.length}, mass={self.mass}, time={self.time}, "
                f"G={self.G!r}  # {self.G_source})")

    # -- helpers ----------------------------------------------------------------
    def _astropy_G(self, g_unit):
        for unit, gm, source in _GM_FOR_MASS_UNIT:
            if self.mass == unit:
                return (gm / (1 * unit)).to_value(g_unit), f"{source} ({gm.reference})"
        return const.G.to_value(g_unit), f"astropy.constants.G ({const.G.reference})"

    def _default_name(self):
        if self._dimensionless:
            return "nbody"
        return f"{self.length}-{self.mass}-{self.time}"


def time_unit(span):
    """The unit in which a time of this size reads best.

    Parameters
    ----------
    span : Quantity, scalar, time (or dimensionless)
        The time, or the span of times, to be shown; its sign is ignored.

    Returns
    -------
    astropy.units.Unit
        ``s`` below a day, ``d`` below a (Julian) year, ``yr`` below 1000
        years, ``kyr`` below a million, ``Myr`` below a billion, else ``Gyr``
        (:data:`TIME_UNITS`); the span's own unit where it is not a time
        (N-body units).

    Examples
    --------
    >>> from orbits.units import time_unit
    >>> time_unit(1e5 * u.yr), time_unit(30 * u.day), time_unit(4.383e9 * u.day)
    (Unit("kyr"), Unit("d"), Unit("Myr"))
    """
    span = u.Quantity(span)
    if span.unit.physical_type != "time":
        return span.unit
    years = abs(span.to_value(u.yr))
    for bound, unit in TIME_UNITS:
        if years < bound:
            return unit
    return TIME_UNITS[-1][1]


def format_time(time, unit=None, digits=6):
    """A time as a person reads it: ``"100 kyr"``, ``"12 Myr"``, ``"30 d"``.

    Parameters
    ----------
    time : Quantity, time (or dimensionless), or float
        A float is shown as it is, without a unit.
    unit : astropy.units.Unit, optional
        The unit to show it in; default :func:`time_unit` of ``time``.  Give
        the unit of the largest of several times to show them alike.
    digits : int
        Significant digits.

    Returns
    -------
    str

    Examples
    --------
    >>> from orbits.units import format_time, time_unit
    >>> format_time(4.383e9 * u.day), format_time(3652.5 * u.day), format_time(0.5 * u.day)
    ('12 Myr', '10 yr', '43200 s')
    >>> format_time(0 * u.day, time_unit(1e5 * u.yr)), format_time(12.5 * u.one)
    ('0 kyr', '12.5')
    """
    if not isinstance(time, u.Quantity):
        return f"{float(time):.{digits}g}"
    unit = time_unit(time) if unit is None else u.Unit(unit)
    text = f"{time.to_value(unit):.{digits}g}"
    name = unit.to_string()
    return f"{text} {name}" if name else text
