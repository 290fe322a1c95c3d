"""Wisdom-Holman speed against REBOUND's WHFast and WHFast512, per step.

For each scene our ``wh`` (no corrector) and REBOUND's ``whfast``
(``safe_mode = 0``, corrector 0) take the same bodies, G and step, first in
Jacobi coordinates (where this REBOUND has it, with ``whfast512`` beside
them), then in democratic heliocentric ones (rows marked "DH"); they are timed in turn in one
process, ``--repeats`` times, ``n`` steps each (``n`` chosen so that one
REBOUND run lasts about ``--target`` seconds).  Ours is timed around the
public ``Simulation.run`` with the default options, as a user runs it (the
default monitors, recorded at the run's two outputs; ``--monitors none``
times ``monitors=()`` instead), with ``lanes="on"``: the planets in vector
lanes, the loop that the default ``lanes="auto"`` takes for a run of 1e8
steps or more, and for every run once that loop is compiled on the machine
(``--lanes off`` times the scalar loop, which a shorter run takes on a
machine that has not compiled the lanes' one; the same results bit for
bit).  The table gives median microseconds per
step and the median of the paired ratios.

The steps.  Each scene has the benchmark's short step, tuned to where the
vector-lane Kepler drift always applies (Kepler 1 d, Earth-Moon 1 h, the
outer solar system 10 d, the Sun and eight planets 0.5 d).  The outer solar
system and the Sun with eight planets are also run at the step people use,
about a twentieth of the innermost orbital period (``P_in / 20``: Jupiter's,
216.6 d; Mercury's, 4.4 d), at the longest step of the goal below
(``P_in / 15``: 288.8 d; 5.9 d), and at steps between (50 and 100 d; 2 d).
The periods are the innermost planet's osculating period about the Sun,
computed from the scene.  The ``which`` column says which step a row is:
``short (tuned)``, ``between``, ``users' P_in/20`` or ``P_in/15``.

After ``whfast512`` has run, REBOUND's other integrators run about twice as
slow until an AVX ``vzeroupper`` executes (the 512-bit registers are left
dirty); any numba call executes one, so a one-step run of ours is made before
each timed REBOUND run to put every measurement on the same footing.

WHFast512 works in democratic heliocentric coordinates only, so it is timed
beside both kinds of row; the DH rows compare the same splitting, and the
script prints their worst ratio apart.  It runs only on a CPU with AVX-512;
elsewhere the script says why and compares against WHFast alone.

Goals, printed with PASS/MISS (the ``goal`` columns for each row, then a
line for each goal):

* at most 0.4 of ``whfast``'s time per step at every step from the short
  one to ``P_in / 15``, on the outer solar system and the Sun with eight
  planets, in both coordinate systems (issue 40);
* at most 1.0 times ``whfast512``'s at ``P_in / 20`` (issue 40), where it
  runs; where it does not, the line says so and gives the WHFast ratio at
  that step instead;
* at the short steps, every scene: at most 0.5 of ``whfast``'s (issue 14; it
  was 0.6 in issue 4) and at most 1.0 times ``whfast512``'s (issue 14).

Run ``python benchmarks/bench_wh.py`` (about a minute and a half) or
``--quick`` (the same rows, fewer steps and repeats).
``--clock cpu`` times with the process's CPU time instead of the wall clock:
on a machine that other work shares, a run that is descheduled then does not
count the other work's time, and the paired ratios scatter less (on two
busy cores, wall-clock ratios moved by up to 0.15 from run to run).
"""

import argparse
import statistics
import time

import astropy.units as u

import orbits

#: issue 40: wh / whfast at every step from the short one to P_in / 15
WHFAST_RATIO_GOAL = 0.4
#: issue 40: wh / whfast512 at P_in / 20
WHFAST512_RATIO_GOAL = 1.0
#: issue 14: wh / whfast and wh / whfast512 at the short steps
SHORT_WHFAST_RATIO_GOAL = 0.5
SHORT_WHFAST512_RATIO_GOAL = 1.0

#: the scenes of issue 40's goals, run at the users' steps
ISSUE40_SCENES = ("outer solar system", "Sun + 8 planets")

