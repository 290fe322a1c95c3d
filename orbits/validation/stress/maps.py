"""The stress suite's section of the report: a map a sweep (integrators as rows,
the swept value as columns, each cell coloured by its class) and the Markdown
that says where each integrator is accurate, degraded or failed, from the
rows that :func:`orbits.validation.stress.sweeps.measure` returns.
"""

import pathlib

import numpy as np

from .classes import (ACCURATE, ACCURATE_ENERGY, ACCURATE_POSITION, CLASSES, DEGRADED, FAILED,
                      FAILED_ENERGY, FAILED_POSITION, LEFT_OUT, cell_text, classify)
from .problems import (ENCOUNTER_DT, ENCOUNTER_MASS, ENCOUNTER_SPEED, ENCOUNTER_TIME,
                       SPRING_DT, SPRING_SEGMENTS, SPRING_STEPS, adaptive)
from . import sweeps as _sweeps
from .sweeps import (KEPLER_ORBITS, KEPLER_STEPS_PER_ORBIT, MASS_RATIO_ECCENTRICITY,
                     MASS_RATIO_STEPS_PER_ORBIT, P_JUPITER, PYTHAGOREAN_OUTPUTS,
                     PYTHAGOREAN_UNTIL, STEP_ORBITS, map_rows, sci, wall_limit)

__all__ = ["TITLE", "section"]

TITLE = "Stress suite"


def _error_against(sweep, cell, ref, col):
    """Fill the cell's error from the sweep's REBOUND reference."""
    if cell["outcome"] != "completed" or cell.get("x") is None:
        return None
    x = np.asarray(cell["x"])
    if sweep == "step":
        xr = np.asarray(ref["x"])
        h, hr = x[1:] - x[0], xr[1:] - xr[0]
        # worst planet: heliocentric position error over heliocentric distance
        return float(np.max(np.linalg.norm(h - hr, axis=1) / np.linalg.norm(hr, axis=1)))
    if sweep == "encounter":
        xr = np.asarray(ref["columns"][col]["x"])
        # the pair's separation vector after the pass, relative: the outcome of
        # the encounter (the deflection), not the pair's smooth orbit
        s, sr = x[2] - x[1], xr[2] - xr[1]
        return float(np.linalg.norm(s - sr) / np.linalg.norm(sr))
    raise ValueError(sweep)


def _ranges(labels, idx):
    """Consecutive column indices as "a to b" runs."""
    parts, start = [], None
    for i, j in enumerate(idx):
        if start is None:
            start = j
        if i + 1 == len(idx) or idx[i + 1] != j + 1:
            parts.append(labels[start] if start == j else f"{labels[start]} to {labels[j]}")
            start = None
    return ", ".join(parts)


def _describe(labels, classes, outcomes):
    """For the summary table: where a row is accurate, degraded, failed.  Failed
    columns are grouped by how they failed, each named error after its
    columns ("e = 0.5 to e = 0.99, e = 0.9999 (NonFiniteState)")."""
    out = {}
    for cls in (ACCURATE, DEGRADED, FAILED):
        idx = [i for i, c in enumerate(classes) if c == cls]
        if not idx:
            out[cls] = "-"
        elif cls != FAILED:
            out[cls] = _ranges(labels, idx)
        else:
            parts = []
            for outcome in dict.fromkeys(outcomes[i] for i in idx):
                sub = [i for i in idx if outcomes[i] == outcome]
                text = _ranges(labels, sub)
                parts.append(text if outcome == "completed" else f"{text} ({outcome})")
            out[cls] = ", ".join(parts)
    return out


def _verdict(labels, classes, outcomes):
    """One sentence: accurate up to ..., degraded ..., fails at ... (Error)."""
    d = _describe(labels, classes, outcomes)
    parts = []
    if d[ACCURATE] != "-":
        parts.append(f"accurate at {d[ACCURATE]}")
    if d[DEGRADED] != "-":
        parts.append(f"degraded at {d[DEGRADED]}")
    if d[FAILED] != "-":
        parts.append(f"fails at {d[FAILED]}")
    return "; ".join(parts) or "left out"


_COLOURS = {ACCURATE: "#4caf50", DEGRADED: "#ffc107", FAILED: "#e53935",
            LEFT_OUT: "#d9d9d9"}


