"""Close encounters and collisions: mergers beside REBOUND's, and the outcomes
of violently unstable planetary systems.

Two measurements:

* **mergers**: a ring of planetesimals with inflated radii about a Sun-mass
  star (``examples/planetesimal_accretion.py``'s problem), integrated with our
  ``ias15`` and ``collisions="merge"`` and with REBOUND's IAS15 with
  ``collision = "line"`` and its merge resolution, from the same floats.  The
  table gives the times and pairs of the first collisions of each code (the
  run is chaotic: the codes part after a few collisions, as two runs of one
  code do whose floats differ in the last bit), how many bodies are left, the
  energy error with what the mergers took out booked (our ``E + W``,
  REBOUND's ``energy()`` with ``track_energy_offset``), and the wall time.
* **scattering**: an ensemble of three Jupiter-mass planets 2 mutual Hill
  radii apart about a Sun-mass star (random phases and nodes, small random
  inclinations; radii three times Jupiter's, so that collisions come within
  the run), each run until its first event: a planet passing 30 au from the
  centre of mass (ejection), two planets touching, a planet touching the
  star, or the end.  The fractions of each outcome, with their
  binomial standard errors, are compared between our ``ias15`` and REBOUND's
  IAS15 (and ``trace`` and REBOUND's TRACE where the registry has ``trace``),
  with the energy error at the end of each run and the wall time.
"""

import ctypes
import math
import time

import astropy.units as u
import numpy as np

from .. import integrators, scenes
from ..bodies import BodySet
from ..errors import Collision, Escape, RunError
from ..simulation import Simulation
from ._format import fmt_err, fmt_time
from ._runner import Task

__all__ = ["TITLE", "tasks", "section", "summary_line", "ring", "three_planets",
           "merge_run", "scatter_member", "OUTCOMES", "fractions"]

TITLE = "Close encounters and collisions"

#: a Julian year in days
YEAR = 365.25
#: Jupiter's mass and radius (solar masses, au), the Sun's radius (au)
JUPITER_MASS, JUPITER_RADIUS, SUN_RADIUS = 9.547919e-4, 4.779e-4, 4.6505e-3
#: the scattering ensemble's spacing in mutual Hill radii and inner orbit (au)
SPACING, INNER = 2.0, 5.0
#: years of a scattering run in the full report (the quick one: 1000)
YEARS_FULL = 5000.0
#: the planets' radii in Jupiter's (inflated, so that collisions come within the run)
RADIUS_FACTOR = 3.0
#: a planet this far from the centre of mass (au) counts as ejected
EJECTION_DISTANCE = 30.0
#: the first events a scattering run ends with
OUTCOMES = ("ejection", "planet-planet", "star", "survived")


def _sizes(quick):
    # (ring bodies, ring years, scattering members, scattering years)
    return (24, 60.0, 24, 1000.0) if quick else (40, 150.0, 100, YEARS_FULL)


def ring(n, seed=1):
    """The planetesimal ring of ``n`` bodies (:func:`orbits.scenes.planetesimal_ring`)."""
    return scenes.planetesimal_ring(n, seed=seed)


def three_planets(member):
    """Member ``member`` of the scattering ensemble (a BodySet): three Jupiters
    :data:`SPACING` mutual Hill radii apart from :data:`INNER` au, circular,
    inclinations Rayleigh(0.001 rad), random nodes and phases, radii
    :data:`RADIUS_FACTOR` times Jupiter's."""
    rng = np.random.default_rng(1000 + member)
    x = (2 * JUPITER_MASS / 3) ** (1 / 3)
    k = SPACING * x / 2
    b = BodySet()
    b.add("Star", mass=1 * u.Msun, radius=SUN_RADIUS * u.au)
    a = INNER
    for name in ("b", "c", "d"):
        b.add(name, mass=JUPITER_MASS * u.Msun, primary="Star", a=a * u.au,
              inc=rng.rayleigh(0.001) * u.rad, Omega=rng.uniform(0, 360) * u.deg,
              M=rng.uniform(0, 360) * u.deg, radius=RADIUS_FACTOR * JUPITER_RADIUS * u.au)
        a = a * (1 + k) / (1 - k)
    b.move_to_com()
    return b


