"""Body sets: names, masses, radii and states, with astropy units at the edge.

A :class:`BodySet` stores its numbers as float64 arrays in its
:class:`~orbits.units.UnitSystem`; its public properties give Quantities.
Bodies enter by Cartesian state (:meth:`BodySet.add` with ``position`` and
``velocity``), by orbital elements about a primary (:meth:`BodySet.add` with
``a``, ``e``, ...), or all at once from arrays (:meth:`BodySet.from_arrays`).
A body may also be given a physical radius (``radius=``; default 0, a point
mass), which the set carries through copies, simulations and output files.
Every value is checked where it enters; a bad one raises a
:class:`~orbits.errors.BodyError` naming the body and the field.
"""

import copy as _copy
import functools
import html
import math

import astropy.units as u
import numpy as np

from . import epochs as _epochs
from . import geometry as _geometry
from . import orbit_fields as _orbit_fields
from ._kernels import anomalies as _anomalies
from ._kernels import elements as _elements
from ._kernels.status import describe_status
from .body import Body, _position, unknown_body
from .errors import (BodyError, CoincidentBodiesError, DuplicateBodyError,
                     ElementsError, NoMassiveBodyError, UnknownBodyError)
from .units import UnitSystem

__all__ = ["BodySet"]

_ELEMENT_NAMES = ("a", "e", "inc", "Omega", "omega", "f", "M")
#: what each field of :meth:`BodySet.add`'s orbit is
_FIELD_KINDS = {"a": "length", "e": "dimensionless", "inc": "angle", "Omega": "angle",
                "omega": "angle", "f": "angle", "M": "angle",
                **_orbit_fields.ALTERNATIVE_FIELDS}
_REPR_ROWS = 5  # rows a repr shows at each end of a long set


