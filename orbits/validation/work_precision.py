"""Work against precision: error against wall time and force evaluations.

Fixed-step methods sweep ``dt`` (factors of two about the problem's step),
adaptive ones their tolerance (``rtol``, with ``atol = rtol / 1000``) and the
IAS15s their ``epsilon``; REBOUND's leapfrog, WHFast and IAS15 are swept the
same way on the same axes.  The error is the final position error against
REBOUND's IAS15 at its default epsilon, and the largest relative energy error
at the outputs.  For each accuracy the text names the integrator that reached
it in the least wall time.
"""

import math
import pathlib

from . import cases
from ._format import fmt_time
from ._measure import run_orbits, run_rebound
from ._runner import Task

__all__ = ["TITLE", "tasks", "section", "measure", "SWEEP", "TOLERANCES", "EPSILONS",
           "cheapest", "HEADLINE"]

TITLE = "Work against precision"

#: problem -> (run length full, quick) in its time unit
SWEEP = {
    "outer-solar-system": (1000 * 365.25, 200 * 365.25),
    "kepler-e0.9": (100 * cases._P_KEPLER, 20 * cases._P_KEPLER),
}

#: factors applied to the problem's dt (full, quick)
DT_FACTORS = ((16, 8, 4, 2, 1, 0.5, 0.25), (8, 1, 0.25))

#: rtol of the embedded and step-doubling methods (full, quick); atol = rtol / 1000
TOLERANCES = ((1e-4, 1e-6, 1e-8, 1e-10, 1e-12, 1e-14), (1e-5, 1e-8, 1e-11))

#: epsilon of ours and REBOUND's IAS15 (full, quick)
EPSILONS = ((1e-2, 1e-3, 1e-4, 1e-5, 1e-7, 1e-9), (1e-2, 1e-4, 1e-9))

#: Python-force methods stop at this tolerance (tighter ones would take minutes)
PYTHON_FORCE_TIGHTEST = 1e-10

#: a run shorter than this many seconds is repeated (up to REPEATS times) and
#: its shortest wall time kept, so that timer and scheduling noise do not
#: dominate the plot's left end
SHORT_RUN = 0.05
REPEATS = 5

#: the plot the README shows
HEADLINE = "work_precision_outer-solar-system.png"

#: accuracies at which the cheapest integrator is named
ACCURACIES = (1e-2, 1e-4, 1e-6, 1e-8, 1e-10)

_REBOUND = ("leapfrog", "whfast", "ias15")


#: outputs per run (the energy error is the largest at these); few, so that
#: the cost of an output (tens of microseconds) does not weigh on short runs
OUTPUTS = 11


def measure(problem, integrator, quick, dt=None, options=None, rebound=False,
            reference=False):
    """One point of a line (runs on a worker)."""
    prob = cases.problem(problem)
    body_set = cases.bodies(prob)
    until = SWEEP[problem][1 if quick else 0]
    run = run_rebound if rebound else run_orbits
    best = None
    for _ in range(REPEATS):
        extra = {"count_evaluations": True} if rebound and integrator == "ias15" else {}
        row = run(body_set, integrator, options, dt=dt, until=until, outputs=OUTPUTS, **extra)
        if best is None or row["wall_time"] < best["wall_time"]:
            best = row
        if row["wall_time"] > SHORT_RUN or row["outcome"] != "completed":
            break
    for key in ("times", "energy_error", "angular_momentum_error"):
        best.pop(key, None)
    best.update(problem=problem, rebound=rebound,
                series="reference" if reference else _series_name(integrator, rebound),
                knob=dt if dt is not None else next(iter((options or {}).values()), None))
    return best


def _series_name(integrator, rebound):
    return f"REBOUND {integrator}" if rebound else integrator


