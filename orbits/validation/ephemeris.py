"""Against JPL DE421: the de421 scene integrated and compared with the ephemeris.

From the :func:`~orbits.scenes.de421` scene (the Sun, the planets, the Moon
and Pluto at J2000.0 TDB, barycentric as DE421 gives them, with DE421's GM
values), ``ias15`` runs Newtonian and with each general-relativity term of
:mod:`orbits.forces`, and REBOUND's IAS15 runs Newtonian and with the
matching REBOUNDx force, on the same floats with the same G and c.  Each
body's barycentric position is compared with DE421's at the same TDB date
(:func:`~orbits.scenes.de421_states`) after one and ten Julian years (one
and two in the quick report).

DE421's model has more than these eleven point masses: 343 asteroids, the
figures of the Earth, the Moon and the Sun, tides and the Moon's libration.
None is here, so the errors have a floor that no term below reaches; what
the tables show is the ordering (a relativistic term takes Mercury's error
down to that floor) and that our terms equal REBOUNDx's on the same start.

REBOUNDx's ``gr`` is not the same model as our :class:`~orbits.forces.GR`
for a body with a moon: it corrects Jacobi coordinates, with each body's
whole acceleration in the correction (Anderson et al. 1975 in implicit
form), so the Earth's pull on the Moon enters the Moon's term; ours is the
one-body formula about the Sun.  A second pair of ``gr`` runs without the
Moon measures the parity where the two models coincide, and a further run of
ours, GRFull() with the Earth's J2 (DE421's J2E and RE), measures how much of
the Moon's floor is the Earth's figure.
"""

import math
import pathlib

import astropy.constants as const
import astropy.units as u
import numpy as np

from .. import forces, scenes
from ..bodies import BodySet
from ..errors import RunError
from ..scenes import ephemerides
from ..simulation import Simulation
from ._measure import REBOUNDX_MISSING, rebound_with_extras
from ._runner import Task

__all__ = ["TITLE", "tasks", "section", "measure", "summary_line", "TERMS", "horizons",
           "YEAR", "parity"]

TITLE = "Against JPL DE421"

#: a Julian year in days
YEAR = 365.25

#: km in the au of the scene (IAU 2012, exact)
KM_PER_AU = (1 * u.au).to_value(u.km)

#: The runs, one column each: (key, our term, the REBOUNDx force).  The key
#: names the term in the tasks, so a task travels as strings.
TERMS = (("newtonian", None, None),
         ("gr", 'GR("Sun")', "gr"),
         ("gr_potential", 'GRPotential("Sun")', "gr_potential"),
         ("gr_full", "GRFull()", "gr_full"))

_TERM_LABEL = {key: ours for key, ours, _ in TERMS}
#: a further run of ours, for the floor: GRFull() with the Earth's J2 of DE421
_TERM_LABEL["gr_full_j2"] = "GRFull() + the Earth's J2"
_EFFECT = {key: theirs for key, _, theirs in TERMS}


def horizons(quick):
    """The compared times in Julian years."""
    return (1, 2) if quick else (1, 10)


def _forces(key):
    """Our terms for the run ``key``."""
    if key == "gr_full_j2":
        ephemeris = ephemerides._de421_ephemeris()
        return [forces.GRFull(), forces.ZonalHarmonics("Earth", ephemeris.RE * u.km,
                                                       J2=ephemeris.J2E)]
    return {"newtonian": [], "gr": [forces.GR("Sun")],
            "gr_potential": [forces.GRPotential("Sun")], "gr_full": [forces.GRFull()]}[key]


def _bodies_and_reference(moon, years):
    """The de421 scene (``moon=False``: without the Moon) and DE421's
    barycentric positions (n, N, 3) in au of its bodies at ``years``."""
    full = scenes.de421()
    x, _ = scenes.de421_states(ephemerides._J2000_JD_TDB + YEAR * np.asarray(years, dtype=float))
    keep = [i for i, name in enumerate(full.names) if moon or name != "Moon"]
    bodies = full if moon else BodySet.from_arrays(
        full.masses[keep], full.positions[keep], full.velocities[keep],
        names=[full.names[i] for i in keep], units=full.units)
    return bodies, x.to_value(u.au)[:, keep]


