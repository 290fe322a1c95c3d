"""Force terms: physics beyond Newtonian point-mass gravity.

A simulation integrates Newtonian gravity plus the terms it is given::

    sim = orbits.Simulation(bodies, "ias15", forces=[orbits.forces.GR("Sun")])

Every term is compiled into the same loop as gravity and reaches every
integrator that can honour it, the energy monitor, output files, restarts
and ensembles.  A term declares what the rest of the package needs to know,
so that nothing downstream asks for its name:

* ``velocity_dependent``: its accelerations read velocities (``ias15``
  predicts them at its substeps; the leapfrog and its compositions solve
  the kick implicitly);
* its energy: the potential, or the first post-Newtonian correction to the
  conserved energy, which the energy monitor adds, so that
  ``result.energy_error`` measures the integration and not the physics;
  ``conservative`` is False for a term without one, whose work ``W`` the
  loops integrate instead (:attr:`orbits.Simulation.work`), the energy error
  being that of ``E + W``;
* its Jacobian ``da/dx``, ``da/dv``, for the implicit methods (analytic for
  :class:`GR`, :class:`GRPotential`, :class:`ZonalHarmonics`, :class:`Migration`,
  :class:`TidesConstantTimeLag` and :class:`RadiationPressure`; central
  differences of the term alone for :class:`GRFull` and :class:`UserForce`);
* ``wisdom_holman``: whether the Wisdom-Holman map can take it in its
  interaction step and stay symplectic (conservative, positions only).

The dissipative terms (:class:`Migration`, :class:`TidesConstantTimeLag`,
:class:`RadiationPressure`) add nothing to the conserved energy: their energy
kernel is zero and ``conservative`` is False.

Which integrators take which term:

=============================  ==========================================  ==================
term                           Wisdom-Holman family (``wh``, ``saba*``)    every other method
=============================  ==========================================  ==================
:class:`GRPotential`           yes, symplectic                             yes
:class:`ZonalHarmonics`        yes, symplectic                             yes
:class:`UserForce`             with ``potential``, not velocity-dependent  yes
:class:`GR`                    no (velocities)                             yes
:class:`GRFull`                no (velocities)                             yes
:class:`Migration`             no (dissipative, velocities)                yes
:class:`TidesConstantTimeLag`  no (dissipative, velocities)                yes
:class:`RadiationPressure`     no (dissipative, velocities)                yes
=============================  ==========================================  ==================

With a velocity-dependent term the leapfrog, Verlet and the compositions
kick with ``v' = v + h a(x, (v + v') / 2)``, solved by fixed-point
iteration to round-off: the kick is then symmetric and the methods keep
their order (2 for the leapfrog; measured in the tests), but they are no
longer symplectic, and energy errors grow slowly.

Parameters given as Quantities are converted once, through the body set's
:class:`~orbits.units.UnitSystem`; the speed of light defaults to astropy's
``c`` in those units.

References
----------
Anderson et al. 1975, ApJ 200, 221 (:class:`GR`); Nobili & Roxburgh 1986,
IAU Symp. 114, 105 (:class:`GRPotential`); Newhall, Standish & Williams 1983,
A&A 125, 150 (:class:`GRFull`); Murray & Dermott 1999, *Solar System
Dynamics*, sect. 4.9 (:class:`ZonalHarmonics`); Papaloizou & Larwood 2000, MNRAS
315, 823 (:class:`Migration`); Hut 1981, A&A 99, 126 (:class:`TidesConstantTimeLag`);
Burns, Lamy & Soter 1979, Icarus 40, 1 (:class:`RadiationPressure`).
"""

import inspect
import math
from collections.abc import Mapping
from typing import NamedTuple

import astropy.constants as const
import astropy.units as u
import numpy as np

from ._kernels import terms as _k
from .errors import BodyUnitsError, ForceTermError, UnknownBodyError

__all__ = ["ForceTerm", "Gravity", "GR", "GRPotential", "GRFull", "ZonalHarmonics",
           "Migration", "TidesConstantTimeLag", "RadiationPressure", "UserForce",
           "from_dict", "functions_needed", "functions_of", "BoundTerm"]


class BoundTerm(NamedTuple):
    """A term bound to one simulation's bodies: its row of the simulation's
    table of terms (:class:`orbits._kernels.terms.TermTable`), and for a
    :class:`UserForce` the term itself, whose functions the table calls
    through a compiled pointer.

    Examples
    --------
    >>> import numpy as np
    >>> import orbits
    >>> from orbits.forces import Context
    >>> b = orbits.scenes.kepler()
    >>> m = b.masses.value
    >>> ctx = Context(b.names, m, b.units.G * m, 2, b.units, False, np.arange(2),
    ...               b.positions.value, b.velocities.value)
    >>> bound = orbits.forces.GRPotential("Star").bind(ctx)
    >>> type(bound).__name__, bound.args[0]    # the source's internal index
    ('BoundTerm', 0)
    """

    row: _k.TermRow
    user: "UserForce" = None

    @property
    def args(self):
        """The row's integers, then its reals, then its per-body values, if any."""
        r = self.row
        return tuple(r.ints) + tuple(r.reals) + (() if r.per_body is None else (r.per_body,))


class Context(NamedTuple):
    """What a term sees of the simulation when it is bound."""

    names: list         # body names, in the internal order (massive bodies first)
    m: np.ndarray       # masses, internal order
    gm: np.ndarray      # G times the masses
    n_active: int
    units: object       # the UnitSystem
    bare_ok: bool       # plain numbers are read in the body set's units
    order: np.ndarray   # internal row i is the body set's row order[i]
    x_user: np.ndarray  # the initial state in the body set's order
    v_user: np.ndarray

    def index(self, name, term, field):
        """The internal index of body ``name``, or a named error."""
        try:
            return self.names.index(name)
        except ValueError:
            shown = ", ".join(map(repr, self.names[:10])) + (
                f", ... ({len(self.names)} bodies)" if len(self.names) > 10 else "")
            raise UnknownBodyError(
                f"{term} names body {name!r} as its {field}, but the body set has no "
                f"such body (bodies: {shown})", body=name, field=field) from None


_REGISTRY = {}


class ForceTerm:
    """Base class of the force terms; see the module notes.

    A subclass sets the class facts below and implements ``bind(ctx)``,
    returning a :class:`BoundTerm`, and ``to_dict()``; it is registered by
    name for :func:`from_dict` (output files and ensembles rebuild terms
    from their dictionaries).

    Examples
    --------
    >>> import orbits
    >>> from orbits.forces import ForceTerm
    >>> [cls.__name__ for cls in (orbits.forces.GR, orbits.forces.ZonalHarmonics)
    ...  if issubclass(cls, ForceTerm)]
    ['GR', 'ZonalHarmonics']
    >>> orbits.forces.GR.velocity_dependent, orbits.forces.GRPotential.wisdom_holman
    (True, True)
    """

    velocity_dependent = False
    conservative = True
    wisdom_holman = False
    #: why the Wisdom-Holman interaction step cannot take it (for the error)
    why_not_wisdom_holman = ""
    #: whether the term holds functions of the user's, which its dictionary
    #: names but cannot hold: :func:`from_dict` takes them from the caller
    takes_functions = False

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        _REGISTRY[cls.__name__] = cls

    def bind(self, ctx):
        """Compile the term for one simulation's bodies.

        Parameters
        ----------
        ctx : Context
            The bodies as the simulation holds them (names, masses and ``G m`` in
            the internal order and units).

        Returns
        -------
        BoundTerm
            The kernel and its arguments, in the simulation's units.

        Examples
        --------
        >>> import numpy as np
        >>> import orbits
        >>> from orbits.forces import Context
        >>> b = orbits.scenes.kepler()
        >>> m = b.masses.value
        >>> ctx = Context(b.names, m, b.units.G * m, 2, b.units, False, np.arange(2),
        ...               b.positions.value, b.velocities.value)
        >>> bound = orbits.forces.GR("Star").bind(ctx)
        >>> bound.args[0], round(1 / bound.args[1] ** 0.5, 1)   # source index; c in au/day
        (0, 173.1)
        """
        raise NotImplementedError

    def to_dict(self):
        """Plain JSON-able values, Quantities as ``[value, unit]``: what output
        files and ensembles store.

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> orbits.forces.GRPotential("Sun", c=3e5 * u.km / u.s).to_dict()
        {'type': 'GRPotential', 'source': 'Sun', 'c': [300000.0, 'km / s']}
        """
        raise NotImplementedError

    @classmethod
    def functions_needed(cls, d):
        """The functions the dictionary ``d`` of this term names and
        :func:`from_dict` takes from its caller: recorded name -> what it is
        (none for a term that holds only numbers).

        Examples
        --------
        >>> import orbits
        >>> orbits.forces.GR.functions_needed({"type": "GR", "source": "Sun", "c": None})
        {}
        """
        return {}

    def functions(self):
        """The user's functions this term holds, by the names its dictionary
        records (none for a term that holds only numbers).

        Examples
        --------
        >>> import orbits
        >>> orbits.forces.GR("Sun").functions()
        {}
        """
        return {}

    def __eq__(self, other):
        return type(self) is type(other) and self.to_dict() == other.to_dict()

    def __hash__(self):
        return hash(repr(self))

    def __repr__(self):
        d = self.to_dict()
        d.pop("type")
        args = ", ".join(f"{k}={v!r}" for k, v in d.items() if v is not None)
        return f"{type(self).__name__}({args})"