class BodySet:
    """An ordered set of named bodies with masses, radii, positions and velocities.

    Parameters
    ----------
    units : UnitSystem, optional
        The unit system in which the set stores its numbers.  Default:
        au, solar masses and days with astropy's G.  When a unit system is given
        explicitly, plain numbers are accepted everywhere and read in it.

    Examples
    --------
    >>> import astropy.units as u
    >>> import orbits
    >>> bodies = orbits.BodySet()
    >>> bodies.add("Sun", mass=1 * u.Msun)
    >>> bodies.add("Jupiter", mass=1 * u.Mjup, primary="Sun", a=5.2 * u.au, e=0.048,
    ...            inc=1.3 * u.deg)
    >>> bodies.move_to_com()
    >>> len(bodies)
    2
    """

    def __init__(self, units=None):
        if units is not None and not isinstance(units, UnitSystem):
            raise TypeError(f"units must be a UnitSystem, got {type(units).__name__}")
        self.units = units if units is not None else UnitSystem.default()
        self._bare_ok = units is not None
        self._names = []
        self._m = np.zeros(0)
        self._r = np.zeros(0)   # physical radii; 0 for a point mass
        self._x = np.zeros((0, 3))
        self._v = np.zeros((0, 3))
        self._epoch = None      # the date the state holds at (TDB), if known
        self.history = []  # how the bodies were made, recorded with results

    # -- construction -----------------------------------------------------------
    def add(self, name, mass, *, position=None, velocity=None, primary=None, a=None,
            e=None, inc=None, Omega=None, omega=None, f=None, M=None, radius=None,
            P=None, pomega=None, l=None, T=None, E=None, theta=None):
        """Add one body, by Cartesian state or by orbital elements.

        Parameters
        ----------
        name : str
            Unique name.
        mass : Quantity, scalar, mass
            Must be finite and >= 0.  A massless body feels gravity but exerts none.
        position, velocity : Quantity, shape (3,), length and velocity
            Cartesian state in the frame of the set.  Both default to zero (a
            body at rest at the origin, as a central star is usually given).
        primary : str, optional
            With elements: the body the orbit is about.  Default: the centre of
            mass of all bodies added before (Jacobi-like, as for hierarchical
            systems).
        a : Quantity, length
            Semi-major axis; negative for a hyperbolic orbit (e > 1).
        e : float
            Eccentricity, >= 0; default 0.  Parabolic orbits (e = 1) cannot be
            given by ``a``: give a Cartesian state instead.
        inc, Omega, omega : Quantity, angle
            Inclination, longitude of the ascending node, argument of pericentre.
            Default 0.
        f, M : Quantity, angle
            True or mean anomaly.  Default ``f = 0``.
        P : Quantity, time
            Orbital period, in place of ``a``: ``a = (mu P^2 / 4 pi^2)^(1/3)``
            (a bound orbit, ``e < 1``).
        pomega : Quantity, angle
            Longitude of pericentre ``Omega + omega``, in place of ``omega``
            (with ``omega`` too only if the three agree).
        l, theta : Quantity, angle
            Mean longitude ``pomega + M`` and true longitude ``pomega + f``.
            For ``inc`` above 90 degrees the three longitudes are measured
            the other way round, as REBOUND does: ``pomega = Omega - omega``,
            ``l = pomega - M``, ``theta = pomega - f``.
        E : Quantity, angle
            Eccentric anomaly (a bound orbit).
        T : Quantity, time
            Time of pericentre passage, on the clock of a simulation made from
            the set, which starts at t = 0: ``M = -n T``.
        radius : Quantity, scalar, length, optional
            The body's physical radius: finite and >= 0.  Default 0 (a point
            mass).  Gravity does not read it; it is kept for collision
            detection and travels with the set into simulations and files.

        Give at most one of ``f``, ``M``, ``E``, ``l``, ``theta``, ``T``, and
        ``a`` or ``P``; these are REBOUND's ``Particle`` fields, with the
        same meanings (:mod:`orbits.orbit_fields`).

        Notes
        -----
        The orbit about the primary uses ``mu = G (m_primary + m_body)``, so a
        massive body on a circular orbit given this way stays circular in the
        two-body problem; ``P`` and ``T`` are read with the same ``mu``.

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> bodies = orbits.BodySet()
        >>> bodies.add("Sun", mass=1 * u.Msun)
        >>> bodies.add("Earth", mass=1 * u.Mearth, primary="Sun", a=1 * u.au, e=0.0167,
        ...            radius=1 * u.Rearth)
        >>> bodies.add("probe", mass=0 * u.kg, position=[0, 2, 0] * u.au,
        ...            velocity=[-20, 0, 0] * u.km / u.s)
        >>> bodies.names
        ['Sun', 'Earth', 'probe']
        >>> round(float(bodies.elements("Earth", primary="Sun")["e"]), 4)
        0.0167
        >>> bodies.radii.to(u.km).round(1)
        <Quantity [   0. , 6378.1,    0. ] km>

        REBOUND's ways to give an orbit: a period, the longitude of pericentre
        and the mean longitude.

        >>> bodies.add("Mars", mass=0.107 * u.Mearth, primary="Sun", P=686.98 * u.day,
        ...            e=0.0934, pomega=336.04 * u.deg, l=355.45 * u.deg)
        >>> el = bodies.elements("Mars", primary="Sun")
        >>> round(float(el["a"].to_value(u.au)), 4), round(float(el["omega"].to(u.deg).value), 2)
        (1.5237, 336.04)
        """
        self._check_name(name)
        m = self._scalar(mass, "mass", name, "mass")
        if not math.isfinite(m):
            raise BodyError(f"mass must be finite, got {m}", body=name, field="mass")
        if m < 0:
            raise BodyError(f"mass must be >= 0, got {m} {self.units.mass}",
                            body=name, field="mass")
        r = 0.0 if radius is None else self._scalar(radius, "length", name, "radius")
        if not (math.isfinite(r) and r >= 0):
            raise BodyError(f"radius must be finite and >= 0, got {r} {self.units.length}",
                            body=name, field="radius")
        elements = dict(a=a, e=e, inc=inc, Omega=Omega, omega=omega, f=f, M=M, P=P,
                        pomega=pomega, l=l, T=T, E=E, theta=theta)
        given = [k for k, val in elements.items() if val is not None]
        if given or primary is not None:
            if position is not None or velocity is not None:
                raise BodyError("give either a Cartesian state (position, velocity) or "
                                f"orbital elements, not both (got {', '.join(given)})",
                                body=name, field="position")
            x, v = self._state_from_elements(name, m, primary, **elements)
            how = {"name": name, "from": "elements", "primary": primary,
                   **{k: _describe(val) for k, val in elements.items() if val is not None}}
        else:
            x = (np.zeros(3) if position is None
                 else self._vector(position, "length", name, "position"))
            v = (np.zeros(3) if velocity is None
                 else self._vector(velocity, "velocity", name, "velocity"))
            how = {"name": name, "from": "state"}
        self._append(name, m, x, v, r)
        self.history.append(how)

    @classmethod
    def from_arrays(cls, masses, positions, velocities, names=None, units=None, radii=None):
        """Make a body set from arrays.

        Parameters
        ----------
        masses : Quantity or array, shape (N,), mass
        positions : Quantity or array, shape (N, 3), length
        velocities : Quantity or array, shape (N, 3), velocity
            Plain arrays are read in ``units``.
        names : sequence of str, optional
            Default ``"0"``, ``"1"``, ...
        units : UnitSystem, optional
            If given, plain numbers are read in it; otherwise Quantities are needed.
        radii : Quantity or array, shape (N,), length, optional
            Physical radii, each finite and >= 0.  Default: all 0 (point masses).

        Returns
        -------
        BodySet

        Examples
        --------
        >>> import numpy as np
        >>> import orbits
        >>> U = orbits.UnitSystem.nbody()
        >>> bodies = orbits.BodySet.from_arrays([1.0, 1e-3], [[0, 0, 0], [1, 0, 0]],
        ...                                     [[0, 0, 0], [0, 1, 0]], names=["A", "B"],
        ...                                     units=U)
        >>> bodies.names, bodies.positions.shape
        (['A', 'B'], (2, 3))
        >>> with_radii = orbits.BodySet.from_arrays([1.0, 1e-3], [[0, 0, 0], [1, 0, 0]],
        ...                                         [[0, 0, 0], [0, 1, 0]], units=U,
        ...                                         radii=[5e-3, 1e-4])
        >>> with_radii.radii
        <Quantity [0.005 , 0.0001]>
        """
        bs = cls(units)
        m = bs._array(masses, "mass", "masses", (None,))
        n = m.shape[0]
        x = bs._array(positions, "length", "positions", (n, 3))
        v = bs._array(velocities, "velocity", "velocities", (n, 3))
        r = np.zeros(n) if radii is None else bs._array(radii, "length", "radii", (n,))
        if names is None:
            names = [str(i) for i in range(n)]
        names = list(names)
        if len(names) != n:
            raise BodyError(f"expected {n} names (one per mass), got {len(names)}",
                            field="names")
        for name in names:
            _check_name_text(name)
        if len(set(names)) != n:
            seen = set()
            dup = next(nm for nm in names if nm in seen or seen.add(nm))
            raise DuplicateBodyError("a body of this name is already in the set",
                                     body=dup, field="name")
        bad = ~np.isfinite(m) | (m < 0)
        if bad.any():
            i = int(np.argmax(bad))
            raise BodyError(f"mass must be finite and >= 0, got {m[i]}", body=names[i],
                            field="mass")
        bad = ~(np.isfinite(r) & (r >= 0))
        if bad.any():
            i = int(np.argmax(bad))
            raise BodyError(f"radius must be finite and >= 0, got {r[i]} {bs.units.length}",
                            body=names[i], field="radius")
        for field, arr in (("position", x), ("velocity", v)):
            bad = ~np.all(np.isfinite(arr), axis=1)
            if bad.any():
                i = int(np.argmax(bad))
                raise BodyError(f"{field} must be finite, got {arr[i]}", body=names[i],
                                field=field)
        bs._names = names
        bs._m = m.copy()
        bs._r = r + 0.0     # a new array, with -0.0 stored as 0.0
        bs._x = x.copy()
        bs._v = v.copy()
        bs.history.append({"from": "arrays", "n": n})
        return bs

    @classmethod
    def from_rebound(cls, sim, units=None, names=None):
        """Make a body set from a ``rebound.Simulation``.

        REBOUND keeps plain numbers; they are read in ``units`` (default: a
        dimensionless system with REBOUND's ``sim.G``).  Each particle's ``r``
        becomes the body's radius.  Particle hashes are not names, so names
        default to ``"0"``, ``"1"``, ...

        Examples
        --------
        >>> import rebound
        >>> import orbits
        >>> sim = rebound.Simulation()
        >>> sim.add(m=1.0)
        >>> sim.add(m=1e-3, a=1.0)
        >>> bodies = orbits.BodySet.from_rebound(sim)
        >>> bodies.names, bodies.units.G
        (['0', '1'], 1.0)
        >>> round(float(bodies.elements("1", primary="0")["a"].value), 12)
        1.0
        """
        n = sim.N
        m = np.array([sim.particles[i].m for i in range(n)])
        x = np.array([sim.particles[i].xyz for i in range(n)], dtype=float).reshape(n, 3)
        v = np.array([sim.particles[i].vxyz for i in range(n)], dtype=float).reshape(n, 3)
        r = np.array([sim.particles[i].r for i in range(n)], dtype=float)
        if units is None:
            units = UnitSystem.nbody(G=sim.G)
        elif not math.isclose(units.G, sim.G, rel_tol=1e-15):
            raise ValueError(f"units.G = {units.G!r} differs from the REBOUND "
                             f"simulation's G = {sim.G!r}")
        bs = cls.from_arrays(m, x, v, names=names, units=units, radii=r)
        bs.history[-1] = {"from": "rebound", "n": n}
        return bs

    def to_rebound(self):
        """A ``rebound.Simulation`` with the same G, masses, radii (each
        particle's ``r``) and states (plain floats).

        Massive bodies must come before massless ones in REBOUND's active/test
        particle split; the order of this set is kept as it is.

        Examples
        --------
        >>> import orbits
        >>> sim = orbits.scenes.kepler().to_rebound()
        >>> sim.N, round(sim.particles[1].a, 12), sim.particles[1].r
        (2, 1.0, 0.0)
        """
        import rebound
        sim = rebound.Simulation()
        sim.G = self.units.G
        for i in range(len(self)):
            sim.add(m=float(self._m[i]), r=float(self._r[i]), x=self._x[i, 0], y=self._x[i, 1],
                    z=self._x[i, 2], vx=self._v[i, 0], vy=self._v[i, 1], vz=self._v[i, 2])
        return sim

    def copy(self):
        """An independent copy.

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> a = orbits.scenes.kepler()
        >>> b = a.copy()
        >>> b.add("Moon", mass=0 * u.kg, position=[2, 0, 0] * u.au)
        >>> len(a), len(b)
        (2, 3)
        """
        new = object.__new__(type(self))
        new.__dict__.update(self.__dict__)      # units: immutable, shared
        new._names = list(self._names)
        for key in ("_m", "_r", "_x", "_v"):
            setattr(new, key, getattr(self, key).copy())
        # the history's entries are small dicts of plain values; a deep copy
        # of the whole set (its unit system too) took 0.3 ms, a sweep's
        # building of each member
        new.history = _copy.deepcopy(self.history)
        return new

    @classmethod
    def read(cls, path):
        """Read a body set from a TOML or CSV file (format: :mod:`orbits.systemfile`).

        Parameters
        ----------
        path : str or os.PathLike
            Ending in ``.toml`` or ``.csv``.

        Returns
        -------
        BodySet
            In the file's unit system (default au, solar masses, days).

        Raises
        ------
        orbits.errors.SystemFileError
            A malformed file; the message gives the file, line, body and field.

        Examples
        --------
        >>> import os, tempfile
        >>> import orbits
        >>> path = os.path.join(tempfile.mkdtemp(), "earth-moon.toml")
        >>> orbits.scenes.earth_moon().write(path)
        >>> orbits.BodySet.read(path).names
        ['Earth', 'Moon']
        """
        from . import systemfile
        return systemfile.read(path).bodies

    def write(self, path):
        """Write the set to a TOML or CSV file that :meth:`read` gives back bit for bit.

        Parameters
        ----------
        path : str or os.PathLike
            Ending in ``.toml`` or ``.csv``; an existing file is replaced.

        Examples
        --------
        >>> import os, tempfile
        >>> import numpy as np
        >>> import orbits
        >>> bodies = orbits.scenes.figure_eight()
        >>> path = os.path.join(tempfile.mkdtemp(), "figure-eight.csv")
        >>> bodies.write(path)
        >>> bool(np.array_equal(orbits.BodySet.read(path).velocities, bodies.velocities))
        True
        """
        from . import systemfile
        systemfile.write(self, path)

    # -- access -----------------------------------------------------------------
    def __len__(self):
        return len(self._names)

    def __contains__(self, name):
        """Whether a body of this name (or a :class:`~orbits.body.Body` view's
        name) is in the set."""
        if isinstance(name, Body):
            name = name.name
        return name in self._names

    def __getitem__(self, key):
        """A read-only view of one body, by name or by index.

        Parameters
        ----------
        key : str or int
            The body's name, or its place in the set (from 0; negative counts
            from the end).

        Returns
        -------
        orbits.body.Body
            Its ``name``, ``mass``, ``radius``, ``position``, ``velocity``,
            ``elements(primary=...)`` and ``orbit(primary=...)``, read from
            this set when read.

        Raises
        ------
        UnknownBodyError
            No body of that name; the message suggests the nearest name.
        IndexError
            An index past either end.

        Examples
        --------
        >>> import orbits
        >>> bodies = orbits.scenes.outer_solar_system()
        >>> bodies["Jupiter"].mass
        <Quantity 0.00095479 solMass>
        >>> bodies[-1].name
        'Pluto'
        >>> try:
        ...     bodies["Jupyter"]
        ... except orbits.errors.UnknownBodyError as exc:
        ...     print(str(exc).split(";")[0])
        body 'Jupyter': no such body (did you mean 'Jupiter'?)
        """
        return Body(self, _position(self._names, key))

    def __iter__(self):
        """The bodies in order, each as a :class:`~orbits.body.Body` view."""
        return (Body(self, i) for i in range(len(self._names)))

    def __repr__(self):
        """The bodies with their masses, their radii where any is non-zero, and, for
        bound orbits, a, e and inc about the bodies before each (the default
        primary of :meth:`elements`); a long set shows its first and last rows."""
        head, rows = self._table()
        widths = [max(len(r[k]) for r in [head, *filter(None, rows)])
                  for k in range(len(head))]
        lines = [f"BodySet of {len(self)} bodies ({self.units.name}; a, e, inc about the "
                 f"centre of mass of the bodies before each)"]
        if self._epoch is not None:
            lines.append(f"  epoch {_epochs.describe(self._epoch)}")
        for row in [head, *rows]:
            if row is None:
                lines.append(f"  ... {len(self) - 2 * _REPR_ROWS} more ...")
            else:
                lines.append("  " + "  ".join(c.ljust(w) for c, w in zip(row, widths)).rstrip())
        return "\n".join(lines)

    def _repr_html_(self):
        """The table of :meth:`__repr__`, for Jupyter."""
        head, rows = self._table()

        def cells(row, tag):
            return "".join(f"<{tag}>{html.escape(c)}</{tag}>" for c in row)
        body = "".join(
            f"<tr><td colspan='{len(head)}'>&hellip; {len(self) - 2 * _REPR_ROWS} more "
            f"&hellip;</td></tr>" if row is None else f"<tr>{cells(row, 'td')}</tr>"
            for row in rows)
        return (f"<div><strong>BodySet</strong> of {len(self)} bodies, units "
                f"{html.escape(self.units.name)} (G = {self.units.G!r})"
                f"<table><thead><tr>{cells(head, 'th')}</tr></thead><tbody>{body}</tbody>"
                f"</table><small>a, e, inc: osculating, about the centre of mass of the "
                f"bodies before each; blank where the orbit is not bound.</small></div>")

    def _table(self):
        """Header and rows (strings) of the reprs; None marks the rows left out."""
        n = len(self)
        if n > 2 * _REPR_ROWS + 1:
            shown = [*range(_REPR_ROWS), None, *range(n - _REPR_ROWS, n)]
        else:
            shown = list(range(n))
        # point masses (every radius 0, the usual case) get no radius column
        sized = bool(np.any(self._r != 0))
        length = str(self.units.length)
        columns = (("mass", str(self.units.mass)),
                   *((("radius", length),) if sized else ()), ("a", length))
        head = ["name", *(f"{label} [{unit}]" if unit else label for label, unit in columns),
                "e", "inc [deg]"]
        rows = []
        for i in shown:
            if i is None:
                rows.append(None)
                continue
            el = _bound_elements(self, i)
            rows.append([self._names[i], f"{self._m[i]:.6g}",
                         *((f"{self._r[i]:.6g}",) if sized else ()),
                         *(("", "", "") if el is None else
                           (f"{el[0]:.6g}", f"{el[1]:.4g}", f"{math.degrees(el[2]):.4g}"))])
        return head, rows

    @property
    def epoch(self):
        """The date the positions and velocities hold at: an ``astropy.time.Time``
        in TDB, or None (the default: a set of no particular date).

        Set it to a Time of any scale; it is carried to TDB (:mod:`orbits.epochs`).
        A :class:`~orbits.Simulation` made from the set takes it as the date of
        its time 0, and its results give the outputs' dates (``result.epochs``).

        Raises
        ------
        orbits.errors.EpochError
            On setting anything but one Time (or None).

        Examples
        --------
        >>> from astropy.time import Time
        >>> import orbits
        >>> bodies = orbits.scenes.kepler()
        >>> print(bodies.epoch)
        None
        >>> bodies.epoch = Time("2024-01-01T00:00:00", scale="utc")
        >>> bodies.epoch.scale, bodies.epoch.isot
        ('tdb', '2024-01-01T00:01:09.184')
        """
        return self._epoch

    @epoch.setter
    def epoch(self, value):
        self._epoch = None if value is None else _epochs.as_epoch(value)

    @property
    def names(self):
        """Body names, in order (list of str).

        Examples
        --------
        >>> import orbits
        >>> orbits.scenes.kepler().names
        ['Star', 'Planet']
        """
        return list(self._names)

    @property
    def masses(self):
        """Quantity, shape (N,), mass.

        Examples
        --------
        >>> import orbits
        >>> orbits.scenes.kepler().masses
        <Quantity [1.   , 0.001] solMass>
        """
        return self.units.quantity(self._m.copy(), "mass")

    @property
    def radii(self):
        """Physical radii: Quantity, shape (N,), length (0 for a point mass).

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> bodies = orbits.scenes.kepler()
        >>> bodies.add("moon", mass=0 * u.kg, position=[2, 0, 0] * u.au, radius=1737 * u.km)
        >>> bodies.radii.to(u.km)
        <Quantity [   0.,    0., 1737.] km>
        """
        return self.units.quantity(self._r.copy(), "length")

    @property
    def positions(self):
        """Quantity, shape (N, 3), length.

        Examples
        --------
        >>> import orbits
        >>> x = orbits.scenes.kepler().positions
        >>> x.shape, x.unit
        ((2, 3), Unit("AU"))
        """
        return self.units.quantity(self._x.copy(), "length")

    @property
    def velocities(self):
        """Quantity, shape (N, 3), velocity.

        Examples
        --------
        >>> import orbits
        >>> v = orbits.scenes.kepler().velocities
        >>> v.unit, v.shape
        (Unit("AU / d"), (2, 3))
        """
        return self.units.quantity(self._v.copy(), "velocity")

    def index(self, name):
        """Position of ``name`` in the set (int, from 0).

        Raises
        ------
        UnknownBodyError
            No body of that name; the message lists the known ones.

        Examples
        --------
        >>> import orbits
        >>> orbits.scenes.kepler().index("Planet")
        1
        """
        try:
            return self._names.index(name)
        except ValueError:
            raise unknown_body(name, self._names) from None

    @property
    def total_mass(self):
        """Quantity, scalar, mass.

        Examples
        --------
        >>> import orbits
        >>> orbits.scenes.kepler().total_mass
        <Quantity 1.001 solMass>
        """
        return self.units.quantity(self._m.sum(), "mass")

    def center_of_mass(self):
        """Position and velocity of the centre of mass: two Quantities, shape (3,).

        Examples
        --------
        >>> import orbits
        >>> x, v = orbits.scenes.kepler().center_of_mass()   # the scene is barycentric
        >>> bool(abs(x).max().value < 1e-15), x.unit, v.unit
        (True, Unit("AU"), Unit("AU / d"))
        """
        x, v = self._com()
        return self.units.quantity(x, "length"), self.units.quantity(v, "velocity")

    def move_to_com(self):
        """Shift positions and velocities so that the centre of mass is at rest at the origin.

        Raises
        ------
        NoMassiveBodyError
            Every body is massless.

        Examples
        --------
        >>> import orbits
        >>> bodies = orbits.scenes.kepler()
        >>> bodies.move_to_com()
        >>> x, v = bodies.center_of_mass()
        >>> bool(abs(x).max().value < 1e-15 and abs(v).max().value < 1e-15)
        True
        """
        self._require_mass()
        x, v = self._com()
        self._x -= x
        self._v -= v
        self.history.append({"from": "move_to_com"})

    def elements(self, name, primary=None):
        """Osculating orbital elements of a body about a primary.

        Parameters
        ----------
        name : str
        primary : str, optional
            A body's name; ``"barycentre"`` (or ``"barycenter"``): the centre of
            mass of all bodies, ``name`` included, with ``mu = G (M + m)`` for
            the total mass ``M`` and the body's mass ``m``, as REBOUND's
            ``particle.orbit(primary=sim.com())``.  Default: the centre of mass
            of the bodies before ``name`` in the set (Jacobi-like, REBOUND's
            default in ``particle.orbit()``).

        Returns
        -------
        dict
            ``a`` (length), ``e``, ``inc``, ``Omega``, ``omega``, ``f``, ``M``
            (angles in rad), as Quantities.

        Examples
        --------
        >>> import orbits
        >>> el = orbits.scenes.outer_solar_system().elements("Jupiter", primary="Sun")
        >>> round(float(el["a"].value), 2), el["a"].unit, round(float(el["e"]), 3)
        (5.2, Unit("AU"), 0.048)
        """
        out, status = self._element_values(name, primary)
        if status != 0:
            raise ElementsError(describe_status(status), body=name, field="elements")
        q = self.units.quantity
        return {"a": q(out[0], "length"), "e": out[1] << u.dimensionless_unscaled,
                **{k: out[j] << u.rad for j, k in enumerate(_ELEMENT_NAMES[2:], start=2)}}

    def _element_values(self, name, primary):
        # (a, e, inc, Omega, omega, f, M) in internal units and rad, and the
        # kernel's status
        mu, r, v = self._relative(name, primary)
        out = np.empty(7)
        status = _elements.state_to_elements(mu, r, v, out)
        return out, status

    def _relative(self, name, primary):
        # mu = G (m_primary + m_body) and the state relative to the primary
        # (internal units): of a named body, of the bodies before ``name``
        # (None), or of the barycentre of all bodies, ``name`` included
        i = self.index(name)
        if _geometry.is_barycentre(primary):
            self._require_mass()
            mp = self._m.sum()
            xp, vp = self._com()
        else:
            if primary == name:
                raise BodyError("a body has no orbit about itself; name another primary",
                                body=name, field="primary")
            mp, xp, vp = self._primary_state(name, primary, before=i)
        mu = self.units.G * (mp + self._m[i])
        return mu, self._x[i] - xp, self._v[i] - vp

    def mutual_inclination(self, a, b, primary=None):
        """The angle between the orbital planes of two bodies.

        Parameters
        ----------
        a, b : str
            The bodies' names.
        primary : str, optional
            The primary of both orbits, as for :meth:`elements`: a body's name,
            ``"barycentre"``, or None for each body's default (the centre of
            mass of the bodies before it, so that in a hierarchical system each
            orbit is about what it goes around).

        Returns
        -------
        Quantity, scalar, rad
            In [0, pi]: the angle between the orbits' angular momentum vectors
            ``r x v`` (relative to their primaries), which for two orbits about
            one primary is ``cos I = cos i_a cos i_b + sin i_a sin i_b
            cos(Omega_a - Omega_b)``.

        Raises
        ------
        UnknownBodyError, BodyError
            As :meth:`elements` raises them.

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> bodies = orbits.BodySet()
        >>> bodies.add("Sun", mass=1 * u.Msun)
        >>> bodies.add("b", mass=1 * u.Mearth, primary="Sun", a=1 * u.au, inc=10 * u.deg)
        >>> bodies.add("c", mass=1 * u.Mearth, primary="Sun", a=2 * u.au, inc=10 * u.deg,
        ...            Omega=180 * u.deg)
        >>> bodies.mutual_inclination("b", "c", primary="Sun").to(u.deg).round(10)
        <Quantity 20. deg>
        """
        _, ra, va = self._relative(a, primary)
        _, rb, vb = self._relative(b, primary)
        return float(_geometry.angle_between(np.cross(ra, va), np.cross(rb, vb))) << u.rad

    def to_invariable_plane(self):
        """Rotate the set so that its total angular momentum points along +z.

        In place, as :meth:`move_to_com`: positions and velocities are rotated
        about the origin, so distances, speeds, the energy and ``|L|`` are
        unchanged.  The angular momentum is the one about the centre of mass
        (the same in any frame moving uniformly); in a set moved to its
        centre of mass, the total angular momentum.  The new x axis points
        along the ascending node of the invariable plane on the old x-y plane
        (``z x L``), as REBOUND's
        ``sim.rotate(rebound.Rotation.to_new_axes(newz=sim.angular_momentum()))``
        chooses it; where ``L`` is already along z to within rounding, x is
        kept.

        Raises
        ------
        NoMassiveBodyError
            Every body is massless.
        BodyError
            The set has no angular momentum about its centre of mass (field
            ``angular_momentum``), so no plane is defined.

        Examples
        --------
        >>> import numpy as np
        >>> import orbits
        >>> bodies = orbits.scenes.outer_solar_system(com=True)
        >>> bodies.to_invariable_plane()
        >>> m = bodies.masses.value
        >>> L = (m[:, None] * np.cross(bodies.positions.value, bodies.velocities.value)).sum(0)
        >>> bool(np.hypot(L[0], L[1]) < 1e-15 * L[2])
        True
        """
        self._require_mass()
        L = _geometry.angular_momentum(self._m, self._x, self._v)
        if not np.any(L):
            raise BodyError("the set has no angular momentum about its centre of mass; "
                            "no invariable plane is defined", field="angular_momentum")
        R = _geometry.invariable_plane_rotation(L)
        self._x = self._x @ R.T
        self._v = self._v @ R.T
        self.history.append({"from": "to_invariable_plane"})

    def plot_orbits(self, primary=None, plane="xy", ax=None, path=None):
        """A sketch of the set: each body on its osculating Keplerian orbit.

        See :func:`orbits.plotting.plot_orbits` (needs matplotlib).

        Parameters
        ----------
        primary : str, optional
            The body every orbit is about; default as for :meth:`elements`.
        plane : {"xy", "xz", "yz"}
        ax : matplotlib.axes.Axes, optional
        path : str or path-like, optional
            Also write the figure there (PNG).

        Returns
        -------
        matplotlib.figure.Figure

        Examples
        --------
        >>> import orbits
        >>> fig = orbits.scenes.outer_solar_system().plot_orbits(primary="Sun")
        >>> [line.get_label() for line in fig.axes[0].lines][:2]
        ['Jupiter', 'Saturn']
        """
        from .plotting import plot_orbits
        return plot_orbits(self, primary=primary, plane=plane, ax=ax, path=path)

    def check(self):
        """Check the set as a whole: at least one massive body, no two at one place.

        Raises
        ------
        NoMassiveBodyError, CoincidentBodiesError

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> bodies = orbits.scenes.kepler()
        >>> bodies.check()
        >>> bodies.add("twin", mass=1 * u.Mearth, position=bodies.positions[1])
        >>> try:
        ...     bodies.check()
        ... except orbits.BodyError as exc:
        ...     print(type(exc).__name__, exc.body, exc.field)
        CoincidentBodiesError Planet position
        """
        self._require_mass()
        n = len(self)
        if n > 1:
            if n <= 64:
                # every pair compared at once: for a few bodies a tenth of the
                # time of np.unique over rows, which sorts a structured view
                same = (self._x[:, None, :] == self._x[None, :, :]).all(axis=2)
                np.fill_diagonal(same, False)
                repeated = same.any(axis=1)
                found, j = bool(repeated.any()), int(np.argmax(repeated))
            else:
                _, first, counts = np.unique(self._x, axis=0, return_index=True,
                                             return_counts=True)
                found, j = bool(np.any(counts > 1)), first[np.argmax(counts > 1)]
            if found:
                same = [self._names[k] for k in range(len(self))
                        if np.array_equal(self._x[k], self._x[j])]
                raise CoincidentBodiesError(
                    f"is at the same position as {', '.join(map(repr, same[1:]))} "
                    f"({self._x[j]} {self.units.length}); bodies must be at distinct "
                    f"positions", body=same[0], field="position")

    # -- internals ----------------------------------------------------------------
    def _append(self, name, m, x, v, r=0.0):
        self._names.append(name)
        self._m = np.append(self._m, m)
        self._r = np.append(self._r, r + 0.0)     # -0.0 stored as 0.0
        self._x = np.vstack([self._x, np.asarray(x, dtype=float).reshape(1, 3)])
        self._v = np.vstack([self._v, np.asarray(v, dtype=float).reshape(1, 3)])

    def _check_name(self, name):
        _check_name_text(name)
        if name in self._names:
            raise DuplicateBodyError("a body of this name is already in the set",
                                     body=name, field="name")

    def _require_mass(self):
        if len(self) == 0 or not np.any(self._m > 0):
            raise NoMassiveBodyError(
                f"the body set has no body with positive mass ({len(self)} bodies); "
                "at least one is needed")

    def _com(self):
        mt = self._m.sum()
        if mt <= 0:
            return np.zeros(3), np.zeros(3)
        return (self._m @ self._x) / mt, (self._m @ self._v) / mt

    def _scalar(self, value, kind, body, field):
        val = self.units.to_internal(value, kind, bare_ok=self._bare_ok, body=body,
                                     field=field)
        if val.shape != ():
            raise BodyError(f"expected a scalar, got shape {val.shape}", body=body,
                            field=field)
        return float(val)

    def _vector(self, value, kind, body, field):
        val = self.units.to_internal(value, kind, bare_ok=self._bare_ok, body=body,
                                     field=field)
        if val.shape != (3,):
            raise BodyError(f"expected 3 components (x, y, z), got shape {val.shape}",
                            body=body, field=field)
        if not np.all(np.isfinite(val)):
            raise BodyError(f"must be finite, got {val}", body=body, field=field)
        return val.copy()

    def _array(self, value, kind, field, shape):
        val = self.units.to_internal(value, kind, bare_ok=self._bare_ok, field=field)
        ok = val.ndim == len(shape) and all(s is None or s == d
                                            for s, d in zip(shape, val.shape))
        if not ok:
            want = "(" + ", ".join("N" if s is None else str(s) for s in shape) + ")"
            raise BodyError(f"expected shape {want}, got {val.shape}", field=field)
        return np.ascontiguousarray(val, dtype=np.float64)

    def _primary_state(self, name, primary, before):
        if primary is None:
            if before == 0 or not np.any(self._m[:before] > 0):
                raise BodyError("orbital elements need a primary: name one with "
                                "primary=, or add a massive body first",
                                body=name, field="primary")
            m = self._m[:before]
            mt = m.sum()
            return mt, (m @ self._x[:before]) / mt, (m @ self._v[:before]) / mt
        if not isinstance(primary, str):
            raise BodyError(f"primary must be a body's name, got {primary!r}",
                            body=name, field="primary")
        if primary not in self._names:
            raise unknown_body(primary, self._names, field="primary", body=name,
                               what=f"unknown primary {primary!r}", label="known bodies")
        j = self._names.index(primary)
        return self._m[j], self._x[j], self._v[j]

    def _state_from_elements(self, name, m, primary, **fields):
        mp, xp, vp = self._primary_state(name, primary, before=len(self))
        values = {key: None if val is None else self._scalar(val, _FIELD_KINDS[key], name, key)
                  for key, val in fields.items()}
        el = _orbit_fields.classical(name, self.units.G * (mp + m), values)
        e_ = 0.0 if el["e"] is None else el["e"]
        pos, vel = _relative_state(name, self.units, mp, m, el["a"], e_, el["inc"],
                                   el["Omega"], el["omega"], el["f"], el["M"])
        return xp + pos, vp + vel