def _run_ours(bodies, key, days):
    sim = Simulation(bodies, "ias15", forces=_forces(key), monitors=())
    x = np.full((len(days), len(bodies), 3), np.nan)
    outcome, message = "completed", ""
    try:
        for k, t in enumerate(days):
            res = sim.run(until=t * u.day, outputs=1, progress=False)
            x[k] = res.positions[-1].to_value(bodies.units.length)
    except RunError as exc:
        outcome, message = type(exc).__name__, str(exc)
    return x, outcome, message


def _run_rebound(bodies, key, days):
    effect = _EFFECT.get(key)

    def load(sim, extras):
        force = extras.load_force(effect)
        extras.add_force(force)
        force.params["c"] = const.c.to_value(bodies.units.length / bodies.units.time)
        sim.particles[bodies.names.index("Sun")].params["gr_source"] = 1

    x = np.full((len(days), len(bodies), 3), np.nan)
    try:
        sim, extras = rebound_with_extras(bodies, None if effect is None else load)
    except ImportError:
        return x, "not run", REBOUNDX_MISSING
    outcome, message = "completed", ""
    try:
        for k, t in enumerate(days):
            sim.integrate(float(t), exact_finish_time=1)
            x[k] = [p.xyz for p in sim.particles]
            if not np.all(np.isfinite(x[k])):
                outcome, message = "NonFiniteState", f"REBOUND state non-finite by t = {t}"
                break
    except Exception as exc:  # REBOUND raises its own kinds
        outcome, message = type(exc).__name__, str(exc)
    del extras
    return x, outcome, message


def measure(term, code, quick, moon=True):
    """One run of the table: ``code`` ``"orbits"`` (our ``ias15``) or
    ``"rebound"`` (REBOUND's IAS15 with REBOUNDx), with the term ``term`` (a
    key of :data:`TERMS`), from the de421 scene (``moon=False``: without the
    Moon).  Positions (au, barycentric) and errors against DE421 (km) at
    each of :func:`horizons`."""
    years = horizons(quick)
    bodies, reference = _bodies_and_reference(moon, years)
    days = [YEAR * y for y in years]
    run = _run_ours if code == "orbits" else _run_rebound
    x, outcome, message = run(bodies, term, days)
    error = np.linalg.norm(x - reference, axis=-1) * KM_PER_AU
    return {"term": term, "code": code, "moon": bool(moon), "years": list(years),
            "names": list(bodies.names), "x": x, "error_km": error, "outcome": outcome,
            "message": message}


def tasks(quick):
    long = max(horizons(quick))
    out = []
    for key, _, _ in TERMS:
        for code in ("orbits", "rebound"):
            # rough seconds a year: REBOUNDx's gr_full is the slowest
            cost = {("gr_full", "rebound"): 0.2, ("gr_full", "orbits"): 0.05}.get(
                (key, code), 0.02) * long
            out.append(Task("orbits.validation.ephemeris:measure",
                            dict(term=key, code=code, quick=quick), cost))
    for code in ("orbits", "rebound"):
        out.append(Task("orbits.validation.ephemeris:measure",
                        dict(term="gr", code=code, quick=quick, moon=False), long * 0.02))
    out.append(Task("orbits.validation.ephemeris:measure",
                    dict(term="gr_full_j2", code="orbits", quick=quick), long * 0.05))
    return out


# -- the section --------------------------------------------------------------------
def _km(x):
    """A distance in km to three significant digits, thousands separated."""
    if x is None or not math.isfinite(x):
        return "–"
    if x == 0:
        return "0"
    digits = 2 - math.floor(math.log10(abs(x)))
    return f"{round(x, digits):,.{max(digits, 0)}f}"


def _au(x):
    return "–" if not math.isfinite(x) else f"{x:.1e}"


