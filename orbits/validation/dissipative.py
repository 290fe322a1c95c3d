"""Dissipative forces: Migration, TidesConstantTimeLag and RadiationPressure
beside REBOUNDx and against their analytic rates.

Two checks of each term of :mod:`orbits.forces` that takes energy out of an
orbit:

* **parity**: our ``ias15`` with the term and REBOUND's IAS15 with the
  matching REBOUNDx force (``modify_orbits_forces``,
  ``tides_constant_time_lag``, ``radiation_forces``), from the same floats
  with the same G and c, over 1000 orbits (200 in the quick report).  The
  table gives the largest distance between the two codes' positions of a
  body, as a fraction of the orbit's size, beside how far the term moves the
  bodies (REBOUNDx with the force against REBOUND without it), so that the
  agreement is seen against the size of the effect;
* **analytic rates**: the orbit-averaged rates of the papers, measured from
  runs of ours: the exponential migration and damping time scales
  (Papaloizou & Larwood 2000), Hut's (1981) tidal de/dt and the
  Poynting-Robertson in-spiral of Wyatt & Whipple (1950).  Each rate is
  fitted over whole orbits, and its relative error is set beside the size of
  what the analytic rate leaves out.

The problems are those of ``tests/test_dissipative.py``, which asserts the
bounds (1e-8 of the orbit for parity, 1 % for the rates).
"""

import math
import pathlib
import time

import astropy.constants as const
import astropy.units as u
import numpy as np

from .. import forces
from ..bodies import BodySet
from ..errors import RunError
from ..simulation import Simulation
from ..units import UnitSystem
from ._format import fmt_err, fmt_time
from ._measure import REBOUNDX_MISSING, rebound_with_extras
from ._runner import Task

__all__ = ["TITLE", "tasks", "section", "measure", "rate", "summary_line", "PARITY_CASES",
           "RATE_CASES", "YEAR", "parity_series", "hut_de_dt", "orbits_run"]

TITLE = "Dissipative forces"

#: a Julian year in days
YEAR = 365.25

#: evenly spaced outputs of a parity run, the start included
OUTPUTS = 21

#: the parity problems, in the table's order: key -> (our term, REBOUNDx's
#: force, what the problem is, the body whose orbit is the scale)
PARITY_CASES = {
    "migration": ('Migration("Planet", tau_a=5000 yr, tau_e=2000 yr, tau_inc=3000 yr)',
                  "modify_orbits_forces",
                  "a Jupiter at 1 au (e = 0.1, inc = 0.1) migrating and damping", "Planet"),
    "tides-planet": ('TidesConstantTimeLag("Planet", k2=0.5, time_lag=0.01 d, radius=1 R_J, '
                     "spin=2 pi / 0.4 d)", "tides_constant_time_lag",
                     "a hot Jupiter at 0.05 au (e = 0.1), the tide raised on it by the star",
                     "Planet"),
    "tides-star": ('TidesConstantTimeLag("Star", k2=0.03, time_lag=0.2 d, radius=1 R_sun, '
                   "spin=2 pi / 25 d)", "tides_constant_time_lag",
                   "the same hot Jupiter and a second planet at 0.12 au, the tide raised on "
                   "the star by both", "Planet"),
    "radiation": ('RadiationPressure("Sun", beta={"dust1": 0.05, "dust2": 0.2})',
                  "radiation_forces",
                  "two dust grains at 1 and 1.5 au (e = 0.1, 0.2) with Jupiter at 5.2 au, "
                  "which feels no radiation", "dust1"),
}

#: the analytic-rate runs: key -> (the term, what is measured)
RATE_CASES = {
    "migration-a": ("Migration", "tau_a = +100 yr and -100 yr: the e-folding time of a"),
    "migration-e-inc": ("Migration", "tau_e = 40 yr, tau_inc = 60 yr: the e-folding times "
                                     "of e and inc"),
    "tides": ("TidesConstantTimeLag", "Hut's (1981) de/dt, spin 0 and synchronous"),
    "radiation": ("RadiationPressure", "the Poynting-Robertson in-spiral time"),
}


def orbits_run(quick):
    """How many orbits of the scale body a parity run lasts."""
    return 200 if quick else 1000


# -- the problems ------------------------------------------------------------------------