SHORT = "short (tuned)"
BETWEEN = "between"
USERS = "users' P_in/20"
LONGEST = "P_in/15"


def inner_period(bodies):
    """The innermost planet's osculating period about the first body (days)."""
    first = bodies.names[0]
    return min(bodies[name].orbit(primary=first).P.to_value(u.day)
               for name in bodies.names[1:])


def scenes():
    """(label, bodies, the benchmark's short step) for each scene (also used
    by ``bench_divider.py``)."""
    s = orbits.scenes
    return [("Kepler e=0.1", s.kepler(e=0.1), 1 * u.day),
            ("Earth-Moon", s.earth_moon(), 1 * u.hour),
            ("outer solar system", s.outer_solar_system(), 10 * u.day),
            ("Sun + 8 planets", s.solar_system(moon=False), 0.5 * u.day)]


#: steps between the short one and the users' (days), as issue 40's table
BETWEEN_STEPS = {"outer solar system": (50.0, 100.0), "Sun + 8 planets": (2.0,)}


def steps(label, bodies, short):
    """[(step, which), ...] of a scene in increasing order: the short step,
    and for issue 40's scenes the steps between, ``P_in / 20`` and
    ``P_in / 15``."""
    out = [(short, SHORT)]
    if label in ISSUE40_SCENES:
        period = inner_period(bodies)
        out += [*[(d * u.day, BETWEEN) for d in BETWEEN_STEPS[label]],
                (period / 20 * u.day, USERS), (period / 15 * u.day, LONGEST)]
    return out


def step_text(dt):
    days = dt.to_value(u.day)
    return f"{days:.4g} d" if days >= 0.1 else f"{dt.to_value(u.hour):.4g} h"


#: our coordinate system -> REBOUND's name for it
COORDINATES = {"jacobi": "jacobi", "democratic-heliocentric": "democraticheliocentric"}


def rebound_sim(bodies, dt, name, coordinates="jacobi"):
    sim = bodies.to_rebound()
    sim.integrator = name
    if name == "whfast":
        sim.integrator.safe_mode = 0
        sim.integrator.corrector = 0
        sim.integrator.coordinates = COORDINATES[coordinates]
    if name == "whfast512":
        # it takes G = 1 only, never shortens a step to land on a time, and
        # fuses steps in its own loop: time scaled so that G = 1 (the step
        # with it), exact_finish_time off, steps concatenated
        scale = sim.G ** 0.5
        for p in sim.particles:
            p.vx, p.vy, p.vz = p.vx / scale, p.vy / scale, p.vz / scale
        sim.G = 1.0
        dt = dt * scale
        sim.exact_finish_time = 0
        sim.integrator.concatenate_steps = 1000
    sim.dt = dt
    return sim


def whfast512_status():
    """(True, "") where REBOUND's WHFast512 runs here, else (False, why)."""
    import rebound
    if not getattr(rebound, "avx512_available", False):
        return False, ("this CPU has no AVX-512 (rebound.avx512_available is False; "
                       "REBOUND says 'AVX512 is not supported by your CPU')")
    try:
        sim = rebound.Simulation()
        sim.add(m=1.0)
        sim.add(m=1e-3, a=1.0)
        sim.integrator = "whfast512"
        sim.dt = 0.01
        sim.exact_finish_time = 0
        sim.integrator.concatenate_steps = 10
        sim.steps(2)
        sim.integrate(1.0, exact_finish_time=0)
        return True, ""
    except Exception as exc:   # a build without it, or another refusal: say which
        return False, f"REBOUND refused it: {exc}"


def rebound_step_time(sim, n, clock, before=None):
    """Seconds a step of REBOUND's ``sim`` over about ``n`` steps (``before()``
    runs first, untimed: the ``vzeroupper`` of the module notes)."""
    if before is not None:
        before()
    t_start = sim.t
    t0 = clock()
    if sim.exact_finish_time:
        sim.steps(n)
    else:
        # whfast512 fuses steps: integrate to a time, count the steps it took
        sim.integrate(sim.t + n * sim.dt, exact_finish_time=0)
    elapsed = clock() - t0
    return elapsed / max(1, round((sim.t - t_start) / sim.dt))