def from_dict(d, functions=None):
    """The term a :meth:`ForceTerm.to_dict` dictionary describes.

    Nothing a dictionary names is imported: the functions of a
    :class:`UserForce` come from ``functions``.

    Parameters
    ----------
    d : dict
        As :meth:`ForceTerm.to_dict` gives it.
    functions : mapping, optional
        The functions the dictionary names (see :meth:`UserForce.from_dict`):
        recorded name (``"module:qualname"``, or the bare ``qualname``) ->
        the function.

    Raises
    ------
    ForceTermError
        The dictionary's ``type`` names no known term, or it names a function
        that ``functions`` does not give.

    Examples
    --------
    >>> import orbits
    >>> term = orbits.forces.from_dict({"type": "GR", "source": "Sun", "c": None})
    >>> term
    GR(source='Sun')
    >>> orbits.forces.from_dict(term.to_dict()) == term
    True
    """
    cls = _record_class(d)
    d = dict(d)
    d.pop("type")
    if cls.takes_functions:
        return cls.from_dict(d, functions=functions)
    return cls.from_dict(d)


def _record_class(d):
    # the registered class a term's dictionary names, or a named error
    if not isinstance(d, Mapping):
        raise ForceTermError(f"a force term's record must be a dictionary, got {d!r}")
    name = d.get("type")
    if not isinstance(name, str) or name not in _REGISTRY:
        raise ForceTermError(f"unknown force term type {name!r}; known: "
                             f"{', '.join(sorted(_REGISTRY))}")
    return _REGISTRY[name]


def functions_needed(records):
    """The functions that force terms' dictionaries name but cannot hold.

    Parameters
    ----------
    records : sequence of dict
        :meth:`ForceTerm.to_dict` dictionaries.

    Returns
    -------
    dict
        Recorded name (``"module:qualname"``) -> what it is, in words, for
        every function :func:`from_dict` needs from its caller.

    Raises
    ------
    ForceTermError
        A record names no known term, or names a function in a form that is
        not ``"module:qualname"``.

    Examples
    --------
    >>> import orbits
    >>> orbits.forces.functions_needed([{"type": "UserForce", "func": "models:drag",
    ...                                  "velocity_dependent": True, "potential": None}])
    {'models:drag': 'UserForce func(x, v, t, m), velocity-dependent'}
    """
    needed = {}
    for d in records:
        needed.update(_record_class(d).functions_needed(d))
    return needed


def functions_of(terms):
    """The functions of the user's that ``terms`` hold, by the names their
    dictionaries record: what :func:`from_dict` takes to rebuild them (an
    ensemble ships these with a simulation's configuration).

    Examples
    --------
    >>> import numba, orbits
    >>> @numba.njit
    ... def drag(x, v, t, m):
    ...     return -1e-6 * v
    >>> term = orbits.forces.UserForce(drag, velocity_dependent=True)
    >>> [name.split(":")[1] for name in orbits.forces.functions_of([term])]
    ['drag']
    """
    out = {}
    for term in terms:
        out.update(term.functions())
    return out


def _quantity_dict(value):
    # a Quantity as [value, unit] for JSON; None and plain numbers as they are
    if value is None:
        return None
    if isinstance(value, u.Quantity):
        return [np.asarray(value.value).tolist(), value.unit.to_string()]
    return float(value)


def _quantity_from(value):
    if isinstance(value, list) and len(value) == 2 and isinstance(value[1], str):
        return u.Quantity(value[0], value[1])
    return value


class Gravity(ForceTerm):
    """Newtonian point-mass gravity, every simulation's first term.

    Give it in ``forces`` only to set its options; the keywords of
    :class:`~orbits.Simulation` of the same names do the same.

    Parameters
    ----------
    softening : Quantity (length), optional
        Plummer softening length.
    parallel : bool, optional
        Force the threaded (True) or serial (False) kernel.
    rebound_arithmetic : bool
        REBOUND's floating-point operations (see :class:`~orbits.Simulation`).

    Examples
    --------
    >>> import astropy.units as u
    >>> import orbits
    >>> sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day,
    ...                         forces=[orbits.forces.Gravity(softening=1e-4 * u.au)])
    >>> sim.softening, sim.forces
    (<Quantity 0.0001 AU>, ())
    """

    def __init__(self, softening=None, parallel=None, rebound_arithmetic=False):
        self.softening = softening
        self.parallel = parallel
        self.rebound_arithmetic = bool(rebound_arithmetic)

    def to_dict(self):
        """Plain JSON-able values, Quantities as ``[value, unit]``: what output
        files and ensembles store.

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> d = orbits.forces.Gravity(softening=0.01 * u.au).to_dict()
        >>> d["type"], d["softening"], d["parallel"], d["rebound_arithmetic"]
        ('Gravity', [0.01, 'AU'], None, False)
        """
        return {"type": "Gravity", "softening": _quantity_dict(self.softening),
                "parallel": self.parallel, "rebound_arithmetic": self.rebound_arithmetic}

    @classmethod
    def from_dict(cls, d):
        """The term that :meth:`to_dict` describes.

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> term = orbits.forces.Gravity(softening=0.01 * u.au)
        >>> orbits.forces.Gravity.from_dict(term.to_dict()).softening
        <Quantity 0.01 AU>
        """
        return cls(softening=_quantity_from(d.get("softening")), parallel=d.get("parallel"),
                   rebound_arithmetic=d.get("rebound_arithmetic", False))


class _SourceTerm(ForceTerm):
    """A GR term about one dominant body, the ``source``."""

    def __init__(self, source, *, c=None):
        if not isinstance(source, str):
            raise ForceTermError(f"source must be a body's name, got {source!r}",
                                 term=type(self).__name__, field="source")
        self.source = source
        self.c = c

    def to_dict(self):
        return {"type": type(self).__name__, "source": self.source,
                "c": _quantity_dict(self.c)}

    @classmethod
    def from_dict(cls, d):
        return cls(d["source"], c=_quantity_from(d.get("c")))

    def _source(self, ctx):
        i = ctx.index(self.source, repr(self), "source")
        if not ctx.m[i] > 0:
            raise ForceTermError(f"the source {self.source!r} has no mass", term=repr(self),
                                 field="source")
        return i

    def _inv_c2(self, ctx):
        return _inv_c2(self, self.c, ctx)


def _speed_of_light(term, c, ctx):
    value = const.c if c is None else c
    cv = float(ctx.units.to_internal(value, "velocity", bare_ok=ctx.bare_ok, field="c"))
    if not (cv > 0 and math.isfinite(cv)):
        raise ForceTermError(f"the speed of light must be a positive finite speed, got {c}",
                             term=repr(term), field="c")
    return cv


def _inv_c2(term, c, ctx):
    cv = _speed_of_light(term, c, ctx)
    return 1.0 / (cv * cv)