def _star_planet(a, e, inc, mass=1 * u.Mjup):
    b = BodySet()
    b.add("Star", mass=1 * u.Msun)
    b.add("Planet", mass=mass, primary="Star", a=a * u.au, e=e, inc=inc * u.rad,
          Omega=0.3 * u.rad, omega=1.0 * u.rad, f=0.5 * u.rad)
    b.move_to_com()
    return b


def _parity_problem(key):
    """``(bodies, our terms, load(sim, rebx), period [day])`` of a parity case;
    ``load`` adds REBOUNDx's force to a REBOUND simulation of the bodies."""
    if key == "migration":
        b = _star_planet(1.0, 0.1, 0.1)
        taus = {"tau_a": 5000 * YEAR, "tau_e": 2000 * YEAR, "tau_inc": 3000 * YEAR}
        terms = [forces.Migration("Planet", **{k: t * u.day for k, t in taus.items()})]

        def load(sim, rebx):
            rebx.add_force(rebx.load_force("modify_orbits_forces"))
            for k, tau in taus.items():
                sim.particles[1].params[k] = -tau     # REBOUNDx: negative damps
        return b, terms, load, YEAR
    if key in ("tides-planet", "tides-star"):
        b = _star_planet(0.05, 0.1, 0.02)
        if key == "tides-star":
            b.add("Outer", mass=0.5 * u.Mjup, primary="Star", a=0.12 * u.au, e=0.05,
                  inc=0.01 * u.rad, f=2.0 * u.rad)
            b.move_to_com()
            body, k2, R, lag, spin = "Star", 0.03, 1 * u.Rsun, 0.2, 2 * math.pi / 25.0
        else:
            body, k2, R, lag, spin = "Planet", 0.5, 1 * u.Rjup, 0.01, 2 * math.pi / 0.4
        i = b.names.index(body)
        terms = [forces.TidesConstantTimeLag(body, k2=k2, time_lag=lag * u.day, radius=R,
                                             spin=[0, 0, spin] * u.rad / u.day)]

        def load(sim, rebx):
            rebx.add_force(rebx.load_force("tides_constant_time_lag"))
            p = sim.particles[i]
            p.r = R.to_value(u.au)
            p.params["tctl_k2"] = k2
            p.params["tctl_tau"] = lag
            p.params["OmegaMag"] = spin          # a spin along z, as ours
        return b, terms, load, 0.05 ** 1.5 * YEAR
    if key == "radiation":
        b = BodySet()
        b.add("Sun", mass=1 * u.Msun)
        b.add("Jupiter", mass=1 * u.Mjup, primary="Sun", a=5.2 * u.au, e=0.05)
        b.add("dust1", mass=0 * u.kg, primary="Sun", a=1.0 * u.au, e=0.1, inc=0.1 * u.rad)
        b.add("dust2", mass=0 * u.kg, primary="Sun", a=1.5 * u.au, e=0.2, f=1 * u.rad)
        b.move_to_com()
        betas = {"dust1": 0.05, "dust2": 0.2}
        terms = [forces.RadiationPressure("Sun", beta=betas)]

        def load(sim, rebx):
            f = rebx.load_force("radiation_forces")
            rebx.add_force(f)
            f.params["c"] = const.c.to_value(u.au / u.day)
            sim.particles[0].params["radiation_source"] = 1
            for name, beta in betas.items():
                sim.particles[b.names.index(name)].params["beta"] = beta
        return b, terms, load, YEAR
    raise KeyError(f"unknown case {key!r}; valid: {', '.join(PARITY_CASES)}")


def _scale(bodies, key):
    """The scale body's osculating semi-major axis at the start, au."""
    body = PARITY_CASES[key][3]
    return float(bodies.elements(body, primary=bodies.names[0])["a"].to_value(u.au))


# -- the measurements --------------------------------------------------------------------

def _run_ours(bodies, terms, times):
    x = np.full((len(times), len(bodies), 3), np.nan)
    make = lambda: Simulation(bodies, "ias15", forces=terms, monitors=())  # noqa: E731
    # compile first (a few steps of a fresh copy), so the wall time is the run's
    make().run(until=times[1] * 1e-6 * u.day, outputs=2, progress=False)
    sim = make()
    outcome, message = "completed", ""
    t0 = time.perf_counter()
    try:
        res = sim.run(until=times[-1] * u.day, outputs=len(times), progress=False)
        x[:] = res.positions.to_value(u.au)
    except RunError as exc:
        outcome, message = type(exc).__name__, str(exc)
    return x, time.perf_counter() - t0, sim.steps, outcome, message