def _relative_state(name, units, mp, m, a, e, inc, Omega, omega, f, M):
    """Position and velocity, shape (3,) each, of body ``name`` (mass ``m``)
    relative to its primary (mass ``mp``), from its elements as plain floats in
    ``units`` (angles in rad; ``None`` for an angle not given).

    What :meth:`BodySet.add` computes for a body given by elements, and
    :mod:`orbits.systemfile` for a table of them: the same arithmetic, so the
    same state bit for bit.

    Raises
    ------
    ElementsError
        The elements are not finite, not an orbit, or both masses are zero.

    Examples
    --------
    >>> from orbits import UnitSystem
    >>> from orbits.bodies import _relative_state
    >>> pos, vel = _relative_state("Earth", UnitSystem(), 1.0, 0.0, 1.0, 0.0, None,
    ...                            None, None, None, None)
    >>> pos.tolist()
    [1.0, 0.0, 0.0]
    """
    a_, e_ = a, e
    ang = dict(inc=inc, Omega=Omega, omega=omega, f=f, M=M)
    for key, val in (("a", a_), ("e", e_), *ang.items()):
        if val is not None and not math.isfinite(val):
            raise ElementsError(f"must be finite, got {val}", body=name, field=key)
    if e_ < 0:
        raise ElementsError(f"eccentricity must be >= 0, got {e_}", body=name, field="e")
    if a_ == 0:
        raise ElementsError("semi-major axis must be non-zero", body=name, field="a")
    if a_ > 0 and e_ >= 1:
        raise ElementsError(f"e = {e_} >= 1 needs a < 0 (a hyperbolic orbit); "
                            f"got a = {a_} {units.length}. Parabolic orbits "
                            f"(e = 1) must be given as a state", body=name, field="e")
    if a_ < 0 and e_ <= 1:
        raise ElementsError(f"a < 0 means a hyperbolic orbit and needs e > 1; "
                            f"got e = {e_}", body=name, field="e")
    if ang["f"] is not None and ang["M"] is not None:
        raise ElementsError("give the true anomaly f or the mean anomaly M, not both",
                            body=name, field="f")
    anomaly = ang["f"] if ang["f"] is not None else (
        _anomalies.true_from_mean(ang["M"], e_) if ang["M"] is not None else 0.0)
    mu = units.G * (mp + m)
    if mu <= 0:
        raise ElementsError("the primary and the body are both massless; an orbit "
                            "needs mass", body=name, field="primary")
    pos, vel = np.empty(3), np.empty(3)
    status = _elements.elements_to_state(mu, a_, e_, ang["inc"] or 0.0,
                                       ang["Omega"] or 0.0, ang["omega"] or 0.0,
                                       anomaly, pos, vel)
    if status != 0:
        raise ElementsError(describe_status(status), body=name,
                            field="f" if ang["f"] is not None else "elements")
    return pos, vel


