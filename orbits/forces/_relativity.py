"""General relativity, in three forms: the 1PN correction about one dominant
body (:class:`GR`), its potential form, which the Wisdom-Holman family takes
(:class:`GRPotential`), and the Einstein-Infeld-Hoffmann equations among all
massive bodies (:class:`GRFull`).  Each reads the speed of light ``c``,
astropy's unless given."""

from .._kernels import terms as _k
from . import _parameters as _p
from ._base import ForceTerm
from ._binding import BoundTerm

__all__ = ["GR", "GRPotential", "GRFull"]


class _SourceTerm(ForceTerm):
    """A GR term about one dominant body, the ``source``: its kernel reads the
    source's index and ``1 / c^2``."""

    FIELDS = ("source", "c")
    QUANTITIES = ("c",)
    #: the kernel's code in the table of terms
    _KERNEL = None

    def __init__(self, source, *, c=None):
        self.source = _p.body_name(source, type(self).__name__, "source")
        self.c = c

    def bind(self, ctx):
        src = ctx.massive_index(self.source, repr(self), "source", "source")
        cv = _p.speed_of_light(self, ctx)
        return BoundTerm(_k.TermRow(self._KERNEL, (src,), (1.0 / (cv * cv),)))


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
    >>> sim = orbits.Simulation(orbits.scenes.solar_system(), "ias15",
    ...                         forces=[orbits.forces.GR("Sun")])
    >>> sim.forces
    (GR(source='Sun'),)
    """

    velocity_dependent = True
    why_not_wisdom_holman = "it depends on velocities"
    _KERNEL = _k.GR


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
    >>> sim = orbits.Simulation(orbits.scenes.kepler(), "wh", dt=5 * u.day,
    ...                         forces=[orbits.forces.GRPotential("Star")])
    >>> sim.forces
    (GRPotential(source='Star'),)
    """

    wisdom_holman = True
    _KERNEL = _k.GR_POTENTIAL


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
    >>> sim = orbits.Simulation(orbits.scenes.kepler(), "ias15",
    ...                         forces=[orbits.forces.GRFull()])
    >>> sim.forces, orbits.forces.GRFull.velocity_dependent
    ((GRFull(),), True)
    """

    velocity_dependent = True
    why_not_wisdom_holman = "it depends on velocities"
    FIELDS = ("c",)
    QUANTITIES = ("c",)

    def __init__(self, *, c=None):
        self.c = c

    def bind(self, ctx):
        cv = _p.speed_of_light(self, ctx)
        return BoundTerm(_k.TermRow(_k.GR_FULL, (ctx.n_active,), (1.0 / (cv * cv),)))
