"""One body by name: a read-only view of a body set's entry, its orbit as
REBOUND's ``particle.orbit()`` gives it, and its track through a run's outputs.

``bodies["Jupiter"]`` gives a :class:`Body`, ``result["Jupiter"]`` a
:class:`Track`; ``body.orbit()`` an :class:`Orbit`.  A name that is not in the
set raises :class:`~orbits.errors.UnknownBodyError` with the nearest known
name as a suggestion (:func:`unknown_body`).
"""

import dataclasses
import difflib
import math
import numbers

import astropy.units as u
import numpy as np

from ._kernels import elements as _elements
from ._kernels.status import describe_status
from .errors import ElementsError, UnknownBodyError

__all__ = ["Body", "Orbit", "Track", "unknown_body"]


def unknown_body(name, known, field=None, what="no such body", body=None,
                 label="known"):
    """The :class:`~orbits.errors.UnknownBodyError` for ``name``: the message
    (``what``, the suggestion, then ``label`` and the known names) suggests
    the nearest known name where one is close.  ``body`` is the error's
    ``body`` (default ``name``).

    Examples
    --------
    >>> from orbits.body import unknown_body
    >>> print(unknown_body("jupiter", ["Sun", "Jupiter", "Saturn"]))
    body 'jupiter': no such body (did you mean 'Jupiter'?); known: Sun, Jupiter, Saturn
    >>> print(unknown_body("Moon", ["Star", "Planet"]))
    body 'Moon': no such body; known: Star, Planet
    """
    known = [str(k) for k in known]
    hint = ""
    if isinstance(name, str):
        folded = {k.casefold(): k for k in known}
        close = ([folded[name.casefold()]] if name.casefold() in folded
                 else difflib.get_close_matches(name, known, n=1))
        hint = f" (did you mean {close[0]!r}?)" if close else ""
    return UnknownBodyError(f"{what}{hint}; {label}: {', '.join(known)}",
                            body=name if body is None else body, field=field)


def _position(names, key):
    """Index of ``key`` (a name, or an int counted from 0, negative from the end)."""
    if isinstance(key, str):
        try:
            return names.index(key)
        except ValueError:
            raise unknown_body(key, names) from None
    if isinstance(key, numbers.Integral) and not isinstance(key, bool):
        n = len(names)
        if not -n <= key < n:
            raise IndexError(f"body index {key} out of range for {n} bodies")
        return int(key) % n
    raise TypeError(f"bodies are looked up by name (str) or index (int), got "
                    f"{type(key).__name__}")