def _check_name_text(name):
    """Refuse a name that is not a non-empty string, or that an HDF5 file cannot
    hold: a NUL character, or a lone surrogate (text that UTF-8 cannot encode)."""
    if not isinstance(name, str) or not name:
        raise BodyError(f"name must be a non-empty string, got {name!r}",
                        body=name, field="name")
    if "\0" in name:
        raise BodyError("name must not contain a NUL character ('\\x00'), which an output "
                        "file cannot hold", body=name, field="name")
    try:
        name.encode("utf-8")
    except UnicodeEncodeError as exc:
        raise BodyError(f"name must be text that UTF-8 can encode; character "
                        f"{exc.object[exc.start]!r} at {exc.start} is a lone surrogate",
                        body=name, field="name") from None


def _describe(value):
    # str(value), with a Quantity's unit written once per unit (astropy
    # formats the unit anew at every str(), a third of BodySet.add's time)
    if isinstance(value, u.Quantity):
        unit = _unit_string(value.unit)
        return f"{value.value} {unit}" if unit else str(value.value)
    return str(value)


@functools.lru_cache(maxsize=64)
def _unit_string(unit):
    return unit.to_string()


def _bound_elements(bodies, i):
    """``(a, e, inc)`` of body ``i`` about the centre of mass of the bodies before it
    (internal units, inc in rad), or None where that orbit is not a bound ellipse."""
    m = bodies._m[:i]
    mt = m.sum()
    if i == 0 or not mt > 0:
        return None
    mu = bodies.units.G * (mt + bodies._m[i])
    out = np.empty(7)
    status = _elements.state_to_elements(mu, bodies._x[i] - (m @ bodies._x[:i]) / mt,
                                       bodies._v[i] - (m @ bodies._v[:i]) / mt, out)
    if status != 0 or not (0 <= out[1] < 1 and out[0] > 0):
        return None
    return float(out[0]), float(out[1]), float(out[2])