class GR(_SourceTerm):
    """General relativity from one dominant body: the 1PN correction of
    Anderson et al. (1975), the model of REBOUNDx's ``gr`` for planets.

    REBOUNDx's ``gr`` works in Jacobi coordinates and puts each body's whole
    acceleration into its correction, so a moon's term there also carries its
    planet's pull; here each body's orbit about the source is corrected as a
    two-body orbit.  The two agree to 2e-9 au on the planets over 10 years and
    differ by 1.6e-7 au on the Moon (the validation report's section *Against
    JPL DE421*).

    Every other body ``i``, test particles included, feels ::

        a_i = mu / (c^2 r^3) [ (4 mu_i / r - v^2) r + 4 (r . v) v ]

    with ``r``, ``v`` relative to the source, ``mu = G m_source`` and
    ``mu_i = G (m_source + m_i)``; the source takes the reaction
    ``-(m_i / m_source) a_i``, so momentum is conserved.  The relative motion
    of body and source then feels Schwarzschild's test-body correction about
    ``mu_i``: the periapsis advances by ``6 pi G (m_source + m_i) / (c^2 a
    (1 - e^2))`` a period at any mass ratio.  Cost O(N).  Velocity-dependent:
    not for the Wisdom-Holman family (use :class:`GRPotential` there).

    Its energy is that correction's 1PN energy times the reduced mass
    ``m_r = m_i m_source / (m_source + m_i)`` of each body,
    ``m_r (3/8 v^4 + 3/2 mu_i v^2 / r + 1/2 mu_i^2 / r^2) / c^2``, from the
    Lagrangian whose equations the accelerations are: with a source and one
    massive body the energy monitor measures the integration (the energy is
    conserved to O(1/c^4)).  With several massive bodies their pulls on one
    another's orbits about the source, left out of the correction, leave an
    energy change of their mass ratio to the source times the 1PN energy's
    variation (1.4e-10 of the energy for two planets of a thousandth of the
    star's mass at a = 1 and 1.6, with G = 1 and c = 1e4); :class:`GRFull`
    conserves its energy there.

    Parameters
    ----------
    source : str
        Name of the dominant body (the Sun).
    c : Quantity (speed), optional
        Speed of light; default astropy's ``c``.

    Examples
    --------
    >>> import astropy.units as u, orbits
    >>> sim = orbits.Simulation(orbits.scenes.solar_system(), "ias15",
    ...                         forces=[orbits.forces.GR("Sun")])
    >>> sim.forces
    (GR(source='Sun'),)
    """

    velocity_dependent = True
    why_not_wisdom_holman = "it depends on velocities"

    def bind(self, ctx):
        """Compile the term for one simulation's bodies.

        Parameters
        ----------
        ctx : Context
            The bodies as the simulation holds them (names, masses and ``G m`` in
            the internal order and units).

        Returns
        -------
        BoundTerm
            The kernel and its arguments, in the simulation's units.

        Examples
        --------
        >>> import numpy as np
        >>> import orbits
        >>> from orbits.forces import Context
        >>> b = orbits.scenes.kepler()
        >>> m = b.masses.value
        >>> ctx = Context(b.names, m, b.units.G * m, 2, b.units, False, np.arange(2),
        ...               b.positions.value, b.velocities.value)
        >>> orbits.forces.GR("Star").bind(ctx).args[0]
        0
        """
        src = self._source(ctx)
        ic2 = self._inv_c2(ctx)
        return BoundTerm(_k.TermRow(_k.GR, (src,), (ic2,)))


class GRPotential(_SourceTerm):
    """General relativity as a potential (Nobili & Roxburgh 1986), as
    REBOUNDx's ``gr_potential``::

        Phi = -3 (G m_source)^2 / (c^2 r^2)      per unit mass

    about the source, which takes the reaction.  It gives the right perihelion
    precession, is conservative, depends on positions only and joins the
    interaction step of ``wh``, which stays symplectic.

    Parameters
    ----------
    source : str
        Name of the dominant body.
    c : Quantity (speed), optional
        Speed of light; default astropy's ``c``.

    Examples
    --------
    >>> import astropy.units as u
    >>> import orbits
    >>> sim = orbits.Simulation(orbits.scenes.kepler(), "wh", dt=5 * u.day,
    ...                         forces=[orbits.forces.GRPotential("Star")])
    >>> sim.forces
    (GRPotential(source='Star'),)
    """

    wisdom_holman = True

    def bind(self, ctx):
        """Compile the term for one simulation's bodies.

        Parameters
        ----------
        ctx : Context
            The bodies as the simulation holds them (names, masses and ``G m`` in
            the internal order and units).

        Returns
        -------
        BoundTerm
            The kernel and its arguments, in the simulation's units.

        Examples
        --------
        >>> import numpy as np
        >>> import orbits
        >>> from orbits.forces import Context
        >>> b = orbits.scenes.kepler()
        >>> m = b.masses.value
        >>> ctx = Context(b.names, m, b.units.G * m, 2, b.units, False, np.arange(2),
        ...               b.positions.value, b.velocities.value)
        >>> orbits.forces.GRPotential("Star").bind(ctx).args[0]
        0
        """
        src = self._source(ctx)
        ic2 = self._inv_c2(ctx)
        return BoundTerm(_k.TermRow(_k.GR_POTENTIAL, (src,), (ic2,)))


class GRFull(ForceTerm):
    """The Einstein-Infeld-Hoffmann 1PN equations among all massive bodies, as
    integrated for the JPL ephemerides (Newhall, Standish & Williams 1983).

    Test particles feel the massive bodies and pull on none.  The 1PN terms
    use the Newtonian accelerations.  Cost O(N_active N).  Its energy is the
    1PN correction of the EIH Lagrangian's energy.  Velocity-dependent: not
    for the Wisdom-Holman family.

    Parameters
    ----------
    c : Quantity (speed), optional
        Speed of light; default astropy's ``c``.

    Examples
    --------
    >>> import orbits
    >>> sim = orbits.Simulation(orbits.scenes.kepler(), "ias15",
    ...                         forces=[orbits.forces.GRFull()])
    >>> sim.forces, orbits.forces.GRFull.velocity_dependent
    ((GRFull(),), True)
    """

    velocity_dependent = True
    why_not_wisdom_holman = "it depends on velocities"

    def __init__(self, *, c=None):
        self.c = c

    def to_dict(self):
        """Plain JSON-able values, Quantities as ``[value, unit]``: what output
        files and ensembles store.

        Examples
        --------
        >>> import orbits
        >>> orbits.forces.GRFull().to_dict()
        {'type': 'GRFull', 'c': None}
        """
        return {"type": "GRFull", "c": _quantity_dict(self.c)}

    @classmethod
    def from_dict(cls, d):
        """The term that :meth:`to_dict` describes.

        Examples
        --------
        >>> import orbits
        >>> term = orbits.forces.GRFull()
        >>> orbits.forces.GRFull.from_dict(term.to_dict()) == term
        True
        """
        return cls(c=_quantity_from(d.get("c")))

    def bind(self, ctx):
        """Compile the term for one simulation's bodies.

        Parameters
        ----------
        ctx : Context
            The bodies as the simulation holds them (names, masses and ``G m`` in
            the internal order and units).

        Returns
        -------
        BoundTerm
            The kernel and its arguments, in the simulation's units.

        Examples
        --------
        >>> import numpy as np
        >>> import orbits
        >>> from orbits.forces import Context
        >>> b = orbits.scenes.kepler()
        >>> m = b.masses.value
        >>> ctx = Context(b.names, m, b.units.G * m, 2, b.units, False, np.arange(2),
        ...               b.positions.value, b.velocities.value)
        >>> bound = orbits.forces.GRFull().bind(ctx)
        >>> bound.args[0]    # massive bodies
        2
        """
        ic2 = _inv_c2(self, self.c, ctx)
        return BoundTerm(_k.TermRow(_k.GR_FULL, (ctx.n_active,), (ic2,)))


