"""Long-horizon drift: energy and angular-momentum error against time.

The outer solar system (Hairer, Lubich & Wanner's, moved to its centre of
mass) runs for a million years (the quick report: ten thousand) with outputs
spaced evenly in log t, under each integrator that a long planetary run would
use, and under REBOUND's leapfrog, WHFast and IAS15 with the same steps.  For
each run the growth exponent of the error, the slope of log(running maximum)
against log t over the later nine tenths of the log time range
(:func:`orbits.monitors.growth_exponent`), classifies it as bounded, a random
walk (t^0.5, Brouwer's law for round-off), linear or quadratic.
"""

import math
import pathlib

import numpy as np

from .. import scenes
from ..monitors import growth_exponent
from ._format import fmt_err, fmt_time, outcome_cell
from ._measure import run_orbits, run_rebound
from ._runner import Task

__all__ = ["TITLE", "tasks", "section", "measure", "RUNS", "LEFT_OUT", "classify",
           "YEARS"]

TITLE = "Long-horizon drift"

#: run length in years (full, quick)
YEARS = (1e6, 1e4)

#: outputs, evenly spaced in log t from the first to the last year (full, quick)
OUTPUTS = (150, 60)
FIRST_OUTPUT_YEARS = 1.0

_YEAR = 365.25
_P_JUPITER = 4332.59
#: Wisdom-Holman's customary step, a twentieth of Jupiter's period
DT_WH = _P_JUPITER / 20
#: the other fixed-step methods' step (days), HLW's usual 10 days
DT = 10.0

#: (label, rebound?, integrator, options, dt in days or None)
RUNS = (
    ("leapfrog", False, "leapfrog", {}, DT),
    ("verlet", False, "verlet", {}, DT),
    ("yoshida4", False, "yoshida4", {}, DT),
    ("yoshida6", False, "yoshida6", {}, DT),
    ("yoshida8", False, "yoshida8", {}, DT),
    ("rk4", False, "rk4", {}, DT),
    ("wh", False, "wh", {}, DT_WH),
    ("wh, corrector 17", False, "wh", {"corrector": 17}, DT_WH),
    ("saba2", False, "saba2", {}, DT_WH),
    ("saba3", False, "saba3", {}, DT_WH),
    ("saba4", False, "saba4", {}, DT_WH),
    ("dop853", False, "dop853", {"rtol": 1e-12, "atol": 1e-15}, None),
    ("ias15", False, "ias15", {}, None),
    ("ias15, prs24", False, "ias15", {"adaptive_mode": "prs24"}, None),
    ("taylor", False, "taylor", {}, None),
    ("REBOUND leapfrog", True, "leapfrog", {}, DT),
    ("REBOUND whfast", True, "whfast", {}, DT_WH),
    ("REBOUND whfast, corrector 17", True, "whfast", {"corrector": 17}, DT_WH),
    ("REBOUND ias15", True, "ias15", {}, None),
)

#: integrators of the registry not run here, and why
LEFT_OUT = {
    "euler": "first order and not symplectic: its energy error reaches order one within "
             "a few thousand years at this step, so a million years measures only divergence",
    "symplectic-euler": "first order: bounded, but its error at a 10-day step is some "
                        "thousand times the leapfrog's at the same cost",
    "rk2": "second order and not symplectic: its energy drifts linearly from a large "
           "start, as rk4's does from a small one (shown)",
    "dopri5": "an embedded Runge-Kutta pair like dop853 (shown), at several times its "
              "cost for a million years at a tolerance that keeps the error small",
    "rk4-doubling": "an adaptive Runge-Kutta like dop853 (shown), at many times its cost",
    "radau": "calls the force from Python: a million years would take days",
    "lsoda": "calls the force from Python: a million years would take days",
    "implicit-euler": "for stiff problems: it damps the orbits (Jupiter spirals in), and "
                      "a Newton solve every step makes a million years take hours",
    "implicit-midpoint": "for stiff problems: symplectic like the leapfrog but a Newton "
                         "solve every step makes a million years take hours",
    "trace": "on the outer solar system no encounter is ever flagged, and it then follows "
             "wh's democratic heliocentric map bit for bit (tests/integrators/test_trace.py): "
             "its drift is that map's",
}

#: growth-exponent classes: upper bounds, between the laws they separate
CLASSES = ((0.25, "bounded"), (0.75, "random walk (t^0.5)"), (1.5, "linear"),
           (math.inf, "quadratic or faster"))


def classify(exponent):
    """The drift law nearest a fitted growth exponent."""
    if not math.isfinite(exponent):
        return "–"
    for bound, name in CLASSES:
        if exponent < bound:
            return name
    return CLASSES[-1][1]


def output_times(quick):
    years = YEARS[1 if quick else 0]
    return np.geomspace(FIRST_OUTPUT_YEARS, years, OUTPUTS[1 if quick else 0]) * _YEAR


def measure(index, quick):
    """Run ``RUNS[index]`` (on a worker)."""
    label, rebound, integrator, options, dt = RUNS[index]
    body_set = scenes.outer_solar_system(com=True)
    times = output_times(quick)
    run = run_rebound if rebound else run_orbits
    limit = 3600.0 if not quick else 300.0
    row = run(body_set, integrator, options, dt=dt, until=float(times[-1]), times=times,
              wall_limit=limit, label=label)
    row.pop("x", None)
    t = row["times"] / _YEAR
    for key in ("energy_error", "angular_momentum_error"):
        err = row[key]
        row[f"{key}_exponent"] = (growth_exponent(t[1:], err[1:]) if err is not None
                                  and len(err) > 3 else math.nan)
    row["index"] = index
    return row