def _draw(path, title, panels):
    """One map: panels of (subtitle, row names, column labels, class grid,
    text grid)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    heights = [max(len(p[1]), 1) for p in panels]
    width = max(len(p[2]) for p in panels)
    fig, axes = plt.subplots(len(panels), 1, squeeze=False,
                             figsize=(2.4 + 0.95 * width, 1.2 + 0.3 * sum(heights)
                                      + 0.6 * len(panels)),
                             gridspec_kw={"height_ratios": heights})
    cmap = ListedColormap([_COLOURS[c] for c in CLASSES])
    for ax, (subtitle, rows, cols, grid, text) in zip(axes[:, 0], panels):
        codes = np.array([[CLASSES.index(c) for c in r] for r in grid], dtype=float)
        codes = codes.reshape(len(rows), len(cols))
        ax.imshow(codes, cmap=cmap, vmin=-0.5, vmax=len(CLASSES) - 0.5, aspect="auto")
        for i in range(len(rows)):
            for j in range(len(cols)):
                ax.text(j, i, text[i][j], ha="center", va="center", fontsize=7)
        ax.set_xticks(range(len(cols)), cols, fontsize=8)
        ax.set_yticks(range(len(rows)), rows, fontsize=8)
        ax.xaxis.tick_top()
        ax.set_xticks(np.arange(-0.5, len(cols)), minor=True)
        ax.set_yticks(np.arange(-0.5, len(rows)), minor=True)
        ax.grid(which="minor", color="white", linewidth=1)
        ax.tick_params(which="minor", length=0)
        if subtitle:
            ax.set_title(subtitle, fontsize=9, loc="left")
    fig.suptitle(title, fontsize=11)
    fig.legend(handles=[Patch(color=_COLOURS[c], label=c) for c in CLASSES],
               loc="lower center", ncol=4, fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0.04, 1, 0.97))
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _grid(spec, rows_by_name, names, refs, quick, tolerance):
    """Classes, texts and sentences of one panel (``tolerance``: the panel of the
    adaptive methods, which sweep their tolerance)."""
    values = spec.values(quick, tolerance)
    fmt = spec.adaptive_label if (tolerance and spec.split) else spec.label
    labels = [fmt(v) for v in values]
    classes, texts, table, notes = [], [], [], []
    for name in names:
        row = rows_by_name.get(name)
        if row is None or row["left_out"] is not None:
            classes.append([LEFT_OUT] * len(values))
            texts.append(["n/a"] * len(values))
            table.append((name, None, row["left_out"] if row else "not measured"))
            continue
        cls_row, txt_row, outs, reason = [], [], [], ""
        for j, cell in enumerate(row["cells"]):
            err = cell["error"]
            if spec.key in refs:
                err = cell["error"] = _error_against(spec.key, cell, refs[spec.key], j)
            cls = classify(err, cell["outcome"], spec.metric)
            cls_row.append(cls)
            txt_row.append(cell_text(cls, cell["outcome"], err))
            outs.append(cell["outcome"])
            if cls == LEFT_OUT and cell["outcome"] != "Skipped":
                reason = cell["message"].split(";")[0]
            if cell["warning"]:
                notes.append(f"{name} at {labels[j]}: {cell['warning'][:160]}")
        classes.append(cls_row)
        texts.append(txt_row)
        if all(c == LEFT_OUT for c in cls_row):
            table.append((name, None, reason))
        else:
            verdict = _verdict(labels, cls_row, outs)
            skipped = [labels[j] for j, o in enumerate(outs) if o == "Skipped"]
            if skipped:
                verdict += (f"; not run at {', '.join(skipped)} (an easier column passed "
                            f"the wall-time limit)")
            table.append((name, _describe(labels, cls_row, outs), verdict))
    return labels, classes, texts, table, notes


_INTRO = """\
Each map shows one sweep: integrators as rows, the swept value as columns.  A
cell is **accurate** (green) when its error is below {ap:g} (position, relative)
or {ae:g} (energy), **failed** (red) from {fp:g} (position) or {fe:g}
(energy), or when the run stopped with a named error, and **degraded** (amber)
in between; grey cells are integrators that do not apply ("n/a"), listed
below each map with the reason, or harder columns not run after an easier one
passed the wall-time limit ("skip").  The number in a cell is log10 of the error; a failed run
shows its error's abbreviation: NFS = NonFiniteState, SSU = StepSizeUnderflow,
CF = ConvergenceFailure, WTE = WallTimeExceeded (the run passed {wall:g} s of
wall time; a limit, not a wrong result).  A position error of a tenth of the
orbit is a different trajectory, hence the failure threshold; an energy error
of one per cent is already a tenth of an orbit in phase within an orbit.
Adaptive methods run at their default tolerance (rtol 1e-9, atol 1e-12;
IAS15 epsilon 1e-9) except where a sweep varies it.
"""

_SWEEP_TEXT = {
    "eccentricity": """\