class ZonalHarmonics(ForceTerm):
    """The oblateness of one body (J2, J4) acting on every other body.

    The potential beyond the point mass, per unit mass at ``r`` from the body
    with ``u = (r . pole) / r``::

        Phi = (G m / r) [ J2 (R / r)^2 P2(u) + J4 (R / r)^4 P4(u) ]

    The oblate body takes the reaction, so momentum is conserved (its spin
    axis is held fixed: the torque on it is not followed, so only the
    component of angular momentum along ``pole`` is conserved).
    Conservative and positions only: ``wh`` takes it.

    Parameters
    ----------
    body : str
        Name of the oblate body.
    radius : Quantity (length)
        Its equatorial (reference) radius ``R``; positive.
    J2, J4 : float
        Zonal coefficients (dimensionless).
    pole : sequence of 3 floats
        Direction of its spin axis in the simulation's frame (normalised
        here); default the frame's z axis.

    Examples
    --------
    >>> import astropy.units as u, orbits
    >>> J2 = orbits.forces.ZonalHarmonics("Earth", 6378.137 * u.km, J2=1.08263e-3)
    >>> J2.wisdom_holman
    True
    """

    wisdom_holman = True

    def __init__(self, body, radius, J2=0.0, J4=0.0, pole=(0.0, 0.0, 1.0)):
        name = f"ZonalHarmonics({body!r})"
        if not isinstance(body, str):
            raise ForceTermError(f"body must be a body's name, got {body!r}", term=name,
                                 field="body")
        self.body = body
        self.radius = radius
        for field, value in (("J2", J2), ("J4", J4)):
            try:
                ok = math.isfinite(float(value))
            except (TypeError, ValueError):
                ok = False
            if not ok:
                raise ForceTermError(f"{field} must be a finite number, got {value!r}",
                                     term=name, field=field)
        self.J2 = float(J2)
        self.J4 = float(J4)
        p = np.asarray(pole, dtype=float)
        norm = float(np.linalg.norm(p)) if p.shape == (3,) else 0.0
        if not (norm > 0 and math.isfinite(norm)):
            raise ForceTermError(f"pole must be a non-zero finite 3-vector, got {pole!r}",
                                 term=name, field="pole")
        self._pole_given = [float(c) for c in p]
        self.pole = tuple(float(c) for c in p / norm)
        if isinstance(radius, u.Quantity):
            self._check_radius(radius.value, name)

    @staticmethod
    def _check_radius(value, name):
        value = np.asarray(value, dtype=float)
        if value.shape != () or not (value > 0 and math.isfinite(value)):
            raise ForceTermError(f"radius must be a positive finite length, got {value}",
                                 term=name, field="radius")

    def to_dict(self):
        """Plain JSON-able values, Quantities as ``[value, unit]``: what output
        files and ensembles store.

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> d = orbits.forces.ZonalHarmonics("Earth", 6378 * u.km, J2=1.08e-3).to_dict()
        >>> d["type"], d["radius"], d["J2"], d["pole"]
        ('ZonalHarmonics', [6378.0, 'km'], 0.00108, [0.0, 0.0, 1.0])
        """
        return {"type": "ZonalHarmonics", "body": self.body,
                "radius": _quantity_dict(self.radius), "J2": self.J2, "J4": self.J4,
                "pole": self._pole_given}

    @classmethod
    def from_dict(cls, d):
        """The term that :meth:`to_dict` describes.

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> term = orbits.forces.ZonalHarmonics("Earth", 6378 * u.km, J2=1.08e-3)
        >>> orbits.forces.ZonalHarmonics.from_dict(term.to_dict()) == term
        True
        """
        return cls(d["body"], _quantity_from(d["radius"]), J2=d["J2"], J4=d["J4"],
                   pole=d["pole"])

    def bind(self, ctx):
        """Compile the term for one simulation's bodies.

        Parameters
        ----------
        ctx : Context
            The bodies as the simulation holds them (names, masses and ``G m`` in
            the internal order and units).

        Returns
        -------
        BoundTerm
            The kernel and its arguments, in the simulation's units.

        Examples
        --------
        >>> import numpy as np
        >>> import astropy.units as u
        >>> import orbits
        >>> from orbits.forces import Context
        >>> b = orbits.scenes.kepler()
        >>> m = b.masses.value
        >>> ctx = Context(b.names, m, b.units.G * m, 2, b.units, False, np.arange(2),
        ...               b.positions.value, b.velocities.value)
        >>> bound = orbits.forces.ZonalHarmonics("Star", 0.005 * u.au, J2=1e-6).bind(ctx)
        >>> bound.args[0], f"{bound.args[1] / b.units.G:.2e}"   # index; m J2 R^2 [Msun au^2]
        (0, '2.50e-11')
        """
        b = ctx.index(self.body, repr(self), "body")
        if not ctx.m[b] > 0:
            raise ForceTermError(f"the oblate body {self.body!r} has no mass",
                                 term=repr(self), field="body")
        R = float(ctx.units.to_internal(self.radius, "length", bare_ok=ctx.bare_ok,
                                        field="radius"))
        self._check_radius(R, repr(self))
        gmb = float(ctx.gm[b])
        return BoundTerm(_k.TermRow(_k.ZONAL, (b,), (gmb * self.J2 * R ** 2,
                                                     gmb * self.J4 * R ** 4)
                                    + tuple(float(c) for c in self.pole)))


# -- dissipative terms --------------------------------------------------------------------

def _number(value, term, field, body=None):
    # a plain finite float, or a named error
    try:
        out = float(value)
    except (TypeError, ValueError):
        out = math.nan
    if not math.isfinite(out):
        raise ForceTermError(f"expected a finite number, got {value!r}", term=term,
                             field=field, body=body)
    return out


def _given(value, kind, ctx, field):
    # a Quantity (or, where allowed, a plain number) as a float in the internal units
    return float(ctx.units.to_internal(value, kind, bare_ok=ctx.bare_ok, field=field))


def _angular_velocity(value, ctx, term):
    # an angular velocity 3-vector in rad per internal time unit; astropy's
    # dimensionless_angles lets it be given as rad / s or as 1 / s alike
    per_time = u.rad / ctx.units.unit("time")
    if value is None:
        return np.zeros(3)
    if isinstance(value, u.Quantity):
        try:
            out = np.asarray(value.to_value(per_time, equivalencies=u.dimensionless_angles()),
                             dtype=np.float64)
        except u.UnitConversionError:
            raise BodyUnitsError(f"expected an angular velocity (e.g. in {per_time}), got "
                                 f"{value.unit.physical_type} ({value.unit})",
                                 field="spin") from None
    else:
        try:  # plain numbers where the body set's own units are implied, as for lengths
            out = ctx.units.to_internal(value, "velocity", bare_ok=ctx.bare_ok, field="spin")
        except BodyUnitsError:
            raise BodyUnitsError(f"expected a Quantity with a unit of angular velocity (e.g. "
                                 f"{per_time}), got the bare value {value!r}",
                                 field="spin") from None
    _check_spin(out, term)
    return np.ascontiguousarray(out, dtype=np.float64)


def _vector_dict(value):
    # a 3-vector as [[x, y, z], unit] for JSON, plain numbers as a list
    if value is None or isinstance(value, u.Quantity):
        return _quantity_dict(value)
    return [float(c) for c in np.asarray(value, dtype=float).ravel()]


def _check_spin(value, term):
    value = np.asarray(value, dtype=float)
    if value.shape != (3,) or not np.all(np.isfinite(value)):
        raise ForceTermError(f"spin must be a finite angular-velocity 3-vector, got {value}",
                             term=term, field="spin")


def _massive_index(ctx, name, term, field, role):
    i = ctx.index(name, term, field)
    if not ctx.m[i] > 0:
        raise ForceTermError(f"the {role} {name!r} has no mass", term=term, field=field,
                             body=name)
    return i