def tasks(quick):
    from .. import integrators
    out = []
    k = 1 if quick else 0
    for key, lengths in SWEEP.items():
        prob = cases.problem(key)
        body_set = cases.bodies(prob)
        length = lengths[k]
        steps = length / prob.dt

        def add(name, cost, rebound=False, **kw):
            out.append(Task("orbits.validation.work_precision:measure",
                            dict(problem=key, integrator=name, quick=quick,
                                 rebound=rebound, **kw), cost))

        for name in cases.integrator_names():
            if cases.applies(prob, name, quick, body_set, length) is not None:
                continue
            integ = integrators.get(name)
            if name == "ias15":
                for eps in EPSILONS[k]:
                    add(name, steps * 1e-6, options={"epsilon": eps})
            elif integ.adaptive:
                for tol in TOLERANCES[k]:
                    if name in cases.PYTHON_FORCE and tol < PYTHON_FORCE_TIGHTEST:
                        continue
                    cost = steps * 1e-6 * (300 if name in cases.PYTHON_FORCE else 1)
                    add(name, cost, options={"rtol": tol, "atol": tol * 1e-3})
            else:
                for f in DT_FACTORS[k]:
                    add(name, steps / f * integ.forces_per_step * 1e-7, dt=prob.dt * f)
        for name in _REBOUND:
            if cases.applies(prob, f"rebound-{name}", quick, body_set) is not None:
                continue
            if name == "ias15":
                for eps in EPSILONS[k]:
                    add(name, steps * 1e-6, rebound=True, options={"epsilon": eps})
            else:
                for f in DT_FACTORS[k]:
                    add(name, steps / f * 1e-7, rebound=True, dt=prob.dt * f)
        # the reference: REBOUND's IAS15 at its default epsilon
        add("ias15", steps * 1e-6, rebound=True, options={"epsilon": 1e-9}, reference=True)
    return out


def _attach_errors(rows):
    """Add ``position_error`` (against the reference) to every row."""
    from .accuracy import position_error
    refs = {r["problem"]: r for r in rows if r["series"] == "reference"}
    for r in rows:
        r["position_error"] = (math.nan if r is refs.get(r["problem"]) else
                               position_error(r, refs.get(r["problem"]), r["problem"]))
    return refs


def cheapest(rows, accuracy, error="position_error"):
    """``[(series, wall time)]`` sorted by the least wall time at which each
    series reached ``error <= accuracy`` (failed runs do not count)."""
    best = {}
    for r in rows:
        err = r.get(error, math.nan)
        if (r["outcome"] != "completed" or not (err <= accuracy)
                or r["series"] == "reference"):
            continue
        s = r["series"]
        if s not in best or r["wall_time"] < best[s]:
            best[s] = r["wall_time"]
    return sorted(best.items(), key=lambda kv: kv[1])


def _lines(rows):
    series = {}
    for r in rows:
        if r["series"] != "reference":
            series.setdefault(r["series"], []).append(r)
    return series


