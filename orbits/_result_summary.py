"""How well a run kept its invariants, in numbers and in words: the largest
relative errors of the monitors, the test particles' energies, and the
summary (text, and HTML for Jupyter) of a :class:`~orbits.Result`, whose
methods of those names these functions are.
"""

import html

import astropy.units as u
import numpy as np

from ._monitor_specs import BY_NAME
from .monitors import massless_energy_errors
from .units import format_time, time_unit

__all__ = []


def max_energy_error(result):
    """Largest relative energy error seen, at outputs or by the in-loop monitor.

    Returns
    -------
    float or None
        Dimensionless; None where the energy was not monitored.

    Examples
    --------
    >>> err = two_body.max_energy_error()
    >>> bool(0 < err < 1e-10), bool(err == two_body.energy_error.max())
    (True, True)
    """
    return result._max_error("energy")


def max_angular_momentum_error(result):
    """Largest relative angular-momentum error seen.

    Returns
    -------
    float or None
        Dimensionless; None where the angular momentum was not monitored.

    Examples
    --------
    >>> bool(two_body.max_angular_momentum_error() < 1e-13)
    True
    """
    return result._max_error("angular_momentum")


def _max_error(result, name):
    """The largest relative error of monitor ``name`` seen: at the outputs,
    in the in-loop series, and over the whole run where the result holds
    only part of it (:attr:`largest_errors`); None where it was not
    monitored."""
    field = BY_NAME[name].error_field
    recorded = (result.largest_errors or {}).get(name)
    return _largest(getattr(result, field), result.monitor and result.monitor.get(field),
                    None if recorded is None else np.array([recorded]))


def particle_energy_error(result):
    """The massless bodies' largest relative energy change at each output
    (see :class:`~orbits.Result`'s attributes), or None.

    Examples
    --------
    >>> b = orbits.scenes.kepler()
    >>> b.add("comet", mass=0 * u.Msun, primary="Star", a=3 * u.au, e=0.9)
    >>> sim = orbits.Simulation(b, "ias15")
    >>> result = sim.run(until=10 * u.yr, outputs=11, progress=False)
    >>> err = result.test_particle_energy_error
    >>> err.shape, bool(err.max() < 1e-13)
    ((11,), True)
    >>> line = result.summary().splitlines()[7]      # the planet's orbit is circular
    >>> line[:45], line.split("(")[1]
    ('test particles  largest relative energy error', 'comet; Jacobi integral)')
    """
    found = _massless_errors(result)
    return None if found is None else np.fmax.reduce(found[3], axis=1)


def _massless_errors(result):
    """(kind, primary's name, the massless bodies' names, errors (n, k)) of
    :func:`orbits.monitors.massless_energy_errors` on the outputs, made once;
    None where ``test_particle_energy_error`` is."""
    if "_massless" not in result.__dict__:
        result.__dict__["_massless"] = _make_massless_errors(result)
    return result.__dict__["_massless"]


def _make_massless_errors(result):
    if "energy" not in (getattr(result, "monitors", None) or ()):
        return None
    m0 = result.masses.value
    if not np.any(m0 == 0) or not np.any(m0 > 0) or not len(result.times):
        return None
    if result.start_time is not None and result.start_time != result.times[0]:
        return None             # the last output of a run written to a file
    U, x, v, m = result._internal()
    masses = (None if result.masses_at_outputs is None
              else result.masses_at_outputs.to_value(U.unit("mass")))
    kind, primary, index, errors = massless_energy_errors(x, v, m, U.G, masses)
    return (kind, None if primary is None else result.names[primary],
            [result.names[i] for i in index], errors)


