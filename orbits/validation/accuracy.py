"""Accuracy against REBOUND: every applicable integrator on every problem.

For each problem of :mod:`~orbits.validation.cases`, REBOUND's IAS15 at its
default ``epsilon`` (1e-9, where its error is at the level of round-off) is
the reference; each of our integrators (fixed-step ones at the problem's
``dt``, adaptive ones at their default tolerances) and REBOUND's WHFast and
leapfrog at the same ``dt`` start from the same floats with the same G.  The
table gives the final position error against the reference, the largest
relative energy and angular-momentum errors at the outputs, steps, force
evaluations and wall time.  A second table puts our ``ias15`` and ``wh`` beside
REBOUND's IAS15 and WHFast.
"""

import math

from .. import integrators
from . import cases, work_precision
from ._format import fmt_count, fmt_err, fmt_time, outcome_cell
from ._measure import position_error, run_orbits, run_rebound
from ._runner import Task

__all__ = ["TITLE", "tasks", "section", "measure", "OUTPUTS"]

TITLE = "Accuracy against REBOUND"

#: Outputs per run at which the energy and angular-momentum errors are taken.
OUTPUTS = 201

#: the reference run of every problem
REFERENCE = "REBOUND ias15"


#: variants run beside the defaults where Wisdom-Holman applies:
#: (label, our options, REBOUND's label, REBOUND's options)
VARIANTS = (("wh, democratic heliocentric", {"coordinates": "democratic-heliocentric"},
             "REBOUND whfast, democratic heliocentric",
             {"coordinates": "democraticheliocentric"}),)


def measure(problem, integrator, quick, rebound=False, options=None, label=None):
    """One row of the table (runs on a worker)."""
    prob = cases.problem(problem)
    body_set = cases.bodies(prob)
    until = prob.length(quick)
    if rebound:
        dt = None if integrator == "ias15" else prob.dt
        row = run_rebound(body_set, integrator, options, dt=dt, until=until,
                          outputs=OUTPUTS, count_evaluations=integrator == "ias15",
                          label=label)
    else:
        adaptive = integrators.get(integrator).adaptive
        row = run_orbits(body_set, integrator, options, dt=None if adaptive else prob.dt,
                         until=until, outputs=OUTPUTS, label=label)
    row.update(problem=problem, rebound=rebound)
    for key in ("times", "energy_error", "angular_momentum_error"):
        row.pop(key, None)
    return row



def _cost(prob, name, quick):
    # rough seconds: steps x stages, Python-force methods far more
    stages = {"yoshida8": 15, "yoshida6": 7, "rk4": 4, "saba4": 4, "implicit-euler": 8,
              "implicit-midpoint": 8, "rk4-doubling": 11}.get(name, 2)
    return prob.steps(quick) * stages * 1e-7 * (300 if name in cases.PYTHON_FORCE else 1)


def tasks(quick):
    out = []
    for prob in cases.PROBLEMS:
        body_set = cases.bodies(prob)
        for name in ("ias15", "whfast", "leapfrog"):
            if cases.applies(prob, f"rebound-{name}", quick, body_set) is None:
                out.append(Task("orbits.validation.accuracy:measure",
                                dict(problem=prob.key, integrator=name, quick=quick,
                                     rebound=True), _cost(prob, name, quick)))
        for name in cases.integrator_names():
            if cases.applies(prob, name, quick, body_set) is None:
                out.append(Task("orbits.validation.accuracy:measure",
                                dict(problem=prob.key, integrator=name, quick=quick),
                                _cost(prob, name, quick)))
        if cases.applies(prob, "wh", quick, body_set) is None:
            for label, ours, their_label, theirs in VARIANTS:
                out.append(Task("orbits.validation.accuracy:measure",
                                dict(problem=prob.key, integrator="wh", quick=quick,
                                     options=ours, label=label), _cost(prob, "wh", quick)))
                out.append(Task("orbits.validation.accuracy:measure",
                                dict(problem=prob.key, integrator="whfast", quick=quick,
                                     rebound=True, options=theirs, label=their_label),
                                _cost(prob, "wh", quick)))
    return out


def left_out(quick):
    """``[(problem key, integrator, reason)]`` for every pair not run."""
    rows = []
    for prob in cases.PROBLEMS:
        body_set = cases.bodies(prob)
        for name in ["rebound-whfast"] + cases.integrator_names():
            reason = cases.applies(prob, name, quick, body_set)
            if reason is not None:
                rows.append((prob.key, name, reason))
    return rows


def _options(row, prob):
    opts = row.get("options") or {}
    if row.get("dt") is not None:
        return f"dt = {row['dt']:.4g} {prob.time_unit}"
    name = row["integrator"]
    if name.startswith("rebound-"):
        return "epsilon = 1e-09 (default)"
    defaults = dict(integrators.get(name).config)
    defaults.update(opts)
    keep = {k: v for k, v in defaults.items() if k in ("epsilon", "rtol", "atol")}
    return ", ".join(f"{k} = {v:g}" for k, v in keep.items())