def _column(row):
    if row["code"] == "orbits":
        label = _TERM_LABEL[row["term"]]
        return "ias15" if label is None else f"ias15 + {label}"
    effect = _EFFECT[row["term"]]
    return "REBOUND" if effect is None else f"REBOUND + {effect}"


def _table(rows):
    """``{(code, term): row}`` of the runs with the Moon."""
    return {(r["code"], r["term"]): r for r in rows if r["moon"]}


def parity(ours, theirs, k, skip=()):
    """Largest |ours - REBOUND| (au) over the bodies at horizon ``k``, and
    the body where it is; ``skip`` names bodies left out."""
    if ours is None or theirs is None:
        return math.nan, ""
    d = np.linalg.norm(np.asarray(ours["x"][k]) - np.asarray(theirs["x"][k]), axis=-1)
    keep = [i for i, n in enumerate(ours["names"]) if n not in skip]
    d = d[keep]
    if not np.all(np.isfinite(d)):
        return math.nan, ""
    i = int(np.argmax(d))
    return float(d[i]), ours["names"][keep[i]]


def _error(table, code, term, body, k):
    row = table.get((code, term))
    if row is None or body not in row["names"]:
        return math.nan
    return float(row["error_km"][k][row["names"].index(body)])


def section(rows, out_dir, quick):
    out_dir = pathlib.Path(out_dir)
    table = _table(rows)
    years = rows[0]["years"]
    names = next(iter(table.values()))["names"]
    order = [(code, key) for code in ("orbits", "rebound") for key, _, _ in TERMS]
    present = [c for c in order if c in table]
    lines = [f"## {TITLE}", "",
             "The de421 scene (the Sun, the planets, the Moon and Pluto at J2000.0 TDB, "
             "barycentric as the ephemeris gives them and not moved to their centre of "
             "mass, with DE421's GM values) is integrated with our `ias15` and with "
             "REBOUND's IAS15, each at its default tolerance, Newtonian and with each "
             "general-relativity term: ours from `orbits.forces` and REBOUNDx's matching "
             "forces, with the Sun as the source, on the same floats with the same G and "
             "c (astropy's, in au/day). The tables give each body's barycentric position "
             "error against DE421 at the same TDB date, in km.", "",
             "DE421's model has more than these eleven point masses: 343 asteroids, the "
             "figures of the Earth, the Moon and the Sun, tides and the Moon's libration. "
             "None of them is in the scene, so every error has a floor that no "
             "relativistic term removes. The point of the tables is the ordering, and that "
             "our terms give what REBOUNDx's give.", ""]
    for k, y in enumerate(years):
        lines += [f"### After {y} year{'s' if y != 1 else ''}", "",
                  "| body | " + " | ".join(_column(table[c]) for c in present) + " |",
                  "|---|" + "---|" * len(present)]
        for name in names:
            cells = [_km(_error(table, code, key, name, k)) for code, key in present]
            lines.append(f"| {name} | " + " | ".join(cells) + " |")
        lines.append("")
    failed = [r for r in rows if r["outcome"] != "completed"]
    for r in failed:
        lines.append(f"- {_column(r)}{'' if r['moon'] else ' (no Moon)'}: "
                     f"**{r['outcome']}** {r['message']}")
    if failed:
        lines.append("")
    lines += [_reading(rows, table, years), ""]
    lines += _parity_lines(rows, table, years)
    name = "ephemeris_de421.png"
    try:
        _plot(table, present, names, years, out_dir / name)
        lines += ["", f"![position error against DE421 per body]({name})", ""]
    except ImportError:      # matplotlib missing: the tables stand alone
        pass
    return "\n".join(lines)


def _com_drift_km(years):
    """How far the scene's centre of mass moves from DE421's barycentre in
    ``years``: the scene keeps DE421's barycentric velocities, and the bodies
    left out (the asteroids) carry the rest of the momentum."""
    _, v = scenes.de421().center_of_mass()
    return float(np.linalg.norm(v.to_value(u.km / u.day))) * YEAR * years