def _run_rebound(bodies, load, times):
    x = np.full((len(times), len(bodies), 3), np.nan)
    try:
        sim, extras = rebound_with_extras(bodies, load)    # extras kept while sim integrates
    except ImportError:
        return x, math.nan, 0, "not run", REBOUNDX_MISSING
    outcome, message = "completed", ""
    t0 = time.perf_counter()
    try:
        for k, t in enumerate(times):
            if k:
                sim.integrate(float(t), exact_finish_time=1)
            x[k] = [p.xyz for p in sim.particles]
    except Exception as exc:  # REBOUND raises its own kinds
        outcome, message = type(exc).__name__, str(exc)
    wall = time.perf_counter() - t0
    del extras
    return x, wall, int(sim.steps_done), outcome, message


def measure(case, code, quick):
    """One parity run: ``code`` ``"orbits"`` (our ``ias15`` with the term),
    ``"reboundx"`` (REBOUND's IAS15 with REBOUNDx's force) or ``"rebound"``
    (REBOUND's IAS15 without it), positions (au) at :data:`OUTPUTS` evenly
    spaced times over :func:`orbits_run` orbits."""
    bodies, terms, load, period = _parity_problem(case)
    times = np.linspace(0.0, orbits_run(quick) * period, OUTPUTS)
    if code == "orbits":
        x, wall, steps, outcome, message = _run_ours(bodies, terms, times)
    else:
        x, wall, steps, outcome, message = _run_rebound(
            bodies, load if code == "reboundx" else None, times)
    return {"kind": "parity", "case": case, "code": code, "times": times, "period": period,
            "names": list(bodies.names), "scale": _scale(bodies, case), "x": x,
            "wall_time": wall, "steps": steps, "outcome": outcome, "message": message}


def _fit_rate(t, y):
    """Least-squares slope of ln y: over whole orbits, with ~20 outputs an orbit,
    the osculating elements' short-period terms average out."""
    return float(np.polyfit(t, np.log(y), 1)[0])


def hut_de_dt(e, n, a, k2, tau, R, m_body, m_other, spin):
    """Hut (1981) eq. 10 for the tide raised on ``m_body`` by ``m_other``, his
    ``k`` written ``k2`` as in :class:`~orbits.forces.TidesConstantTimeLag`::

        de/dt = -27 k2 tau n^2 (m_other / m_body) (R / a)^5 e / (1 - e^2)^(13/2)
                [f3(e^2) - (11/18) (1 - e^2)^(3/2) f4(e^2) Omega / n]

    with f3 = 1 + 15/4 e^2 + 15/8 e^4 + 5/64 e^6, f4 = 1 + 3/2 e^2 + 1/8 e^4.
    """
    e2 = e * e
    f3 = 1 + 3.75 * e2 + 1.875 * e2 ** 2 + 5 / 64 * e2 ** 3
    f4 = 1 + 1.5 * e2 + 0.125 * e2 ** 2
    return (-27 * k2 * tau * n ** 2 * (m_other / m_body) * (R / a) ** 5 * e
            / (1 - e2) ** 6.5 * (f3 - 11 / 18 * (1 - e2) ** 1.5 * f4 * spin / n))


def _run(bodies, terms, until_days, outputs):
    return Simulation(bodies, "ias15", forces=terms, monitors=()).run(
        until=until_days * u.day, outputs=outputs, progress=False)


def _elements(res, body):
    el = res.elements(body, primary=res.names[0])
    return (res.times.to_value(u.day), el["a"].to_value(u.au), el["e"].to_value(u.one),
            el["inc"].to_value(u.rad))