class Migration(ForceTerm):
    """Orbital migration and eccentricity and inclination damping of one body on
    prescribed time scales (Papaloizou & Larwood 2000), the forces of REBOUNDx's
    ``modify_orbits_forces``.

    The body's acceleration relative to its ``primary`` is ::

        a = -u / (2 tau_a) - 2 (r . u) r / (r^2 tau_e) - 2 u_z z_hat / tau_inc

    with ``r``, ``u`` the body's position and velocity relative to the primary
    and ``z_hat`` the frame's z axis (the reference plane is the xy plane).
    Orbit-averaged, ``a`` decays as ``exp(-t / tau_a)``, and a low ``e`` as
    ``exp(-t / tau_e)`` (at constant angular momentum, so that damping ``e``
    also moves ``a`` a little), a low inclination as ``exp(-t / tau_inc)``.
    The pair shares the acceleration in inverse proportion to the masses, the
    body taking ``m_p / (m_p + m_b)`` of it and the primary the rest with the
    opposite sign, so the relative acceleration is ``a`` and momentum is
    conserved.  For the innermost body about the central one this is REBOUNDx's
    default (Jacobi) choice exactly.  Give one term per body.

    A positive time scale damps (inward migration), a negative one grows
    (outward migration): REBOUNDx's ``tau_a`` is minus this one.
    Dissipative and velocity-dependent: not for the Wisdom-Holman family.  Its
    energy kernel is zero.

    Parameters
    ----------
    body : str
        Name of the migrating body.
    tau_a, tau_e, tau_inc : Quantity (time) or None
        E-folding times of the semi-major axis, the eccentricity and the
        inclination; non-zero and finite; None leaves that part out (give at
        least one).
    primary : str, optional
        Name of the body the orbit is relative to; default the most massive
        other body.

    Raises
    ------
    ForceTermError
        A time scale that is zero or not finite, or none given; when bound, a
        primary without mass or the body as its own primary.
    UnknownBodyError
        When bound, ``body`` or ``primary`` is not in the body set.

    References
    ----------
    Papaloizou, J. C. B. & Larwood, J. D. 2000, MNRAS 315, 823.  Kostov, V. B. et
    al. 2016, ApJ 832, 183 (the form REBOUNDx implements).

    Examples
    --------
    >>> import astropy.units as u, orbits
    >>> term = orbits.forces.Migration("Planet", tau_a=1e4 * u.yr, tau_e=1e3 * u.yr)
    >>> sim = orbits.Simulation(orbits.scenes.kepler(), "ias15", forces=[term])
    >>> term.velocity_dependent, term.conservative, term.wisdom_holman
    (True, False, False)
    """

    velocity_dependent = True
    conservative = False
    why_not_wisdom_holman = "it is dissipative and depends on velocities"

    def __init__(self, body, tau_a=None, tau_e=None, tau_inc=None, primary=None):
        name = f"Migration({body!r})"
        if not isinstance(body, str):
            raise ForceTermError(f"body must be a body's name, got {body!r}", term=name,
                                 field="body")
        if primary is not None and not isinstance(primary, str):
            raise ForceTermError(f"primary must be a body's name or None, got {primary!r}",
                                 term=name, field="primary", body=body)
        self.body = body
        self.primary = primary
        self.tau_a = tau_a
        self.tau_e = tau_e
        self.tau_inc = tau_inc
        if tau_a is None and tau_e is None and tau_inc is None:
            raise ForceTermError("give at least one of tau_a, tau_e, tau_inc (a time "
                                 "scale, Quantity)", term=name, field="tau_a", body=body)
        for field, value in self._scales():
            if isinstance(value, u.Quantity):
                self._check_scale(np.asarray(value.value, dtype=float), name, field)

    def _scales(self):
        return (("tau_a", self.tau_a), ("tau_e", self.tau_e), ("tau_inc", self.tau_inc))

    def _check_scale(self, value, term, field):
        if value.shape != () or not (math.isfinite(value) and value != 0):
            raise ForceTermError(
                f"expected a non-zero finite time scale (positive damps, negative grows) "
                f"or None, got {value}", term=term, field=field, body=self.body)

    def to_dict(self):
        """Plain JSON-able values, Quantities as ``[value, unit]``: what output
        files and ensembles store.

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> orbits.forces.Migration("Planet", tau_a=1e4 * u.yr).to_dict()["tau_a"]
        [10000.0, 'yr']
        """
        return {"type": "Migration", "body": self.body,
                "tau_a": _quantity_dict(self.tau_a), "tau_e": _quantity_dict(self.tau_e),
                "tau_inc": _quantity_dict(self.tau_inc), "primary": self.primary}

    @classmethod
    def from_dict(cls, d):
        """The term that :meth:`to_dict` describes.

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> term = orbits.forces.Migration("Planet", tau_e=-300 * u.yr, primary="Star")
        >>> orbits.forces.Migration.from_dict(term.to_dict()) == term
        True
        """
        return cls(d["body"], tau_a=_quantity_from(d.get("tau_a")),
                   tau_e=_quantity_from(d.get("tau_e")),
                   tau_inc=_quantity_from(d.get("tau_inc")), primary=d.get("primary"))

    def bind(self, ctx):
        """Compile the term for one simulation's bodies.

        Parameters
        ----------
        ctx : Context
            The bodies as the simulation holds them (names, masses and ``G m`` in
            the internal order and units).

        Returns
        -------
        BoundTerm
            The kernel and its arguments, in the simulation's units.

        Examples
        --------
        >>> import numpy as np
        >>> import astropy.units as u
        >>> import orbits
        >>> from orbits.forces import Context
        >>> b = orbits.scenes.kepler()
        >>> m = b.masses.value
        >>> ctx = Context(b.names, m, b.units.G * m, 2, b.units, False, np.arange(2),
        ...               b.positions.value, b.velocities.value)
        >>> bound = orbits.forces.Migration("Planet", tau_a=1 * u.yr).bind(ctx)
        >>> bound.args[:2], bound.args[4]     # body, primary; 1 / tau_a in 1 / day
        ((1, 0), 0.0027378507871321013)
        """
        term = repr(self)
        b = ctx.index(self.body, term, "body")
        if self.primary is None:
            others = [i for i in range(len(ctx.m)) if i != b]
            if not others or not ctx.m[others].max() > 0:
                raise ForceTermError("no other body has mass to be the primary", term=term,
                                     field="primary", body=self.body)
            p = others[int(np.argmax(ctx.m[others]))]
        else:
            p = _massive_index(ctx, self.primary, term, "primary", "primary")
        if p == b:
            raise ForceTermError("the body cannot be its own primary", term=term,
                                 field="primary", body=self.body)
        inv = []
        for field, value in self._scales():
            if value is None:
                inv.append(0.0)
                continue
            tau = np.asarray(_given(value, "time", ctx, field))
            self._check_scale(tau, term, field)
            inv.append(1.0 / float(tau))
        gb = float(ctx.gm[b])
        gp = float(ctx.gm[p])
        return BoundTerm(_k.TermRow(_k.MIGRATION, (b, p), (gp / (gp + gb), gb / (gp + gb),
                                                           inv[0], inv[1], inv[2])))