def section(rows, out_dir, quick):
    by_problem = {}
    for row in rows:
        by_problem.setdefault(row["problem"], []).append(row)
    lines = [f"## {TITLE}", "",
             "Each problem starts from the same floats with the same G in both codes. "
             "The final position error is against the exact Kepler orbit for the two-body "
             "problems, and against REBOUND's IAS15 at its default epsilon (1e-9, an error "
             "at the level of round-off) for the others. Fixed-step methods "
             "run at the step given under each problem, adaptive ones at their default "
             "tolerances; REBOUND's WHFast and leapfrog at the same step as ours. "
             "Energy and angular-momentum errors are the largest relative errors at "
             f"{OUTPUTS} evenly spaced outputs. Wall times are of one core each, compilation "
             "excluded. Force evaluations of REBOUND's IAS15 are counted in a second, "
             "untimed run; those of the implicit methods are nominal (two per step; "
             "Newton's iterations cost more). A failed run shows its named error and "
             "its errors up to the last good state.", ""]
    lines += _problems_table(quick)
    for prob in cases.PROBLEMS:
        prows = by_problem.get(prob.key, [])
        if not prows:
            continue
        ref = next((r for r in prows if r["rebound"] and r["integrator"] == "rebound-ias15"),
                   None)
        lines += [f"### {prob.title}", "",
                  f"{prob.span_quick if quick else prob.span}; fixed step "
                  f"{prob.dt:.4g} {prob.time_unit}; lengths in {prob.length_unit}.", "",
                  "| integrator | step or tolerance | final position error | "
                  "max energy error | max L error | steps | force evaluations | "
                  "wall time [s] | outcome |",
                  "|---|---|---|---|---|---|---|---|---|"]
        ordered = ([r for r in prows if r["rebound"]]
                   + [r for r in prows if not r["rebound"]])
        for r in ordered:
            if prob.scene == "kepler":
                perr = fmt_err(position_error(r, None, prob.key))
            else:
                perr = "reference" if r is ref else fmt_err(position_error(r, ref))
            lines.append(
                f"| {r['label']} | {_options(r, prob)} | {perr} | "
                f"{fmt_err(r['energy_error_max'])} | "
                f"{fmt_err(r['angular_momentum_error_max'])} | {fmt_count(r['steps'])} | "
                f"{fmt_count(r['force_evaluations'])} | {fmt_time(r['wall_time'])} | "
                f"{outcome_cell(r)} |")
        lines.append("")
    lines += _side_by_side(by_problem)
    skipped = left_out(quick)
    if skipped:
        lines += ["### Left out, and why", "", "| problem | integrator | reason |",
                  "|---|---|---|"]
        lines += [f"| {p} | {n} | {why} |" for p, n, why in skipped]
        lines.append("")
    return "\n".join(lines)


def _problems_table(quick):
    """Which checks each problem takes, and how many integrators it leaves out."""
    skipped = {}
    for key, name, _ in left_out(quick):
        skipped.setdefault(key, []).append(name)
    lines = ["| problem | bodies | run | fixed step | checks | left out (reasons below) |",
             "|---|---|---|---|---|---|"]
    for prob in cases.PROBLEMS:
        checks = ["accuracy"]
        if prob.key in work_precision.SWEEP:
            checks.append("work-precision")
        if prob.scene == "outer-solar-system":
            checks.append("long-horizon drift (centre-of-mass frame)")
        names = ", ".join(f"`{n}`" for n in skipped.get(prob.key, [])) or "none"
        lines.append(f"| {prob.title} | {len(cases.bodies(prob))} | "
                     f"{prob.span_quick if quick else prob.span} | {prob.dt:.4g} "
                     f"{prob.time_unit} | {', '.join(checks)} | {names} |")
    return lines + [""]


def _side_by_side(by_problem):
    lines = ["### `ias15` and `wh` beside REBOUND's IAS15 and WHFast", "",
             "Difference: the largest final position difference between the two codes "
             "(lengths in the problem's unit). Time ratio: our wall time over REBOUND's "
             "for the same run (runs of a few milliseconds are dominated by the cost of "
             f"{OUTPUTS} outputs; `benchmarks/` times long runs). `wh` in Jacobi "
             "coordinates by default, and in democratic heliocentric ones beside "
             "REBOUND's WHFast in the same.", "",
             "| problem | ias15 − IAS15 | energy error ias15 / IAS15 | time ratio | "
             "wh − WHFast | energy error wh / WHFast | time ratio | "
             "democratic heliocentric: wh − WHFast | energy error | time ratio |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for prob in cases.PROBLEMS:
        prows = by_problem.get(prob.key, [])
        get = {r["label"]: r for r in prows}
        cells = [prob.title]
        for ours, theirs in (("ias15", "REBOUND ias15"), ("wh", "REBOUND whfast"),
                             (VARIANTS[0][0], VARIANTS[0][2])):
            a, b = get.get(ours), get.get(theirs)
            if a is None or b is None:
                cells += ["left out", "", ""]
                continue
            ratio = a["wall_time"] / b["wall_time"] if b["wall_time"] > 0 else math.nan
            cells += [fmt_err(position_error(a, b)),
                      f"{fmt_err(a['energy_error_max'])} / {fmt_err(b['energy_error_max'])}",
                      f"{ratio:.2f}"]
        lines.append("| " + " | ".join(cells) + " |")
    lines.append("")
    return lines