def _heliocentric_km(row, body, k):
    """``body``'s error against DE421 at horizon ``k`` measured from the Sun."""
    if row is None or body not in row["names"]:
        return math.nan
    _, reference = _bodies_and_reference(row["moon"], row["years"])
    i, sun = row["names"].index(body), row["names"].index("Sun")
    x = np.asarray(row["x"][k])
    return float(np.linalg.norm((x[i] - x[sun]) - (reference[k, i] - reference[k, sun]))
                 * KM_PER_AU)


def _reading(rows, table, years):
    k = len(years) - 1
    y = years[k]
    span = f"{y} year{'s' if y != 1 else ''}"
    err = lambda key, body: _error(table, "orbits", key, body, k)  # noqa: E731
    newt, gr, full, pot = (err(key, "Mercury")
                           for key in ("newtonian", "gr", "gr_full", "gr_potential"))
    parts = []
    if all(math.isfinite(e) for e in (newt, gr, full)):
        parts.append(f"After {span}, Mercury is {_km(newt)} km from DE421 in the Newtonian "
                     f"run, {_km(gr)} km with GR(\"Sun\") and {_km(full)} km with GRFull(): "
                     f"GRFull() takes its error down {newt / full:.0f}-fold.")
        inner = [err("gr_full", b) for b in ("Venus", "Earth", "Mars")]
        sun = err("gr_full", "Sun")
        text = (f"What is left is a floor that the inner bodies share: with GRFull() the Sun "
                f"is {_km(sun)} km off and Venus, the Earth and Mars "
                f"{', '.join(_km(e) for e in inner)} km. The Sun's part is the eleven bodies' "
                f"centre of mass moving away from DE421's barycentre, "
                f"{_km(_com_drift_km(y))} km in {span} (the asteroids left out carry the "
                "rest of the momentum), and the planets follow the Sun")
        h_gr, h_full = (_heliocentric_km(table.get(("orbits", key)), "Mercury", k)
                        for key in ("gr", "gr_full"))
        if math.isfinite(h_gr) and math.isfinite(h_full):
            text += (f": measured from the Sun, Mercury is {_km(h_gr)} km off with "
                     f"GR(\"Sun\") and {_km(h_full)} km with GRFull()")
        parts.append(text + ".")
        if abs(gr - full) < 0.5 * min(inner):
            parts.append(
                "So the table shows that a relativistic term is needed, and not which of "
                "the two is nearer DE421's own relativity (the full EIH form of GRFull()): "
                f"they leave Mercury's barycentric errors {_km(abs(gr - full))} km apart, "
                "well inside the floor, and at that level the terms left out count too.")
        else:
            better = "GRFull()" if full < gr else "GR(\"Sun\")"
            parts.append(f"{better} leaves Mercury {_km(abs(gr - full))} km closer to DE421 "
                         "than the other.")
    moon_full = err("gr_full", "Moon")
    moon_j2 = err("gr_full_j2", "Moon")
    if math.isfinite(moon_full) and math.isfinite(moon_j2):
        parts.append(
            f"The Moon's floor is the highest, {_km(moon_full)} km with GRFull(), and is "
            "mostly the Earth's figure: a further run of ours with GRFull() and the Earth's "
            "J2 (ZonalHarmonics with DE421's own J2E and RE, the pole along the ICRF z "
            f"axis) leaves the Moon {_km(moon_j2)} km off.")
    if math.isfinite(pot) and math.isfinite(newt):
        parts.append(
            f"GRPotential(\"Sun\") leaves Mercury {_km(pot)} km off, "
            f"{'more' if pot > newt else 'less'} than the Newtonian run: the potential gives "
            "the right perihelion precession but not the right mean motion (REBOUNDx's "
            "documentation of gr_potential says so: wrong by order GM/(a c²)), and from "
            "the ephemeris's positions and velocities a wrong mean motion is an along-track "
            "error that grows with time. It is there for the Wisdom-Holman methods, which "
            "take no velocity-dependent term.")
    return " ".join(parts)


