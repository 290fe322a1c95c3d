"""Monitors of the conserved quantities, and fits of how their errors grow.

The quantities themselves are computed by the compiled kernels in
:mod:`orbits._kernels.invariants`, inside the stepping loop; this module
names them, turns raw rows into relative errors, and fits drift laws.
"""

import numpy as np

from ._kernels import invariants as _inv

__all__ = ["MONITORS", "CHAOS_MONITORS", "DEFAULT_MONITORS", "CIRCULAR_E", "monitor_mask",
           "relative_error", "vector_relative_error", "growth_exponent",
           "ensemble_growth_exponent", "monitor_fields", "massless_energies",
           "massless_energy_errors"]

#: monitor name -> bit of the kernel mask
MONITORS = {
    "energy": _inv.ENERGY,
    "angular_momentum": _inv.ANGULAR_MOMENTUM,
    "momentum": _inv.MOMENTUM,
    "center_of_mass": _inv.CENTER_OF_MASS,
    "megno": _inv.MEGNO,
    "lyapunov": _inv.LYAPUNOV,
    "fli": _inv.FLI,
}

#: the monitors that need a tangent vector (orbits._kernels.variational)
CHAOS_MONITORS = ("megno", "lyapunov", "fli")

DEFAULT_MONITORS = ("energy", "angular_momentum")

#: eccentricity below which two massive bodies count as a circular binary, so
#: that their test particles keep the Jacobi integral (the circular restricted
#: three-body problem); a binary of eccentricity e changes it by O(e)
CIRCULAR_E = 1e-8


def monitor_mask(names):
    """Bit mask for the named monitors; unknown names are an error listing the valid ones.

    Parameters
    ----------
    names : iterable of str
        Keys of :data:`MONITORS`.

    Returns
    -------
    int

    Raises
    ------
    ValueError
        A name is not a monitor.

    Examples
    --------
    >>> from orbits.monitors import MONITORS, monitor_mask
    >>> mask = monitor_mask(["energy", "angular_momentum"])
    >>> mask == MONITORS["energy"] | MONITORS["angular_momentum"]
    True
    >>> monitor_mask([])
    0
    """
    mask = 0
    for name in names:
        try:
            mask |= MONITORS[name]
        except KeyError:
            raise ValueError(f"unknown monitor {name!r}; valid: {', '.join(MONITORS)}") from None
    return mask


def relative_error(values, reference, scale=None):
    """``|values - reference| / |reference|``; ``scale`` replaces ``|reference|`` when it is 0.

    Parameters
    ----------
    values : array-like, shape (n,)
        The monitored quantity (an energy, say) as plain floats in one unit.
    reference : float
        Its value at the start, in the same unit.
    scale : float, optional
        Denominator where ``reference`` is 0 (same unit); default 1.

    Returns
    -------
    numpy.ndarray, shape (n,)
        Dimensionless.

    Examples
    --------
    >>> from orbits.monitors import relative_error
    >>> relative_error([-1.0, -1.001, -0.999], -1.0).round(6)
    array([0.   , 0.001, 0.001])
    >>> relative_error([0.0, 0.5], 0.0, scale=2.0)     # zero reference: against the scale
    array([0.  , 0.25])
    """
    return np.abs(np.asarray(values) - reference) / _denominator(reference, scale)


def _denominator(reference, scale):
    # relative_error's: |reference|, or the scale where the reference is 0
    return abs(reference) if reference != 0 else (scale or 1.0)


def vector_relative_error(values, reference, scale):
    """``|L - L0| / |L0|`` for vectors of shape (n, 3).

    A system with zero total angular momentum (the Pythagorean problem) has
    no relative error; there ``scale`` (sum of ``m |x| |v|`` at the start) is the
    denominator, so the figure still says how large the error is against the
    system's own angular-momentum budget.

    Parameters
    ----------
    values : array-like, shape (n, 3)
        The vectors (angular momenta) in one unit.
    reference : array-like, shape (3,)
        The vector at the start, same unit.
    scale : float
        Denominator where ``|reference|`` is zero (same unit).

    Returns
    -------
    numpy.ndarray, shape (n,)
        Dimensionless.

    Examples
    --------
    >>> import numpy as np
    >>> from orbits.monitors import vector_relative_error
    >>> L = np.array([[0.0, 0.0, 1.0], [0.0, 1e-6, 1.0]])
    >>> vector_relative_error(L, L[0], scale=1.0).tolist()
    [0.0, 1e-06]
    """
    ref = np.asarray(reference, dtype=float)
    norm = np.linalg.norm(ref)
    denom = norm if norm > 1e-14 * scale else scale
    # the norm of each row summed component by component, as np.linalg.norm
    # sums a row of three (the same floats), in one compiled pass over the
    # rows: a norm along an axis of three took 5 ms for 10^5 rows, numpy's
    # whole columns 1.6 ms (the monitor rows of a run), the pass 0.6 ms
    values = np.asarray(values, dtype=float)
    rows = values.reshape(-1, 3)
    out = np.empty(rows.shape[0])
    _inv.error_kernels()[1](rows, ref, float(denom), out)
    return out.reshape(values.shape[:-1])


