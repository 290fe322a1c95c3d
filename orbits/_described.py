"""A simulation in words: its integrator with the options, step, time, forces
and stopping conditions, as the one line of its ``repr`` and the table that
Jupyter shows."""

import html

import astropy.units as u

__all__ = ["rows", "one_line", "html_table"]


def rows(sim):
    """``(label, text)`` rows: bodies, integrator, dt, time, steps, forces, units,
    and the stopping conditions set."""
    integ = sim.integrator
    opts = ", ".join(f"{k}={v!r}" for k, v in integ.config.items())
    kind = ", ".join(w for w, on in (("symplectic", integ.symplectic),
                                     ("adaptive", integ.adaptive)) if on)
    if integ.adaptive and sim._dt == 0:
        dt = "chosen by the integrator"
    else:
        dt = f"{sim.dt:.6g}" + (" (first step)" if integ.adaptive else "")
    names = ", ".join(sim._names[:6]) + (", ..." if len(sim._names) > 6 else "")
    out = [("bodies", f"{len(sim._names)}: {names}"),
           ("integrator", integ.name + (f"({opts})" if opts else "")
            + f" [order {integ.order}{', ' + kind if kind else ''}]"),
           ("dt", dt),
           ("time", f"{sim.time:.6g}"),
           ("steps", str(sim.steps)),
           ("forces", " + ".join(["Newtonian gravity", *map(repr, sim.forces)])),
           ("units", f"{sim.units.name}, G = {sim.units.G!r}")]
    stops = ", ".join(f"{k} = {v:.6g}" if isinstance(v, u.Quantity) else f"{k} = {v}"
                      for k, v in sim.stop_conditions.items()
                      if v is not None and v is not False)
    if stops:
        out.append(("stopping", stops))
    return out


def one_line(sim):
    """``<Simulation of N bodies at t = ...: integrator, dt = ...; forces: ...>``."""
    d = dict(rows(sim))
    return (f"<Simulation of {len(sim._names)} bodies at t = {d['time']}: "
            f"{d['integrator']}, dt = {d['dt']}; forces: {d['forces']}"
            + (f"; stops: {d['stopping']}" if "stopping" in d else "") + ">")


def html_table(sim):
    """The rows as an HTML table."""
    cells = "".join(f"<tr><th style='text-align:left'>{k}</th><td>{html.escape(v)}</td>"
                    f"</tr>" for k, v in rows(sim))
    return f"<div><strong>Simulation</strong><table>{cells}</table></div>"
