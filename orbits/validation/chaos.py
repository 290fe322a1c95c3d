"""Chaos and frequencies: MEGNO maps and Lyapunov exponents beside REBOUND's,
the map's wall time against REBOUND on a process pool, and the outer solar
system's secular frequencies against published values.

The problem is that of ``examples/megno_map.py``: the Sun, Jupiter and Saturn
on their J2000 orbits and a massless test planet beyond Saturn, its
semi-major axis and eccentricity on a grid, each run carrying one tangent
vector (``monitors=["megno", "lyapunov"]``) with ``wh`` at 216 days (5 % of
Jupiter's period), against REBOUND's WHFast with ``init_megno``, from the
same floats with the same G, step and number of steps.

* **sample points**: ``<Y>`` (MEGNO's running mean) and the Lyapunov
  estimate ``ln(|delta(t)| / |delta(0)|) / t`` at grid points chosen to
  cover the regular, resonant and chaotic parts of the map.  Finite-time
  MEGNO depends on the initial tangent vector, which the two codes draw
  differently: REBOUND is run twice, once from our initial tangent (copied
  into its MEGNO variational particles after ``init_megno``), which compares
  the integrators, and once from its own random one, beside the spread of
  each code over a few seeds, which shows how much of a difference the
  tangent alone makes;
* **maps**: the whole grid, ours as an :class:`~orbits.ensemble.Ensemble` on
  a local Dask cluster, REBOUND's on a ``multiprocessing.Pool`` with as many
  workers, each timed once its workers are up and warm: the
  regular/chaotic classification (:data:`CHAOTIC`) compared point by point,
  ``<Y>`` compared where both codes call the orbit regular, and the wall
  times (goal: ours at most :data:`TIME_RATIO_GOAL` of REBOUND's);
* **secular frequencies** of the outer solar system (the Hairer-Lubich-Wanner
  scene) from a long ``wh`` run, with :func:`orbits.analysis.secular_frequencies`:
  g5, g6, s6 and the great inequality beside published values, to the
  tolerances of ``tests/test_frequencies.py``.

The quick report takes a 12 x 6 grid over 400 Jupiter orbits and a 1 Myr
frequency run; the full one a 32 x 16 grid over 2000 Jupiter orbits and
10 Myr.
"""

import functools
import math
import multiprocessing
import pathlib
import time

import astropy.units as u
import numpy as np

from .. import scenes
from ..analysis import mean_motion_frequencies, secular_frequencies
from ..bodies import BodySet
from ..ensemble import Ensemble, local_cluster
from ..errors import RunError
from ..simulation import Simulation
from ..units import UnitSystem
from ._format import fmt_time
from ._runner import Task

__all__ = ["TITLE", "tasks", "section", "summary_line", "sample", "maps", "frequencies",
           "bodies", "build", "grid", "span_steps", "rebound_member", "classify",
           "sample_points", "JUPITER", "SATURN", "MASS_RATIOS", "DT_DAYS", "SEED", "SEEDS",
           "CHAOTIC", "REGULAR_BELOW", "MEGNO_GOAL", "AGREEMENT_GOAL", "TIME_RATIO_GOAL",
           "PUBLISHED", "FREQUENCY_RTOL", "A_RANGE", "E_RANGE", "SAMPLE_TARGETS",
           "FREQUENCY_DT", "FREQUENCY_OUTPUT_EVERY", "frequency_span", "jupiter_period_days",
           "map_statistics"]

TITLE = "Chaos and frequencies"

# -- the problem ---------------------------------------------------------------------------

#: Jupiter's and Saturn's J2000 mean elements, heliocentric ecliptic (a [au], e,
#: inc, mean longitude L, longitude of perihelion varpi, node Omega [deg]):
#: Standish, "Keplerian elements for approximate positions of the major
#: planets", table 1 (JPL Solar System Dynamics, valid 1800-2050).
JUPITER = dict(a=5.20288700, e=0.04838624, inc=1.30439695, L=34.39644051, varpi=14.72847983,
               Omega=100.47390909)
SATURN = dict(a=9.53667594, e=0.05386179, inc=2.48599187, L=49.95424423, varpi=92.59887831,
              Omega=113.66242448)

#: Sun / planet (with its satellites) mass ratios, IAU 2009 system of
#: astronomical constants (Luzum et al. 2011, Celest. Mech. Dyn. Astr. 110, 293).
MASS_RATIOS = {"Jupiter": 1047.348644, "Saturn": 3497.9018}

#: The step, days: 5.0 % of Jupiter's period (4332.7 d), 50 steps a Saturn orbit.
DT_DAYS = 216.0