class TidesConstantTimeLag(ForceTerm):
    """The constant-time-lag tide raised on one body by every other massive
    body (Hut 1981; Eggleton, Kiseleva & Hut 1998), the force of REBOUNDx's
    ``tides_constant_time_lag`` (Baronett et al. 2022).

    The body (mass ``m``, radius ``R``, Love number ``k2``, time lag ``tau``,
    fixed spin ``Omega``) is distorted by each other massive body ``j``; the
    bulge, lagging by ``tau``, pulls on ``j`` with ::

        F_j = -3 k2 G m_j^2 R^5 / r^8 [ r + tau (2 (r . u) r / r^2 + u + r x Omega) ]

    where ``r``, ``u`` are ``j``'s position and velocity relative to the body; the
    body takes ``-F_j``, so momentum is conserved.  The first term is the
    conservative tidal distortion (potential ``-k2 G m_j^2 R^5 / (2 r^6)``), the
    rest the lag's dissipation; ``time_lag = 0`` leaves the conservative part
    alone, as REBOUNDx does.  This is Hut's (1981) force with his ``k``
    written ``k2``.  Orbit-averaged, a low eccentricity decays at Hut's
    rate (his eq. 10), with the spin along the orbit's normal ::

        de/dt = -27 k2 tau n^2 (m_j / m) (R / a)^5 e [1 - (11/18) Omega / n]

    The spin is held fixed (the torque on it is not followed): zero by default,
    as REBOUNDx's default; REBOUNDx's ``OmegaMag`` is a spin along the frame's
    z axis, ``spin=[0, 0, OmegaMag]`` here.  REBOUNDx lets only its primary
    raise a tide on a body other than the primary; here every massive body
    does (the same for two bodies, or for the tide on the central body).
    Dissipative and velocity-dependent: not for the Wisdom-Holman family.  Its
    energy kernel is zero (the conservative part's potential included).

    Parameters
    ----------
    body : str
        Name of the tidally distorted body; it must have mass.
    k2 : float
        Its potential Love number of degree 2, twice the apsidal motion constant;
        finite and not negative.
    time_lag : Quantity (time)
        The constant time lag ``tau``; finite and not negative.
    radius : Quantity (length)
        Its physical radius ``R``; positive and finite.
    spin : Quantity (angular velocity), shape (3,), optional
        Its fixed spin vector ``Omega`` (``rad / day`` or ``1 / day``); default zero.

    Raises
    ------
    ForceTermError
        A negative or non-finite ``k2``, ``time_lag`` or ``radius`` (or a zero
        radius), a spin that is not a finite 3-vector; when bound, a body
        without mass.
    UnknownBodyError
        When bound, ``body`` is not in the body set.

    References
    ----------
    Hut, P. 1981, A&A 99, 126.  Eggleton, P. P., Kiseleva, L. G. & Hut, P. 1998,
    ApJ 499, 853.  Baronett, S. A., Ferich, N., Tamayo, D. & Steffen, J. H. 2022,
    MNRAS 510, 6001 (arXiv:2101.12277).

    Examples
    --------
    >>> import astropy.units as u, orbits
    >>> tide = orbits.forces.TidesConstantTimeLag("Planet", k2=0.3, time_lag=600 * u.s,
    ...                                           radius=1 * u.Rjup)
    >>> sim = orbits.Simulation(orbits.scenes.kepler(), "ias15", forces=[tide])
    >>> tide.velocity_dependent, tide.wisdom_holman
    (True, False)
    """

    velocity_dependent = True
    conservative = False
    why_not_wisdom_holman = "it is dissipative and depends on velocities"

    def __init__(self, body, k2, time_lag, radius, spin=None):
        name = f"TidesConstantTimeLag({body!r})"
        if not isinstance(body, str):
            raise ForceTermError(f"body must be a body's name, got {body!r}", term=name,
                                 field="body")
        self.body = body
        self.k2 = _number(k2, name, "k2", body)
        if self.k2 < 0:
            raise ForceTermError(f"expected a Love number k2 >= 0, got {self.k2}", term=name,
                                 field="k2", body=body)
        self.time_lag = time_lag
        self.radius = radius
        self.spin = spin
        if isinstance(time_lag, u.Quantity):
            self._check_lag(time_lag.value, name)
        if isinstance(radius, u.Quantity):
            self._check_radius(radius.value, name)
        if isinstance(spin, u.Quantity):
            _check_spin(spin.value, name)

    def _check_lag(self, value, term):
        value = np.asarray(value, dtype=float)
        if value.shape != () or not (value >= 0 and math.isfinite(value)):
            raise ForceTermError(f"expected a finite time lag >= 0, got {value}", term=term,
                                 field="time_lag", body=self.body)

    def _check_radius(self, value, term):
        value = np.asarray(value, dtype=float)
        if value.shape != () or not (value > 0 and math.isfinite(value)):
            raise ForceTermError(f"expected a positive finite radius, got {value}", term=term,
                                 field="radius", body=self.body)

    def to_dict(self):
        """Plain JSON-able values, Quantities as ``[value, unit]``: what output
        files and ensembles store.

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> d = orbits.forces.TidesConstantTimeLag("Planet", k2=0.3, time_lag=600 * u.s,
        ...                                        radius=7e4 * u.km).to_dict()
        >>> d["k2"], d["time_lag"], d["radius"], d["spin"]
        (0.3, [600.0, 's'], [70000.0, 'km'], None)
        """
        return {"type": "TidesConstantTimeLag", "body": self.body, "k2": self.k2,
                "time_lag": _quantity_dict(self.time_lag),
                "radius": _quantity_dict(self.radius), "spin": _vector_dict(self.spin)}

    @classmethod
    def from_dict(cls, d):
        """The term that :meth:`to_dict` describes.

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> term = orbits.forces.TidesConstantTimeLag(
        ...     "Planet", k2=0.3, time_lag=600 * u.s, radius=7e4 * u.km,
        ...     spin=[0, 0, 2] * u.rad / u.day)
        >>> orbits.forces.TidesConstantTimeLag.from_dict(term.to_dict()) == term
        True
        """
        return cls(d["body"], k2=d["k2"], time_lag=_quantity_from(d["time_lag"]),
                   radius=_quantity_from(d["radius"]), spin=_quantity_from(d.get("spin")))

    def bind(self, ctx):
        """Compile the term for one simulation's bodies.

        Parameters
        ----------
        ctx : Context
            The bodies as the simulation holds them (names, masses and ``G m`` in
            the internal order and units).

        Returns
        -------
        BoundTerm
            The kernel and its arguments, in the simulation's units.

        Examples
        --------
        >>> import numpy as np
        >>> import astropy.units as u
        >>> import orbits
        >>> from orbits.forces import Context
        >>> b = orbits.scenes.kepler()
        >>> m = b.masses.value
        >>> ctx = Context(b.names, m, b.units.G * m, 2, b.units, False, np.arange(2),
        ...               b.positions.value, b.velocities.value)
        >>> bound = orbits.forces.TidesConstantTimeLag("Planet", k2=0.3, time_lag=1 * u.day,
        ...                                            radius=0.001 * u.au).bind(ctx)
        >>> bound.args[0], f"{bound.args[1]:.1e}", bound.args[2]   # body, 3 k2 R^5, tau
        (1, '9.0e-16', 1.0)
        """
        term = repr(self)
        b = ctx.index(self.body, term, "body")
        if not ctx.m[b] > 0:
            raise ForceTermError("the tidally distorted body has no mass: a tide needs "
                                 "a body with mass", term=term, field="body", body=self.body)
        R = _given(self.radius, "length", ctx, "radius")
        self._check_radius(R, term)
        tau = _given(self.time_lag, "time", ctx, "time_lag")
        self._check_lag(tau, term)
        spin = _angular_velocity(self.spin, ctx, term)
        return BoundTerm(_k.TermRow(_k.TIDES, (b,), (3.0 * self.k2 * R ** 5, tau)
                                    + tuple(float(c) for c in spin)))