def one_step(sim):
    """A function that runs ``sim`` (ours) one step, untimed: the
    ``vzeroupper`` of the module notes, before each REBOUND run."""
    return lambda: sim.run(until=sim.time + sim.dt, outputs=1, progress=False)


def our_step_time(sim, n, clock):
    """Seconds a step of ``n`` steps of ``sim`` (ours), by ``clock``."""
    until = sim.time + n * sim.dt
    t0 = clock()
    sim.run(until=until, outputs=2, progress=False)
    return (clock() - t0) / n


def measure(label, bodies, dt, coords, rebound_names, args, clock):
    """One row: median us per step of ours and of each REBOUND integrator
    that runs, and the median paired ratios."""
    wh = orbits.integrators.get("wh", coordinates=coords, lanes=args.lanes)
    monitors = {} if args.monitors == "default" else {"monitors": ()}
    ours = orbits.Simulation(bodies, integrator=wh, dt=dt, **monitors)
    clear = orbits.Simulation(bodies, integrator="wh", dt=dt, monitors=())
    dt_v = ours.dt.to_value(bodies.units.unit("time"))
    rebs = {}
    for name in rebound_names:
        try:
            rebs[name] = rebound_sim(bodies, dt_v, name, coords)
        except Exception:
            pass

    vzeroupper = one_step(clear)

    def time_ours(n):
        return our_step_time(ours, n, clock)

    def time_reb(sim, n):
        return rebound_step_time(sim, n, clock, vzeroupper)

    time_ours(10)
    vzeroupper()
    probe = time_reb(rebs["whfast"], 10000)
    n = max(1000, int(args.target / probe))
    times = {k: [] for k in ["wh", *rebs]}
    for _ in range(args.repeats):
        times["wh"].append(time_ours(n))
        for name, sim in rebs.items():
            times[name].append(time_reb(sim, n))
    row = {"scene": label + ("" if coords == "jacobi" else " (DH)"), "base": label,
           "coords": coords, "N": len(bodies), "step": step_text(dt),
           **{k: 1e6 * statistics.median(v) for k, v in times.items()}}
    for name in rebs:
        row[f"ratio_{name}"] = statistics.median(
            a / b for a, b in zip(times["wh"], times[name]))
    return row


def verdict(ok):
    return "PASS" if ok else "MISS"