def _rate_rows(case):
    G = UnitSystem().G
    rows = []
    if case == "migration-a":
        # a circular orbit under -u / (2 tau_a): da/dt = -a / tau_a exactly while
        # e stays ~0; the forced e is O(1 / (n tau_a)) ~ 2e-3
        for tau in (100.0, -100.0):
            b = _star_planet(1.0, 0.0, 0.0, mass=1 * u.Mearth)
            res = _run(b, [forces.Migration("Planet", tau_a=tau * u.yr)], 50 * YEAR, 1001)
            t, a, _, _ = _elements(res, "Planet")
            rows.append({"what": f"tau_a = {tau:+g} yr: e-folding time of a",
                         "analytic": tau, "measured": -1 / _fit_rate(t, a) / YEAR,
                         "unit": "yr", "left_out": "the forced e, O(1 / (n tau_a)) = 2e-3"})
    elif case == "migration-e-inc":
        # orbit averages: de/dt = -e (1 - 3 e^2 / 4) / tau_e and
        # di/dt = -sin i / tau_inc, first order in 1 / (n tau)
        b = _star_planet(1.0, 0.05, 0.05, mass=1 * u.Mearth)
        term = forces.Migration("Planet", tau_e=40 * u.yr, tau_inc=60 * u.yr)
        t, _, e, inc = _elements(_run(b, [term], 40 * YEAR, 801), "Planet")
        rows.append({"what": "tau_e = 40 yr: e-folding time of e", "analytic": 40.0,
                     "measured": -1 / _fit_rate(t, e) / YEAR, "unit": "yr",
                     "left_out": "3 e² / 4 = 2e-3 at e = 0.05; terms of order "
                                 "1 / (n tau_e) = 4e-3"})
        rows.append({"what": "tau_inc = 60 yr: e-folding time of inc", "analytic": 60.0,
                     "measured": -1 / _fit_rate(t, inc) / YEAR, "unit": "yr",
                     "left_out": "1 - sin(i) / i = 4e-4 at i = 0.05; terms of order "
                                 "1 / (n tau_inc) = 3e-3"})
    elif case == "tides":
        # an inflated hot Jupiter (2 R_J at 0.03 au, k2 = 0.5, lag 0.05 d, e = 0.02)
        # over 200 orbits; Hut's rate at the run's mean a and e
        for synchronous in (False, True):
            b = _star_planet(0.03, 0.02, 0.0)
            m, M = b.masses[1].to_value(u.Msun), b.masses[0].to_value(u.Msun)
            n0 = math.sqrt(G * (M + m) / 0.03 ** 3)
            spin = n0 if synchronous else 0.0
            R = (2 * u.Rjup).to_value(u.au)
            term = forces.TidesConstantTimeLag("Planet", k2=0.5, time_lag=0.05 * u.day,
                                               radius=R * u.au, spin=[0, 0, spin] / u.day)
            t, a, e, _ = _elements(_run(b, [term], 200 * 2 * math.pi / n0, 4001), "Planet")
            n = math.sqrt(G * (M + m) / a.mean() ** 3)
            expected = hut_de_dt(e.mean(), n, a.mean(), 0.5, 0.05, R, m, M, spin) / e.mean()
            # the tide is 5e-5 of the star's pull and Hut's rate first order in it;
            # its conservative part makes the osculating e wobble by ~5e-5 / e; the
            # rate goes as a^-8, so at the mean a it is the mean rate to 3 d^2 for
            # an a falling by d over the run
            left_out = ("second order in the tide (5e-5 of gravity); the osculating e's "
                        "wobble, 5e-5 / e = 3e-3 of e, fitted over 200 orbits")
            d = (a[0] - a[-1]) / a.mean()
            if d > 1e-3:
                left_out += (f"; a falls by {100 * d:.1f} % and the rate is taken at the "
                             f"mean a: 3 d² = {3 * d * d:.0e}")
            rows.append({"what": f"Hut's d ln e / dt, spin {'= n' if synchronous else '0'}",
                         "analytic": expected * YEAR, "measured": _fit_rate(t, e) * YEAR,
                         "unit": "1/yr", "left_out": left_out})
    elif case == "radiation":
        # a circular orbit: r^2 = r0^2 - 4 beta G M t / c (Wyatt & Whipple 1950)
        beta, r0 = 0.2, 1.0
        mu = G * 1.0
        b = BodySet()
        b.add("Sun", mass=1 * u.Msun)
        b.add("dust", mass=0 * u.kg, position=[r0, 0, 0] * u.au,
              velocity=[0, math.sqrt((1 - beta) * mu / r0), 0] * u.au / u.day)
        res = _run(b, [forces.RadiationPressure("Sun", beta={"dust": beta})], 200 * YEAR,
                   2001)
        x = (res.positions[:, 1] - res.positions[:, 0]).to_value(u.au)
        slope = np.polyfit(res.times.to_value(u.day), np.sum(x * x, axis=1), 1)[0]
        c = const.c.to_value(u.au / u.day)
        rows.append({"what": "beta = 0.2 from 1 au: time to reach the Sun",
                     "analytic": c * r0 ** 2 / (4 * beta * mu) / YEAR,
                     "measured": r0 ** 2 / -slope / YEAR, "unit": "yr",
                     "left_out": "the forced e, O(beta v / c) = 2e-5; terms of order "
                                 "v² / c² = 1e-8"})
    else:
        raise KeyError(f"unknown case {case!r}; valid: {', '.join(RATE_CASES)}")
    return rows


