"""Monitors of the conserved quantities, and fits of how their errors grow.

The quantities themselves are computed by the compiled kernels in
:mod:`orbits._kernels.invariants`, inside the stepping loop; this module
names them (each declared once, by its spec in :data:`MONITOR_SPECS`), turns
raw rows into relative errors, and fits drift laws.
"""

import astropy.units as u
import numpy as np

from ._kernels import invariants as _inv
from ._monitor_specs import BY_NAME, CHOSEN, MONITOR_SPECS, MonitorSpec, added_to, result_fields

__all__ = ["MONITORS", "CHAOS_MONITORS", "DEFAULT_MONITORS", "MONITOR_SPECS", "MonitorSpec",
           "CIRCULAR_E", "monitor_mask", "relative_error", "vector_relative_error",
           "error_series", "row_series", "row_errors", "growth_exponent",
           "ensemble_growth_exponent", "monitor_fields", "massless_energies",
           "massless_energy_errors"]

#: monitor name -> bit of the kernel mask
MONITORS = {s.name: s.bit for s in CHOSEN}

#: the monitors that need a tangent vector (orbits._kernels.variational)
CHAOS_MONITORS = tuple(s.name for s in CHOSEN if s.chaos)

DEFAULT_MONITORS = tuple(s.name for s in CHOSEN if s.default)

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
        The relative error at each value (dimensionless).

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
        The relative error of each vector (dimensionless).

    Examples
    --------
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
    # rows: the cheapest way to a run's monitor rows (benchmarks/RESULTS.md)
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


def error_series(name, values, reference, scales, added=None):
    """The relative error of monitor ``name`` at each row of its series, as its
    spec says (:attr:`MonitorSpec.error`).

    A scalar monitor's error is that of the series plus those added to it
    (the energy's, of ``E + W``): ``|(values + added) - (E0 + W0)|`` over
    ``|E0 + W0|`` (over its scale where that is 0), as
    :func:`relative_error` gives it, in one compiled pass over the rows; a
    vector's is :func:`vector_relative_error`.

    Parameters
    ----------
    name : str
        A monitor with an error (``"energy"``, ``"angular_momentum"``).
    values : array-like, shape (n,) or (n, 3)
        Its series, in the internal units.
    reference : array-like, shape (w,)
        The monitor row at the start (the kernels' layout; a row of 10 columns,
        written before the work was kept, counts it as 0).
    scales : sequence of float
        The simulation's error scales, indexed by :attr:`MonitorSpec.scale`.
    added : array-like, shape (n,), optional
        The series added to this one (the work), summed; default 0.

    Returns
    -------
    numpy.ndarray, shape (n,)
        One relative error (dimensionless) a row of ``values``.

    Examples
    --------
    >>> from orbits.monitors import error_series
    >>> start = [-1.0] + [0.0] * 13                     # E0 = -1, no work yet
    >>> error_series("energy", [-1.0, -1.5], start, (1.0, 1.0), added=[0.0, 0.5]).tolist()
    [0.0, 0.0]
    """
    spec = BY_NAME[name]
    reference = np.asarray(reference, dtype=float)
    if spec.error == "vector":
        return vector_relative_error(values, reference[spec.row_slice], scales[spec.scale])
    # the compiled pass takes writable float64 arrays of any stride
    values = np.require(np.asarray(values, dtype=float).reshape(-1), requirements="W")
    if added is None or np.ndim(added) == 0:
        added = np.full(values.shape[0], 0.0 if added is None else float(added))
    else:
        added = np.require(np.asarray(added, dtype=float).reshape(-1), requirements="W")
    ref = float(reference[spec.row_slice.start] + _added(reference, name))
    out = np.empty(values.shape[0])
    _inv.error_kernels()[0](values, added, ref, float(_denominator(ref, scales[spec.scale])),
                            out)
    return out