@dataclasses.dataclass(frozen=True)
class Orbit:
    """The osculating orbit of a body about a primary: the fields of REBOUND's
    ``rebound.Orbit``, as Quantities in the body set's units.

    Attributes
    ----------
    d : Quantity, length
        Distance from the primary.
    v : Quantity, velocity
        Speed relative to the primary.
    h : Quantity, length^2 / time
        Specific angular momentum ``|r x v|``.
    P : Quantity, time
        Period ``2 pi sqrt(a^3 / mu)``; NaN for a hyperbolic orbit (REBOUND
        gives a negative number there).
    n : Quantity, rad / time
        Mean motion ``sqrt(mu / |a|^3)``.
    a, e, inc, Omega, omega, f, M : Quantity
        As :meth:`orbits.BodySet.elements` gives them (``Omega``, ``omega`` in
        [0, 2 pi), ``f``, ``M`` in [-pi, pi]).
    pomega, l, theta : Quantity, angle
        Longitude of pericentre, mean longitude and true longitude, in
        [0, 2 pi), REBOUND's definitions: ``Omega + omega``, ``pomega + M``,
        ``Omega + omega + f`` for a prograde orbit, and ``Omega - omega``,
        ``pomega - M``, ``Omega - omega - f`` for a retrograde one
        (``inc > pi / 2``).
    hvec, evec : Quantity, shape (3,)
        Specific angular momentum vector and eccentricity vector.
    primary : str or None
        The primary's name, ``"barycentre"``, or None for the default (the
        centre of mass of the bodies before this one).

    Notes
    -----
    REBOUND's ``T`` (time of pericentre) needs the simulation's time, which a
    body set does not keep: ``-M / n`` is the time since pericentre.  Its
    ``rhill`` and Pal's coordinates are not given.
    """

    a: u.Quantity
    e: u.Quantity
    inc: u.Quantity
    Omega: u.Quantity
    omega: u.Quantity
    f: u.Quantity
    M: u.Quantity
    pomega: u.Quantity
    l: u.Quantity      # noqa: E741  (REBOUND's name for the mean longitude)
    theta: u.Quantity
    P: u.Quantity
    n: u.Quantity
    d: u.Quantity
    v: u.Quantity
    h: u.Quantity
    hvec: u.Quantity
    evec: u.Quantity
    primary: object = None

    def __repr__(self):
        deg = {k: getattr(self, k).to_value(u.deg) for k in ("inc", "Omega", "omega", "f")}
        return (f"<Orbit a={self.a:.6g} e={float(self.e):.6g} inc={deg['inc']:.6g} deg "
                f"Omega={deg['Omega']:.6g} deg omega={deg['omega']:.6g} deg "
                f"f={deg['f']:.6g} deg>")

    @classmethod
    def from_state(cls, mu, r, v, units, primary=None, body=None):
        """The orbit of relative state ``r``, ``v`` (plain floats in ``units``)
        under ``mu = G (m_primary + m_body)``.

        Raises
        ------
        ElementsError
            The state describes no orbit (the body on its primary, a radial
            or parabolic orbit to within rounding).

        Examples
        --------
        >>> from orbits import UnitSystem
        >>> from orbits.body import Orbit
        >>> o = Orbit.from_state(1.0, np.array([1.0, 0, 0]), np.array([0, 1.0, 0]),
        ...                      UnitSystem.nbody())
        >>> float(o.a.value), float(o.P.value) == 2 * np.pi
        (1.0, True)
        """
        r = np.asarray(r, dtype=float)
        v = np.asarray(v, dtype=float)
        out = np.empty(7)
        status = _elements.state_to_elements(mu, r, v, out)
        if status != 0:
            raise ElementsError(describe_status(status), body=body, field="elements")
        a, e, inc, Omega, omega, f, M = (float(x) for x in out)
        hvec = np.cross(r, v)
        dist = float(np.linalg.norm(r))
        evec = np.cross(v, hvec) / mu - r / dist
        if inc < 0.5 * math.pi:
            pomega, lam, theta = Omega + omega, Omega + omega + M, Omega + omega + f
        else:
            pomega, lam, theta = Omega - omega, Omega - omega - M, Omega - omega - f
        two_pi = 2.0 * math.pi
        q = units.quantity
        return cls(
            a=q(a, "length"), e=e << u.dimensionless_unscaled, inc=inc << u.rad,
            Omega=Omega << u.rad, omega=omega << u.rad, f=f << u.rad, M=M << u.rad,
            pomega=(pomega % two_pi) << u.rad, l=(lam % two_pi) << u.rad,
            theta=(theta % two_pi) << u.rad,
            P=q(two_pi * math.sqrt(a ** 3 / mu) if a > 0 else math.nan, "time"),
            n=math.sqrt(mu / abs(a) ** 3) / units.unit("time") * u.rad,
            d=q(dist, "length"), v=q(float(np.linalg.norm(v)), "velocity"),
            h=float(np.linalg.norm(hvec)) * units.unit("length") ** 2 / units.unit("time"),
            hvec=hvec * units.unit("length") ** 2 / units.unit("time"),
            evec=evec << u.dimensionless_unscaled, primary=primary)