A Sun-mass star and a Jupiter-mass planet (1e-3 Msun), a = 1 au, from true
anomaly 1 rad, for {orbits:g} orbits, so that the run ends away from
pericentre.  Fixed-step methods take dt = P/{kn}.  Error: the final planet-star
vector against the analytic orbit (Kepler's equation solved by
`orbits._kernels.anomalies`, no integrator involved), in units of a.""",
    "step": """\
The outer solar system (Hairer, Lubich & Wanner: Sun, four giant planets,
Pluto) for {jorb} periods of Jupiter (P_J = {pj:g} days; {years:.0f} years).
Fixed-step methods sweep the step; adaptive methods have no step to set and sweep their
tolerance instead (rtol = tol, atol = 1e-3 tol; IAS15 epsilon = tol).  Error:
the worst planet's final heliocentric position against REBOUND's IAS15
(default epsilon), over its heliocentric distance.""",
    "mass-ratio": """\
Two bodies, m2/m1 = q with m1 = 1 Msun, e = {me:g}, a = 1 au, for {orbits:g} orbits
at dt = P/{mn} (fixed-step methods).  Error: the final relative vector
against the analytic orbit, in units of a.  With two bodies the Jacobi split
of the Wisdom-Holman family is exact at any q (one Kepler orbit, no
interaction term); democratic heliocentric coordinates, added as a row, keep
the star's reflex motion as a separate term whose error grows with q.""",
    "encounter": """\
A Sun-mass star and two planets of {em:g} Msun each on a 1 au orbit, meeting
at {vinf:g} km/s at infinity, passing at the column's distance at t = {te:g} days;
the run ends at {te2:g} days.  The initial state is the closest approach
integrated backwards by REBOUND's IAS15, so the pass distance is set, not
hoped for; the table below measures it again in the forward reference run.
Fixed-step methods take dt = {edt:g} day.  Reference: REBOUND's IAS15 from the
same initial state.  Error: the planets' final separation vector against the
reference, over its length (the outcome of the encounter).  Point masses: at
1e-8 au the planets would have merged long before.""",
    "pythagorean": """\
Burrau's three bodies (masses 3, 4, 5 at rest, G = 1) from t = 0 to {pu:g},
through their close encounters.  Fixed-step methods sweep dt, adaptive ones
their tolerance.  The motion is chaotic, so the error is the largest relative
energy error over {po} outputs, not a final position.""",
    "spring": """\
x'' = -k x with m = 1, x0 = 1, v0 = 0, through `orbits.integrate`; fixed-step
methods take dt = {sdt:g} for {sn} steps (the integrator-choice guide's step;
sqrt(k) dt runs from 0.01 to 10), adaptive ones cover the same t = 0 to {su:g} at
their default tolerance.  One compiled force serves every k: k travels in
the state as a second component with zero velocity and acceleration (it
stays exactly k), and a third, zero, fills the state's row of three.  Runs are made of {seg} pieces with a wall-time check
between them (adaptive ones restart their step control at each).  Error: the
largest |x(t) - cos(sqrt(k) t)| over the run (amplitude 1).""",
}