def rate(case, quick):
    """The analytic-rate rows of one case (runs on a worker); the runs are the
    same in the quick report, a few seconds each."""
    out = {"kind": "rate", "case": case, "rows": [], "outcome": "completed", "message": ""}
    try:
        out["rows"] = _rate_rows(case)
    except RunError as exc:
        out.update(outcome=type(exc).__name__, message=str(exc))
    return out


def tasks(quick):
    n = orbits_run(quick)
    out = []
    for case in PARITY_CASES:
        for code in ("orbits", "reboundx", "rebound"):
            # rough seconds: 1e-3 an orbit, twice that for REBOUNDx's forces
            out.append(Task("orbits.validation.dissipative:measure",
                            dict(case=case, code=code, quick=quick),
                            (2e-3 if code == "reboundx" else 1e-3) * n))
    for case in RATE_CASES:
        out.append(Task("orbits.validation.dissipative:rate", dict(case=case, quick=quick),
                        2.0))
    return out


# -- the section --------------------------------------------------------------------

def parity_series(rows, case):
    """For one case: times (orbits), ``|ours - REBOUNDx|`` and ``|REBOUNDx -
    REBOUND|`` (the term's effect), each the largest over the bodies at every
    output as a fraction of the scale orbit's semi-major axis; None where a run
    is missing."""
    runs = {r["code"]: r for r in rows if r.get("kind") == "parity" and r["case"] == case}
    if not all(code in runs for code in ("orbits", "reboundx", "rebound")):
        return None
    ours, theirs, plain = (np.asarray(runs[c]["x"]) for c in ("orbits", "reboundx", "rebound"))
    scale = runs["orbits"]["scale"]
    diff = np.linalg.norm(ours - theirs, axis=-1).max(axis=-1) / scale
    effect = np.linalg.norm(theirs - plain, axis=-1).max(axis=-1) / scale
    return runs["orbits"]["times"] / runs["orbits"]["period"], diff, effect, runs


def _cell(x):
    return "–" if x is None or not math.isfinite(x) else f"{x:.1e}"


