"""Higher-order symmetric compositions of the leapfrog (Yoshida 1990).

Each method is the drift-kick-drift leapfrog applied with a sequence of
weighted sub-steps; its table of drift and kick coefficients
(:func:`orbits.integrators.tableaux.compose_leapfrog`) runs on the shared
splitting loop like any other splitting method, so a new composition is a new
table and nothing else.
"""

from . import tableaux
from .base import SplittingMethod

__all__ = ["Yoshida4", "Yoshida6", "Yoshida8"]


class Yoshida4(SplittingMethod):
    """Fourth-order composition of three leapfrogs (Yoshida 1990).

    Notes
    -----
    With the drift-kick-drift leapfrog ``S(h)``::

        Phi(h) = S(w_1 h) S(w_0 h) S(w_1 h),
        w_1 = 1 / (2 - 2^(1/3)),  w_0 = 1 - 2 w_1 = -2^(1/3) w_1

    Neighbouring half drifts merge: four drifts and three kicks (three force
    evaluations) a step.  Symplectic and time-symmetric; order 4.  The
    negative middle weight makes one sub-step go backwards in time, so the
    method wants a force that is defined there (always true for gravity).

    References
    ----------
    Yoshida, H. 1990, "Construction of higher order symplectic integrators",
    Phys. Lett. A 150, 262, eq. (4.12).  Found independently by Forest &
    Ruth (1990), Physica D 43, 105, and Candy & Rozmus (1991), J. Comput.
    Phys. 92, 230.

    Examples
    --------
    >>> sim = orbits.Simulation(orbits.scenes.kepler(e=0.1), integrator="yoshida4",
    ...                         dt=5 * u.day)
    >>> result = sim.run(until=1 * u.yr, outputs=5, progress=False)
    >>> bool(result.energy_error.max() < 1e-5)
    True
    """

    name = "yoshida4"
    order = 4
    summary = "Yoshida's fourth-order composition of three leapfrogs"
    operators = tableaux.YOSHIDA4


class Yoshida6(SplittingMethod):
    """Sixth-order composition of seven leapfrogs (Yoshida 1990, solution A).

    Notes
    -----
    ::

        Phi(h) = S(w_3 h) S(w_2 h) S(w_1 h) S(w_0 h) S(w_1 h) S(w_2 h) S(w_3 h)

    with Yoshida's weights ``w_1 = -1.17767998417887``,
    ``w_2 = 0.235573213359357``, ``w_3 = 0.784513610477560`` and
    ``w_0 = 1 - 2 (w_1 + w_2 + w_3)``: seven force evaluations a step.

    References
    ----------
    Yoshida, H. 1990, Phys. Lett. A 150, 262, table 1.

    Examples
    --------
    >>> integ = orbits.integrators.get("yoshida6")
    >>> integ.order, sum(1 for kind, _ in integ.operators if kind == "kick")
    (6, 7)
    """

    name = "yoshida6"
    order = 6
    summary = "Yoshida's sixth-order composition of seven leapfrogs"
    operators = tableaux.YOSHIDA6


class Yoshida8(SplittingMethod):
    """Eighth-order composition of fifteen leapfrogs (Yoshida 1990, solution D).

    Notes
    -----
    ``Phi(h) = S(w_7 h) ... S(w_1 h) S(w_0 h) S(w_1 h) ... S(w_7 h)`` with the
    weights of Yoshida's solution D and ``w_0 = 1 - 2 (w_1 + ... + w_7)``:
    fifteen force evaluations a step.  The weights are published to 15
    digits; their residual in the order conditions (about 1e-15) is far below
    the method's own error at any step worth taking.

    References
    ----------
    Yoshida, H. 1990, Phys. Lett. A 150, 262, table 2.

    Examples
    --------
    Fifteen leapfrogs, fifteen forces a step:

    >>> orbits.integrators.get("yoshida8").forces_per_step
    15
    """

    name = "yoshida8"
    order = 8
    summary = "Yoshida's eighth-order composition of fifteen leapfrogs"
    operators = tableaux.YOSHIDA8