def row_goals(row):
    """The goal columns of a row: (against whfast, against whfast512); the
    stricter goal where two apply."""
    g = WHFAST_RATIO_GOAL if row["base"] in ISSUE40_SCENES else SHORT_WHFAST_RATIO_GOAL
    g512 = {SHORT: SHORT_WHFAST512_RATIO_GOAL, USERS: WHFAST512_RATIO_GOAL}.get(row["which"])
    r512 = row.get("ratio_whfast512")
    return [f"<={g:g} {verdict(row['ratio_whfast'] <= g)}",
            "-" if g512 is None or r512 is None else f"<={g512:g} {verdict(r512 <= g512)}"]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--target", type=float, default=0.2)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--clock", choices=("wall", "cpu"), default="wall",
                    help="wall clock (default) or this process's CPU time")
    ap.add_argument("--monitors", choices=("default", "none"), default="default",
                    help="ours with the default monitors (default) or monitors=()")
    ap.add_argument("--lanes", choices=("on", "off"), default="on",
                    help="ours with lanes='on' (default: the loop of a run of 1e8 steps "
                         "or more, and of every run once compiled) or 'off' (the scalar "
                         "loop of a shorter run on a machine that has not compiled it)")
    args = ap.parse_args(argv)
    clock = time.perf_counter if args.clock == "wall" else time.process_time
    if args.quick:
        args.repeats, args.target = 2, 0.02
    ok512, why512 = whfast512_status()
    rebound_names = ["whfast"] + (["whfast512"] if ok512 else [])
    rows = []
    for coords in COORDINATES:
        for label, bodies, short in scenes():
            for dt, which in steps(label, bodies, short):
                row = measure(label, bodies, dt, coords, rebound_names, args, clock)
                row["which"] = which
                rows.append(row)
    print(f"us per step, median of {args.repeats} ({args.clock} clock, "
          f"{'default monitors' if args.monitors == 'default' else 'monitors=()'}); "
          f"ratio: wh / the column before it, the median of the paired ratios")
    print(f"which step: '{SHORT}' the benchmark's short step, where the lanes' Kepler drift "
          f"always applies;\n  '{USERS}' the users' step, a twentieth of the innermost "
          f"period;\n  '{LONGEST}' the goal's longest step; '{BETWEEN}' steps between")
    print(f"{'scene':26s} {'step':>8s} {'which':15s} {'N':>2s} {'wh us':>7s} " + " ".join(
        f"{k + ' us':>{len(k) + 3}s} {'ratio':>5s} {'goal':>9s}" for k in rebound_names))
    for r in rows:
        goals = row_goals(r)
        print(f"{r['scene']:26s} {r['step']:>8s} {r['which']:15s} {r['N']:2d} {r['wh']:7.3f} "
              + " ".join(f"{r.get(k, float('nan')):{len(k) + 3}.3f} "
                         f"{r.get('ratio_' + k, float('nan')):5.2f} {g:>9s}"
                         for k, g in zip(rebound_names, goals)))

    def worst(key, chosen):
        chosen = [r for r in chosen if key in r]
        r = max(chosen, key=lambda r: r[key])
        return r[key], f"{r['scene']}, {r['step']}, {r['which']}"

    issue40 = [r for r in rows if r["base"] in ISSUE40_SCENES]
    w, where = worst("ratio_whfast", issue40)
    print(f"goal wh <= {WHFAST_RATIO_GOAL} x whfast at every step from the short one to P_in/15, "
          f"outer solar system and Sun + 8, both coordinate systems (issue 40):\n"
          f"  worst {w:.2f} at {where} {verdict(w <= WHFAST_RATIO_GOAL)}")
    users = [r for r in issue40 if r["which"] == USERS]
    print("  at the users' step P_in/20, wh / whfast: " + "; ".join(
        f"{r['scene']} {r['ratio_whfast']:.2f}" for r in users))
    if ok512:
        w, where = worst("ratio_whfast512", users)
        print(f"goal wh <= {WHFAST512_RATIO_GOAL} x whfast512 at the users' step P_in/20 "
              f"(issue 40):\n  worst {w:.2f} at {where} {verdict(w <= WHFAST512_RATIO_GOAL)}")
        print("  wh / whfast512: " + "; ".join(
            f"{r['scene']} {r['ratio_whfast512']:.2f}" for r in users))
    else:
        w, where = worst("ratio_whfast", users)
        print(f"whfast512: not run: {why512}")
        print(f"goal wh <= {WHFAST512_RATIO_GOAL} x whfast512 at the users' step P_in/20 "
              f"(issue 40): not measured here;\n  against whfast instead: worst {w:.2f} at "
              f"{where} (its goal above: <= {WHFAST_RATIO_GOAL})")
    short = [r for r in rows if r["which"] == SHORT]
    w, where = worst("ratio_whfast", short)
    print(f"goal wh <= {SHORT_WHFAST_RATIO_GOAL} x whfast at the benchmark's short steps, every "
          f"scene (issue 14):\n  worst {w:.2f} at {where} "
          f"{verdict(w <= SHORT_WHFAST_RATIO_GOAL)}")
    if ok512:
        w, where = worst("ratio_whfast512", short)
        w_dh, where_dh = worst("ratio_whfast512", [r for r in short if r["coords"] != "jacobi"])
        print(f"goal wh <= {SHORT_WHFAST512_RATIO_GOAL} x whfast512 at the benchmark's short "
              f"steps (issue 14):\n  worst {w:.2f} at {where} "
              f"{verdict(w <= SHORT_WHFAST512_RATIO_GOAL)}; in whfast512's own coordinates "
              f"(DH rows) worst {w_dh:.2f} at {where_dh} "
              f"{verdict(w_dh <= SHORT_WHFAST512_RATIO_GOAL)}")
    return rows


if __name__ == "__main__":
    main()