def _sweep_text(key, quick):
    return _SWEEP_TEXT[key].format(
        orbits=KEPLER_ORBITS[quick], kn=KEPLER_STEPS_PER_ORBIT, jorb=STEP_ORBITS[quick],
        years=STEP_ORBITS[quick] * P_JUPITER / 365.25,
        pj=P_JUPITER, me=MASS_RATIO_ECCENTRICITY, mn=MASS_RATIO_STEPS_PER_ORBIT,
        em=ENCOUNTER_MASS, vinf=round(ENCOUNTER_SPEED * 1.495978707e8 / 86400, 1),
        te=ENCOUNTER_TIME, te2=2 * ENCOUNTER_TIME, edt=ENCOUNTER_DT,
        pu=PYTHAGOREAN_UNTIL[quick], po=PYTHAGOREAN_OUTPUTS, sdt=SPRING_DT, sn=SPRING_STEPS,
        su=SPRING_DT * SPRING_STEPS, seg=SPRING_SEGMENTS)


def section(rows, out_dir, quick):
    """The stress suite's Markdown, with its maps written into ``out_dir``."""
    out_dir = pathlib.Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    refs = {r["sweep"]: r for r in rows if r.get("kind") == "reference"}
    by_sweep = {}
    for r in rows:
        if r.get("kind") == "row":
            by_sweep.setdefault(r["sweep"], {})[r["label"]] = r
    md = [f"## {TITLE}", "",
          _INTRO.format(ap=ACCURATE_POSITION, ae=ACCURATE_ENERGY, fp=FAILED_POSITION,
                        fe=FAILED_ENERGY, wall=wall_limit(quick)).strip(), ""]
    if quick:
        md += ["*Quick mode: fewer columns and shorter runs than the full report.*", ""]
    for key, spec in _sweeps.SWEEPS.items():
        if key not in by_sweep:
            continue
        rows_by_name = by_sweep[key]
        md += [f"### {spec.title}", "", _sweep_text(key, quick), ""]
        panels, tables, notes = [], [], []
        labels = [lab for lab, _, _ in map_rows(key)]
        tolerance = {lab: adaptive(name) for lab, name, _ in map_rows(key)}
        groups = ([("fixed-step methods: step", [n for n in labels if not tolerance[n]], False),
                   ("adaptive methods: tolerance", [n for n in labels if tolerance[n]], True)]
                  if spec.split else [("", labels, False)])
        for subtitle, group, swept in groups:
            labels, classes, texts, table, nts = _grid(spec, rows_by_name, group, refs,
                                                       quick, swept)
            panels.append((subtitle, group, labels, classes, texts))
            tables.append((subtitle, table))
            notes += nts
        png = f"stress_{key.replace('-', '_')}.png"
        _draw(out_dir / png, spec.title, panels)
        md += [f"![{spec.title}]({png})", ""]
        if key == "encounter" and key in refs:
            md += _encounter_table(refs[key])
        left = []
        for subtitle, table in tables:
            if subtitle:
                md += [f"*{subtitle[0].upper()}{subtitle[1:]}*", ""]
            md += ["| integrator | accurate | degraded | failed | in a sentence |",
                   "|---|---|---|---|---|"]
            for name, desc, verdict in table:
                if desc is None:
                    md.append(f"| {name} | - | - | - | left out |")
                    left.append(f"- **{name}**: {verdict}")
                else:
                    md.append(f"| {name} | {desc[ACCURATE]} | {desc[DEGRADED]} | "
                              f"{desc[FAILED]} | {verdict} |")
            md.append("")
        if left:
            md += ["Left out:", ""] + left + [""]
        if notes:
            md += ["Warnings:", ""] + [f"- {n}" for n in sorted(set(notes))] + [""]
    return "\n".join(md).rstrip() + "\n"


def _encounter_table(ref):
    md = ["Pass distance measured in the reference run (REBOUND IAS15): the separation at",
          f"t = {ENCOUNTER_TIME:g} days and the pericentre of the pair's osculating "
          "two-body orbit there.", "",
          "| asked (au) | separation (au) | pericentre (au) | relative difference |",
          "|---|---|---|---|"]
    for c in ref["columns"]:
        diff = max(abs(c["separation"] / c["value"] - 1), abs(c["pericentre"] / c["value"] - 1))
        md.append(f"| {sci(c['value'])} | {c['separation']:.6e} | {c['pericentre']:.6e} | "
                  f"{diff:.1e} |")
    return md + [""]