class Body:
    """A read-only view of one body of a :class:`~orbits.BodySet`.

    ``bodies["Jupiter"]``, ``bodies[1]`` and ``for body in bodies`` give
    these.  Each attribute reads the set when it is read, so a view follows
    what is done to its set afterwards (:meth:`~orbits.BodySet.move_to_com`,
    :meth:`~orbits.BodySet.to_invariable_plane`).  The view itself cannot be
    written to: change the set, or make a new one.

    ``sim.bodies`` is a new body set holding the simulation's current state
    each time it is read, so ``sim.bodies["Jupiter"].position`` is where
    Jupiter is now; a view kept from before a run still shows the state at the
    time ``sim.bodies`` was read (REBOUND's ``sim.particles[i]`` instead
    points into the running simulation).

    Attributes
    ----------
    name : str
    index : int
        Its place in the set, from 0.
    mass : Quantity, mass
    radius : Quantity, length
    position : Quantity, shape (3,), length
    velocity : Quantity, shape (3,), velocity

    Examples
    --------
    >>> bodies = orbits.scenes.outer_solar_system()
    >>> jupiter = bodies["Jupiter"]
    >>> jupiter
    <Body 'Jupiter' (1 of 6): mass 0.000954786 solMass>
    >>> jupiter.position.unit, jupiter.velocity.shape
    (Unit("AU"), (3,))
    >>> round(float(jupiter.orbit(primary="Sun").a.value), 2)
    5.2
    >>> [body.name for body in bodies][:3], "Saturn" in bodies
    (['Sun', 'Jupiter', 'Saturn'], True)
    """

    __slots__ = ("_set", "_name", "_index")

    def __init__(self, bodies, index):
        object.__setattr__(self, "_set", bodies)
        object.__setattr__(self, "_index", index)
        object.__setattr__(self, "_name", bodies._names[index])

    def __setattr__(self, key, value):
        raise AttributeError(f"a Body is a read-only view of {self._name!r}; change the "
                             f"body set (or make a new one) instead")

    def __repr__(self):
        return (f"<Body {self._name!r} ({self.index} of {len(self._set)}): "
                f"mass {self.mass:.6g}>")

    def _i(self):
        names = self._set._names
        i = self._index
        if i < len(names) and names[i] == self._name:
            return i
        return _position(names, self._name)

    @property
    def name(self):
        """str."""
        return self._name

    @property
    def index(self):
        """int: the body's place in the set."""
        return self._i()

    @property
    def mass(self):
        """Quantity, mass."""
        return self._set.units.quantity(float(self._set._m[self._i()]), "mass")

    @property
    def radius(self):
        """Quantity, length: the physical radius (0 for a point mass)."""
        return self._set.units.quantity(float(self._set._r[self._i()]), "length")

    @property
    def position(self):
        """Quantity, shape (3,), length (a copy)."""
        return self._set.units.quantity(self._set._x[self._i()].copy(), "length")

    @property
    def velocity(self):
        """Quantity, shape (3,), velocity (a copy)."""
        return self._set.units.quantity(self._set._v[self._i()].copy(), "velocity")

    def elements(self, primary=None):
        """Osculating elements: :meth:`orbits.BodySet.elements` of this body.

        Parameters
        ----------
        primary : str, optional
            A body's name, ``"barycentre"``, or None: the centre of mass of the
            bodies before this one (Jacobi-like, REBOUND's default in
            ``particle.orbit()``).

        Returns
        -------
        dict of Quantity
            ``a``, ``e``, ``inc``, ``Omega``, ``omega``, ``f``, ``M``.
        """
        return self._set.elements(self._name, primary=primary)

    def orbit(self, primary=None):
        """The orbit as REBOUND's ``particle.orbit(primary=...)`` gives it.

        Parameters
        ----------
        primary : str, optional
            As for :meth:`elements`; REBOUND's ``primary=sim.particles["Sun"]``
            is ``primary="Sun"`` and ``primary=sim.com()`` is
            ``primary="barycentre"``.

        Returns
        -------
        Orbit

        Raises
        ------
        UnknownBodyError, BodyError, ElementsError
            As :meth:`orbits.BodySet.elements` raises them.

        Examples
        --------
        >>> o = orbits.scenes.outer_solar_system()["Saturn"].orbit(primary="Sun")
        >>> round(float(o.a.value), 1), o.P.to("yr").round(1)
        (9.5, <Quantity 29.5 yr>)
        """
        mu, r, v = self._set._relative(self._name, primary)
        return Orbit.from_state(mu, r, v, self._set.units, primary=primary, body=self._name)


class Track:
    """One body through a run's outputs: ``result["Jupiter"]``.

    Attributes
    ----------
    name : str
    index : int
        The body's column in the result.
    times : Quantity, shape (n,)
        The result's output times.
    positions, velocities : Quantity, shape (n, 3)
        The body's states at the outputs, in the result's frame (views of the
        result's arrays); NaN from the output at which a collision merged the
        body away.
    masses : Quantity, shape (n,)
        Its mass at every output (NaN once merged away).
    radius : Quantity, length, or None
        Its radius at the start, where the result records radii.

    Examples
    --------
    >>> sim = orbits.Simulation(orbits.scenes.outer_solar_system(), "leapfrog",
    ...                         dt=10 * u.day)
    >>> result = sim.run(until=100 * u.yr, outputs=11, progress=False)
    >>> jupiter = result["Jupiter"]
    >>> jupiter
    <Track 'Jupiter': 11 outputs>
    >>> jupiter.positions.shape, jupiter.elements(primary="Sun")["a"].shape
    ((11, 3), (11,))
    """

    __slots__ = ("_result", "name", "index")

    def __init__(self, result, index):
        self._result = result
        self.index = index
        self.name = result.names[index]

    def __repr__(self):
        return f"<Track {self.name!r}: {len(self._result.times)} outputs>"

    def __len__(self):
        return len(self._result.times)

    @property
    def times(self):
        return self._result.times

    @property
    def positions(self):
        return self._result.positions[:, self.index]

    @property
    def velocities(self):
        return self._result.velocities[:, self.index]

    @property
    def masses(self):
        r = self._result
        if r.masses_at_outputs is not None:
            return r.masses_at_outputs[:, self.index]
        return np.broadcast_to(r.masses[self.index].value, (len(r.times),)) << r.masses.unit

    @property
    def radius(self):
        radii = self._result.radii
        return None if radii is None else radii[self.index]

    def elements(self, primary=None):
        """:meth:`orbits.Result.elements` of this body: a dict of Quantities, shape (n,)."""
        return self._result.elements(self.name, primary=primary)

    def mutual_inclination(self, other, primary=None):
        """:meth:`orbits.Result.mutual_inclination` of this body and ``other``."""
        return self._result.mutual_inclination(self.name, other, primary=primary)
