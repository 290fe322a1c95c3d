"""The status codes that the compiled code returns: one set, one meaning per value.

numba compiles members of an ``IntEnum`` as integer constants, so kernels and
Python share one set of names.  Two kinds of kernel return them:

* the compiled loops (a run's outcome): ``OK`` and the codes up to
  ``LOG_FULL``, which ``Simulation`` turns into the matching exception of
  :mod:`orbits.errors` (or acts on: ``RENORMALISE``, ``LOG_FULL``);
* the two-body kernels (:mod:`.elements`, :mod:`.kepler`,
  :mod:`.kepler_tangent`): ``OK`` and the codes from 16 up, which the
  Python layer turns into :class:`orbits.errors.ElementsError` with
  :func:`describe_status`'s sentence.  A loop never returns one: a Kepler
  drift that fails (``INVALID_STATE``) leaves its row NaN, and the loop's
  finite check reports that as ``NON_FINITE``.

The values are unique (``@unique``), so a code read back (from a loop, a
kernel or a file's ``restart/progress``) has one meaning.
"""

from enum import IntEnum, unique

__all__ = ["Status", "describe_status", "with_status"]


@unique
class Status(IntEnum):
    OK = 0
    # -- a run's outcome (the compiled loops) --------------------------------------
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
    # -- a two-body kernel's outcome (elements, kepler, kepler_tangent); from 16
    # up, so that the run's codes can grow below them --------------------------------
    BEYOND_ASYMPTOTE = 16   # hyperbola with 1 + e cos f <= 0: no such point
    INVALID_ELEMENTS = 17   # non-finite, mu <= 0, e < 0, e == 1, or sign(a) wrong for e
    INVALID_STATE = 18      # non-finite, mu <= 0, or body at the primary (r == 0)
    RADIAL_ORBIT = 19       # zero angular momentum: no orbital plane
    PARABOLIC_ORBIT = 20    # energy zero (or of the wrong sign for e) within rounding
    BAD_SHAPE = 21          # an array argument is too short


_MESSAGES = {
    Status.OK: "ok",
    Status.NON_FINITE: "the state became non-finite",
    Status.STEP_UNDERFLOW: "the step size underflowed",
    Status.CLOSE_ENCOUNTER: "a close encounter",
    Status.ESCAPE: "a body escaped",
    Status.NO_CONVERGENCE: "the implicit method's Newton iteration did not converge",
    Status.RENORMALISE: "the chaos indicators' tangent vector wants renormalising",
    Status.COLLISION: "two bodies collided",
    Status.LOG_FULL: "the encounter log is nearly full",
    Status.BEYOND_ASYMPTOTE: "the true anomaly lies beyond the asymptote of the "
                             "hyperbola (1 + e cos f <= 0)",
    Status.INVALID_ELEMENTS: "invalid orbital elements: they must be finite with mu > 0, "
                             "e >= 0, e != 1, a > 0 for e < 1 and a < 0 for e > 1",
    Status.INVALID_STATE: "invalid state: it must be finite with mu > 0 and the body "
                          "away from its primary",
    Status.RADIAL_ORBIT: "the orbit is radial (zero angular momentum), so its plane "
                         "and orientation are undefined",
    Status.PARABOLIC_ORBIT: "the orbit is parabolic to within rounding (zero energy); "
                            "its semi-major axis is infinite or meaningless",
    Status.BAD_SHAPE: "an array argument is too short",
}


def describe_status(status):
    """Sentence describing a status code, for the exception the Python layer raises.

    Parameters
    ----------
    status : int or Status

    Returns
    -------
    str

    Examples
    --------
    >>> from orbits._kernels.status import Status, describe_status
    >>> describe_status(Status.RADIAL_ORBIT)
    'the orbit is radial (zero angular momentum), so its plane and orientation are undefined'
    >>> describe_status(99)
    'unknown status code 99'
    """
    return _MESSAGES.get(int(status), f"unknown status code {int(status)}")


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
