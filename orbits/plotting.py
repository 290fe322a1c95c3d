"""Plots a person would rather look at than read (needs matplotlib).

* :func:`plot_result`: a run's orbits in the x-y plane, in a chosen frame, and
  the relative errors of its invariants against time;
* :func:`plot_elements`: semi-major axis, eccentricity and inclination against
  time;
* :func:`plot_orbits`: a sketch of a :class:`~orbits.BodySet`, each body on
  its osculating Keplerian orbit about its primary;
* :func:`plot_file`: :func:`plot_result` of an output file, as a PNG.

Figures are :class:`matplotlib.figure.Figure` objects made without pyplot, so
making one changes no global state (no backend switch, no figure left open);
a notebook shows one returned as the last value of a cell, and
``fig.savefig`` writes it.  Time axes are in seconds, days, years, kyr, Myr
or Gyr as the span of the run asks (:func:`time_unit`, the chooser of
:mod:`orbits.units` that the run summary uses too).
"""

import math
import pathlib

import astropy.units as u
import numpy as np

from ._kernels import elements as _elements
from .errors import ElementsError
from .io.h5md import OrbitsFileError, load
from .units import TIME_UNITS, time_unit

__all__ = ["plot_result", "plot_elements", "plot_orbits", "plot_file", "time_unit",
           "TIME_AXIS_UNITS", "MAX_BODIES_DRAWN", "MAX_BODIES_IN_LEGEND",
           "ORBIT_POINTS", "SPARSE_STEP"]

#: Units of a time axis: those of the run summary (:data:`orbits.units.TIME_UNITS`),
#: chosen by :func:`time_unit`.  A run of 1e5 years is drawn in kyr, one of a
#: month in days.
TIME_AXIS_UNITS = TIME_UNITS

#: Trajectories drawn at most (the first bodies of the set): a cluster of
#: thousands of stars would be one black blot and take seconds.
MAX_BODIES_DRAWN = 50

#: Above this many bodies a legend would cover the plot.
MAX_BODIES_IN_LEGEND = 12

#: Points per osculating orbit in :func:`plot_orbits`: a polygon of 721
#: vertices differs from an ellipse of eccentricity 0.9 by less than a line's width.
ORBIT_POINTS = 721

#: A body's outputs are drawn as dots, not joined, when the median distance
#: between consecutive ones exceeds this fraction of its median distance from
#: the origin (a chord of about 30 degrees of a circle): a line would join
#: points on different turns of the orbit into a mesh.
SPARSE_STEP = 0.5

# A hyperbola's branch runs to infinity: it is drawn out to the largest of
# these multiples of its pericentre distance and of its body's distance, or to
# the farthest body of the set from its primary.
_HYPERBOLA_REACH = (4.0, 2.0)

_PLANES = {"xy": (0, 1), "xz": (0, 2), "yz": (1, 2)}