#: Seed of our random tangent vector (and of REBOUND's ``init_megno``) in the
#: maps; the sample points also use :data:`SEEDS` for the spread over seeds.
SEED = 1
SEEDS = (1, 2, 3, 4)

#: The test planet's grid: beyond Saturn, where Saturn's chaotic zone, the
#: Saturn-crossing orbits, the regular low-eccentricity region and Saturn's
#: mean-motion resonances (3:2 at 12.5 au, 2:1 at 15.1 au) all appear.
A_RANGE = (10.0, 16.0)     # au
E_RANGE = (0.0, 0.45)

#: ``<Y>`` above which an orbit counts as chaotic.  A regular orbit's <Y> tends
#: to 2, but after 2000 Jupiter orbits it still wanders with the tangent vector:
#: from 1.55 to 2.34 over seeds and codes near the resonances, up to 3.11 at
#: the edge of Saturn's chaotic zone (benchmarks/RESULTS.md lists the points).
#: A chaotic orbit's grows as lambda t / 2, passing 3 after six Lyapunov times.
#: 3 stays above nearly all of that wandering (2.5 would not: half the resonant
#: points above would then be called chaotic by one seed and regular by
#: another) and still catches Lyapunov times up to a sixth of the run.
CHAOTIC = 3.0

#: Where both codes' ``<Y>`` are below this, the orbit is regular for the
#: MEGNO comparison (the issue's "regular regions": both below about 2.5).
REGULAR_BELOW = 2.5

#: The issue's goals: ``<Y>`` within 0.05 of REBOUND's in regular regions, the
#: classification the same at 95 % of the points at least, and our map in at
#: most half of REBOUND's wall time on the same number of workers.
MEGNO_GOAL = 0.05
AGREEMENT_GOAL = 0.95
TIME_RATIO_GOAL = 0.5

#: Targets of the sample points (a [au], e), each moved to the nearest grid
#: point: Saturn's chaotic zone, the low-eccentricity regular region, the
#: 3:2, 5:3 and 2:1 resonances with Saturn, and the Saturn-crossing orbits.
#: The quick report takes the first 8.
SAMPLE_TARGETS = ((13.0, 0.05), (10.5, 0.05), (12.5, 0.2), (15.15, 0.1), (16.0, 0.0),
                  (11.0, 0.3), (13.4, 0.1), (15.5, 0.4), (11.5, 0.0), (12.5, 0.3),
                  (14.0, 0.1), (14.5, 0.15), (15.5, 0.05), (16.0, 0.3), (13.0, 0.4),
                  (14.5, 0.25))


def grid(quick):
    """The map's semi-major axes (au) and eccentricities: 12 x 6 (quick), 32 x 16."""
    na, ne = (12, 6) if quick else (32, 16)
    return np.linspace(*A_RANGE, na), np.linspace(*E_RANGE, ne)


def jupiter_period_days():
    """Jupiter's period about the Sun, days (two-body, with the package's G)."""
    mu = UnitSystem().G * (1 + 1 / MASS_RATIOS["Jupiter"])
    return 2 * math.pi * math.sqrt(JUPITER["a"] ** 3 / mu)


def span_steps(quick):
    """Steps of a map run: 400 Jupiter orbits (quick) or 2000."""
    return int(round((400 if quick else 2000) * jupiter_period_days() / DT_DAYS))


def sample_points(quick):
    """The sample points as (a, e) grid values, in :data:`SAMPLE_TARGETS`' order."""
    a, e = grid(quick)
    targets = SAMPLE_TARGETS[:8] if quick else SAMPLE_TARGETS
    out = []
    for ta, te in targets:
        p = (float(a[np.argmin(abs(a - ta))]), float(e[np.argmin(abs(e - te))]))
        if p not in out:
            out.append(p)
    return out


def bodies(a, e):
    """Sun, Jupiter, Saturn and a massless test planet at (a [au], e), in the
    ecliptic with its pericentre on the x axis, starting at aphelion (130 deg
    ahead of Saturn); barycentric."""
    b = _giants().copy()
    # last, so that in both codes' Jacobi coordinates it orbits the three others
    b.add("planet", mass=0 * u.kg, primary="Sun", a=a * u.au, e=e, M=180 * u.deg)
    b.move_to_com()
    return b


@functools.lru_cache(maxsize=1)
def _giants():
    # the same for every grid point: made once a process (it is a third of a
    # member's set-up time)
    b = BodySet()
    b.add("Sun", mass=1 * u.Msun)
    for name, el in (("Jupiter", JUPITER), ("Saturn", SATURN)):
        b.add(name, mass=u.Msun / MASS_RATIOS[name], primary="Sun", a=el["a"] * u.au,
              e=el["e"], inc=el["inc"] * u.deg, Omega=el["Omega"] * u.deg,
              omega=(el["varpi"] - el["Omega"]) * u.deg, M=(el["L"] - el["varpi"]) * u.deg)
    return b


