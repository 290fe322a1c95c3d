"""Resolving collisions: merging, bouncing, or a function that chooses.

``Simulation(..., collisions=...)`` with bodies that have radii checks every
step for pairs whose separation fell below the sum of their radii, at the end
of the step or inside it (:mod:`orbits._kernels.stopping`).  What happens
then is the resolution:

``"halt"``
    The run stops with :class:`~orbits.errors.Collision` and keeps the state.
``"merge"``
    The pair becomes one body: mass and momentum are conserved, the merged
    body sits at the pair's centre of mass with its velocity, and its radius
    is that of the summed volumes, ``(R1^3 + R2^3)^(1/3)``.  It keeps the name
    of the more massive body (the first in the body set on a tie); the other
    leaves the simulation.
``"bounce"``
    Hard spheres: the relative velocity's component along the line of centres
    is reversed and scaled by the coefficient of restitution (``restitution``,
    1 by default: elastic), momentum conserved.
a function
    Called as ``f(event)`` with a :class:`CollisionEvent`; it returns
    ``"merge"``, ``"bounce"`` or ``"halt"``, and may be a different answer
    for every pair (say, merge planetesimals but halt on two planets).

Every collision a run resolves is a row of ``result.collisions`` (an astropy
table; also in output files) with its time, the two bodies, the resolution,
the body that survived a merger and the energy change.  A collision is
resolved at the end of the step in which it happened, with the state there
(the pair's time of contact, found inside the step, is in the table); the
step can be the first, whose start the check records.  Bodies that touch at
the start are merged there with ``"merge"`` (their row has time 0).  Where
the integrator cannot carry the bodies through their contact (``trace``,
whose inner step collapses as a planet falls head-on into its star), the
collision is resolved at the last state it reached whole, before the contact
(the table's ``step_time`` then precedes ``time``), and the survivors are
carried on to the step's end.  All
the collisions of one step are resolved in the order of their contact times;
a merged body that then overlaps a third is merged again (chains).  A pair
already moving apart at the end of the step (it passed through within one
step) is left as it is by ``"bounce"``.

What a merger takes out of the bodies' energy (the pair's kinetic energy of
relative motion and their mutual binding) and their angular momentum (the
pair's orbital angular momentum about each other, which becomes the merged
body's spin) is kept as an offset, so that the energy and angular-momentum
monitors stay meaningful: the energy monitor reports ``E + W`` with ``W``
the energy taken out (as for dissipative forces, :attr:`Simulation.work`)
and the angular momentum includes the spin taken up.
"""

import math
from typing import NamedTuple

import numpy as np

from .errors import SimulationOptionError

__all__ = ["RESOLUTIONS", "CollisionEvent", "merge_pair", "bounce_pair", "pair_energy_change"]

#: the resolutions a collision can have (``Simulation``'s ``collisions`` or a
#: function's answer)
RESOLUTIONS = ("halt", "merge", "bounce")


class CollisionEvent(NamedTuple):
    """What a collision function is given (Quantities in the simulation's units).

    Attributes
    ----------
    time : Quantity
        When the pair was closest inside the step (their contact).
    step_time : Quantity
        The end of the step, where the collision is resolved.
    bodies : tuple of str
        The two bodies' names.
    masses, radii : Quantity, shape (2,)
    positions, velocities : Quantity, shape (2, 3)
        At the end of the step.
    distance, speed : Quantity
        Separation and relative speed at contact.
    """

    time: object
    step_time: object
    bodies: tuple
    masses: object
    radii: object
    positions: object
    velocities: object
    distance: object
    speed: object


