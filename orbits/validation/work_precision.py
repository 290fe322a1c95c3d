"""Work against precision: error against wall time and force evaluations.

Fixed-step methods sweep ``dt`` (factors of two about the problem's step),
adaptive ones their tolerance (``rtol``, with ``atol = rtol / 1000``; the
Taylor method its ``tol``) and the IAS15s their ``epsilon``; REBOUND's
integrators are swept the same way on the same axes: its defaults
(leapfrog, WHFast without a corrector, IAS15) and its best fixed-step
methods (WHFast with the 11th-order symplectic corrector, WHCKL,
SABA(10,6,4), and WHFast512 where the CPU has AVX-512), so that the
cheapest way to an accuracy is named against REBOUND's best, not its
defaults.  The error is the final position error against REBOUND's IAS15 at
its default epsilon, and the largest relative energy error at the outputs.
For each accuracy the text names the integrator that reached it in the least
wall time.
"""

import functools
import math
import pathlib
import time

import numpy as np

from .. import integrators
from ..monitors import vector_relative_error
from . import cases
from ._format import fmt_time
from ._measure import (WALL_LIMIT, _set_options, energy_and_momentum, on_steps,
                       position_error, row_template, run_orbits, run_rebound)
from ._runner import Task

__all__ = ["TITLE", "tasks", "section", "measure", "SWEEP", "TOLERANCES", "EPSILONS",
           "cheapest", "HEADLINE", "REBOUND_FIXED_STEP", "rebound_method", "whfast512_status",
           "force_evaluations_per_step"]

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

#: REBOUND's fixed-step methods on the axes (a series "REBOUND <name>" each),
#: swept over DT_FACTORS like ours.  "leapfrog" and "whfast" (no corrector)
#: are its defaults; the rest are the best it offers for a dominant central
#: body (Rein, Tamayo & Brown 2019, MNRAS 489, 4632, compare them): WHFast
#: with the 11th-order symplectic corrector (Wisdom, Holman & Touma 1996),
#: WHCKL (the lazy implementer's kernel and the 17th-order corrector) and
#: SABA(10,6,4) (Blanes et al. 2013, Appl. Numer. Math. 68, 58).  "whfast512"
#: is added where :func:`whfast512_status` says it runs.  All of the
#: Wisdom-Holman kind run with ``safe_mode = 0``: synchronised, and corrected,
#: only at outputs, as our ``wh`` is.
REBOUND_FIXED_STEP = ("leapfrog", "whfast", "whfast, corrector 11", "whckl", "SABA(10,6,4)")

#: force evaluations a step, roughly, for ordering the tasks only (the rows
#: carry the counted number)
_REBOUND_COST = {"whckl": 2, "SABA(10,6,4)": 8}


#: outputs per run (the energy error is the largest at these); few, so that
#: the cost of an output (tens of microseconds) does not weigh on short runs
OUTPUTS = 11


def rebound_method(name):
    """``(integrator, options)`` that set up REBOUND's method ``name`` (a key
    of :data:`REBOUND_FIXED_STEP`, ``"ias15"`` or ``"whfast512"``) through
    :func:`~orbits.validation._measure.run_rebound`, in REBOUND 4 and 5.

    WHCKL and SABA(10,6,4) are set field by field rather than with REBOUND's
    shorthand strings: REBOUND 4 keeps the options on ``sim.ri_<name>``, where
    the shorthand's integrator name has none, and REBOUND 5.2's
    ``sim.integrator = "SABA(10,6,4)"`` fails (it passes ``"(10_6_4)"`` on as
    the type; ``"10_6_4"`` is the name it knows).
    """
    import rebound
    major = int(rebound.__version__.split(".")[0])
    table = {
        "leapfrog": ("leapfrog", {}),
        "whfast": ("whfast", {}),
        "ias15": ("ias15", {}),
        "whfast512": ("whfast512", {}),
        "whfast, corrector 11": ("whfast", {"corrector": 11}),
        "whckl": ("whfast", {"kernel": "lazy", "corrector": 17}),
        "SABA(10,6,4)": ("saba", {"type": "10_6_4" if major >= 5 else "(10,6,4)",
                                  "safe_mode": 0}),
    }
    try:
        integrator, options = table[name]
    except KeyError:
        raise KeyError(f"unknown REBOUND method {name!r}; valid: {', '.join(table)}") from None
    return integrator, dict(options)


@functools.lru_cache(maxsize=None)
def whfast512_status():
    """``(True, "")`` where REBOUND's WHFast512 runs on this machine, else
    ``(False, why)``.

    Tried once for real, as it must be run (G = 1, ``exact_finish_time = 0``),
    on a two-body problem; the error REBOUND raises is the reason given.  It
    needs a CPU with AVX-512 (and a REBOUND built with it); REBOUND refuses
    it on others with a ``RuntimeError`` rather than crashing.
    """
    import rebound
    try:
        sim = rebound.Simulation()
        sim.G = 1.0
        sim.add(m=1.0)
        sim.add(m=1e-3, a=1.0)
        sim.integrator = "whfast512"
        sim.dt = 0.01
        sim.exact_finish_time = 0
        sim.integrate(0.1)
    except Exception as exc:    # REBOUND's refusal, whatever its kind, is the answer
        why = f"{type(exc).__name__}: {exc}"
        if not getattr(rebound, "avx512_available", True):
            why = f"not available on this CPU (no AVX-512): {why}"
        return False, why
    return True, ""


