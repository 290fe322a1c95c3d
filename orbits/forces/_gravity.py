"""Newtonian point-mass gravity as a term: every simulation has it, and a
:class:`Gravity` in ``forces`` only sets its options (the kernels are
:mod:`orbits._kernels.gravity`'s)."""

from ._base import ForceTerm

__all__ = ["Gravity"]


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
    >>> sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day,
    ...                         forces=[orbits.forces.Gravity(softening=1e-4 * u.au)])
    >>> sim.softening, sim.forces
    (<Quantity 0.0001 AU>, ())
    """

    FIELDS = ("softening", "parallel", "rebound_arithmetic")
    QUANTITIES = ("softening",)

    def __init__(self, softening=None, parallel=None, rebound_arithmetic=False):
        self.softening = softening
        self.parallel = parallel
        self.rebound_arithmetic = bool(rebound_arithmetic)