def growth_exponent(t, err):
    """Slope of ``log err`` against ``log t``: 0 bounded, 0.5 random walk, 1 linear.

    Uses the running maximum of the error, so oscillations do not hide growth,
    and only the later nine tenths of the logarithmic time range.

    Parameters
    ----------
    t : array-like, shape (n,)
        Times since the start, in any one unit (only their ratios matter).
    err : array-like, shape (n,)
        Relative errors (dimensionless) at those times.

    Returns
    -------
    float
        NaN with fewer than three positive points.

    Examples
    --------
    >>> import numpy as np
    >>> from orbits.monitors import growth_exponent
    >>> t = np.logspace(0, 4, 50)
    >>> round(growth_exponent(t, 1e-12 * t), 6), round(growth_exponent(t, 1e-12 * np.sqrt(t)), 6)
    (1.0, 0.5)
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

    Examples
    --------
    >>> import numpy as np
    >>> from orbits.monitors import ensemble_growth_exponent
    >>> rng = np.random.default_rng(0)
    >>> steps = rng.normal(size=(16, 10000)) * 1e-16          # 16 random walks
    >>> walks = np.cumsum(steps, axis=1)
    >>> t = np.arange(1, 10001, dtype=float)
    >>> keep = np.unique(np.geomspace(1, 10000, 60).astype(int)) - 1
    >>> exponent, spread = ensemble_growth_exponent(t[keep], walks[:, keep], t_from=10)
    >>> bool(abs(exponent - 0.5) < 3 * spread), bool(spread < 0.1)
    (True, True)
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


def monitor_fields(rows, monitors, reference, scales, units, work=False):
    """A result's monitor fields from monitor ``rows`` (the compiled kernels'
    layout, :data:`orbits._kernels.invariants.MONITOR_COLUMNS`: energy, L, P,
    centre of mass, work), as Quantities, with the relative errors against
    ``reference`` (``scales``: energy and angular-momentum scales used where
    the reference is zero).

    The energy error is that of ``E + W``, the energy plus the work ``W`` that
    non-conservative force terms have taken out (zero without them), so that
    it measures the integration and not the dissipation.

    Parameters
    ----------
    rows : numpy.ndarray, shape (n, 11)
        Monitor rows in the internal units (rows of 10 columns, without the
        work, count it as zero).
    monitors : sequence of str
        The monitors that were recorded.
    reference : numpy.ndarray, shape (11,)
        The row at the start.
    scales : tuple of float
        Energy and angular-momentum scales (internal units).
    units : UnitSystem
        The units of the rows.
    work : bool
        Also return the work series (for a simulation with non-conservative terms).

    Returns
    -------
    dict
        ``energy`` (energy), ``angular_momentum`` (angular momentum), ``momentum``
        (momentum) and ``center_of_mass`` (length) as Quantities, and
        ``energy_error`` and ``angular_momentum_error`` (dimensionless arrays), for
        the monitors recorded; ``work`` (energy) with ``work`` and the energy
        monitor.

    Examples
    --------
    >>> import numpy as np
    >>> import orbits
    >>> from orbits.monitors import monitor_fields
    >>> rows = np.zeros((2, 11))
    >>> rows[:, 0] = [-1.0, -1.000001]                  # energy
    >>> rows[:, 3] = [2.0, 2.0]                         # L_z
    >>> out = monitor_fields(rows, ("energy", "angular_momentum"), rows[0], (1.0, 1.0),
    ...                      orbits.UnitSystem())
    >>> out["energy"].unit
    Unit("AU2 solMass / d2")
    >>> out["energy_error"].round(9).tolist(), out["angular_momentum_error"].tolist()
    ([0.0, 1e-06], [0.0, 0.0])
    >>> rows[:, 10] = [0.0, 0.000001]                   # work: the energy drag took out
    >>> out = monitor_fields(rows, ("energy",), rows[0], (1.0, 1.0), orbits.UnitSystem(),
    ...                      work=True)
    >>> out["work"].value.tolist(), out["energy_error"].round(9).tolist()
    ([0.0, 1e-06], [0.0, 0.0])
    """
    q = units.quantity
    out = {}
    rows = np.asarray(rows, dtype=float)
    if "energy" in monitors:
        w = _work_column(rows)
        out["energy"] = q(rows[:, 0], "energy")
        ref = reference[0] + float(_work_column(reference))
        # relative_error of E + W in one pass over the rows
        err = np.empty(rows.shape[0])
        _inv.error_kernels()[0](rows[:, 0], w, float(ref),
                                float(_denominator(ref, scales[0])), err)
        out["energy_error"] = err
        if work:
            out["work"] = q(np.broadcast_to(w, rows[:, 0].shape).copy(), "energy")
    if "angular_momentum" in monitors:
        out["angular_momentum"] = q(rows[:, 1:4], "angular_momentum")
        out["angular_momentum_error"] = vector_relative_error(rows[:, 1:4], reference[1:4],
                                                              scales[1])
    if "momentum" in monitors:
        out["momentum"] = q(rows[:, 4:7], "momentum")
    if "center_of_mass" in monitors:
        out["center_of_mass"] = q(rows[:, 7:10], "length")
    col = _inv.MONITOR_COLUMNS.index("megno")
    if rows.shape[1] > col:
        if "megno" in monitors:
            out["megno"] = rows[:, col].copy()
        if "lyapunov" in monitors:
            out["lyapunov"] = rows[:, col + 1] / q(1.0, "time")
        if "fli" in monitors:
            out["fli"] = rows[:, col + 2].copy()
    return out


def monitor_field_names(monitors, columns, work=False):
    """The keys :func:`monitor_fields` returns for ``monitors``, rows of
    ``columns`` columns and ``work``, without computing them (a run's result
    computes its fields when they are first read)."""
    names = []
    if "energy" in monitors:
        names += ["energy", "energy_error"] + (["work"] if work else [])
    if "angular_momentum" in monitors:
        names += ["angular_momentum", "angular_momentum_error"]
    names += [k for k in ("momentum", "center_of_mass") if k in monitors]
    if columns > _inv.MONITOR_COLUMNS.index("megno"):
        names += [k for k in ("megno", "lyapunov", "fli") if k in monitors]
    return tuple(names)


def _work_column(rows):
    """The work column of monitor rows (or of one row); 0.0 where the rows have
    none (written before it was kept)."""
    rows = np.asarray(rows)
    if rows.shape[-1] > _inv.WORK_COLUMN:
        return rows[..., _inv.WORK_COLUMN]
    return 0.0 if rows.ndim == 1 else np.zeros(rows.shape[0])


def massless_energies(x, v, m, G, masses=None):
    """Each test particle's specific energy at every output, in the form its
    motion keeps.

    The energy monitor sums ``m E`` and cannot see a massless body; this is
    its measure for them, computed from output states.  With two massive
    bodies on a circular orbit (eccentricity below :data:`CIRCULAR_E` at the
    first output) it is the Jacobi integral of the circular restricted
    three-body problem, ::

        E_J = |v'|^2 / 2 - sum_j G m_j / |x - x_j| - Omega . (x' x v')

    with ``x'``, ``v'`` relative to the pair's barycentre and ``Omega = r x u
    / |r|^2`` the pair's angular velocity (``r``, ``u`` its relative
    position and velocity), a constant of the motion.  Otherwise it is the
    Kepler energy about the primary, the most massive body, ::

        E = |v - v_p|^2 / 2 - G m_p / |x - x_p|

    a constant of the motion with one massive body; with more, the others'
    pull changes it by about their mass ratio to the primary.  Newtonian
    gravity only: force terms that act on test particles change either.

    Parameters
    ----------
    x, v : numpy.ndarray, shape (n, N, 3)
        Positions and velocities at n outputs, in one unit system.
    m : numpy.ndarray, shape (N,)
        Masses at the start: the test particles are the bodies of mass 0.
    G : float
        The gravitational constant in that unit system.
    masses : numpy.ndarray, shape (n, N), optional
        Masses at each output where collisions changed them (NaN for a body
        merged away, whose positions are NaN too).

    Returns
    -------
    kind : str or None
        ``"jacobi"`` or ``"kepler"``; None, and the rest empty, without test
        particles or without a massive body.
    primary : int or None
        Index of the primary (``"kepler"``); None for ``"jacobi"``.
    index : numpy.ndarray, shape (k,)
        Indices of the test particles.
    energy : numpy.ndarray, shape (n, k)
        Their specific energies (energy per mass in the unit system).
    scale : numpy.ndarray, shape (k,)
        The sum of the magnitudes of its terms at the first output: what the
        energy is relative to where it is 0 there.

    Examples
    --------
    >>> import numpy as np
    >>> from orbits.monitors import massless_energies
    >>> x = np.array([[[0.0, 0, 0], [1.0, 0, 0]]])      # a star and, at r = 1,
    >>> v = np.array([[[0.0, 0, 0], [0.0, 1, 0]]])      # a particle at v = 1
    >>> kind, primary, index, energy, scale = massless_energies(x, v, [1.0, 0.0], 1.0)
    >>> kind, primary, index.tolist(), energy.tolist(), scale.tolist()
    ('kepler', 0, [1], [[-0.5]], [1.5])
    """
    m = np.asarray(m, dtype=float)
    index = np.flatnonzero(m == 0)
    massive = np.flatnonzero(m > 0)
    n = x.shape[0]
    if index.size == 0 or massive.size == 0:
        return None, None, index, np.empty((n, 0)), np.empty(0)
    mt = np.broadcast_to(m, (n, m.size)) if masses is None else np.nan_to_num(masses)
    gm = G * mt[:, massive]                                    # (n, j)
    xt, vt = x[:, index], v[:, index]                          # (n, k, 3)
    # (n, k) distances to every massive body and the Newtonian potential
    d = np.linalg.norm(xt[:, :, None] - x[:, None, massive], axis=-1)
    if massive.size == 2 and _eccentricity(x[0], v[0], gm[0], massive) < CIRCULAR_E:
        a, b = massive
        w = gm / gm.sum(axis=1, keepdims=True)
        X = w[:, 0, None] * x[:, a] + w[:, 1, None] * x[:, b]
        V = w[:, 0, None] * v[:, a] + w[:, 1, None] * v[:, b]
        r, u = x[:, b] - x[:, a], v[:, b] - v[:, a]
        omega = np.cross(r, u) / np.sum(r * r, axis=1)[:, None]
        xp, vp = xt - X[:, None], vt - V[:, None]
        kinetic = 0.5 * np.sum(vp * vp, axis=-1)
        potential = np.sum(gm[:, None, :] / d, axis=-1)
        spin = np.einsum("nd,nkd->nk", omega, np.cross(xp, vp))
        energy = kinetic - potential - spin
        scale = (kinetic + potential + np.abs(spin))[0]
        return "jacobi", None, index, energy, scale
    p = int(massive[np.argmax(m[massive])])
    j = int(np.flatnonzero(massive == p)[0])
    u = vt - v[:, p, None]
    kinetic = 0.5 * np.sum(u * u, axis=-1)
    potential = gm[:, j, None] / d[:, :, j]
    return "kepler", p, index, kinetic - potential, (kinetic + potential)[0]


def massless_energy_errors(x, v, m, G, masses=None):
    """The relative change of each test particle's energy (as
    :func:`massless_energies` defines it) since the first output,
    ``|E - E_0| / |E_0|`` (``E_0 = 0``: over the scale of its terms).

    Parameters
    ----------
    x, v, m, G, masses
        As for :func:`massless_energies`.

    Returns
    -------
    kind, primary, index
        As :func:`massless_energies` returns them.
    errors : numpy.ndarray, shape (n, k)
        Dimensionless; NaN after a collision merged the particle away.

    Examples
    --------
    >>> import numpy as np
    >>> from orbits.monitors import massless_energy_errors
    >>> x = np.array([[[0.0, 0, 0], [1.0, 0, 0]], [[0.0, 0, 0], [0.0, 1, 0]]])
    >>> v = np.array([[[0.0, 0, 0], [0.0, 1, 0]], [[0.0, 0, 0], [-1.1, 0, 0]]])
    >>> kind, primary, index, errors = massless_energy_errors(x, v, [1.0, 0.0], 1.0)
    >>> kind, errors[:, 0].round(6).tolist()
    ('kepler', [0.0, 0.21])
    """
    kind, primary, index, energy, scale = massless_energies(x, v, m, G, masses)
    if kind is None:
        return kind, primary, index, energy
    e0 = energy[0]
    with np.errstate(invalid="ignore"):
        errors = np.abs(energy - e0) / np.where(e0 != 0, np.abs(e0), scale)
    return kind, primary, index, errors


def _eccentricity(x, v, gm, pair):
    """Eccentricity of the relative orbit of the two bodies ``pair`` (one
    state, ``gm`` their ``G m``)."""
    a, b = pair
    r, u = x[b] - x[a], v[b] - v[a]
    mu = gm[0] + gm[1]
    e = np.cross(u, np.cross(r, u)) / mu - r / np.linalg.norm(r)
    return float(np.linalg.norm(e))