@functools.lru_cache(maxsize=None)
def force_evaluations_per_step(problem, method):
    """``(per step, per synchronisation)`` force evaluations of REBOUND's
    fixed-step ``method`` on ``problem``.

    REBOUND has no counter: a no-op additional force counts the calls over
    runs of 32 and 64 steps (``safe_mode = 0``), the difference per step and
    the rest per synchronisation (the corrector applied and undone about an
    output).  Counted, not taken from the papers: WHCKL's kernel, for one,
    adds an evaluation to every step.
    """
    integrator, options = rebound_method(method)
    if integrator in ("whfast", "saba"):
        options.setdefault("safe_mode", 0)
    body_set = cases.bodies(cases.problem(problem))
    dt = cases.problem(problem).dt
    counts = []
    for n in (32, 64):
        sim = body_set.to_rebound()
        sim.gravity = "basic"
        sim.integrator = integrator
        _set_options(sim, integrator, options)
        sim.dt = float(dt)
        count = [0]

        def tally(_sim, count=count):
            count[0] += 1

        sim.additional_forces = tally
        sim.force_is_velocity_dependent = 0
        sim.integrate((n - 0.5) * dt, exact_finish_time=0)
        counts.append(count[0])
    per_step = (counts[1] - counts[0]) / 32
    return per_step, counts[0] - 32 * per_step


def _run_unit_g(bodies, integrator, options=None, *, dt, until, outputs=2,
                wall_limit=WALL_LIMIT, label=None):
    """Run REBOUND's fixed-step ``integrator`` in a time unit in which G = 1,
    measured as :func:`~orbits.validation._measure.run_rebound` measures.

    WHFast512 takes G = 1 only and cannot shorten a step to land on a time:
    velocities are divided by sqrt(G) and times (dt among them) multiplied by
    it, which leaves positions and relative energy and angular-momentum
    errors as they are; it integrates to half a step before each output
    with ``exact_finish_time = 0``, so it takes whole steps as the others do.
    """
    options = dict(options or {})
    label = label or f"REBOUND {integrator}"
    row = row_template(label, integrator=f"rebound-{integrator}", options=options, dt=dt)
    sim = bodies.to_rebound()
    scale = math.sqrt(sim.G)
    for p in sim.particles:
        p.vx, p.vy, p.vz = p.vx / scale, p.vy / scale, p.vz / scale
    sim.G = 1.0
    sim.gravity = "basic"
    sim.integrator = integrator
    _set_options(sim, integrator, options)
    sim.dt = float(dt) * scale
    sim.exact_finish_time = 0
    m = bodies._m
    v0 = bodies._v / scale
    l_scale = float(np.sum(m * np.linalg.norm(bodies._x, axis=1)
                           * np.linalg.norm(v0, axis=1))) or 1.0
    e0, l0 = energy_and_momentum(sim)
    out_t = on_steps(np.linspace(0.0, until, max(outputs, 2))[1:], dt)
    ts, es, ls = [0.0], [e0], [l0]
    t_start = time.perf_counter()
    try:
        for t_out in out_t:
            sim.integrate((float(t_out) - 0.5 * dt) * scale, exact_finish_time=0)
            e, lvec = energy_and_momentum(sim)
            ts.append(sim.t / scale)
            es.append(e)
            ls.append(lvec)
            x = np.array([p.xyz for p in sim.particles])
            if not (np.all(np.isfinite(x)) and math.isfinite(e)):
                row.update(outcome="NonFiniteState",
                           message=f"REBOUND state non-finite by t = {sim.t / scale:.10g}")
                break
            if time.perf_counter() - t_start > wall_limit:
                row.update(outcome="WallTimeExceeded",
                           message=f"passed {wall_limit:g} s at t = {sim.t / scale:.10g}")
                break
    except Exception as exc:  # REBOUND raises its own kinds
        row.update(outcome=type(exc).__name__, message=str(exc))
    wall = time.perf_counter() - t_start
    es = np.array(es)
    energy = np.abs(es - e0) / abs(e0) if e0 != 0 else np.abs(es - e0)
    momentum = vector_relative_error(np.array(ls), l0, l_scale)
    row.update(wall_time=wall, steps=int(sim.steps_done), t_end=float(sim.t / scale),
               x=np.array([p.xyz for p in sim.particles]), times=np.array(ts),
               energy_error=energy, angular_momentum_error=momentum,
               energy_error_max=_largest(energy), angular_momentum_error_max=_largest(momentum),
               force_evaluations=int(sim.steps_done))     # one kick a step, no corrector
    return row


def _largest(a):
    a = np.asarray(a, dtype=float)
    if a.size == 0:
        return math.nan
    return float(a.max()) if np.all(np.isfinite(a)) else math.inf


