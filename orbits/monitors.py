"""Monitors of the conserved quantities, and fits of how their errors grow.

The quantities themselves are computed by the compiled kernels in
:mod:`orbits._kernels.invariants`, inside the stepping loop; this module
names them, turns raw rows into relative errors, and fits drift laws.
"""

import numpy as np

from ._kernels import invariants as _inv

__all__ = ["MONITORS", "DEFAULT_MONITORS", "monitor_mask", "relative_error",
           "vector_relative_error", "growth_exponent", "ensemble_growth_exponent",
           "monitor_fields"]

#: monitor name -> bit of the kernel mask
MONITORS = {
    "energy": _inv.ENERGY,
    "angular_momentum": _inv.ANGULAR_MOMENTUM,
    "momentum": _inv.MOMENTUM,
    "center_of_mass": _inv.CENTER_OF_MASS,
}

DEFAULT_MONITORS = ("energy", "angular_momentum")


def monitor_mask(names):
    """Bit mask for the named monitors; unknown names are an error listing the valid ones."""
    mask = 0
    for name in names:
        try:
            mask |= MONITORS[name]
        except KeyError:
            raise ValueError(f"unknown monitor {name!r}; valid: {', '.join(MONITORS)}") from None
    return mask


def relative_error(values, reference, scale=None):
    """``|values - reference| / |reference|``; ``scale`` replaces ``|reference|`` when it is 0."""
    denom = abs(reference) if reference != 0 else (scale or 1.0)
    return np.abs(np.asarray(values) - reference) / denom


def vector_relative_error(values, reference, scale):
    """``|L - L0| / |L0|`` for vectors of shape (n, 3).

    A system with zero total angular momentum (the Pythagorean problem) has
    no relative error; there ``scale`` (sum of ``m |x| |v|`` at the start) is the
    denominator, so the figure still says how large the error is against the
    system's own angular-momentum budget.
    """
    ref = np.asarray(reference)
    norm = np.linalg.norm(ref)
    denom = norm if norm > 1e-14 * scale else scale
    return np.linalg.norm(np.asarray(values) - ref, axis=-1) / denom


def growth_exponent(t, err):
    """Slope of ``log err`` against ``log t``: 0 bounded, 0.5 random walk, 1 linear.

    Uses the running maximum of the error, so oscillations do not hide growth,
    and only the later nine tenths of the logarithmic time range.
    """
    t = np.asarray(t, dtype=float)
    err = np.maximum.accumulate(np.asarray(err, dtype=float))
    keep = (t > 0) & (err > 0)
    t, err = t[keep], err[keep]
    if t.size < 3:
        return float("nan")
    lo = np.exp(np.log(t[0]) + 0.1 * (np.log(t[-1]) - np.log(t[0])))
    sel = t >= lo
    return float(np.polyfit(np.log(t[sel]), np.log(err[sel]), 1)[0])


def ensemble_growth_exponent(t, errors, t_from, boots=400, seed=1):
    """Growth exponent of the RMS over an ensemble of runs, and its uncertainty.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Output times, > 0 (best spread evenly in ``log t``).
    errors : ndarray, shape (members, n)
        Signed errors (e.g. ``E / E0 - 1``) of each run at the times.
    t_from : float
        Fit only ``t >= t_from``: leave out the early part, where the bounded
        error of single steps, not accumulated rounding, dominates.

    Returns
    -------
    exponent : float
        Slope of ``log RMS`` against ``log t``: 0.5 for independent rounding
        errors (a random walk, Brouwer's law), 1 for an error of a persistent sign.
    spread : float
        Standard deviation of the exponent over ``boots`` resamplings of the
        members with replacement.  For a random walk it is about
        ``1 / (sqrt(members) ln(t_end / t_from))`` (the RMS of M members
        scatters by ``1 / sqrt(2 M)`` at each end of the fit): 0.05 for 16
        members over 2.4 decades.

    Notes
    -----
    One run's exponent scatters by about +-0.25 (its single random walk);
    the RMS over independent runs narrows that, which is why the exponent is
    fitted to the ensemble.  ``abs(errors.mean(axis=0))`` against the RMS tells
    a common drift (truncation, or rounding with a bias) from a random walk:
    for M independent runs it stays near ``RMS / sqrt(M)``.
    """
    t = np.asarray(t, dtype=float)
    errors = np.atleast_2d(np.asarray(errors, dtype=float))
    sel = t >= t_from

    def fit(e):
        rms = np.sqrt(np.mean(e[:, sel] ** 2, axis=0))
        ok = rms > 0
        return float(np.polyfit(np.log(t[sel][ok]), np.log(rms[ok]), 1)[0])

    exponent = fit(errors)
    rng = np.random.default_rng(seed)
    m = errors.shape[0]
    draws = [fit(errors[rng.integers(0, m, m)]) for _ in range(boots)]
    return exponent, float(np.std(draws))


def monitor_fields(rows, monitors, reference, scales, units):
    """A result's monitor fields from monitor ``rows`` (the compiled kernels'
    layout: energy, L, P, centre of mass), as Quantities, with the relative
    errors against ``reference`` (``scales``: energy and angular-momentum
    scales used where the reference is zero)."""
    q = units.quantity
    out = {}
    if "energy" in monitors:
        out["energy"] = q(rows[:, 0], "energy")
        out["energy_error"] = relative_error(rows[:, 0], reference[0], scale=scales[0])
    if "angular_momentum" in monitors:
        out["angular_momentum"] = q(rows[:, 1:4], "angular_momentum")
        out["angular_momentum_error"] = vector_relative_error(rows[:, 1:4], reference[1:4],
                                                              scales[1])
    if "momentum" in monitors:
        out["momentum"] = q(rows[:, 4:7], "momentum")
    if "center_of_mass" in monitors:
        out["center_of_mass"] = q(rows[:, 7:10], "length")
    return out
