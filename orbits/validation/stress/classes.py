"""How a cell of a stress map is classified: accurate, degraded or failed by
its error against two thresholds (position or energy), failed by a named run
error, left out where the integrator refuses the problem; and the cell's text.
"""

import math

__all__ = ["ACCURATE", "DEGRADED", "FAILED", "LEFT_OUT", "CLASSES", "ACCURATE_POSITION",
           "FAILED_POSITION", "ACCURATE_ENERGY", "FAILED_ENERGY", "abbreviation", "classify",
           "cell_text"]

ACCURATE, DEGRADED, FAILED, LEFT_OUT = "accurate", "degraded", "failed", "left out"
CLASSES = (ACCURATE, DEGRADED, FAILED, LEFT_OUT)

#: Relative position error below which a run is accurate: six digits of the
#: orbit, what an ephemeris comparison or a figure at any zoom would need.
ACCURATE_POSITION = 1e-6
#: Relative position error from which a run has failed: a tenth of the orbit
#: (or of the separation, or of the amplitude) off is a different trajectory,
#: no longer a less precise one.
FAILED_POSITION = 1e-1
#: Relative energy error below which a run is accurate (the same six digits).
ACCURATE_ENERGY = 1e-6
#: Relative energy error from which a run has failed: one per cent of the
#: energy changes which pair of the Pythagorean problem ends as the binary,
#: and a position error grows about 2 pi (3/2) dE/E per orbit, so 1e-2 in
#: energy is already a tenth of an orbit in phase within one orbit.
FAILED_ENERGY = 1e-2

_THRESHOLDS = {"position": (ACCURATE_POSITION, FAILED_POSITION),
               "energy": (ACCURATE_ENERGY, FAILED_ENERGY)}

_ABBREVIATIONS = {"NonFiniteState": "NFS", "StepSizeUnderflow": "SSU",
                  "ConvergenceFailure": "CF", "WallTimeExceeded": "WTE",
                  "IntegratorOptionError": "IOE"}


def abbreviation(outcome):
    """The short name of a run error for a map cell (``"NonFiniteState"`` -> ``"NFS"``)."""
    return _ABBREVIATIONS.get(outcome) or "".join(c for c in outcome if c.isupper()) or outcome


def classify(error, outcome="completed", metric="position"):
    """The class of one cell.

    Parameters
    ----------
    error : float
        The sweep's error measure (relative position or energy error).
    outcome : str
        ``"completed"``, or the class name of the run error.
    metric : {"position", "energy"}
        Which pair of thresholds applies.

    Returns
    -------
    str
        :data:`ACCURATE`, :data:`DEGRADED`, :data:`FAILED`, or :data:`LEFT_OUT`
        for an integrator that refused the problem (``IntegratorOptionError``)
        and for a cell not run (``"Skipped"``).
    """
    if outcome in ("IntegratorOptionError", "Skipped"):
        return LEFT_OUT
    if outcome != "completed":
        return FAILED
    good, bad = _THRESHOLDS[metric]
    if error is None or not math.isfinite(error) or error >= bad:
        return FAILED
    return ACCURATE if error < good else DEGRADED


def cell_text(cls, outcome, error):
    """The text of a map's cell: log10 of the error, the run error's
    abbreviation, or why it is left out."""
    if cls == LEFT_OUT:
        return "skip" if outcome == "Skipped" else "n/a"
    if outcome != "completed":
        return abbreviation(outcome)
    if error is None or not math.isfinite(error):
        return "inf"
    if error <= 0:
        return "0"
    text = f"{math.log10(error):.1f}"
    return "0.0" if text == "-0.0" else text