def build(a, e, seed=SEED):
    """Our simulation of one grid point (module level: the ensemble pickles it)."""
    return Simulation(bodies(a, e), "wh", dt=DT_DAYS * u.day, monitors=("megno", "lyapunov"),
                      seed=seed)


def _job(a, e, steps, seed, same_tangent):
    """What a REBOUND worker needs: plain floats (ours, to the bit) and, to
    start from our tangent vector, that vector."""
    sim = build(a, e, seed)
    b = sim.bodies
    tangent = sim.tangent_vectors[0].copy() if same_tangent else None
    return (b.masses.to_value(b.units.mass), b.positions.to_value(b.units.length),
            b.velocities.to_value(b.units.length / b.units.time), b.units.G, DT_DAYS, steps,
            seed, tangent)


def rebound_member(job):
    """One run of REBOUND's WHFast with ``init_megno`` (in a pool worker): a dict of
    ``megno``, ``lyapunov`` (ln|delta| / t, 1/day), ``lyapunov_fit``
    (``sim.lyapunov()``, 1/day), ``wall`` (integration only, s), ``steps`` and
    ``outcome``."""
    import rebound
    m, x, v, G, dt, steps, seed, tangent = job
    sim = rebound.Simulation()
    sim.G = G
    for i in range(len(m)):
        sim.add(m=float(m[i]), x=float(x[i, 0]), y=float(x[i, 1]), z=float(x[i, 2]),
                vx=float(v[i, 0]), vy=float(v[i, 1]), vz=float(v[i, 2]))
    sim.integrator = "whfast"    # safe mode: REBOUND refuses MEGNO with safe_mode = 0
    sim.dt = dt
    sim.init_megno(seed=seed)
    var = sim.var_config[0]
    if tangent is not None:
        for p, row in zip(var.particles, tangent):
            p.x, p.y, p.z, p.vx, p.vy, p.vz = (float(c) for c in row)
    norm0 = _tangent_norm(var)
    out = {"outcome": "completed", "megno": math.nan, "lyapunov": math.nan,
           "lyapunov_fit": math.nan}
    t0 = time.perf_counter()
    try:
        # half a step short with exact_finish_time=0: exactly `steps` steps
        sim.integrate((steps - 0.5) * dt, exact_finish_time=0)
    except Exception as exc:    # REBOUND raises its own kinds
        out["outcome"] = type(exc).__name__
    out["wall"] = time.perf_counter() - t0
    out["steps"] = int(sim.steps_done)
    if out["outcome"] == "completed" and sim.t > 0:
        # the logarithm REBOUND took out when it rescaled the vector (where it does)
        lost = float(getattr(var, "lrescale", 0.0))
        out["megno"] = float(sim.megno())
        out["lyapunov"] = (math.log(_tangent_norm(var) / norm0) + lost) / sim.t
        out["lyapunov_fit"] = float(sim.lyapunov())
    return out


def _tangent_norm(var):
    return math.sqrt(sum(p.x * p.x + p.y * p.y + p.z * p.z + p.vx * p.vx + p.vy * p.vy
                         + p.vz * p.vz for p in var.particles))


def _ours(a, e, steps, seed):
    sim = build(a, e, seed)
    out = {"outcome": "completed", "megno": math.nan, "lyapunov": math.nan}
    t0 = time.perf_counter()
    try:
        res = sim.run(until=steps * DT_DAYS * u.day, outputs=2, progress=False)
        out["megno"] = float(res.megno[-1])
        out["lyapunov"] = float(res.lyapunov[-1].to_value(1 / u.day))
    except RunError as exc:
        out["outcome"] = type(exc).__name__
    out["wall"] = time.perf_counter() - t0
    out["steps"] = sim.steps
    return out


def classify(megno):
    """True where chaotic: ``<Y>`` above :data:`CHAOTIC`, or no value (a run that
    failed, which on this problem means an orbit thrown out)."""
    megno = np.asarray(megno, dtype=float)
    return ~(megno <= CHAOTIC)


# -- the measurements ----------------------------------------------------------------------

def sample(a, e, quick):
    """One sample point: ours and REBOUND's (from our tangent and from its own)
    with :data:`SEED`, and both over :data:`SEEDS` (runs on one core)."""
    steps = span_steps(quick)
    build(a, e).run(until=3 * DT_DAYS * u.day, outputs=2, progress=False)   # compile first
    seeds = SEEDS[:3] if quick else SEEDS
    ours = [_ours(a, e, steps, s) for s in seeds]
    same = rebound_member(_job(a, e, steps, SEED, same_tangent=True))
    own = [rebound_member(_job(a, e, steps, s, same_tangent=False)) for s in seeds]
    return {"kind": "sample", "a": a, "e": e, "steps": steps, "ours": ours[0],
            "rebound_same": same, "rebound_own": own[0],
            "ours_seeds": [r["megno"] for r in ours],
            "rebound_seeds": [r["megno"] for r in own]}