class RadiationPressure(ForceTerm):
    """Radiation pressure and Poynting-Robertson drag from one source (Burns,
    Lamy & Soter 1979), the force of REBOUNDx's ``radiation_forces``.

    A body with ``beta`` (radiation pressure over the source's gravity) feels ::

        a = beta G m_s / r^2 [ (1 - rdot / c) r_hat - u / c ]

    with ``r``, ``u`` its position and velocity relative to the source and
    ``rdot = r_hat . u``: the pressure cancels ``beta`` of the source's pull, the
    velocity terms are the drag.  The source takes no reaction (it radiates
    isotropically), so momentum is not conserved, as in REBOUNDx.  A circular
    orbit spirals in as ``r^2 = r0^2 - 4 beta G m_s t / c`` (Wyatt & Whipple
    1950), reaching the source after ``c r0^2 / (4 beta G m_s)``.
    Dissipative and velocity-dependent: not for the Wisdom-Holman family.  Its
    energy kernel is zero.

    Parameters
    ----------
    source : str
        Name of the radiating body (the Sun); it must have mass.
    beta : float, dict or sequence of float
        One ``beta`` for every body but the source; a dict ``{name: beta}`` (the
        others feel nothing); or one value per body in the body set's order, 0
        for the source.  Finite and not negative; below 1 for a body on a bound
        orbit about the source.
    c : Quantity (speed), optional
        Speed of light; default astropy's ``c``.

    Raises
    ------
    ForceTermError
        A negative or non-finite ``beta``; when bound, ``beta >= 1`` for a body
        bound to the source, a ``beta`` for the source itself, a sequence of the
        wrong length, a source without mass.
    UnknownBodyError
        When bound, the source or a name in ``beta`` is not in the body set.

    References
    ----------
    Burns, J. A., Lamy, P. L. & Soter, S. 1979, Icarus 40, 1.  Wyatt, S. P. &
    Whipple, F. L. 1950, ApJ 111, 134.

    Examples
    --------
    >>> import astropy.units as u, orbits
    >>> b = orbits.scenes.kepler()
    >>> b.add("dust", mass=0 * u.kg, primary="Star", a=2 * u.au)
    >>> rad = orbits.forces.RadiationPressure("Star", beta={"dust": 0.1})
    >>> sim = orbits.Simulation(b, "ias15", forces=[rad])
    >>> sim.forces
    (RadiationPressure(source='Star', beta={'dust': 0.1}),)
    """

    velocity_dependent = True
    conservative = False
    why_not_wisdom_holman = "it is dissipative and depends on velocities"

    def __init__(self, source, beta, *, c=None):
        name = f"RadiationPressure({source!r})"
        if not isinstance(source, str):
            raise ForceTermError(f"source must be a body's name, got {source!r}", term=name,
                                 field="source")
        self.source = source
        self.c = c
        if isinstance(beta, dict):
            self.beta = {}
            for key, value in beta.items():
                if not isinstance(key, str):
                    raise ForceTermError(f"beta's keys must be body names, got {key!r}",
                                         term=name, field="beta")
                self.beta[key] = self._check_beta(value, name, key)
        elif np.ndim(beta) == 1:
            self.beta = [self._check_beta(value, name, k) for k, value in enumerate(beta)]
        else:
            self.beta = self._check_beta(beta, name, None)

    @staticmethod
    def _check_beta(value, term, body):
        out = _number(value, term, "beta", body)
        if out < 0:
            raise ForceTermError(f"expected beta >= 0 (radiation pushes outward), got {out}",
                                 term=term, field="beta", body=body)
        return out

    def to_dict(self):
        """Plain JSON-able values, Quantities as ``[value, unit]``: what output
        files and ensembles store.

        Examples
        --------
        >>> import orbits
        >>> orbits.forces.RadiationPressure("Sun", beta={"dust": 0.2}).to_dict()
        {'type': 'RadiationPressure', 'source': 'Sun', 'beta': {'dust': 0.2}, 'c': None}
        """
        beta = dict(self.beta) if isinstance(self.beta, dict) else (
            list(self.beta) if isinstance(self.beta, list) else self.beta)
        return {"type": "RadiationPressure", "source": self.source, "beta": beta,
                "c": _quantity_dict(self.c)}

    @classmethod
    def from_dict(cls, d):
        """The term that :meth:`to_dict` describes.

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> term = orbits.forces.RadiationPressure("Sun", beta=[0, 0.1, 0.3],
        ...                                        c=3e5 * u.km / u.s)
        >>> orbits.forces.RadiationPressure.from_dict(term.to_dict()) == term
        True
        """
        return cls(d["source"], d["beta"], c=_quantity_from(d.get("c")))

    def bind(self, ctx):
        """Compile the term for one simulation's bodies.

        Parameters
        ----------
        ctx : Context
            The bodies as the simulation holds them (names, masses and ``G m`` in
            the internal order and units).

        Returns
        -------
        BoundTerm
            The kernel and its arguments, in the simulation's units.

        Raises
        ------
        ForceTermError
            ``beta >= 1`` for a body on a bound orbit about the source (read from
            the initial state), among the others of the class.

        Examples
        --------
        >>> import numpy as np
        >>> import orbits
        >>> from orbits.forces import Context
        >>> b = orbits.scenes.kepler()
        >>> m = b.masses.value
        >>> ctx = Context(b.names, m, b.units.G * m, 2, b.units, False, np.arange(2),
        ...               b.positions.value, b.velocities.value)
        >>> bound = orbits.forces.RadiationPressure("Star", beta=0.1).bind(ctx)
        >>> bound.args[0], bound.args[3]     # the source; beta of each body
        (0, array([0. , 0.1]))
        """
        term = repr(self)
        s = _massive_index(ctx, self.source, term, "source", "source")
        n = len(ctx.m)
        beta = np.zeros(n)
        if isinstance(self.beta, dict):
            for name, value in self.beta.items():
                i = ctx.index(name, term, "beta")
                if i == s:
                    raise ForceTermError("the source feels no radiation of its own; leave "
                                         "it out of beta", term=term, field="beta", body=name)
                beta[i] = value
        elif isinstance(self.beta, list):
            if len(self.beta) != n:
                raise ForceTermError(f"expected {n} values of beta, one per body in the body "
                                     f"set's order, got {len(self.beta)}", term=term,
                                     field="beta")
            beta[:] = np.asarray(self.beta)[ctx.order]
            if beta[s] != 0:
                raise ForceTermError(f"the source feels no radiation of its own; expected "
                                     f"beta = 0 for it, got {beta[s]}", term=term,
                                     field="beta", body=self.source)
        else:
            beta[:] = self.beta
            beta[s] = 0.0
        self._check_bound(ctx, s, beta, term)
        ic = 1.0 / _speed_of_light(self, self.c, ctx)
        return BoundTerm(_k.TermRow(_k.RADIATION, (s,), (float(ctx.gm[s]), ic), beta))

    def _check_bound(self, ctx, s, beta, term):
        # beta >= 1 cancels the source's pull or more: a bound body would be flung out
        us = ctx.order[s]
        for i in np.flatnonzero(beta >= 1.0):
            k = ctx.order[i]
            r = float(np.linalg.norm(ctx.x_user[k] - ctx.x_user[us]))
            v2 = float(np.sum((ctx.v_user[k] - ctx.v_user[us]) ** 2))
            if 0.5 * v2 - (ctx.gm[s] + ctx.gm[i]) / r < 0:
                raise ForceTermError(
                    f"beta = {beta[i]} >= 1 for a body on a bound orbit about "
                    f"{self.source!r}: radiation would cancel the source's gravity or more; "
                    f"expected beta < 1 for a bound body", term=term, field="beta",
                    body=ctx.names[i])