def plot_result(result, path=None, frame=None, fig=None):
    """A run's orbits in the x-y plane, and its invariants' errors against time.

    Left: each body's path in the chosen frame (at most
    :data:`MAX_BODIES_DRAWN` bodies), a dot where it ends, the central body as
    a star at the origin; a body whose outputs are far apart along its orbit
    (:data:`SPARSE_STEP`: a long run with few outputs) is drawn as one dot per
    output.  Right: the relative energy and angular-momentum
    errors against the time since the start, on log axes.

    Parameters
    ----------
    result : Result
        A run's outputs (from :meth:`orbits.Simulation.run` or :func:`orbits.load`).
    path : str or path-like, optional
        Also write the figure there (PNG, 110 dpi).
    frame : str, optional
        ``"barycentric"``, ``"heliocentric"`` (about the most massive body) or
        a body's name; default about the most massive body where it holds most
        of the mass, else barycentric (see :meth:`orbits.Result.in_frame`).
    fig : matplotlib.figure.Figure, optional
        An empty figure to draw into, e.g. ``matplotlib.pyplot.figure()`` so
        that pyplot shows it; default a new figure that pyplot does not manage.

    Returns
    -------
    matplotlib.figure.Figure
        Two axes: the orbits (title ``"orbits (x-y plane), about <body>"`` or
        ``"..., barycentric"``; one line per body drawn, except the central
        one) and the errors.

    Raises
    ------
    ValueError
        The result holds no outputs.
    UnknownBodyError
        ``frame`` is neither a frame name nor a body's name.

    Examples
    --------
    >>> from orbits.plotting import plot_result
    >>> sim = orbits.Simulation(orbits.scenes.outer_solar_system(),
    ...                         integrator="leapfrog", dt=10 * u.day)
    >>> result = sim.run(until=100 * u.yr, outputs=50, progress=False)
    >>> fig = plot_result(result, frame="barycentric")
    >>> orbit_axes, error_axes = fig.axes
    >>> len(orbit_axes.lines), error_axes.get_xlabel()
    (6, 'time since start [yr]')
    """
    if not len(result.times):
        raise ValueError("the result holds no outputs: nothing to plot")
    framed = result.in_frame(frame)
    fig = _figure(figsize=(12, 5.5)) if fig is None else fig
    ax_orbit, ax_err = fig.subplots(1, 2)

    x = framed.positions
    unit = x.unit
    centre = framed.frame if framed.frame in framed.names else None
    for i, name in enumerate(framed.names[:MAX_BODIES_DRAWN]):
        if name == centre:
            ax_orbit.scatter([0.0], [0.0], marker="*", s=120, color="goldenrod",
                             edgecolor="k", linewidth=0.5, zorder=3, label=f"{name} (centre)")
            continue
        xy = x[:, i, :2].value
        if _sparse(xy):
            line, = ax_orbit.plot(xy[:, 0], xy[:, 1], ".", ms=2, label=name)
        else:
            line, = ax_orbit.plot(xy[:, 0], xy[:, 1], lw=0.8, label=name)
        ax_orbit.scatter(x[-1:, i, 0].value, x[-1:, i, 1].value, s=10, color=line.get_color(),
                         edgecolor="k", linewidth=0.4, zorder=3)
    ax_orbit.set_aspect("equal", adjustable="datalim")
    ax_orbit.set_xlabel(_label("x", unit))
    ax_orbit.set_ylabel(_label("y", unit))
    ax_orbit.set_title("orbits (x-y plane), " + _frame_words(framed.frame))
    if len(framed.names) <= MAX_BODIES_IN_LEGEND:
        ax_orbit.legend(fontsize=8, loc="upper right")

    t = result.times
    tu = time_unit(t[-1] - t[0])
    since = (t - t[0]).to_value(tu)
    keep = since > 0
    drawn = False
    for label, err in (("energy", result.energy_error),
                       ("angular momentum", result.angular_momentum_error)):
        if err is not None and len(err) == len(t):
            e = np.asarray(err)[keep]
            ax_err.loglog(since[keep], np.where(e > 0, e, np.nan), lw=1,
                          label=f"|{label} error| (relative)")
            drawn = True
    ax_err.set_xlabel(_label("time since start", tu))
    ax_err.set_ylabel("relative error")
    ax_err.set_title(f"{result.integrator['name']}: conservation")
    if drawn:
        ax_err.legend(fontsize=8)
    else:
        ax_err.text(0.5, 0.5, "no monitors recorded", ha="center", transform=ax_err.transAxes)
    fig.tight_layout()
    _save(fig, path)
    return fig


def plot_elements(result, bodies=None, primary=None, path=None, fig=None):
    """Osculating semi-major axis, eccentricity and inclination against time.

    Parameters
    ----------
    result : Result
        A run's outputs.
    bodies : sequence of str, optional
        The bodies to draw, one line each on every panel.  Default: every body
        but ``primary`` (but the first when no primary is named), at most
        :data:`MAX_BODIES_IN_LEGEND`.
    primary : str, optional
        The body the orbits are about; default the centre of mass of the bodies
        before each one (see :meth:`orbits.Result.elements`).
    path, fig
        As for :func:`plot_result`.

    Returns
    -------
    matplotlib.figure.Figure
        Three axes sharing the time axis: ``a`` (the run's length unit), ``e``
        and ``inc`` (deg), labelled with their units; the time axis in days,
        yr, kyr or Myr as the span asks (:func:`time_unit`).

    Raises
    ------
    ValueError
        The result holds no outputs.
    UnknownBodyError, BodyError, ElementsError
        As :meth:`orbits.Result.elements` raises them.

    Examples
    --------
    The outer solar system over a century (``planets``, as in :class:`orbits.Result`):

    >>> from orbits.plotting import plot_elements
    >>> fig = plot_elements(planets, bodies=["Jupiter", "Saturn"], primary="Sun")
    >>> [len(ax.lines) for ax in fig.axes], fig.axes[-1].get_xlabel()
    ([2, 2, 2], 'time [yr]')
    """
    if not len(result.times):
        raise ValueError("the result holds no outputs: nothing to plot")
    if bodies is None:
        candidates = result.names[1:] if primary is None else result.names
        bodies = [n for n in candidates if n != primary][:MAX_BODIES_IN_LEGEND]
    elif isinstance(bodies, str):
        bodies = [bodies]
    series = {name: result.elements(name, primary=primary) for name in bodies}

    t = result.times
    tu = time_unit(t[-1] - t[0])
    time = t.to_value(tu)
    fig = _figure(figsize=(8, 7.5)) if fig is None else fig
    ax_a, ax_e, ax_i = fig.subplots(3, 1, sharex=True)
    length = None
    for name, el in series.items():
        length = el["a"].unit
        ax_a.plot(time, el["a"].value, lw=1, label=name)
        ax_e.plot(time, el["e"].value, lw=1, label=name)
        ax_i.plot(time, el["inc"].to_value(u.deg), lw=1, label=name)
    ax_a.set_ylabel(_label("a", length if length is not None else u.one))
    ax_e.set_ylabel("e")
    ax_i.set_ylabel("inc [deg]")
    ax_i.set_xlabel(_label("time", tu))
    about = (f"about {primary}" if primary is not None
             else "about the centre of mass of the bodies before each (Jacobi)")
    ax_a.set_title(f"osculating elements, {about}")
    if 0 < len(series) <= MAX_BODIES_IN_LEGEND:
        ax_a.legend(fontsize=8, loc="best")
    fig.tight_layout()
    _save(fig, path)
    return fig