def _warm_worker():
    """Load the kernels of a map run on a worker (``client.run`` calls it on each)."""
    build(12.0, 0.0).run(until=3 * DT_DAYS * u.day, outputs=2, progress=False)
    return True


def _warm_pool(_):
    import rebound  # noqa: F401
    time.sleep(0.3)          # long enough that every worker takes one
    return True


def maps(quick, workers=None):
    """The whole grid three times, each timed with its workers warm: ours (an
    :class:`~orbits.ensemble.Ensemble` on a local cluster of ``workers``
    processes), REBOUND's from its own random tangent and REBOUND's from ours
    (a ``multiprocessing.Pool`` of ``workers`` processes).  Exclusive: it needs
    the machine to itself."""
    workers = int(workers or 1)
    a, e = grid(quick)
    steps = span_steps(quick)
    points = [(ai, ei) for ei in e for ai in a]          # e slowest, as Ensemble.grid
    t0 = time.perf_counter()
    own_jobs = [_job(ai, ei, steps, SEED, same_tangent=False) for ai, ei in points]
    same_jobs = [_job(ai, ei, steps, SEED, same_tangent=True) for ai, ei in points]
    prepare = time.perf_counter() - t0
    out = {"kind": "maps", "a": a, "e": e, "steps": steps, "workers": workers,
           "prepare_seconds": prepare}
    ens = Ensemble.grid(build, e=e, a=a)
    t0 = time.perf_counter()
    client = local_cluster(workers)
    pool = multiprocessing.get_context("spawn").Pool(workers)
    try:
        client.run(_warm_worker)
        pool.map(_warm_pool, range(workers), chunksize=1)
        out["startup_seconds"] = time.perf_counter() - t0
        # REBOUND, ours, REBOUND: ours between, so that a drift in the
        # machine's load falls on both
        t0 = time.perf_counter()
        own = pool.map(rebound_member, own_jobs)
        out["wall_rebound_own"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        df = ens.run(until=steps * DT_DAYS * u.day, client=client, outputs=2, progress=False)
        out["wall_ours"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        same = pool.map(rebound_member, same_jobs)
        out["wall_rebound_same"] = time.perf_counter() - t0
    finally:
        pool.close()
        pool.join()
        client.close()
        client.cluster.close()
    shape = (len(e), len(a))
    out["ours"] = df["megno"].to_numpy(dtype=float).reshape(shape)
    out["ours_outcomes"] = df["outcome"].to_numpy().reshape(shape)
    out["ours_run_seconds"] = float(df["wall_time_s"].sum())
    out["ours_steps"] = int(df["steps"].sum())
    for key, rows in (("rebound_own", own), ("rebound_same", same)):
        out[key] = np.array([r["megno"] for r in rows]).reshape(shape)
        out[f"{key}_outcomes"] = np.array([r["outcome"] for r in rows]).reshape(shape)
        out[f"{key}_run_seconds"] = float(sum(r["wall"] for r in rows))
        out[f"{key}_steps"] = int(sum(r["steps"] for r in rows))
    return out


#: Published values: the secular frequencies g5, g6 and s6 of La2004 (Laskar et
#: al. 2004, A&A 428, 261; arcsec/yr) and the great inequality's period from
#: Newcomb's mean motions n_J = 30.349043, n_S = 12.221133 deg/yr (883.3 yr);
#: those of tests/test_frequencies.py.
PUBLISHED = {"g5": 4.257, "g6": 28.245, "s6": -26.348,
             "great inequality": 360 / (5 * 12.221133 - 2 * 30.349043)}

#: Relative tolerances, from tests/test_frequencies.py: the scene's own offsets
#: from the real solar system (measured over 10 Myr: g5 -0.35 %, g6 +0.12 %,
#: s6 -0.08 %, great inequality +0.9 %; its initial conditions, not the
#: integration) plus, over 1 Myr, what the shorter run leaves (3.4e-4 for g5),
#: rounded up.
FREQUENCY_RTOL = {True: {"g5": 6e-3, "g6": 2.5e-3, "s6": 2e-3, "great inequality": 1.2e-2},
                  False: {"g5": 4e-3, "g6": 1.5e-3, "s6": 1.2e-3, "great inequality": 1.2e-2}}

#: the frequency run's step (1/30 of Jupiter's period) and output spacing
#: (4.5 outputs a period of the great inequality), as in tests/test_frequencies.py
FREQUENCY_DT = 146.1 * u.day
FREQUENCY_OUTPUT_EVERY = 200 * u.yr


def frequency_span(quick):
    """1 Myr (quick) or 10 Myr."""
    return (1e6 if quick else 1e7) * u.yr


def frequencies(quick):
    """The outer solar system's g5, g6, s6 (arcsec/yr) and great inequality
    (yr) from a ``wh`` run of :func:`frequency_span`."""
    span = frequency_span(quick)
    outputs = int(round((span / FREQUENCY_OUTPUT_EVERY).to_value(u.one))) + 1
    out = {"kind": "frequencies", "span_yr": span.to_value(u.yr), "outcome": "completed",
           "message": "", "values": {}}
    sim = Simulation(scenes.outer_solar_system(), "wh", dt=FREQUENCY_DT, monitors=())
    t0 = time.perf_counter()
    try:
        res = sim.run(until=span, outputs=outputs, progress=False)
    except RunError as exc:
        out.update(outcome=type(exc).__name__, message=str(exc))
        return out
    out["wall"] = time.perf_counter() - t0
    per = u.arcsec / u.yr
    jupiter = secular_frequencies(res, "Jupiter", n=6)
    saturn = secular_frequencies(res, "Saturn", n=6)
    gi = mean_motion_frequencies(res, {"Jupiter": 2, "Saturn": -5}, n=3)
    out["values"] = {"g5": float(jupiter.g.frequencies[0].to_value(per)),
                     "g6": float(saturn.g.frequencies[0].to_value(per)),
                     "s6": float(saturn.s.frequencies[0].to_value(per)),
                     "great inequality": float(gi.periods[0].to_value(u.yr))}
    return out


def tasks(quick):
    out = [Task("orbits.validation.chaos:sample", dict(a=a, e=e, quick=quick),
                0.5 if quick else 1.5)
           for a, e in sample_points(quick)]
    out.append(Task("orbits.validation.chaos:frequencies", dict(quick=quick),
                    2.0 if quick else 20.0))
    out.append(Task("orbits.validation.chaos:maps", dict(quick=quick), 1.0, exclusive=True))
    return out


# -- the section ---------------------------------------------------------------------------

def _f(x, digits=3):
    return "–" if x is None or not math.isfinite(x) else f"{x:.{digits}f}"


def _g(x):
    return "–" if x is None or not math.isfinite(x) else f"{x:.3g}"


def _per_kyr(per_day):
    return per_day * 365.25e3


def _range(values):
    vals = [v for v in values if math.isfinite(v)]
    return "–" if not vals else f"{min(vals):.3f} – {max(vals):.3f}"


def map_statistics(row):
    """The maps compared: for REBOUND from our tangent (``"same"``) and from its
    own (``"own"``), the fraction of points classified alike, how many points
    both call regular (both below :data:`REGULAR_BELOW`), the largest and the
    median ``|<Y> ours - <Y> REBOUND|`` there and the fraction within
    :data:`MEGNO_GOAL`; and the timing ratio."""
    ours = np.asarray(row["ours"], dtype=float)
    stats = {}
    for key in ("same", "own"):
        theirs = np.asarray(row[f"rebound_{key}"], dtype=float)
        agree = classify(ours) == classify(theirs)
        regular = (ours < REGULAR_BELOW) & (theirs < REGULAR_BELOW)
        diff = np.abs(ours - theirs)[regular]
        stats[key] = {"agreement": float(agree.mean()), "disagree": int((~agree).sum()),
                      "regular": int(regular.sum()),
                      "max_diff": float(diff.max()) if diff.size else math.nan,
                      "median_diff": float(np.median(diff)) if diff.size else math.nan,
                      "within_goal": float((diff <= MEGNO_GOAL).mean()) if diff.size
                      else math.nan}
    stats["chaotic_fraction"] = float(classify(ours).mean())
    stats["failed"] = int(sum(np.sum(np.asarray(row[k]) != "completed") for k in
                              ("ours_outcomes", "rebound_own_outcomes",
                               "rebound_same_outcomes")))
    best = min(row["wall_rebound_own"], row["wall_rebound_same"])
    stats["time_ratio"] = row["wall_ours"] / best
    return stats


def section(rows, out_dir, quick):
    out_dir = pathlib.Path(out_dir)
    samples = [r for r in rows if isinstance(r, dict) and r.get("kind") == "sample"]
    mrow = next((r for r in rows if isinstance(r, dict) and r.get("kind") == "maps"), None)
    frow = next((r for r in rows if isinstance(r, dict) and r.get("kind") == "frequencies"),
                None)
    steps = span_steps(quick)
    years = steps * DT_DAYS / 365.25
    a, e = grid(quick)
    lines = [f"## {TITLE}", "",
             "MEGNO stability maps of a massless test planet beyond Saturn (Sun, Jupiter "
             "and Saturn on their J2000 orbits, the planet's a and e on a "
             f"{len(a)} x {len(e)} grid, {A_RANGE[0]:g}–{A_RANGE[1]:g} au, "
             f"e {E_RANGE[0]:g}–{E_RANGE[1]:g}; `examples/megno_map.py` draws the same "
             f"problem): our `wh` with `monitors=[\"megno\", \"lyapunov\"]` and REBOUND's "
             f"WHFast with `init_megno`, from the same floats with the same G, a "
             f"{DT_DAYS:g}-day step (5 % of Jupiter's period) and the same {steps:,} steps "
             f"({years:,.0f} yr, {steps * DT_DAYS / jupiter_period_days():,.0f} Jupiter "
             f"orbits). `<Y>` tends to 2 on a regular orbit and grows as λt/2 on a chaotic "
             f"one; an orbit counts as chaotic where `<Y>` > {CHAOTIC:g} (or its run "
             "failed): a chaotic orbit passes 3 after six Lyapunov times, while at "
             "this length regular orbits near resonances still wander with the tangent "
             "vector, mostly below 2.5 and rarely up to 3 (the spread over seeds below); "
             "such points are the ones two tangents may classify differently.", "",
             "Finite-time MEGNO depends on the initial tangent vector, which the codes "
             "draw differently (its limit does not). So REBOUND runs twice: from our "
             "tangent, copied into its MEGNO variational particles after `init_megno` "
             "(\"same tangent\": this compares the integrators), and from its own random "
             "one (\"own tangent\"), beside the spread of each code over seeds "
             f"{', '.join(map(str, SEEDS[:3] if quick else SEEDS))}. λ is "
             "ln(|δ(t)| / |δ(0)|) / t for both (REBOUND's from its variational "
             "particles); `sim.lyapunov()`, REBOUND's own estimate, fits `<Y>`'s growth "
             "instead (Cincotta & Simó 2000) and is near 0 on regular orbits, where "
             "ln|δ|/t still falls as ln t / t.", ""]
    if samples:
        lines += [f"| a [au] | e | `<Y>` ours | `<Y>` REBOUND, same tangent | difference | "
                  f"`<Y>` REBOUND, own tangent | over seeds: ours | over seeds: REBOUND | "
                  "λ ours [1/kyr] | λ REBOUND, same tangent [1/kyr] | REBOUND "
                  "`sim.lyapunov()` [1/kyr] | class (ours / REBOUND own) |",
                  "|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for r in samples:
            o, s, w = r["ours"], r["rebound_same"], r["rebound_own"]
            cls = "/".join("chaotic" if classify(m) else "regular"
                           for m in (o["megno"], w["megno"]))
            diff = o["megno"] - s["megno"]
            lines.append(
                f"| {r['a']:.2f} | {r['e']:.3f} | {_f(o['megno'])} | {_f(s['megno'])} | "
                f"{'–' if not math.isfinite(diff) else f'{diff:+.1e}'} | {_f(w['megno'])} | "
                f"{_range(r['ours_seeds'])} | {_range(r['rebound_seeds'])} | "
                f"{_g(_per_kyr(o['lyapunov']))} | {_g(_per_kyr(s['lyapunov']))} | "
                f"{_g(_per_kyr(s['lyapunov_fit']))} | {cls} |")
        lines.append("")
        parted = [abs(math.log(r["ours"]["lyapunov"] / r["rebound_same"]["lyapunov"]))
                  for r in samples
                  if classify(r["ours"]["megno"]) and classify(r["rebound_same"]["megno"])
                  and r["ours"]["lyapunov"] > 0 and r["rebound_same"]["lyapunov"] > 0]
        if parted:
            lines += ["On the regular orbits the two codes' λ agree to the digits shown: "
                      "the same tangent map from the same tangent. On the chaotic ones "
                      "the two runs part at the rounding level and grow apart as fast "
                      "as any two neighbouring orbits, so their finite-time λ and `<Y>` "
                      f"agree in size only (λ within a factor {math.exp(max(parted)):.2f} "
                      "here).", ""]
        failed = [f"- a = {r['a']:.2f}, e = {r['e']:.3f}: {code} **{r[key]['outcome']}**"
                  for r in samples for code, key in (("ours", "ours"),
                                                     ("REBOUND", "rebound_same"),
                                                     ("REBOUND", "rebound_own"))
                  if r[key]["outcome"] != "completed"]
        lines += failed + ([""] if failed else [])
    if mrow is not None:
        st = map_statistics(mrow)
        same, own = st["same"], st["own"]
        verdict = lambda ok: "**met**" if ok else "**missed**"  # noqa: E731
        lines += [
            f"Over the whole {len(a)} x {len(e)} grid ({100 * st['chaotic_fraction']:.0f} % "
            "of it chaotic by our map):", "",
            "| | REBOUND from our tangent | REBOUND from its own | goal |",
            "|---|---|---|---|",
            f"| classification alike (`<Y>` > {CHAOTIC:g}) | "
            f"{100 * same['agreement']:.1f} % ({same['disagree']} differ) | "
            f"{100 * own['agreement']:.1f} % ({own['disagree']} differ) | "
            f"≥ {100 * AGREEMENT_GOAL:.0f} %: {verdict(same['agreement'] >= AGREEMENT_GOAL)} "
            f"/ {verdict(own['agreement'] >= AGREEMENT_GOAL)} |",
            f"| points both call regular (`<Y>` < {REGULAR_BELOW:g}) | {same['regular']} | "
            f"{own['regular']} | |",
            f"| largest \\|Δ`<Y>`\\| there | {_g(same['max_diff'])} | "
            f"{_g(own['max_diff'])} | ≤ {MEGNO_GOAL:g}: "
            f"{verdict(same['max_diff'] <= MEGNO_GOAL)} / "
            f"{verdict(own['max_diff'] <= MEGNO_GOAL)} |",
            f"| median \\|Δ`<Y>`\\| there | {_g(same['median_diff'])} | "
            f"{_g(own['median_diff'])} | |",
            f"| within {MEGNO_GOAL:g} there | {100 * same['within_goal']:.1f} % | "
            f"{100 * own['within_goal']:.1f} % | |", ""]
        if st["failed"]:
            lines += [f"{st['failed']} run(s) of the three maps did not complete; they "
                      "count as chaotic.", ""]
        lines += [
            "From our tangent the two codes integrate the same tangent map, and `<Y>` "
            "differs by what their quadratures of MEGNO's integral leave, of order "
            "ln|δ| / steps, and because our `wh` reads the tangent at the step's internal "
            "point, before the half drift it defers to the next step (REBOUND synchronises "
            "every step): a transient that fades as ln t / t, the same small offset at "
            "every regular point; from REBOUND's own tangent the difference is that of the "
            "tangents, as large as the spread over seeds, and largest near resonances.", ""]
        w = mrow["workers"]
        n = mrow["a"].size * mrow["e"].size

        def per_step(seconds, steps_):
            return 1e6 * seconds / steps_ if steps_ else math.nan

        def overhead(wall, run):
            return (mrow[wall] * w - mrow[run]) / n

        ratio = st["time_ratio"]
        lines += [
            f"Wall time of the whole map ({n} runs of {mrow['steps']:,} steps) on {w} "
            f"worker process(es) of this machine, each started and warm before the clock "
            f"starts (start-up {mrow['startup_seconds']:.1f} s, not counted): ours an "
            f"`Ensemble` on a local Dask cluster, REBOUND's `pool.map` on a "
            f"`multiprocessing.Pool({w})` (the initial states and tangents are made "
            f"beforehand for it, {mrow['prepare_seconds']:.1f} s not counted; ours builds "
            f"each simulation in its worker, counted).", "",
            "| map | wall time [s] | run time on one core, summed [s] | µs a step |",
            "|---|---|---|---|",
            f"| ours (`wh`, Ensemble) | {fmt_time(mrow['wall_ours'])} | "
            f"{fmt_time(mrow['ours_run_seconds'])} | "
            f"{per_step(mrow['ours_run_seconds'], mrow['ours_steps']):.2f} |",
            f"| REBOUND WHFast, own tangent (Pool) | {fmt_time(mrow['wall_rebound_own'])} | "
            f"{fmt_time(mrow['rebound_own_run_seconds'])} | "
            f"{per_step(mrow['rebound_own_run_seconds'], mrow['rebound_own_steps']):.2f} |",
            f"| REBOUND WHFast, our tangent (Pool) | "
            f"{fmt_time(mrow['wall_rebound_same'])} | "
            f"{fmt_time(mrow['rebound_same_run_seconds'])} | "
            f"{per_step(mrow['rebound_same_run_seconds'], mrow['rebound_same_steps']):.2f} |",
            "",
            f"Ours took {ratio:.2f} of REBOUND's faster map (goal ≤ {TIME_RATIO_GOAL:g}: "
            f"{verdict(ratio <= TIME_RATIO_GOAL)}). Per run, beyond its integration "
            f"(wall time × workers − the runs' own time, over the runs): ours "
            f"{1e3 * overhead('wall_ours', 'ours_run_seconds'):.1f} ms (building the "
            "simulation in the worker, the ensemble's row, Dask's scheduling), REBOUND's "
            f"{1e3 * overhead('wall_rebound_own', 'rebound_own_run_seconds'):.1f} ms.", ""]
        name = "chaos_megno_maps.png"
        try:
            _plot(mrow, out_dir / name)
            lines += [f"![our MEGNO map beside REBOUND's]({name})", ""]
        except ImportError:       # matplotlib missing: the tables stand alone
            pass
    if frow is not None:
        lines += _frequency_lines(frow, quick)
    return "\n".join(lines)


def _frequency_lines(frow, quick):
    span = frow["span_yr"]
    lines = [f"Secular frequencies of the outer solar system (the Hairer–Lubich–Wanner "
             f"scene) from a {span / 1e6:g} Myr `wh` run at "
             f"{FREQUENCY_DT.to_value(u.day):g} days with an output every "
             f"{FREQUENCY_OUTPUT_EVERY.to_value(u.yr):g} yr, by "
             "`orbits.analysis.secular_frequencies` (NAFF), beside La2004 (Laskar et al. "
             "2004) and the great inequality from Newcomb's mean motions. The tolerances "
             "are those of `tests/test_frequencies.py`: the scene's own offsets from the "
             "real solar system (its initial conditions, not the integration; "
             "-0.35 %, +0.12 %, -0.08 % and +0.9 % measured over 10 Myr) with room for "
             "the run's length.", ""]
    if frow["outcome"] != "completed":
        return lines + [f"The run failed: **{frow['outcome']}** {frow['message']}", ""]
    lines += ["| quantity | ours | published | relative difference | tolerance | |",
              "|---|---|---|---|---|---|"]
    units = {"g5": "arcsec/yr", "g6": "arcsec/yr", "s6": "arcsec/yr",
             "great inequality": "yr"}
    tol = FREQUENCY_RTOL[bool(quick)]
    for key, ref in PUBLISHED.items():
        val = frow["values"][key]
        rel = val / ref - 1
        ok = abs(rel) <= tol[key]
        label = key if key == "great inequality" else key
        what = "period of 2λ_J − 5λ_S" if key == "great inequality" else "frequency"
        lines.append(f"| {label} ({what}, {units[key]}) | {val:.4f} | {ref:.4f} | "
                     f"{rel:+.2e} | {tol[key]:.1e} | {'ok' if ok else '**outside**'} |")
    lines += ["", f"The run took {frow['wall']:.1f} s on one core.", ""]
    return lines


def summary_line(rows):
    """One sentence for the report's summary."""
    mrow = next((r for r in rows if isinstance(r, dict) and r.get("kind") == "maps"), None)
    if mrow is None:
        return ""
    st = map_statistics(mrow)
    return (f"MEGNO maps: our `wh` and REBOUND's WHFast classify "
            f"{100 * st['own']['agreement']:.1f} % of the points alike (from each code's "
            f"own tangent), and from the same tangent `<Y>` agrees to "
            f"{_g(st['same']['max_diff'])} where regular; our map took "
            f"{st['time_ratio']:.2f} of REBOUND's time on {mrow['workers']} worker(s).")


def _plot(row, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    a, e = np.asarray(row["a"]), np.asarray(row["e"])
    ours = np.asarray(row["ours"], dtype=float)
    theirs = np.asarray(row["rebound_own"], dtype=float)
    differ = classify(ours) != classify(theirs)
    cmap = plt.get_cmap("RdYlBu_r").with_extremes(bad="0.6")
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.4), sharey=True, layout="constrained")
    for ax, values, title in ((axes[0], ours, "ours: wh, Ensemble"),
                              (axes[1], theirs, "REBOUND: WHFast, init_megno")):
        mesh = ax.pcolormesh(a, e, np.clip(values, 1.8, 4.0), cmap=cmap, vmin=1.8, vmax=4.0,
                             shading="nearest")
        aa, ee = np.meshgrid(a, e)
        if differ.any():
            ax.plot(aa[differ], ee[differ], "kx", ms=5, label="classified differently")
            ax.legend(loc="upper left", fontsize=8, framealpha=0.8)
        ax.set(title=title, xlabel="semi-major axis of the test planet [au]")
    axes[0].set_ylabel("eccentricity")
    bar = fig.colorbar(mesh, ax=axes, extend="both")
    bar.set_label("<Y> (MEGNO), clipped to [1.8, 4]; grey: run failed")
    fig.savefig(path, dpi=110)
    plt.close(fig)