# -- mergers ---------------------------------------------------------------------------

def merge_run(code, quick):
    """The ring with mergers, by ``code`` ("orbits" or "rebound")."""
    n, years = _sizes(quick)[:2]
    bodies = ring(n)
    names = list(bodies.names)
    if code == "orbits":
        sim = Simulation(bodies, "ias15", collisions="merge")
        sim.run(until=1 * u.day, outputs=2, progress=False)      # compiled, warmed
        sim = Simulation(bodies, "ias15", collisions="merge")
        t0 = time.perf_counter()
        res = sim.run(until=years * u.yr, outputs=101, progress=False)
        wall = time.perf_counter() - t0
        c = res.collisions
        events = [(float(t), str(a), str(b)) for t, a, b in
                  zip(c["time"].to_value(u.day), c["body_1"], c["body_2"])]
        return {"kind": "merge", "code": code, "events": events, "left": len(sim.bodies),
                "energy_error": float(res.energy_error.max()), "wall_time": wall,
                "steps": int(res.steps), "n": n, "years": years}
    import rebound
    sim = bodies.to_rebound()
    sim.integrator = "ias15"
    sim.collision = "line"
    sim.track_energy_offset = 1
    hashes = list(names)            # REBOUND's particle index -> name, kept as it merges
    events = []
    merge = rebound.clibrebound.reb_collision_resolve_merge
    merge.restype = ctypes.c_int

    def record(sim_pointer, collision):
        s = sim_pointer.contents
        i, j = sorted((collision.p1, collision.p2))
        events.append((float(s.t), hashes[i], hashes[j]))
        removed = merge(sim_pointer, collision)     # 1: p1 removed, 2: p2 removed
        gone = collision.p1 if removed == 1 else collision.p2 if removed == 2 else None
        if gone is not None:
            del hashes[gone]
        return removed
    sim.collision_resolve = record
    e0 = sim.energy()
    t0 = time.perf_counter()
    sim.integrate(years * YEAR)
    wall = time.perf_counter() - t0
    return {"kind": "merge", "code": code, "events": events, "left": int(sim.N),
            "energy_error": abs((sim.energy() - e0) / e0), "wall_time": wall,
            "steps": int(sim.steps_done), "n": n, "years": years}


# -- scattering ------------------------------------------------------------------------

#: the codes of the scattering ensemble: (label, ours?, integrator, dt in days)
SCATTER_CODES = (("orbits ias15", True, "ias15", None),
                 ("REBOUND IAS15", False, "ias15", None))
TRACE_CODES = (("orbits trace", True, "trace", 20.0),
               ("REBOUND TRACE", False, "trace", 20.0))


def _codes():
    have = any(info.name == "trace" for info in integrators.available())
    return SCATTER_CODES + (TRACE_CODES if have else ())


def scatter_member(label, member, quick):
    """One run of the scattering ensemble by the code ``label`` (see
    :func:`_codes`): its first event, when, the energy error there, wall time."""
    code = {c[0]: c for c in _codes()}[label]
    _, ours, integrator, dt = code
    years = _sizes(quick)[3]
    bodies = three_planets(member)
    if ours:
        return _scatter_ours(label, member, bodies, integrator, dt, years)
    return _scatter_rebound(label, member, bodies, integrator, dt, years)


def _classify(pair, star="Star"):
    return "star" if star in pair else "planet-planet"


