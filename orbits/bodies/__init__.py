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

This module is the record and its methods; the private modules beside it hold
the checks of input (``_input``), the orbit arithmetic (``_elements``), the
table of its repr (``_table``) and the conversion to and from REBOUND
(``_rebound``).
"""

import copy as _copy

import astropy.units as u
import numpy as np

from .. import epochs as _epochs
from .. import geometry as _geometry
from .._kernels.status import describe_status
from ..body import Body, _position, unknown_body
from ..errors import BodyError, ElementsError
from ..units import UnitSystem
from . import _input, _rebound, _table
from ._elements import ELEMENT_NAMES, element_values, relative_to_primary, state_from_elements

__all__ = ["BodySet"]


def _stored(attribute, kind, doc):
    """A read-only property: the array ``attribute`` as a Quantity of ``kind``
    (a copy, so that the set cannot be changed through it)."""
    def get(self):
        return self.units.quantity(getattr(self, attribute).copy(), kind)
    return property(get, doc=doc)


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
    In a unit system given explicitly, plain numbers are read in it:

    >>> bodies = orbits.BodySet(orbits.UnitSystem.nbody())
    >>> bodies.add("A", mass=1.0)
    >>> bodies.add("B", mass=1e-3, primary="A", a=1.0, e=0.1)
    >>> bodies.move_to_com()
    >>> len(bodies), bodies.units.G, bodies.masses
    (2, 1.0, <Quantity [1.   , 0.001]>)
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
        _input.check_names([name], self._names)
        m = self._scalar(mass, "mass", name, "mass")
        _input.check_masses(np.array([m]), [name], self.units.mass)
        r = 0.0 if radius is None else self._scalar(radius, "length", name, "radius")
        _input.check_radii(np.array([r]), [name], self.units.length)
        elements = dict(a=a, e=e, inc=inc, Omega=Omega, omega=omega, f=f, M=M, P=P,
                        pomega=pomega, l=l, T=T, E=E, theta=theta)
        given = [k for k, val in elements.items() if val is not None]
        if given or primary is not None:
            if position is not None or velocity is not None:
                raise BodyError("give either a Cartesian state (position, velocity) or "
                                f"orbital elements, not both (got {', '.join(given)})",
                                body=name, field="position")
            x, v = state_from_elements(self, name, m, primary, elements)
            how = {"name": name, "from": "elements", "primary": primary,
                   **{k: _input.describe(val) for k, val in elements.items()
                      if val is not None}}
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
        names = [str(i) for i in range(n)] if names is None else list(names)
        if len(names) != n:
            raise BodyError(f"expected {n} names (one per mass), got {len(names)}",
                            field="names")
        _input.check_names(names)
        _input.check_masses(m, names, bs.units.mass)
        _input.check_radii(r, names, bs.units.length)
        _input.check_states(x, v, names)
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
        >>> sim = rebound.Simulation()
        >>> sim.add(m=1.0)
        >>> sim.add(m=1e-3, a=1.0)
        >>> bodies = orbits.BodySet.from_rebound(sim)
        >>> bodies.names, bodies.units.G
        (['0', '1'], 1.0)
        >>> round(float(bodies.elements("1", primary="0")["a"].value), 12)
        1.0
        """
        m, x, v, r, units = _rebound.arrays_from_simulation(sim, units)
        bs = cls.from_arrays(m, x, v, names=names, units=units, radii=r)
        bs.history[-1] = {"from": "rebound", "n": len(m)}
        return bs

    def to_rebound(self):
        """A ``rebound.Simulation`` with the same G, masses, radii (each
        particle's ``r``) and states (plain floats).

        Massive bodies must come before massless ones in REBOUND's active/test
        particle split; the order of this set is kept as it is.

        Examples
        --------
        >>> sim = orbits.scenes.kepler().to_rebound()
        >>> sim.N, round(sim.particles[1].a, 12), sim.particles[1].r
        (2, 1.0, 0.0)
        """
        return _rebound.simulation_from(self)

    def copy(self):
        """An independent copy.

        Examples
        --------
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
        # the history's entries are small dicts of plain values: they alone are
        # deep-copied, not the unit system
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
        >>> path = os.path.join(tempfile.mkdtemp(), "earth-moon.toml")
        >>> orbits.scenes.earth_moon().write(path)
        >>> orbits.BodySet.read(path).names
        ['Earth', 'Moon']
        """
        from .. import systemfile     # a cycle: a system file is read into a BodySet
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
        >>> bodies = orbits.scenes.figure_eight()
        >>> path = os.path.join(tempfile.mkdtemp(), "figure-eight.csv")
        >>> bodies.write(path)
        >>> bool(np.array_equal(orbits.BodySet.read(path).velocities, bodies.velocities))
        True
        """
        from .. import systemfile     # a cycle: a system file is read into a BodySet
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
        return _table.text(self)

    def _repr_html_(self):
        """The table of :meth:`__repr__`, for Jupyter."""
        return _table.html_table(self)

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
        >>> orbits.scenes.kepler().names
        ['Star', 'Planet']
        """
        return list(self._names)

    masses = _stored("_m", "mass", """Quantity, shape (N,), mass.

        Examples
        --------
        >>> orbits.scenes.kepler().masses
        <Quantity [1.   , 0.001] solMass>
        """)

    radii = _stored("_r", "length", """Physical radii: Quantity, shape (N,), length (0 for a
        point mass).

        Examples
        --------
        >>> bodies = orbits.scenes.kepler()
        >>> bodies.add("moon", mass=0 * u.kg, position=[2, 0, 0] * u.au, radius=1737 * u.km)
        >>> bodies.radii.to(u.km)
        <Quantity [   0.,    0., 1737.] km>
        """)

    positions = _stored("_x", "length", """Quantity, shape (N, 3), length.

        Examples
        --------
        >>> x = orbits.scenes.kepler().positions
        >>> x.shape, x.unit
        ((2, 3), Unit("AU"))
        """)

    velocities = _stored("_v", "velocity", """Quantity, shape (N, 3), velocity.

        Examples
        --------
        >>> v = orbits.scenes.kepler().velocities
        >>> v.unit, v.shape
        (Unit("AU / d"), (2, 3))
        """)

    def index(self, name):
        """Position of ``name`` in the set (int, from 0).

        Raises
        ------
        UnknownBodyError
            No body of that name; the message lists the known ones.

        Examples
        --------
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
        >>> orbits.scenes.kepler().total_mass
        <Quantity 1.001 solMass>
        """
        return self.units.quantity(self._m.sum(), "mass")

    def center_of_mass(self):
        """Position and velocity of the centre of mass: two Quantities, shape (3,).

        Examples
        --------
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
        >>> el = orbits.scenes.outer_solar_system().elements("Jupiter", primary="Sun")
        >>> round(float(el["a"].value), 2), el["a"].unit, round(float(el["e"]), 3)
        (5.2, Unit("AU"), 0.048)
        """
        out, status = self._element_values(name, primary)
        if status != 0:
            raise ElementsError(describe_status(status), body=name, field="elements")
        q = self.units.quantity
        return {"a": q(out[0], "length"), "e": out[1] << u.dimensionless_unscaled,
                **{k: out[j] << u.rad for j, k in enumerate(ELEMENT_NAMES[2:], start=2)}}

    def _element_values(self, name, primary):
        # (a, e, inc, Omega, omega, f, M) in internal units and rad, and the
        # kernel's status
        return element_values(self, name, primary)

    def _relative(self, name, primary):
        # mu = G (m_primary + m_body) and the state relative to the primary
        # (internal units), for the Body views
        return relative_to_primary(self, name, primary)

    def mutual_inclination(self, a, b, primary=None):
        """The angle between the orbital planes of two bodies.

        Parameters
        ----------
        a, b : str
            The bodies' names.
        primary : str, optional
            The primary of both orbits, as for :meth:`elements`; by default each
            body's own, so that in a hierarchical system each orbit is about
            what it goes around.

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
        >>> fig = orbits.scenes.outer_solar_system().plot_orbits(primary="Sun")
        >>> [line.get_label() for line in fig.axes[0].lines][:2]
        ['Jupiter', 'Saturn']
        """
        # orbits.plotting, matplotlib's gateway, stands above the files, which
        # hold body sets (its plot_file reads one): a cycle, and the layers'
        # contract lists this import
        from .. import plotting
        return plotting.plot_orbits(self, primary=primary, plane=plane, ax=ax, path=path)

    def check(self):
        """Check the set as a whole: at least one massive body, no two at one place.

        Raises
        ------
        NoMassiveBodyError, CoincidentBodiesError

        Examples
        --------
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
        _input.check_distinct_positions(self._names, self._x, self.units.length)

    # -- internals ----------------------------------------------------------------
    def _append(self, name, m, x, v, r=0.0):
        self._names.append(name)
        self._m = np.append(self._m, m)
        self._r = np.append(self._r, r + 0.0)     # -0.0 stored as 0.0
        self._x = np.vstack([self._x, np.asarray(x, dtype=float).reshape(1, 3)])
        self._v = np.vstack([self._v, np.asarray(v, dtype=float).reshape(1, 3)])

    def _require_mass(self):
        _input.require_mass(self._m)

    def _com(self):
        mt = self._m.sum()
        if mt <= 0:
            return np.zeros(3), np.zeros(3)
        return (self._m @ self._x) / mt, (self._m @ self._v) / mt

    def _scalar(self, value, kind, body, field):
        return float(_input.internal(self.units, value, kind, (), bare_ok=self._bare_ok,
                                     body=body, field=field))

    def _vector(self, value, kind, body, field):
        val = _input.internal(self.units, value, kind, (3,), bare_ok=self._bare_ok,
                              body=body, field=field)
        if not np.all(np.isfinite(val)):
            raise BodyError(f"must be finite, got {val}", body=body, field=field)
        return val.copy()

    def _array(self, value, kind, field, shape):
        return _input.internal(self.units, value, kind, shape, bare_ok=self._bare_ok,
                               field=field)
