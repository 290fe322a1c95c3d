"""A result handed to other libraries: tables for pandas and xarray, and
plots with matplotlib (:mod:`orbits.plotting`), as :class:`~orbits.Result`'s
methods ``to_pandas``, ``to_xarray``, ``plot`` and ``plot_elements``.  Each
library is imported when it is first used, so that none is needed to run a
simulation.
"""

import astropy.units as u
import numpy as np

from ._monitor_specs import RESULT_FIELDS

__all__ = []


def to_pandas(result):
    """The outputs as a table, one row per output, units in the column names.

    Returns
    -------
    pandas.DataFrame
        Columns ``"time [d]"``; for each body ``"<name>.x [AU]"``, ``.y``,
        ``.z``, ``.vx [AU / d]``, ``.vy``, ``.vz`` (in the units of
        ``positions``, ``velocities`` and ``times``); then the monitors that
        were recorded: ``"energy [...]"``, ``"energy_error"``,
        ``"test_particle_energy_error"`` (with massless bodies),
        ``"angular_momentum.x [...]"`` ..., ``"angular_momentum_error"``,
        ``"momentum.x [...]"`` ..., ``"center_of_mass.x [...]"`` ....
        Dimensionless quantities have no bracket.  ``DataFrame.attrs``
        holds ``frame``, ``names``, ``masses`` (a list of floats),
        ``mass_unit`` and ``units`` (the unit system, as
        :meth:`~orbits.UnitSystem.to_dict` gives it).

    Raises
    ------
    ImportError
        pandas is not installed (``pip install pandas``).

    Examples
    --------
    >>> list(two_body.to_pandas().columns[:4])
    ['time [d]', 'Star.x [AU]', 'Star.y [AU]', 'Star.z [AU]']
    """
    try:
        import pandas as pd
    except ImportError:
        raise ImportError("Result.to_pandas needs pandas: pip install pandas") from None
    x, v = result.positions, result.velocities
    columns = [_label("time", result.times.unit)]
    data = [result.times.value[:, None]]
    n, nb = x.shape[0], x.shape[1]
    per_body = np.concatenate([x.value, v.value], axis=2)       # (n, N, 6)
    data.append(per_body.reshape(n, 6 * nb))
    for name in result.names:
        columns += [_label(f"{name}.{c}", x.unit) for c in "xyz"]
        columns += [_label(f"{name}.{c}", v.unit) for c in ("vx", "vy", "vz")]
    for key, values in _monitor_series(result):
        if values.ndim == 2:
            columns += [_label(f"{key}.{c}", getattr(values, "unit", None))
                        for c in "xyz"]
        else:
            columns.append(_label(key, getattr(values, "unit", None)))
        data.append(np.asarray(getattr(values, "value", values)).reshape(n, -1))
    df = pd.DataFrame(np.concatenate(data, axis=1), columns=columns)
    df.attrs.update(frame=result.frame, names=list(result.names),
                    masses=result.masses.value.tolist(),
                    mass_unit=result.masses.unit.to_string(), units=result.units.to_dict())
    return df


def to_xarray(result):
    """The outputs as an ``xarray.Dataset``, units in the variables' attributes.

    Returns
    -------
    xarray.Dataset
        Coordinates ``time`` (n), ``body`` (N names) and ``axis``
        (``"x", "y", "z"``); variables ``position`` and ``velocity``
        (time, body, axis), ``mass`` (body) and the monitors that were
        recorded (``energy``, ``energy_error``, ``angular_momentum``
        (time, axis), ...).  Each has a ``units`` attribute (astropy's
        spelling, ``""`` for dimensionless); the dataset's attributes say
        the ``frame``, the ``integrator`` and the unit system.

    Raises
    ------
    ImportError
        xarray is not installed (``pip install xarray``).

    Examples
    --------
    >>> two_body.positions.unit                     # the dataset's "units" of "position"
    Unit("AU")
    >>> ds = two_body.to_xarray()                   # doctest: +SKIP
    >>> ds["position"].attrs["units"]               # doctest: +SKIP
    'AU'
    """
    try:
        import xarray as xr
    except ImportError:
        raise ImportError("Result.to_xarray needs xarray: pip install xarray") from None

    def var(dims, q):
        unit = getattr(q, "unit", u.dimensionless_unscaled)
        return xr.Variable(dims, np.asarray(getattr(q, "value", q)),
                           attrs={"units": unit.to_string()})

    data = {"position": var(("time", "body", "axis"), result.positions),
            "velocity": var(("time", "body", "axis"), result.velocities),
            "mass": var(("body",), result.masses)}
    for key, values in _monitor_series(result):
        data[key] = var(("time", "axis") if values.ndim == 2 else ("time",), values)
    coords = {"time": var(("time",), result.times), "body": list(result.names),
              "axis": ["x", "y", "z"]}
    attrs = {"frame": "as integrated" if result.frame is None else result.frame,
             "integrator": str(result.integrator.get("name", "")),
             "status": str(result.status)}
    attrs.update({f"units_{k}": str(val) for k, val in result.units.to_dict().items()})
    return xr.Dataset(data, coords=coords, attrs=attrs)


def _monitor_series(result):
    """(name, series) of the monitors recorded at every output."""
    n = len(result.times)
    for key in RESULT_FIELDS:
        values = getattr(result, key, None)
        if values is not None and len(values) == n:
            yield key, values


def _label(name, unit):
    """``"name [unit]"``, or ``"name"`` for a dimensionless quantity."""
    text = "" if unit is None else u.Unit(unit).to_string()
    return f"{name} [{text}]" if text else name


def plot(result, frame=None, path=None, fig=None):
    """Orbits in the x-y plane in a chosen frame, and the invariants' errors.

    See :func:`orbits.plotting.plot_result`.

    Parameters
    ----------
    frame : str, optional
        As for :meth:`in_frame`: by default about the most massive body where
        it holds most of the mass, else barycentric.
    path : str or path-like, optional
        Also write the figure there (PNG).
    fig : matplotlib.figure.Figure, optional
        An empty figure to draw into (``matplotlib.pyplot.figure()`` for
        one that pyplot shows); default a new one pyplot does not manage.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> fig = planets.plot()
    >>> fig.axes[0].get_title()
    'orbits (x-y plane), about Sun'
    """
    # orbits.plotting, matplotlib's gateway, stands above the files, which hold
    # results (its plot_file reads one): a cycle, and the layers' contract
    # lists this import and the next
    from . import plotting
    return plotting.plot_result(result, path=path, frame=frame, fig=fig)


def plot_elements(result, bodies=None, primary=None, path=None, fig=None):
    """Semi-major axis, eccentricity and inclination against time.

    See :func:`orbits.plotting.plot_elements`.

    Parameters
    ----------
    bodies : sequence of str, optional
        Default: every body but ``primary`` (but the first when no primary
        is named), at most 12.
    primary : str, optional
        As for :meth:`elements`.
    path, fig
        As for :meth:`plot`.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> fig = planets.plot_elements()
    >>> [ax.get_ylabel() for ax in fig.axes]
    ['a [AU]', 'e', 'inc [deg]']
    """
    from . import plotting
    return plotting.plot_elements(result, bodies=bodies, primary=primary, path=path, fig=fig)
