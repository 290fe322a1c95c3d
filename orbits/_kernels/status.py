"""Status codes returned by the compiled loops.

numba compiles members of an ``IntEnum`` as integer constants, so kernels and
Python share one set of names.  ``Simulation`` turns a non-OK status into the
matching exception of :mod:`orbits.errors`.
"""

from enum import IntEnum

__all__ = ["Status", "with_status"]


class Status(IntEnum):
    OK = 0
    NON_FINITE = 1
    STEP_UNDERFLOW = 2
    CLOSE_ENCOUNTER = 3
    ESCAPE = 4
    NO_CONVERGENCE = 5  # an implicit method's Newton iteration did not converge
    # the chaos indicators' tangent vector wants scaling back (not a failure:
    # the driver renormalises it and carries on; orbits._kernels.variational)
    RENORMALISE = 6
    COLLISION = 7   # two bodies closer than the sum of their radii (collisions=)
    # the encounter log is nearly full (not a failure: the driver empties it
    # and carries on; orbits._kernels.stopping)
    LOG_FULL = 8


def with_status(status, *rest):
    """A loop's return with its status as a :class:`Status` (compiled loops
    return plain integers).

    Examples
    --------
    >>> from orbits._kernels.status import with_status
    >>> with_status(1, 10, 0)
    (<Status.NON_FINITE: 1>, 10, 0)
    """
    return (Status(status),) + rest