def _cost(index, quick):
    label, rebound, integrator, options, dt = RUNS[index]
    stages = {"yoshida8": 15, "yoshida6": 7, "yoshida4": 3, "rk4": 4, "saba3": 3,
              "saba4": 4}.get(integrator, 1)
    step = dt if dt is not None else 50.0
    per = 3e-7 * stages if dt is not None else 1e-5
    return YEARS[1 if quick else 0] * _YEAR / step * per


def tasks(quick):
    return [Task("orbits.validation.drift:measure", dict(index=i, quick=quick),
                 _cost(i, quick)) for i in range(len(RUNS))]


def _plot(rows, path, quick):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(14, 6), sharex=True)
    colours = list(plt.get_cmap("tab20").colors)
    k = 0
    for r in rows:
        if r["times"] is None or len(r["times"]) < 2:
            continue
        t = r["times"][1:] / _YEAR
        if r["label"].startswith("REBOUND"):
            style = dict(color="k", ls="--", lw=1.5, alpha=0.5 + 0.15 * (k % 3))
        else:
            style = dict(color=colours[k % len(colours)], lw=1.2)
        k += 1
        for ax, key in zip(axes, ("energy_error", "angular_momentum_error")):
            err = r[key]
            if err is None:
                continue
            e = np.asarray(err[1:], dtype=float)
            ok = np.isfinite(e) & (e > 0)
            ax.loglog(t[ok], e[ok], label=r["label"], **style)
    years = YEARS[1 if quick else 0]
    tt = np.geomspace(FIRST_OUTPUT_YEARS, years, 10)
    for ax in axes:
        for slope, ls in ((0.5, ":"), (1.0, "-.")):
            ax.loglog(tt, 1e-16 * (tt / tt[0]) ** slope * 10, color="0.5", ls=ls, lw=1)
        ax.set_xlabel("time [yr]")
        ax.grid(True, which="major", alpha=0.3)
    axes[0].set_ylabel("relative energy error")
    axes[1].set_ylabel("relative angular-momentum error")
    axes[0].text(tt[-1], 1e-15 * (tt[-1] / tt[0]) ** 0.5, "t^0.5", fontsize=8, color="0.4",
                 ha="right", va="bottom")
    axes[0].text(tt[-1], 1e-15 * (tt[-1] / tt[0]), "t", fontsize=8, color="0.4",
                 ha="right", va="bottom")
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="center right", fontsize=8, frameon=False)
    fig.suptitle(f"outer solar system, {years:,.0f} years: error against time")
    fig.subplots_adjust(right=0.8, wspace=0.25)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def section(rows, out_dir, quick):
    out_dir = pathlib.Path(out_dir)
    name = "drift_outer-solar-system.png"
    _plot(rows, out_dir / name, quick)
    years = YEARS[1 if quick else 0]
    lines = [f"## {TITLE}", "",
             f"The outer solar system in its centre-of-mass frame for {years:,.0f} years, "
             f"{OUTPUTS[1 if quick else 0]} outputs spaced evenly in log t from "
             f"{FIRST_OUTPUT_YEARS:g} year. Steps: {DT:g} days for the leapfrog family and "
             f"rk4, {DT_WH:.1f} days (a twentieth of Jupiter's period) for the "
             "Wisdom-Holman family; ours and REBOUND's alike. The exponent is the slope of "
             "the running maximum of the error against t on log axes over the later nine "
             "tenths of the log time range: about 0 for a bounded error, 0.5 for a random "
             "walk (Brouwer's law), 1 for a linear and 2 for a quadratic drift; the class "
             "is the nearest of these (bounds at 0.25, 0.75 and 1.5).", "",
             f"![energy and angular-momentum error against time]({name})", "",
             "| run | step | final energy error | max energy error | exponent | law | "
             "max L error | exponent | law | steps | wall time [s] | outcome |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        e = r["energy_error"]
        final = fmt_err(float(e[-1])) if e is not None and len(e) else "–"
        ee, le = r["energy_error_exponent"], r["angular_momentum_error_exponent"]
        step = f"{r['dt']:.4g} d" if r.get("dt") is not None else _tolerance(r)
        lines.append(
            f"| {r['label']} | {step} | {final} | {fmt_err(r['energy_error_max'])} | "
            f"{_exp(ee)} | {classify(ee)} | {fmt_err(r['angular_momentum_error_max'])} | "
            f"{_exp(le)} | {classify(le)} | {r['steps']:,} | {fmt_time(r['wall_time'])} | "
            f"{outcome_cell(r)} |")
    lines += ["", "Left out, and why:", ""]
    lines += [f"- `{k}`: {why}." for k, why in LEFT_OUT.items()]
    lines.append("")
    return "\n".join(lines)


def _exp(x):
    return "–" if not math.isfinite(x) else f"{x:.2f}"


def _tolerance(r):
    opts = r.get("options") or {}
    if "rtol" in opts:
        return f"rtol {opts['rtol']:g}"
    return f"epsilon {opts.get('epsilon', 1e-9):g}" + (
        f", {opts['adaptive_mode']}" if "adaptive_mode" in opts else "")