def _plot(rows, prob, path, quick):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    series = _lines(rows)
    fig, axes = plt.subplots(2, 2, figsize=(13, 9.5), sharey="row")
    colours = list(plt.get_cmap("tab20").colors) + list(plt.get_cmap("Dark2").colors)
    markers = "osD^v<>ph*"
    ours = [s for s in series if not s.startswith("REBOUND")]
    style = {s: dict(color=colours[i % len(colours)], marker=markers[i % len(markers)], ls="-")
             for i, s in enumerate(ours)}
    for j, s in enumerate(s for s in series if s.startswith("REBOUND")):
        style[s] = dict(color=("k", "0.35", "0.6")[j % 3], marker="x+|"[j % 3], ls="--", lw=2)
    panels = (("wall_time", "position_error", "wall time [s]"),
              ("wall_time", "energy_error_max", "wall time [s]"),
              ("force_evaluations", "position_error", "force evaluations"),
              ("force_evaluations", "energy_error_max", "force evaluations"))
    for ax, (xkey, ykey, xlabel) in zip((axes[0, 0], axes[1, 0], axes[0, 1], axes[1, 1]),
                                        panels):
        for s, pts in series.items():
            pts = [p for p in pts if p["outcome"] == "completed"
                   and math.isfinite(p.get(ykey, math.nan)) and p.get(ykey, 0) > 0
                   and math.isfinite(p[xkey]) and p[xkey] > 0]
            if not pts:
                continue
            pts.sort(key=lambda p: p[xkey])
            ax.loglog([p[xkey] for p in pts], [p[ykey] for p in pts], label=s, ms=4,
                      **style[s])
        ax.set_xlabel(xlabel)
        ax.grid(True, which="major", alpha=0.3)
    axes[0, 0].set_ylabel(f"final position error [{prob.length_unit}]")
    axes[1, 0].set_ylabel("largest relative energy error")
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="center right", fontsize=8, frameon=False)
    length = SWEEP[prob.key][1 if quick else 0]
    against = ("the exact Kepler orbit" if prob.scene == "kepler"
               else "REBOUND IAS15 (epsilon 1e-9)")
    fig.suptitle(f"{prob.title}: {length / prob.period:.0f} orbits of the shortest period; "
                 f"error against {against}")
    fig.subplots_adjust(right=0.82, wspace=0.08, hspace=0.25)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def section(rows, out_dir, quick):
    out_dir = pathlib.Path(out_dir)
    lines = [f"## {TITLE}", "",
             "Fixed-step methods sweep dt by factors of two around the problem's step "
             f"({', '.join(f'{f:g}' for f in DT_FACTORS[1 if quick else 0])} times it); "
             "the embedded and step-doubling methods sweep rtol (atol = rtol / 1000); "
             "the IAS15s sweep epsilon. REBOUND's leapfrog, WHFast and IAS15 are on the "
             "same axes (grey, dashed). Position errors are against the exact orbit for "
             "the Kepler problem and against REBOUND's IAS15 at epsilon 1e-9 otherwise; "
             "wall times are of one core, compilation excluded, the shortest of up "
             f"to {REPEATS} repetitions for runs under {SHORT_RUN:g} s. Failed runs "
             "(named errors) are not drawn.", ""]
    for key in SWEEP:
        prob = cases.problem(key)
        prows = [r for r in rows if r["problem"] == key]
        if not prows:
            continue
        _attach_errors(prows)
        name = f"work_precision_{key}.png"
        _plot(prows, prob, out_dir / name, quick)
        lines += [f"### {prob.title}", "", f"![work against precision, {prob.title}]({name})",
                  "", "The cheapest way to each accuracy, of ours and of REBOUND's "
                  f"(final position error in {prob.length_unit}, or largest relative "
                  "energy error):", "",
                  "| accuracy | cheapest, position | wall time [s] | next | wall time [s] | "
                  "REBOUND's cheapest | wall time [s] | cheapest, energy | wall time [s] | "
                  "REBOUND's cheapest | wall time [s] |",
                  "|---|---|---|---|---|---|---|---|---|---|---|"]
        for acc in ACCURACIES:
            cells = [f"{acc:.0e}"]
            for error, picks in (("position_error", (0, 1, None)),
                                 ("energy_error_max", (0, None))):
                ranked = cheapest(prows, acc, error)
                ours = [x for x in ranked if not x[0].startswith("REBOUND")]
                theirs = [x for x in ranked if x[0].startswith("REBOUND")]
                for k in picks:
                    pick = (theirs[0] if theirs else None) if k is None else (
                        ours[k] if len(ours) > k else None)
                    cells += ([f"`{pick[0]}`", fmt_time(pick[1])] if pick
                              else ["none reached it", ""])
            lines.append("| " + " | ".join(cells) + " |")
        body_set = cases.bodies(prob)
        length = SWEEP[key][1 if quick else 0]
        skipped = [(n, cases.applies(prob, n, quick, body_set, length))
                   for n in cases.integrator_names() + ["rebound-whfast"]]
        skipped = [(n, why) for n, why in skipped if why is not None]
        if skipped:
            lines += ["", "Left out: " + "; ".join(f"`{n}` ({why})" for n, why in skipped)
                      + "."]
        if any(r["integrator"] in cases.PYTHON_FORCE for r in prows):
            lines += ["", f"scipy's `radau` and `lsoda` stop at rtol = "
                      f"{PYTHON_FORCE_TIGHTEST:g}: tighter tolerances take minutes with a "
                      "force called from Python."]
        failed = [r for r in prows if r["outcome"] != "completed" and r["series"] != "reference"]
        if failed:
            lines += ["", "Runs that failed: " + "; ".join(
                f"{r['series']} at {_knob(r)}: {r['outcome']}" for r in failed) + "."]
        lines.append("")
    return "\n".join(lines)


def _knob(r):
    if r.get("dt") is not None:
        return f"dt = {r['dt']:.4g}"
    return ", ".join(f"{k} = {v:g}" for k, v in (r.get("options") or {}).items()
                     if k != "atol")


def summary_line(rows):
    """One sentence for the report's summary: who is cheapest at 1e-8 au on the
    outer solar system."""
    prows = [r for r in rows if r["problem"] == "outer-solar-system"]
    if not prows:
        return ""
    _attach_errors(prows)
    ranked = cheapest(prows, 1e-8)
    if not ranked:
        return ""
    return (f"On the outer solar system, the cheapest way to a final position error of "
            f"1e-8 au was `{ranked[0][0]}` ({fmt_time(ranked[0][1])} s).")