def summary(result):
    """A few lines for a person: what ran, how long, and how well it kept the invariants.

    Returns
    -------
    str

    Examples
    --------
    >>> lines = two_body.summary().splitlines()
    >>> lines[0]
    'integrator      leapfrog (order 2, symplectic)'
    >>> [line.split()[0] for line in lines[1:]]
    ['bodies', 'time', 'steps', 'units', 'forces', 'energy', 'ang.', 'status']
    """
    opts = ", ".join(f"{k[7:]}={v}" for k, v in result.integrator.items()
                     if k.startswith("option."))
    wall_text = _wall_text(result.wall_time, result.__dict__.get("compile_time"), result.steps)
    forces = ("force evaluations not recorded" if result.force_evaluations is None
              else f"{result.force_evaluations} force evaluations")
    if len(result.times):
        start = result.times[0] if result.start_time is None else result.start_time
        end = result.times[-1]
        # both ends in the unit of the larger, so that they read alike
        unit = time_unit(max(abs(start), abs(end)))
        span = f"{start.to_value(unit):.6g} -> {format_time(end, unit)}"
    else:
        span = "no outputs"
    lines = [
        f"integrator      {result.integrator['name']} (order {result.integrator['order']}"
        f"{', symplectic' if result.integrator['symplectic'] else ''})"
        + (f" [{opts}]" if opts else ""),
        f"bodies          {len(result.names)}: {', '.join(result.names[:6])}"
        + (", ..." if len(result.names) > 6 else ""),
        f"time            {span}, "
        + ("adaptive steps" if result.integrator.get("adaptive")
           else f"dt = {format_time(result.dt)}"),
        f"steps           {result.steps} "
        + (f"(+{result.steps_rejected} rejected) " if result.integrator.get("adaptive") else "")
        + f"({forces}), {wall_text}",
        f"units           {result.units.name}, G = {result.units.G!r} "
        f"({result.units.G_source})",
        f"forces          {' + '.join(['Newtonian gravity', *result.forces])}",
    ]
    e = result.max_energy_error()
    if e is not None:
        lines.append(f"energy          largest relative error {e:.3e}"
                     + _final(result.energy_error))
    found = _massless_errors(result)
    if found is not None:
        kind, primary, names, errors = found
        worst = np.fmax.reduce(errors, axis=0)
        k = int(np.nanargmax(worst)) if np.isfinite(worst).any() else 0
        what = "Jacobi integral" if kind == "jacobi" else f"Kepler energy about {primary}"
        lines.append(f"test particles  largest relative energy error {worst[k]:.3e} "
                     f"({names[k]}; {what})")
    lerr = result.max_angular_momentum_error()
    if lerr is not None:
        lines.append(f"ang. momentum   largest relative error {lerr:.3e}"
                     + _final(result.angular_momentum_error))
    if result.collisions is not None:
        kinds = ", ".join(f"{k} {int(np.sum(result.collisions['resolution'] == k))}"
                          for k in ("merge", "bounce")
                          if np.any(result.collisions["resolution"] == k))
        lines.append(f"collisions      {len(result.collisions)}"
                     + (f" ({kinds})" if kinds else ""))
    if result.encounters is not None:
        lines.append(f"encounters      {len(result.encounters)} logged")
    lines.append(f"status          {result.status}")
    return "\n".join(lines)


def _repr_html_(result):
    """Outputs, time span, integrator, status and largest errors, for Jupyter."""
    opts = ", ".join(f"{k[7:]}={v!r}" for k, v in result.integrator.items()
                     if k.startswith("option."))
    if len(result.times):
        start = result.times[0] if result.start_time is None else result.start_time
        span = f"{start:.6g} to {result.times[-1]:.6g}"
        length = result.times[-1] - start
        if length.unit.physical_type == "time" and abs(length) > 1 * u.yr:
            span += f" ({length.to(u.yr):.6g})"
    else:
        span = "no outputs"
    names = ", ".join(result.names[:6]) + (", ..." if len(result.names) > 6 else "")
    tp = result.test_particle_energy_error
    errors = (("largest energy error", result.max_energy_error()),
              ("largest test-particle energy error",
               None if tp is None or not np.isfinite(tp).any() else float(np.nanmax(tp))),
              ("largest ang. momentum error", result.max_angular_momentum_error()))
    rows = [("outputs", str(len(result))), ("bodies", f"{len(result.names)}: {names}"),
            ("time", span),
            ("integrator", result.integrator["name"] + (f"({opts})" if opts else "")),
            ("steps", str(result.steps)), ("status", str(result.status)),
            *((k, f"{v:.3e}") for k, v in errors if v is not None)]
    cells = "".join(f"<tr><th style='text-align:left'>{k}</th><td>{html.escape(v)}</td>"
                    f"</tr>" for k, v in rows)
    return f"<div><strong>Result</strong><table>{cells}</table></div>"


def _wall_text(wall, compiling, steps):
    """The run's time for :meth:`Result.summary`: steps per second over the
    time spent stepping, the compiling apart.

    Examples
    --------
    >>> from orbits._result_summary import _wall_text
    >>> _wall_text(34.0, 31.0, 290000)
    'wall time 34 s (compiling 31 s, stepping 3 s, 9.67e+04 steps/s)'
    >>> _wall_text(0.5, 0.0, 50000)
    'wall time 0.5 s (1e+05 steps/s)'
    """
    if wall is None or not np.isfinite(wall):
        return "wall time not recorded"
    if not compiling or not np.isfinite(compiling):
        rate = steps / wall if wall > 0 else float("inf")
        return f"wall time {wall:.3g} s ({rate:.3g} steps/s)"
    stepping = max(wall - compiling, 0.0)
    rate = steps / stepping if stepping > 0 else float("inf")
    return (f"wall time {wall:.3g} s (compiling {compiling:.3g} s, stepping {stepping:.3g} s, "
            f"{rate:.3g} steps/s)")


def _final(series):
    return f", final {series[-1]:.3e}" if series is not None and len(series) else ""


def _largest(*series):
    vals = [np.max(s) for s in series if s is not None and len(s)]
    return float(max(vals)) if vals else None