def plot_orbits(bodies, primary=None, plane="xy", ax=None, path=None):
    """A sketch of a body set: each body on its osculating Keplerian orbit.

    Each body's orbit about its primary, from its elements at this instant
    (:meth:`orbits.BodySet.elements`), is drawn as a closed ellipse, or as the
    near part of a hyperbola's branch, around where the primary is now; the
    body is a dot on it.  Bodies with no orbit to draw (the first body, the
    named primary) are stars.

    Parameters
    ----------
    bodies : BodySet
    primary : str, optional
        The body every orbit is about.  Default: for each body the centre of
        mass of the bodies before it in the set (Jacobi-like), as
        :meth:`~orbits.BodySet.elements` does.
    plane : {"xy", "xz", "yz"}
        The coordinate plane projected on.
    ax : matplotlib.axes.Axes, optional
        Draw into these axes; default a new figure.
    path : str or path-like, optional
        Also write the figure there (PNG, 110 dpi).

    Returns
    -------
    matplotlib.figure.Figure
        One line per drawn orbit, labelled with the body's name; axes labelled
        in the set's length unit.

    Raises
    ------
    ValueError
        ``plane`` is not one of the three.
    UnknownBodyError
        ``primary`` is not in the set.

    Notes
    -----
    A point at true anomaly ``f`` is :func:`orbits._kernels.elements.elements_to_state`
    of ``(a, e, inc, Omega, omega, f)`` with ``mu = G (m_primary + m)``, plus the
    primary's position: ``f`` over a full turn for an ellipse, and for a
    hyperbola over ``|f| <= arccos((p / R - 1) / e)``, ``p = a (1 - e^2)``, out
    to ``R``: the largest of 4 pericentre distances, twice the body's distance,
    and the distance of the set's farthest body from the primary.

    Examples
    --------
    >>> from orbits.plotting import plot_orbits
    >>> fig = plot_orbits(orbits.scenes.outer_solar_system(), primary="Sun")
    >>> ax = fig.axes[0]
    >>> len(ax.lines), ax.get_xlabel()
    (5, 'x [AU]')
    """
    try:
        i0, i1 = _PLANES[plane]
    except (KeyError, TypeError):
        raise ValueError(f"unknown plane {plane!r}; expected one of "
                         f"{', '.join(_PLANES)}") from None
    if primary is not None:
        bodies.index(primary)   # UnknownBodyError, naming the bodies, when unknown
    U = bodies.units
    unit = U.unit("length")
    x = bodies.positions.to_value(unit)
    m = bodies.masses.to_value(U.unit("mass"))
    names = bodies.names
    if ax is None:
        fig = _figure(figsize=(7, 7))
        ax = fig.subplots()
    else:
        fig = ax.figure

    for i, name in enumerate(names[:MAX_BODIES_DRAWN]):
        has_primary = (name != primary) if primary is not None else bool(np.any(m[:i] > 0))
        curve = None
        if has_primary:
            try:
                el = bodies.elements(name, primary=primary)
            except ElementsError:
                el = None   # a radial or parabolic orbit: the body is drawn alone
            if el is not None:
                if primary is None:
                    mp = m[:i].sum()
                    centre = (m[:i] @ x[:i]) / mp
                else:
                    j = names.index(primary)
                    mp, centre = m[j], x[j]
                reach = max(_HYPERBOLA_REACH[1] * np.linalg.norm(x[i] - centre),
                            np.linalg.norm(x - centre, axis=1).max())
                curve = centre + _orbit_curve(U.G * (mp + m[i]), el, U, reach)
        if curve is None:
            ax.scatter([x[i, i0]], [x[i, i1]], marker="*", s=120, color="goldenrod",
                       edgecolor="k", linewidth=0.5, zorder=3, label=name)
            continue
        line, = ax.plot(curve[:, i0], curve[:, i1], lw=1, label=name)
        ax.scatter([x[i, i0]], [x[i, i1]], s=18, color=line.get_color(), edgecolor="k",
                   linewidth=0.5, zorder=3)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(_label(plane[0], unit))
    ax.set_ylabel(_label(plane[1], unit))
    about = (f"about {primary}" if primary is not None
             else "Jacobi (about the interior centre of mass)")
    ax.set_title(f"osculating orbits ({plane[0]}-{plane[1]} plane), {about}")
    if len(names) <= MAX_BODIES_IN_LEGEND:
        ax.legend(fontsize=8, loc="upper right")
    if fig.axes == [ax]:
        fig.tight_layout()
    _save(fig, path)
    return fig