def section(rows, out_dir, quick):
    out_dir = pathlib.Path(out_dir)
    n = orbits_run(quick)
    lines = [f"## {TITLE}", "",
             "The three terms of `orbits.forces` that take energy out of an orbit, each "
             "beside REBOUNDx's matching force and against the rate its paper gives. "
             f"Parity: our `ias15` with the term and REBOUND's IAS15 with REBOUNDx's force, "
             f"each at its default tolerance, from the same floats with the same G and c "
             f"(astropy's, in au/day), over {n} orbits of the body named. Distances are the "
             "largest over the bodies, as a fraction of that body's semi-major axis; the "
             "term's effect is REBOUNDx with the force against REBOUND without it. Wall "
             "times are of one core, compilation excluded.", "",
             f"| term (REBOUNDx force) | problem | \\|ours − REBOUNDx\\| / a after {n} "
             "orbits | the term's effect / a | wall time ours / REBOUNDx [s] |",
             "|---|---|---|---|---|"]
    notes, worst, effects = [], 0.0, []
    for case, (ours, theirs, what, body) in PARITY_CASES.items():
        series = parity_series(rows, case)
        if series is None:
            continue
        _, diff, effect, runs = series
        for code, r in runs.items():
            if r["outcome"] != "completed":
                notes.append(f"- {case}, {code}: **{r['outcome']}** {r['message']}")
        d, eff = float(diff[-1]), float(effect[-1])
        if math.isfinite(d):
            worst = max(worst, d)
        if math.isfinite(eff):
            effects.append(eff)
        walls = " / ".join(fmt_time(runs[c]["wall_time"]) for c in ("orbits", "reboundx"))
        lines.append(f"| `{ours}` ({theirs}) | {what}; a = {runs['orbits']['scale']:.3g} au "
                     f"({body}) | {_cell(d)} | {_cell(eff)} | {walls} |")
    lines += [""] + notes + ([""] if notes else [])
    if effects:
        lines += [f"On every problem the two codes agree to {_cell(worst)} of the orbit, "
                  f"while the terms move the bodies by {_cell(min(effects))} to "
                  f"{_cell(max(effects))} of it, so the agreement is not that of a term "
                  "that does little. The tests (`tests/test_dissipative.py`) hold it "
                  "below 1e-8.", ""]
    name = "dissipative_parity.png"
    try:
        if _plot(rows, out_dir / name):
            lines += [f"![ours against REBOUNDx over time, beside each term's effect]({name})",
                      ""]
    except ImportError:      # matplotlib missing: the tables stand alone
        pass
    lines += ["Against the analytic rates: each measured from a run of ours (`ias15`), "
              "fitted over whole orbits (the slope of ln a, ln e, ln i, or of r² for the "
              "in-spiral).", "",
              "| term | quantity | analytic | measured | relative error | what the analytic "
              "rate leaves out |", "|---|---|---|---|---|---|"]
    largest = 0.0
    for r in rows:
        if r.get("kind") != "rate":
            continue
        if r["outcome"] != "completed":
            lines.append(f"| {RATE_CASES[r['case']][0]} | **{r['outcome']}** "
                         f"{r['message']} | | | | |")
            continue
        for q in r["rows"]:
            err = abs(q["measured"] / q["analytic"] - 1)
            largest = max(largest, err)
            lines.append(f"| {RATE_CASES[r['case']][0]} | {q['what']} | "
                         f"{q['analytic']:.6g} {q['unit']} | "
                         f"{q['measured']:.6g} {q['unit']} | {fmt_err(err)} | "
                         f"{q['left_out']} |")
    lines += ["", f"Every measured rate is within {fmt_err(largest)} of the analytic one "
              "(the tests hold each within 1 %). The right-hand column says what the "
              "analytic rate leaves out, and so how closely it can be expected to hold.", ""]
    return "\n".join(lines)


def summary_line(rows):
    """One sentence for the report's summary."""
    worst, rate_worst, effects = 0.0, 0.0, []
    for case in PARITY_CASES:
        series = parity_series(rows, case)
        if series is None:
            continue
        _, diff, effect, _ = series
        if not (math.isfinite(diff[-1]) and math.isfinite(effect[-1])):
            return ""
        worst = max(worst, float(diff[-1]))
        effects.append(float(effect[-1]))
    for r in rows:
        if r.get("kind") == "rate":
            for q in r["rows"]:
                rate_worst = max(rate_worst, abs(q["measured"] / q["analytic"] - 1))
    if not effects:
        return ""
    return (f"Migration, TidesConstantTimeLag and RadiationPressure equal REBOUNDx's forces "
            f"to {_cell(worst)} of the orbit while moving it by {_cell(min(effects))} or "
            f"more, and their rates match the analytic ones to {fmt_err(rate_worst)}.")


def _plot(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 6))
    drawn = False
    for k, case in enumerate(PARITY_CASES):
        series = parity_series(rows, case)
        if series is None:
            continue
        t, diff, effect, _ = series
        ok = t > 0
        colour = f"C{k}"
        ax.semilogy(t[ok], diff[ok], "o-", color=colour, ms=3, lw=1.2,
                    label=f"{case}: ours − REBOUNDx")
        ax.semilogy(t[ok], effect[ok], "--", color=colour, lw=1,
                    label=f"{case}: the term's effect")
        drawn = True
    if not drawn:
        plt.close(fig)
        return False
    ax.axhline(1e-8, color="k", ls=":", lw=1, label="the tests' bound")
    ax.set_xlabel("orbits of the body named in the table")
    ax.set_ylabel("largest position difference / a")
    ax.set_title("dissipative terms: ours against REBOUNDx (solid), and what the term "
                 "does (dashed)", fontsize=10)
    ax.grid(True, which="major", alpha=0.3)
    ax.legend(fontsize=7, ncol=3, loc="upper center", bbox_to_anchor=(0.5, -0.13))
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True