def measure(problem, integrator, quick, dt=None, options=None, rebound=False,
            reference=False):
    """One point of a line (runs on a worker).  For REBOUND, ``integrator``
    is a method's name (:func:`rebound_method`), which names the series."""
    prob = cases.problem(problem)
    body_set = cases.bodies(prob)
    until = SWEEP[problem][1 if quick else 0]
    name, run_options = integrator, dict(options or {})
    if rebound:
        name, base = rebound_method(integrator)
        run_options = {**base, **run_options}
        run = _run_unit_g if name == "whfast512" else run_rebound
    else:
        run = run_orbits
    best = None
    for _ in range(REPEATS):
        extra = {"count_evaluations": True} if rebound and name == "ias15" else {}
        if rebound:
            extra["label"] = _series_name(integrator, rebound)
        row = run(body_set, name, run_options, dt=dt, until=until, outputs=OUTPUTS, **extra)
        if best is None or row["wall_time"] < best["wall_time"]:
            best = row
        if row["wall_time"] > SHORT_RUN or row["outcome"] != "completed":
            break
    if rebound and integrator in REBOUND_FIXED_STEP and integrator not in ("leapfrog", "whfast"):
        # run_rebound counts one kick a step; these take more, and their
        # correctors more at every output
        per_step, per_sync = force_evaluations_per_step(problem, integrator)
        segments = len(best["times"]) - 1 if best["times"] is not None else 1
        best["force_evaluations"] = int(round(per_step * best["steps"] + per_sync * segments))
    for key in ("times", "energy_error", "angular_momentum_error"):
        best.pop(key, None)
    best.update(problem=problem, rebound=rebound,
                series="reference" if reference else _series_name(integrator, rebound),
                knob=dt if dt is not None else next(iter((options or {}).values()), None))
    return best


def _series_name(integrator, rebound):
    return f"REBOUND {integrator}" if rebound else integrator


def tasks(quick):
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
                    add(name, cost, options=cases.tolerance_options(name, tol))
            else:
                for f in DT_FACTORS[k]:
                    add(name, steps / f * integ.forces_per_step * 1e-7, dt=prob.dt * f)
        for eps in EPSILONS[k]:
            add("ias15", steps * 1e-6, rebound=True, options={"epsilon": eps})
        # every fixed-step method of REBOUND's but leapfrog is a
        # Wisdom-Holman split, left out where ours are
        split_ok = cases.applies(prob, "rebound-whfast", quick, body_set) is None
        fixed = [n for n in REBOUND_FIXED_STEP if n == "leapfrog" or split_ok]
        if split_ok and whfast512_status()[0]:
            fixed.append("whfast512")
        for name in fixed:
            for f in DT_FACTORS[k]:
                add(name, steps / f * 1e-7 * _REBOUND_COST.get(name, 1), rebound=True,
                    dt=prob.dt * f)
        # the reference: REBOUND's IAS15 at its default epsilon
        add("ias15", steps * 1e-6, rebound=True, options={"epsilon": 1e-9}, reference=True)
    return out


def _attach_errors(rows):
    """Add ``position_error`` (against the reference) to every row."""
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
    # REBOUND's in greys, dashed or dotted, a marker each
    for j, s in enumerate(s for s in series if s.startswith("REBOUND")):
        style[s] = dict(color=("k", "0.35", "0.6")[j % 3], marker="x+|1234"[j % 7],
                        ls=("--", ":", "-.")[j // 3 % 3], lw=2)
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
             "taylor sweeps tol (which sets its order); the IAS15s sweep epsilon. "
             "REBOUND's integrators are on the same axes (grey, "
             "dashed or dotted): its defaults, leapfrog, WHFast (no corrector) and IAS15, "
             "and its best fixed-step methods, WHFast with the 11th-order symplectic "
             "corrector, WHCKL (lazy implementer's kernel, 17th-order corrector) and "
             "SABA(10,6,4), all with safe_mode 0 (synchronised at outputs only), so "
             "that REBOUND's cheapest is its best. Their force evaluations are counted "
             "(a no-op additional force tallies REBOUND's calls), not taken as one a step. "
             + _whfast512_sentence() + " Position errors are against the exact orbit for "
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
        if cases.applies(prob, "rebound-whfast", quick, body_set, length) is not None:
            # the same reason keeps out REBOUND's other Wisdom-Holman splits
            skipped += [(f"rebound-{n}", "as rebound-whfast") for n in REBOUND_FIXED_STEP
                        if n not in ("leapfrog", "whfast")]
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


def _whfast512_sentence():
    ok, why = whfast512_status()
    if ok:
        return ("REBOUND's WHFast512 (AVX-512) runs here and is swept too, in a time unit "
                "in which G = 1, as it requires.")
    return f"REBOUND's WHFast512 was tried once and could not run here: {why.rstrip('.')}."


def _knob(r):
    if r.get("dt") is not None:
        return f"dt = {r['dt']:.4g}"
    return ", ".join(f"{k} = {v:g}" for k, v in (r.get("options") or {}).items()
                     if k != "atol" and isinstance(v, (int, float)))


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