def plot_file(path, out=None, frame=None):
    """Plot an output file with :func:`plot_result`; returns the PNG's path.

    Parameters
    ----------
    path : str or path-like
        An HDF5 output file.
    out : str or path-like, optional
        The PNG; default next to the file, with the suffix ``.png``.
    frame : str, optional
        As for :func:`plot_result`.

    Returns
    -------
    pathlib.Path

    Raises
    ------
    OrbitsFileError
        The file cannot be read or holds no outputs.
    UnknownBodyError
        ``frame`` is neither a frame name nor a body's name.

    Examples
    --------
    >>> from orbits.plotting import plot_file
    >>> plot_file("run.h5", frame="barycentric")          # doctest: +SKIP
    PosixPath('run.png')
    """
    out = pathlib.Path(out) if out else pathlib.Path(path).with_suffix(".png")
    result = load(path)
    if not len(result.times):
        raise OrbitsFileError(f"{path}: holds no outputs ({result.status}): nothing to plot")
    plot_result(result, path=out, frame=frame)
    return out


# -- helpers ----------------------------------------------------------------------
def _figure(**kwargs):
    try:
        from matplotlib.figure import Figure
    except ImportError:
        raise ImportError("plots need matplotlib: pip install matplotlib "
                          "(or pip install \"orbits[plot]\")") from None
    return Figure(**kwargs)


def _save(fig, path):
    if path is not None:
        fig.savefig(path, dpi=110)


def _label(name, unit):
    text = u.Unit(unit).to_string()
    return f"{name} [{text}]" if text else name


def _sparse(xy):
    """Whether outputs (n, 2) are too far apart along the path to be joined."""
    if len(xy) < 3:
        return False
    step = np.median(np.hypot(*np.diff(xy, axis=0).T))
    return bool(step > SPARSE_STEP * np.median(np.hypot(*xy.T)))


def _frame_words(frame):
    if frame == "barycentric":
        return "barycentric"
    return "as integrated" if frame is None else f"about {frame}"


def _orbit_curve(mu, el, units, reach):
    """Relative positions (k, 3) along the osculating orbit of elements ``el``;
    a hyperbola out to distance ``reach`` (or 4 pericentre distances)."""
    a = el["a"].to_value(units.unit("length"))
    e = float(el["e"])
    angles = [el[k].to_value(u.rad) for k in ("inc", "Omega", "omega")]
    if e < 1.0:
        f = np.linspace(-math.pi, math.pi, ORBIT_POINTS)
    else:
        q = a * (1.0 - e)
        reach = max(_HYPERBOLA_REACH[0] * q, reach)
        p = a * (1.0 - e * e)
        f_max = math.acos(min(1.0, max(-1.0, (p / reach - 1.0) / e)))
        f = np.linspace(-f_max, f_max, ORBIT_POINTS)
    elems = np.empty((f.size, 6))
    elems[:, :5] = [a, e, *angles]
    elems[:, 5] = f
    pos = np.empty((f.size, 3))
    vel = np.empty((f.size, 3))
    status = np.zeros(f.size, dtype=np.int64)
    _elements.elements_to_state_many(np.full(f.size, mu), elems, pos, vel, status)
    pos[status != 0] = np.nan
    return pos