def _parity_lines(rows, table, years):
    heads = " | ".join(f"after {y} yr" for y in years)
    lines = ["Our runs against REBOUND's on the same start: the largest distance between "
             "the two codes' positions of a body (au), and the body.", "",
             f"| term | {heads} |", "|---|" + "---|" * len(years)]
    for key, ours, theirs in TERMS:
        cells = []
        for k in range(len(years)):
            d, body = parity(table.get(("orbits", key)), table.get(("rebound", key)), k)
            cells.append(f"{_au(d)} ({body})" if body else "–")
        label = ("Newtonian" if ours is None else f"{ours} against {theirs}")
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    k = len(years) - 1
    nomoon = {r["code"]: r for r in rows if not r["moon"]}
    d_all = parity(table.get(("orbits", "gr")), table.get(("rebound", "gr")), k)
    d_rest = parity(table.get(("orbits", "gr")), table.get(("rebound", "gr")), k,
                    skip=("Moon",))
    d_none = parity(nomoon.get("orbits"), nomoon.get("rebound"), k)
    worst = max((parity(table.get(("orbits", key)), table.get(("rebound", key)), k)[0]
                 for key, _, _ in TERMS if key != "gr"), default=math.nan)
    text = (f"Newtonian, with GRPotential and with GRFull the codes agree to "
            f"{_au(worst)} au after {years[k]} years. ")
    if math.isfinite(d_all[0]):
        text += (f"GR(\"Sun\") and REBOUNDx's gr differ by {_au(d_all[0])} au "
                 f"({_km(d_all[0] * KM_PER_AU)} km, the {d_all[1]}), and by at most "
                 f"{_au(d_rest[0])} au for any other body: the two are different models "
                 "for a body with a moon. REBOUNDx's gr corrects Jacobi coordinates and puts "
                 "each body's whole acceleration into the correction (the implicit form of "
                 "Anderson et al. 1975), so the Earth's pull on the Moon enters the Moon's "
                 "term; ours is the one-body formula about the Sun.")
    if math.isfinite(d_none[0]):
        text += (f" Without the Moon (a second pair of runs) the two agree to "
                 f"{_au(d_none[0])} au.")
    return lines + ["", text]


def summary_line(rows):
    """One sentence for the report's summary."""
    table = _table(rows)
    if not table:
        return ""
    years = next(iter(table.values()))["years"]
    k = len(years) - 1
    newt = _error(table, "orbits", "newtonian", "Mercury", k)
    full = _error(table, "orbits", "gr_full", "Mercury", k)
    d = parity(table.get(("orbits", "gr_full")), table.get(("rebound", "gr_full")), k)[0]
    if not (math.isfinite(newt) and math.isfinite(full)):
        return ""
    return (f"Against JPL DE421 over {years[k]} years, GRFull() takes Mercury's error from "
            f"{_km(newt)} km (Newtonian) to {_km(full)} km, and equals REBOUNDx's gr_full "
            f"to {_au(d)} au.")


def _plot(table, present, names, years, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    colours = dict(zip((key for key, _, _ in TERMS), ("C0", "C1", "C2", "C3")))
    shift = dict(zip((key for key, _, _ in TERMS), (-0.24, -0.08, 0.08, 0.24)))
    fig, axes = plt.subplots(1, len(years), figsize=(6 * len(years), 4.8), sharey=True,
                             squeeze=False)
    pos = np.arange(len(names))
    for k, (ax, y) in enumerate(zip(axes[0], years)):
        for code, key in present:
            row = table[(code, key)]
            e = np.asarray(row["error_km"][k], dtype=float)
            ok = np.isfinite(e) & (e > 0)
            ours = code == "orbits"
            ax.semilogy(pos[ok] + shift[key], e[ok], "o", ls="none",
                        ms=5 if ours else 9, color=colours[key],
                        mfc=colours[key] if ours else "none", mew=1.2,
                        label=_column(row))
        ax.set_xticks(pos)
        ax.set_xticklabels(names, rotation=45, ha="right")
        ax.set_title(f"after {y} year{'s' if y != 1 else ''}")
        ax.grid(True, which="major", axis="y", alpha=0.3)
    axes[0][0].set_ylabel("barycentric position error against DE421 [km]")
    axes[0][-1].legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