def _scatter_ours(label, member, bodies, integrator, dt, years):
    def make():
        return Simulation(bodies, integrator, dt=None if dt is None else dt * u.day,
                          collisions="halt", escape_distance=EJECTION_DISTANCE * u.au)
    make().run(until=1 * u.day, outputs=2, progress=False)     # compiled, warmed
    sim = make()
    t0 = time.perf_counter()
    try:
        res = sim.run(until=years * u.yr, outputs=2, progress=False)
        outcome, when = "survived", years
    except Collision as exc:
        res, outcome = exc.result, _classify(exc.bodies)
        when = exc.time.to_value(u.yr)
    except Escape as exc:
        res, outcome, when = exc.result, "ejection", exc.time.to_value(u.yr)
    except RunError as exc:
        res, outcome, when = exc.result, type(exc).__name__, float("nan")
    wall = time.perf_counter() - t0
    err = float(res.energy_error[-1]) if res is not None else float("nan")
    return {"kind": "scatter", "code": label, "member": member, "outcome": outcome,
            "time_yr": when, "energy_error": err, "wall_time": wall, "steps": int(sim.steps)}


def _scatter_rebound(label, member, bodies, integrator, dt, years):
    import rebound
    sim = bodies.to_rebound()
    sim.integrator = integrator
    if dt is not None:
        sim.dt = dt
    sim.collision = "line"
    sim.collision_resolve = "halt"
    sim.exit_max_distance = EJECTION_DISTANCE
    e0 = sim.energy()
    names = list(bodies.names)
    t0 = time.perf_counter()
    outcome, when = "survived", years
    try:
        sim.integrate(years * YEAR, exact_finish_time=0)
    except rebound.Collision:
        x = np.array([[p.x, p.y, p.z] for p in sim.particles])
        r = np.array([p.r for p in sim.particles])
        d = np.linalg.norm(x[:, None] - x[None], axis=-1) - (r[:, None] + r[None])
        np.fill_diagonal(d, np.inf)
        i, j = np.unravel_index(np.argmin(d), d.shape)
        outcome, when = _classify((names[i], names[j])), sim.t / YEAR
    except rebound.Escape:
        outcome, when = "ejection", sim.t / YEAR
    wall = time.perf_counter() - t0
    return {"kind": "scatter", "code": label, "member": member, "outcome": outcome,
            "time_yr": when, "energy_error": abs((sim.energy() - e0) / e0),
            "wall_time": wall, "steps": int(sim.steps_done)}


def fractions(rows, label):
    """``{outcome: (fraction, binomial standard error)}`` of one code's
    scattering runs, and how many runs."""
    runs = [r for r in rows if r.get("kind") == "scatter" and r["code"] == label]
    n = len(runs)
    out = {}
    for k in OUTCOMES:
        p = sum(r["outcome"] == k for r in runs) / n if n else float("nan")
        out[k] = (p, math.sqrt(p * (1 - p) / n) if n else float("nan"))
    return out, n


def tasks(quick):
    members = _sizes(quick)[2]
    out = [Task("orbits.validation.collisions:merge_run", dict(code=code, quick=quick),
                5.0 if quick else 20.0) for code in ("orbits", "rebound")]
    for label, *_ in _codes():
        for m in range(members):
            out.append(Task("orbits.validation.collisions:scatter_member",
                            dict(label=label, member=m, quick=quick), 0.5))
    return out


# -- the section -----------------------------------------------------------------------