def monitor_fields(rows, monitors, reference, scales, units, work=False):
    """A result's monitor fields from monitor ``rows`` (the compiled kernels'
    layout, :data:`orbits._kernels.invariants.MONITOR_COLUMNS`: energy, L, P,
    centre of mass, work, chaos indicators), as Quantities (plain arrays for
    the dimensionless chaos indicators), with the relative errors against
    ``reference`` (``scales``: energy and angular-momentum scales used where
    the reference is zero).  Each monitor's fields are those its spec
    declares (:data:`MONITOR_SPECS`).

    The energy error is that of ``E + W``, the energy plus the work ``W`` that
    non-conservative force terms have taken out (zero without them), so that
    it measures the integration and not the dissipation.

    Parameters
    ----------
    rows : numpy.ndarray, shape (n, 14)
        Monitor rows in the internal units (rows of 10 columns, without the
        work, count it as zero; rows of 10 or 11, without the chaos
        indicators, give none).
    monitors : sequence of str
        The monitors that were recorded.
    reference : numpy.ndarray, shape (14,)
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
        monitor; ``megno``, ``lyapunov`` (1 / time) and ``fli`` with those
        monitors.

    Examples
    --------
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
    rows = np.asarray(rows, dtype=float)
    out = {}
    for name, spec in _fields(monitors, rows.shape[1], work):
        if name == spec.error_field:
            out[name] = row_errors(spec.name, rows, reference, scales)
        else:
            values = row_series(name, rows)
            if spec.kind == "dimensionless":
                out[name] = values.copy()
            else:
                if spec.adds_to is not None:
                    values = np.broadcast_to(values, rows.shape[:1]).copy()
                out[name] = u.Quantity(values, spec.unit(units), copy=False)
    return out


def monitor_field_names(monitors, columns, work=False):
    """The keys :func:`monitor_fields` returns for ``monitors``, rows of
    ``columns`` columns and ``work``, without computing them (a run's result
    computes its fields when they are first read)."""
    return tuple(name for name, _ in _fields(monitors, columns, work))


def _fields(monitors, columns, work):
    """``(field, spec)`` of :func:`monitor_fields`, in the order of
    :func:`~orbits._monitor_specs.result_fields` (what is derived from the
    outputs left out): the monitors recorded, their columns in rows of
    ``columns``, and the series added to them with ``work``."""
    for spec in CHOSEN:
        if spec.name not in monitors or columns < spec.row_slice.stop:
            continue
        added = {s.name: s for s in added_to(spec.name)} if work else {}
        for name in result_fields(spec):
            if name == spec.name or name == spec.error_field:
                yield name, spec
            elif name in added:
                yield name, added[name]


def row_series(name, rows):
    """The series of monitor ``name`` in monitor ``rows`` (n, w) (the kernels'
    layout), or its value in one row (w,): shape (n,) for a scalar, (n, 3)
    for a vector, a view of the rows.  A series added to another (the work)
    is 0 where the rows lack it (written before it was kept).

    Examples
    --------
    >>> from orbits.monitors import row_series
    >>> rows = np.arange(20.0).reshape(2, 10)           # rows without the work
    >>> row_series("angular_momentum", rows).tolist(), row_series("work", rows).tolist()
    ([[1.0, 2.0, 3.0], [11.0, 12.0, 13.0]], [0.0, 0.0])
    """
    spec = BY_NAME[name]
    rows = np.asarray(rows)
    where = spec.row_slice
    if rows.shape[-1] < where.stop and spec.adds_to is not None:
        return 0.0 if rows.ndim == 1 else np.zeros(rows.shape[0])
    values = rows[..., where]
    return values[..., 0] if spec.scalar else values


def row_errors(name, rows, reference, scales):
    """The relative error of monitor ``name`` at each of the monitor ``rows``
    (n, w): :func:`error_series` of its series and of those added to it.

    Examples
    --------
    >>> from orbits.monitors import row_errors
    >>> rows = np.zeros((2, 14))
    >>> rows[:, 0] = [-1.0, -1.5]                       # energy
    >>> rows[:, 10] = [0.0, 0.5]                        # work
    >>> row_errors("energy", rows, rows[0], (1.0, 1.0)).tolist()
    [0.0, 0.0]
    """
    return error_series(name, row_series(name, rows), reference, scales,
                        added=_added(rows, name))


def _added(rows, name):
    """The sum of the series added to monitor ``name``'s in monitor ``rows`` (or
    one row): the work, for the energy; 0 where there are none."""
    total = 0.0
    for spec in added_to(name):
        total = total + row_series(spec.name, rows)
    return total


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