def merge_pair(m, r, x, v, a, b):
    """The body that pair ``a``, ``b`` of the arrays makes when it merges:
    ``(mass, radius, position, velocity)``.

    Mass and momentum are conserved (the centre of mass and its velocity; for
    two massless bodies, their mean); the volume is conserved.

    Examples
    --------
    >>> from orbits.collisions import merge_pair
    >>> m = np.array([3.0, 1.0]); r = np.array([1.0, 1.0])
    >>> x = np.array([[0.0, 0, 0], [4.0, 0, 0]]); v = np.array([[0.0, 1, 0], [0.0, -3, 0]])
    >>> M, R, X, V = merge_pair(m, r, x, v, 0, 1)
    >>> float(M), round(float(R), 6), X.tolist(), V.tolist()
    (4.0, 1.259921, [1.0, 0.0, 0.0], [0.0, 0.0, 0.0])
    """
    M = m[a] + m[b]
    wa, wb = (m[a] / M, m[b] / M) if M > 0 else (0.5, 0.5)
    R = (r[a] ** 3 + r[b] ** 3) ** (1.0 / 3.0)
    return M, R, wa * x[a] + wb * x[b], wa * v[a] + wb * v[b]


def bounce_pair(m, x, v, a, b, restitution):
    """New velocities of a hard-sphere bounce of ``a`` and ``b``: the relative
    velocity's component along the line of centres reversed and scaled by
    ``restitution``, momentum conserved.  Returns ``(va, vb, approaching)``;
    a pair already moving apart is left as it is (``approaching`` False).

    Examples
    --------
    >>> from orbits.collisions import bounce_pair
    >>> m = np.array([1.0, 1.0])
    >>> x = np.array([[0.0, 0, 0], [1.0, 0, 0]]); v = np.array([[1.0, 0, 0], [-1.0, 0, 0]])
    >>> va, vb, closing = bounce_pair(m, x, v, 0, 1, 1.0)
    >>> va.tolist(), vb.tolist(), closing
    ([-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], True)
    """
    d = x[b] - x[a]
    n = d / math.sqrt(float(d @ d))
    un = float((v[b] - v[a]) @ n)
    if un >= 0.0:
        return v[a].copy(), v[b].copy(), False
    M = m[a] + m[b]
    wa, wb = (m[b] / M, m[a] / M) if M > 0 else (0.5, 0.5)
    dv = (1.0 + restitution) * un * n
    return v[a] + wa * dv, v[b] - wb * dv, True


def pair_energy_change(m, x, v, a, b, va, vb):
    """The kinetic energy change of ``a`` and ``b`` when their velocities
    become ``va``, ``vb`` (a bounce: their positions do not change).

    Examples
    --------
    >>> from orbits.collisions import pair_energy_change
    >>> m = np.array([1.0, 1.0]); v = np.array([[1.0, 0, 0], [-1.0, 0, 0]])
    >>> float(pair_energy_change(m, None, v, 0, 1, np.zeros(3), np.zeros(3)))
    -1.0
    """
    before = m[a] * float(v[a] @ v[a]) + m[b] * float(v[b] @ v[b])
    after = m[a] * float(va @ va) + m[b] * float(vb @ vb)
    return 0.5 * (after - before)


def table(rows, units):
    """``result.collisions``: an astropy QTable of the resolved collisions.

    ``rows`` are tuples ``(time, step_time, body_1, body_2, resolution,
    survivor, distance, speed, energy_change)`` in the internal units.
    """
    # (astropy.table is imported where a table is made: 0.24 s a process)
    from astropy.table import QTable
    q = units.quantity
    col = lambda k, kind=float: np.array([r[k] for r in rows], dtype=kind)  # noqa: E731
    return QTable({"time": q(col(0), "time"), "step_time": q(col(1), "time"),
                   "body_1": col(2, str), "body_2": col(3, str),
                   "resolution": col(4, str), "survivor": col(5, str),
                   "distance": q(col(6), "length"),
                   "speed": q(col(7), "length") / units.time,
                   "energy_change": q(col(8), "energy")})


def check_answer(answer, bodies):
    """A collision function's answer, checked."""
    if isinstance(answer, str) and answer in RESOLUTIONS:
        return answer
    raise SimulationOptionError(
        f"the collisions function returned {answer!r} for {bodies[0]!r} and {bodies[1]!r}; "
        f"expected one of {', '.join(map(repr, RESOLUTIONS))}")