def section(rows, out_dir, quick):
    n, years, members, span = _sizes(quick)
    merges = {r["code"]: r for r in rows if r.get("kind") == "merge"}
    lines = [f"## {TITLE}", "",
             f"**Mergers.** {n} planetesimals of 0.05 Earth masses between 0.9 and 1.1 au "
             f"about a Sun-mass star, radii inflated to 5e-4 au, over {years:g} years: our "
             "`ias15` with `collisions=\"merge\"` and REBOUND's IAS15 with `collision = "
             "\"line\"` and its merge resolution, from the same floats. The energy error "
             "counts what the mergers took out (our E + W, REBOUND's `energy()` with "
             "`track_energy_offset`).", "",
             "| code | collisions | bodies left | largest energy error | steps | wall time |",
             "|---|---|---|---|---|---|"]
    for code in ("orbits", "rebound"):
        r = merges.get(code)
        if r is None:
            continue
        lines.append(f"| {'ours' if code == 'orbits' else 'REBOUND'} | {len(r['events'])} | "
                     f"{r['left']} | {fmt_err(r['energy_error'])} | {r['steps']} | "
                     f"{fmt_time(r['wall_time'])} |")
    if len(merges) == 2:
        a, b = merges["orbits"]["events"], merges["rebound"]["events"]
        same = 0
        for ea, eb in zip(a, b):
            if (ea[1], ea[2]) != (eb[1], eb[2]) or abs(ea[0] - eb[0]) > 1.0:
                break
            same += 1
        lines += ["", f"The first {same} collisions are the same pairs in both codes, at "
                  "times within a day:", "",
                  "| # | pair | time ours [d] | time REBOUND [d] |", "|---|---|---|---|"]
        for k, (ea, eb) in enumerate(zip(a, b)):
            if k >= max(same + 1, 3):
                break
            pair = f"{ea[1]}–{ea[2]}" + ("" if (ea[1], ea[2]) == (eb[1], eb[2])
                                          else f" / {eb[1]}–{eb[2]}")
            lines.append(f"| {k + 1} | {pair} | {ea[0]:.4f} | {eb[0]:.4f} |")
        lines += ["", "After that the codes part, as chaotic runs do: a merger's time "
                  "decides where the merged body goes, and every later encounter with it."]
    lines += ["", f"**Scattering.** {members} systems of three Jupiters {SPACING:g} mutual "
              f"Hill radii apart from {INNER:g} au (radii {RADIUS_FACTOR:g} times Jupiter's, "
              "so that collisions come within the run; the Sun's), each run for "
              f"up to {span:g} years until its first event: ejection (a planet beyond "
              f"{EJECTION_DISTANCE:g} au), two planets touching, a planet touching the star. "
              "Fractions with their binomial standard errors; energy error at the end of "
              "each run (median and largest); wall time of the whole ensemble on one core.",
              "", "| code | runs | " + " | ".join(OUTCOMES) + " | median / largest energy "
              "error | wall time |", "|---|---|" + "---|" * len(OUTCOMES) + "---|---|"]
    stats = {}
    for label, *_ in _codes():
        fr, count = fractions(rows, label)
        if not count:
            continue
        runs = [r for r in rows if r.get("kind") == "scatter" and r["code"] == label]
        errs = np.array([r["energy_error"] for r in runs], dtype=float)
        wall = sum(r["wall_time"] for r in runs)
        stats[label] = (fr, count, wall, errs)
        cells = " | ".join(f"{p:.2f} ± {s:.2f}" for p, s in fr.values())
        lines.append(f"| {label} | {count} | {cells} | {fmt_err(float(np.nanmedian(errs)))} "
                     f"/ {fmt_err(float(np.nanmax(errs)))} | {fmt_time(wall)} |")
    pairs = [("orbits ias15", "REBOUND IAS15"), ("orbits trace", "orbits ias15"),
             ("orbits trace", "REBOUND TRACE")]
    notes = []
    for a, b in pairs:
        if a in stats and b in stats:
            worst = max(_sigma(stats[a][0][k], stats[b][0][k]) for k in OUTCOMES)
            notes.append(f"{a} against {b}: the fractions differ by at most "
                         f"{worst:.1f} standard errors; wall time ratio "
                         f"{stats[a][2] / stats[b][2]:.2f}.")
    if notes:
        lines += [""] + [f"- {t}" for t in notes]
    return "\n".join(lines) + "\n"


def _sigma(a, b):
    (pa, sa), (pb, sb) = a, b
    s = math.hypot(sa, sb)
    return abs(pa - pb) / s if s > 0 else (0.0 if pa == pb else math.inf)


def summary_line(rows):
    """One sentence for the report's summary."""
    merges = {r["code"]: r for r in rows if r.get("kind") == "merge"}
    if "orbits" not in merges:
        return ""
    r = merges["orbits"]
    text = (f"Mergers keep the energy books: a ring of planetesimals through "
            f"{len(r['events'])} mergers holds E + W to {fmt_err(r['energy_error'])}")
    if "rebound" in merges:
        text += f" (REBOUND with its energy offset: {fmt_err(merges['rebound']['energy_error'])})"
    return text + "."