class UserForce(ForceTerm):
    """A force of your own, added to gravity and compiled into the same loop.

    Parameters
    ----------
    func : numba-compiled function
        ``func(x, v, t, m) -> a``: positions and velocities (shape (N, 3)),
        time and masses (shape (N,)) in the body set's units and order, and
        the accelerations of this term alone, shape (N, 3).  It must be
        compiled with ``@numba.njit`` so that it runs inside the loop.
    velocity_dependent : bool
        Whether ``a`` reads ``v``.
    potential : numba-compiled function, optional
        ``potential(x, m) -> float``, the term's potential energy, whose
        negative gradient divided by the masses is ``a``: the energy monitor
        adds it, and with ``velocity_dependent=False`` the Wisdom-Holman
        family can take the term.  Without it the term counts as
        non-conservative: its work is integrated into
        :attr:`orbits.Simulation.work` and the energy monitor reports
        ``|E + W - E0| / |E0|``.

    Raises
    ------
    ForceTermError
        ``func`` (or ``potential``) is not a numba function; when bound, ``func``
        returns the wrong shape or a non-finite value on the initial state.

    Examples
    --------
    >>> import numba, numpy as np, orbits
    >>> @numba.njit
    ... def drag(x, v, t, m):
    ...     return -1e-6 * v
    >>> term = orbits.forces.UserForce(drag, velocity_dependent=True)
    """

    def __init__(self, func, velocity_dependent=False, potential=None):
        for field, f in (("func", func), ("potential", potential)):
            if f is not None and not hasattr(f, "py_func"):
                raise ForceTermError(
                    f"{field} must be compiled with @numba.njit so that it runs inside "
                    f"the compiled loop; got the Python function {f!r} (for a plain "
                    "Python force use orbits.integrate)", term="UserForce", field=field)
        self.func = func
        self.potential = potential
        self.velocity_dependent = bool(velocity_dependent)
        self.conservative = potential is not None
        self.wisdom_holman = self.conservative and not self.velocity_dependent
        self.why_not_wisdom_holman = ("it depends on velocities" if self.velocity_dependent
                                      else "it has no potential")

    takes_functions = True
    #: the parameters of each function, as the class documents them
    _SIGNATURES = {"func": ("x", "v", "t", "m"), "potential": ("x", "m")}

    def to_dict(self):
        """Plain values: the functions by name, ``"module:qualname"``, beside
        whether the term reads velocities.  A dictionary names the functions
        but never holds them: :meth:`from_dict` takes them from its caller,
        and nothing is imported from a name.

        Examples
        --------
        >>> import orbits
        >>> import numba
        >>> @numba.njit
        ... def drag(x, v, t, m):
        ...     return -1e-6 * v
        >>> d = orbits.forces.UserForce(drag, velocity_dependent=True).to_dict()
        >>> d["type"], d["func"].endswith(":drag"), d["potential"]
        ('UserForce', True, None)
        """
        return {"type": "UserForce", "func": _reference(self.func),
                "velocity_dependent": self.velocity_dependent,
                "potential": _reference(self.potential)}

    def functions(self):
        """The term's functions by the names its dictionary records.

        Examples
        --------
        >>> import numba, orbits
        >>> @numba.njit
        ... def drag(x, v, t, m):
        ...     return -1e-6 * v
        >>> term = orbits.forces.UserForce(drag, velocity_dependent=True)
        >>> list(term.functions().values()) == [drag]
        True
        """
        return {_reference(f): f for f in (self.func, self.potential) if f is not None}

    @classmethod
    def functions_needed(cls, d):
        """The functions the dictionary ``d`` names, each with what it is.

        Raises
        ------
        ForceTermError
            ``d`` names them in a form other than ``"module:qualname"``, or
            its ``velocity_dependent`` is not a bool.

        Examples
        --------
        >>> import orbits
        >>> orbits.forces.UserForce.functions_needed(
        ...     {"func": "models:pull", "velocity_dependent": False, "potential": "models:pot"})
        {'models:pull': 'UserForce func(x, v, t, m)', 'models:pot': 'UserForce potential(x, m)'}
        """
        if not isinstance(d, Mapping):
            raise ForceTermError(f"a UserForce record must be a dictionary, got {d!r}",
                                 term="UserForce")
        if not isinstance(d.get("velocity_dependent"), bool):
            raise ForceTermError(f"velocity_dependent must be true or false, got "
                                 f"{d.get('velocity_dependent')!r}", term="UserForce",
                                 field="velocity_dependent")
        needed = {}
        for field in ("func", "potential"):
            ref = d.get(field)
            if ref is None and field == "potential":
                continue
            if not _is_reference(ref):
                raise ForceTermError(
                    f"{field} must be named as 'module:qualname', got {ref!r}",
                    term="UserForce", field=field)
            what = f"UserForce {field}({', '.join(cls._SIGNATURES[field])})"
            if field == "func" and d["velocity_dependent"]:
                what += ", velocity-dependent"
            needed[ref] = what
        return needed

    @classmethod
    def from_dict(cls, d, functions=None):
        """The term that :meth:`to_dict` describes, with its functions taken from
        ``functions``.

        Parameters
        ----------
        d : dict
            As :meth:`to_dict` gives it.
        functions : mapping, optional
            Recorded name -> function: the name as the dictionary records it
            (``"module:qualname"``) or its ``qualname`` alone.  Each function
            must have the recorded ``qualname`` and the parameters the class
            documents (``func(x, v, t, m)``, ``potential(x, m)``).

        Raises
        ------
        ForceTermError
            ``functions`` does not give a function the dictionary names (the
            error lists them), or gives one of another name or signature.

        Examples
        --------
        >>> import numba, orbits
        >>> @numba.njit
        ... def drag(x, v, t, m):
        ...     return -1e-6 * v
        >>> d = orbits.forces.UserForce(drag, velocity_dependent=True).to_dict()
        >>> orbits.forces.UserForce.from_dict(d, functions={"drag": drag})
        UserForce(drag, velocity_dependent=True)
        >>> try:
        ...     orbits.forces.UserForce.from_dict(d)
        ... except orbits.ForceTermError as exc:
        ...     print(exc.field, "functions={'drag': ...}" in str(exc))
        func True
        """
        needed = cls.functions_needed(d)
        functions = {} if functions is None else functions
        if not isinstance(functions, Mapping):
            raise ForceTermError(f"functions must be a mapping of recorded names to "
                                 f"functions, got {functions!r}", term="UserForce",
                                 field="functions")
        missing = [ref for ref in needed if _lookup(functions, ref) is None]
        if missing:
            raise ForceTermError(
                "the record names the function(s) "
                + "; ".join(f"{ref!r} ({needed[ref]})" for ref in missing)
                + ", which a record cannot hold; pass them: functions={"
                + ", ".join(f"{_qualname(ref)!r}: ..." for ref in missing) + "}",
                term="UserForce", field="func" if d["func"] in missing else "potential")
        func = _take(functions, d["func"], "func")
        potential = (None if d.get("potential") is None
                     else _take(functions, d["potential"], "potential"))
        return cls(func, velocity_dependent=d["velocity_dependent"], potential=potential)

    def __repr__(self):
        return (f"UserForce({getattr(self.func, '__name__', self.func)}, "
                f"velocity_dependent={self.velocity_dependent})")

    def bind(self, ctx):
        """Compile the term for one simulation's bodies.

        Parameters
        ----------
        ctx : Context
            The bodies as the simulation holds them (names, masses and ``G m`` in
            the internal order and units).

        Returns
        -------
        BoundTerm
            The kernel and its arguments, in the simulation's units.

        Raises
        ------
        ForceTermError
            ``func`` returns the wrong shape or a non-finite value on the initial state.

        Examples
        --------
        >>> import numpy as np
        >>> import orbits
        >>> from orbits.forces import Context
        >>> b = orbits.scenes.kepler()
        >>> m = b.masses.value
        >>> ctx = Context(b.names, m, b.units.G * m, 2, b.units, False, np.arange(2),
        ...               b.positions.value, b.velocities.value)
        >>> import numba
        >>> @numba.njit
        ... def drag(x, v, t, m):
        ...     return -1e-6 * v
        >>> bound = orbits.forces.UserForce(drag, velocity_dependent=True).bind(ctx)
        >>> bound.user.func is drag
        True
        """
        # the body set's row k is internal row pos[k]
        pos = np.argsort(ctx.order)
        self._check(ctx, np.ascontiguousarray(ctx.m[pos]))
        return BoundTerm(_k.TermRow(_k.USER), user=self)

    def _check(self, ctx, m_user):
        x = ctx.x_user
        v = ctx.v_user
        try:
            a = np.asarray(self.func(x.copy(), v.copy(), 0.0, m_user))
        except Exception as exc:  # a numba typing error names the cause
            raise ForceTermError(f"calling func(x, v, t, m) on the initial state failed: "
                                 f"{exc}", term=repr(self), field="func") from None
        if a.shape != x.shape:
            raise ForceTermError(f"func returned an array of shape {a.shape} for "
                                 f"{len(m_user)} bodies; expected accelerations of shape "
                                 f"{x.shape}", term=repr(self), field="func")
        if not np.all(np.isfinite(a)):
            raise ForceTermError("func returned non-finite accelerations on the initial "
                                 "state", term=repr(self), field="func")
        if self.potential is not None:
            e = self.potential(x.copy(), m_user)
            if not (np.ndim(e) == 0 and math.isfinite(float(e))):
                raise ForceTermError(f"potential must return a finite float, got {e!r}",
                                     term=repr(self), field="potential")


def _reference(f):
    # how a record names a function: "module:qualname"
    return None if f is None else f"{f.__module__}:{f.__qualname__}"


def _is_reference(ref):
    if not isinstance(ref, str):
        return False
    module, colon, qualname = ref.partition(":")
    return bool(colon and module and qualname)


def _qualname(ref):
    return ref.partition(":")[2]


def _lookup(functions, ref):
    # the caller's function for a recorded name: by the whole name, or its qualname
    if ref in functions:
        return functions[ref]
    return functions.get(_qualname(ref))


def _take(functions, ref, field):
    """The caller's function for the recorded ``ref``, checked against it: its
    ``qualname`` and its parameters (those :class:`UserForce` documents)."""
    f = _lookup(functions, ref)
    given = getattr(f, "__qualname__", None)
    if given != _qualname(ref):
        raise ForceTermError(
            f"the function given for {ref!r} is {f!r} (qualname {given!r}); the record "
            f"names one of qualname {_qualname(ref)!r}", term="UserForce", field=field)
    py_func = getattr(f, "py_func", f)
    want = UserForce._SIGNATURES[field]
    try:
        params = inspect.signature(py_func).parameters.values()
    except (TypeError, ValueError):
        params = None
    positional = (inspect.Parameter.POSITIONAL_ONLY, inspect.Parameter.POSITIONAL_OR_KEYWORD)
    if params is None or len(params) != len(want) or any(p.kind not in positional
                                                          for p in params):
        raise ForceTermError(
            f"the function given for {ref!r} takes {_signature_text(py_func)}; a UserForce "
            f"{field} takes ({', '.join(want)})", term="UserForce", field=field)
    return f


def _signature_text(f):
    try:
        return str(inspect.signature(f))
    except (TypeError, ValueError):
        return "arguments that cannot be read"
