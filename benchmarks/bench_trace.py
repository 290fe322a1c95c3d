"""``trace`` against ``wh``, ``ias15`` and REBOUND's TRACE and IAS15: energy error
and wall time, side by side.

Three parts, each timed around the public ``Simulation.run`` (warm: every
loop compiled by a short run first) and, for REBOUND, around ``integrate``:

1. **Far from encounters**: ``trace`` against ``wh`` with
   ``coordinates="democratic-heliocentric"``, whose map it is when nothing
   is flagged, both with ``lanes="on"`` (the loop of a long run, and of every
   run once it is compiled on the machine: the planets in vector lanes;
   ``--lanes off`` for the scalar loops, which a shorter first run takes), both with the default options (the default monitors, at the
   run's two outputs; ``--monitors none`` for ``monitors=()``), on the outer
   solar system and the Sun with eight planets at ``bench_wh.py``'s steps:
   the benchmark's short step (10 d; 0.5 d), the steps between (50 and
   100 d; 2 d), the step people use, a twentieth of the innermost period
   (``P_in / 20``: 216.6 d; 4.4 d), and ``P_in / 15`` (288.8 d; 5.9 d); each
   row says which.  Microseconds per step, the median of the paired ratios
   over ``--repeats`` runs, whether the two trajectories are equal, and the
   segments ``trace`` flagged (its pericentre criterion flags a segment
   where a planet comes closer to the Sun than ``2 (G m_0 dt^2)^(1/3)``:
   Mercury's perihelion from steps of about 3.5 d, Jupiter's from about
   226 d; those rows are no longer far from encounters).  Beside them
   REBOUND's TRACE and WHFast (democratic heliocentric, ``safe_mode = 0``)
   at the same step, timed in turn with ours: the peer's own ratio on the
   same work.  Goal (issue 12, and issue 40 at every one of these steps): at
   most 1.3 times ``wh``'s time per step.
2. **Close encounters**: the stress suite's encounter (two Earth-mass
   planets about a Sun-mass star passing at 1e-3 to 1e-8 au at t = 5 days,
   the run ending at 10 days; :func:`orbits.validation.stress.encounter_bodies`),
   ``trace`` and ``wh`` (DH) at a 0.5-day step and ``ias15``: the energy
   error at the end (after the pass; at the pass itself the energy of any
   state in heliocentric float64 carries ~1e-6 of rounding at 1e-8 au) and
   the whole run's wall time; REBOUND's TRACE at the same step and its IAS15
   beside them, for the peer's own ratio on the same work.  Goal: ``trace`` at most 1e-9 where ``wh``
   fails, in at most 0.2 of ``ias15``'s time.
3. **A violently unstable three-planet system**: three Jupiter masses two
   mutual Hill radii apart from 5 au about a Sun-mass star (member 0 of the
   validation report's scattering ensemble,
   :func:`orbits.validation.collisions.three_planets`, as point masses),
   ``--years`` years (2000; 200 with ``--quick``) at a 20-day step for the
   two TRACEs: the relative energy error at the end and the wall time of
   ``trace``, our ``ias15``, and REBOUND's ``trace`` and ``ias15``.

Run ``python benchmarks/bench_trace.py`` (a few minutes) or ``--quick``.
"""

import argparse
import pathlib
import statistics
import sys
import time

import astropy.units as u
import numpy as np

import orbits

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import bench_wh  # noqa: E402 - its scenes and steps

WH_RATIO_GOAL = 1.3
IAS15_RATIO_GOAL = 0.2
ENERGY_GOAL = 1e-9
DH = "democratic-heliocentric"
ENCOUNTER_DISTANCES = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)
ENCOUNTER_DT = 0.5            # days
SCATTER_DT = 20.0             # days
YEAR = 365.25


#: the ``lanes`` option of ``wh`` and ``trace`` in part 1 (``--lanes``)
_lanes = "on"


def _timed_run(make, until, outputs=2, clock=time.perf_counter, loops=None):
    sim = make()
    if loops is not None:
        # the time inside the integrator's calls (the compiled loop and the
        # arguments handed to it), apart from the run's fixed Python cost
        integ = sim.integrator
        name = "advance_to" if integ.adaptive else "advance"
        inner = getattr(integ, name)

        def timed(*args, **kwargs):
            t0 = clock()
            try:
                return inner(*args, **kwargs)
            finally:
                loops.append(clock() - t0)
        setattr(integ, name, timed)
    t0 = clock()
    res = sim.run(until=until, outputs=outputs, progress=False)
    return clock() - t0, sim, res


def far_from_encounters(repeats, steps, clock, monitors="default"):
    print(f"1. far from encounters: wh (DH) and trace, {steps} steps a run, median of "
          f"{repeats} ({'default monitors' if monitors == 'default' else 'monitors=()'}); "
          f"us per step; which step: see bench_wh.py")
    print(f"   {'scene':20s} {'step':>8s} {'which':15s} {'wh (DH)':>8s} {'trace':>8s} "
          f"{'ratio':>6s} {'goal':>10s} {'same bits':>9s} {'flagged':>7s} "
          f"{'REB whfast':>10s} {'REB trace':>9s} {'ratio':>6s}")
    rows = []
    for label, b, short in bench_wh.scenes():
        if label not in bench_wh.ISSUE40_SCENES:
            continue
        for dt, which in bench_wh.steps(label, b, short):
            rows.append(_far_row(label, b, dt, which, repeats, steps, clock, monitors))
    worst = max(rows, key=lambda r: r["ratio"])
    users = [r for r in rows if r["which"] == bench_wh.USERS]
    print(f"   goal trace <= {WH_RATIO_GOAL} x wh (DH) at every step: worst {worst['ratio']:.2f} "
          f"at {worst['scene']}, {worst['step']}, {worst['which']} "
          f"{'PASS' if worst['ratio'] <= WH_RATIO_GOAL else 'MISS'}\n"
          f"   at the users' step P_in/20: " + "; ".join(
              f"{r['scene']} {r['step']} {r['ratio']:.2f} ({r['flagged']} segments flagged)"
              for r in users))
    return rows


def _far_row(label, b, dt, which, repeats, steps, clock, monitors):
    kw = {} if monitors == "default" else {"monitors": ()}
    wh = orbits.integrators.get("wh", coordinates=DH, lanes=_lanes)
    trace = orbits.integrators.get("trace", lanes=_lanes)
    makers = {"wh": lambda: orbits.Simulation(b, wh, dt=dt, **kw),
              "trace": lambda: orbits.Simulation(b, trace, dt=dt, **kw)}
    for make in makers.values():
        make().run(until=2 * dt, outputs=2, progress=False)
    rebs = {}
    for name in ("whfast", "trace"):
        rebs["REB " + name] = sim = b.to_rebound()
        sim.integrator = name
        if name == "whfast":
            sim.integrator.safe_mode = 0
            sim.integrator.coordinates = "democraticheliocentric"
        sim.dt = dt.to_value(b.units.unit("time"))
        sim.steps(10)
    times = {k: [] for k in [*makers, *rebs]}
    last = {}
    for _ in range(repeats):
        for k, make in makers.items():
            wall, sim, res = _timed_run(make, steps * dt, clock=clock)
            times[k].append(wall / steps)
            last[k] = (sim, res)
        for k, sim in rebs.items():
            times[k].append(bench_wh.rebound_step_time(sim, steps, clock))
    ratio = statistics.median(a / b for a, b in zip(times["trace"], times["wh"]))
    peer = statistics.median(a / b for a, b in zip(times["REB trace"], times["REB whfast"]))
    same = bool(np.array_equal(last["wh"][1].positions, last["trace"][1].positions))
    flagged = int(last["trace"][0]._ws["counts"][0])
    row = {"scene": label, "step": bench_wh.step_text(dt), "which": which, "ratio": ratio,
           "same": same, "flagged": flagged, "peer ratio": peer,
           **{k: 1e6 * statistics.median(v) for k, v in times.items()}}
    goal = f"<={WH_RATIO_GOAL:g} {'PASS' if ratio <= WH_RATIO_GOAL else 'MISS'}"
    print(f"   {label:20s} {row['step']:>8s} {which:15s} {row['wh']:8.3f} {row['trace']:8.3f} "
          f"{ratio:6.2f} {goal:>10s} {str(same):>9s} {flagged:7d} "
          f"{row['REB whfast']:10.3f} {row['REB trace']:9.3f} {peer:6.2f}")
    return row


def encounters(repeats, clock):
    from orbits.validation.stress import ENCOUNTER_TIME, encounter_bodies
    until = 2 * ENCOUNTER_TIME * u.day
    dt = ENCOUNTER_DT * u.day
    wh = orbits.integrators.get("wh", coordinates=DH, lanes="on")
    codes = {"wh": (wh, dt), "trace": ("trace", dt), "ias15": ("ias15", None)}
    print(f"2. close encounters (stress suite), {until}, trace and wh at dt = {dt}; "
          f"energy error at the end, wall time (median of {repeats}); below each row "
          f"REBOUND's TRACE (same step) and IAS15 on the same bodies")
    print(f"   {'pass (au)':>9s} " + " ".join(f"{k + ' dE':>11s} {k + ' s':>9s}" for k in codes)
          + f" {'trace/ias15':>11s}")
    rows = []
    for d in ENCOUNTER_DISTANCES:
        b = encounter_bodies(d)
        row = {"distance": d}
        for k, (integ, step) in codes.items():
            def make(integ=integ, step=step):
                return orbits.Simulation(b, integ, dt=step)
            make().run(until=1 * u.day, outputs=2, progress=False)
            walls, inside = [], []
            for _ in range(repeats):
                loops = []
                wall, sim, res = _timed_run(make, until, clock=clock, loops=loops)
                walls.append(wall)
                inside.append(sum(loops))
            row[k] = (abs(float(res.energy_error[-1])), statistics.median(walls))
            row[k + " loop"] = statistics.median(inside)
        row["ratio"] = row["trace"][1] / row["ias15"][1]
        row["loop ratio"] = row["trace loop"] / row["ias15 loop"]
        for name in ("trace", "ias15"):
            walls = []
            for _ in range(repeats):
                sim = b.to_rebound()
                sim.integrator = name
                sim.dt = ENCOUNTER_DT if name == "trace" else sim.dt
                e0 = sim.energy()
                t0 = clock()
                sim.integrate(2 * ENCOUNTER_TIME)
                walls.append(clock() - t0)
            row[f"REBOUND {name}"] = (abs((sim.energy() - e0) / e0), statistics.median(walls))
        row["peer ratio"] = row["REBOUND trace"][1] / row["REBOUND ias15"][1]
        rows.append(row)
        print(f"   {d:9.0e} " + " ".join(f"{row[k][0]:11.2e} {row[k][1]:9.5f}" for k in codes)
              + f" {row['ratio']:11.2f}")
        print(f"   {'':9s} inside the integrators' calls: trace {row['trace loop']:.5f} s, "
              f"ias15 {row['ias15 loop']:.5f} s, ratio {row['loop ratio']:.2f} (the rest of "
              f"each run is its fixed Python cost)")
        print(f"   {'':9s} REBOUND: trace dE {row['REBOUND trace'][0]:9.2e} "
              f"{row['REBOUND trace'][1]:9.5f} s, ias15 dE {row['REBOUND ias15'][0]:9.2e} "
              f"{row['REBOUND ias15'][1]:9.5f} s, its trace/ias15 {row['peer ratio']:5.2f}")
    worst_e = max(r["trace"][0] for r in rows)
    worst_r = max(r["ratio"] for r in rows)
    wh_fails = min(r["wh"][0] for r in rows)
    print(f"   goal trace dE <= {ENERGY_GOAL:g}: worst {worst_e:.2e} "
          f"{'PASS' if worst_e <= ENERGY_GOAL else 'MISS'}; wh's smallest {wh_fails:.2e}; "
          f"goal trace <= {IAS15_RATIO_GOAL} x ias15 time: worst {worst_r:.2f} "
          f"{'PASS' if worst_r <= IAS15_RATIO_GOAL else 'MISS'}")
    return rows


def scattering(years, member, clock):
    from orbits.validation.collisions import three_planets
    b = three_planets(member)
    until = years * u.yr
    print(f"3. three Jupiters 2 mutual Hill radii apart (member {member}), {years:g} yr, "
          f"TRACE at dt = {SCATTER_DT:g} d; point masses, no collisions")
    rows = []
    for label, integ, dt in (("trace", "trace", SCATTER_DT * u.day), ("ias15", "ias15", None)):
        def make(integ=integ, dt=dt):
            return orbits.Simulation(b, integ, dt=dt)
        make().run(until=1 * u.yr, outputs=2, progress=False)
        wall, sim, res = _timed_run(make, until, clock=clock)
        extra = ""
        if label == "trace":
            c = sim._ws["counts"]
            extra = (f"(steps {int(sim.steps)}, flagged {int(c[0])}, redone {int(c[1])}, "
                     f"inner steps {int(c[2])})")
        rows.append((f"orbits {label}", abs(float(res.energy_error[-1])), wall, extra))
    for name in ("trace", "ias15"):
        sim = b.to_rebound()
        sim.integrator = name
        if name == "trace":
            sim.dt = SCATTER_DT
        e0 = sim.energy()
        t0 = clock()
        sim.integrate(years * YEAR, exact_finish_time=1)
        wall = clock() - t0
        rows.append((f"REBOUND {name}", abs((sim.energy() - e0) / e0), wall,
                     f"(steps {int(sim.steps_done)})"))
    ias = {r[0]: r[2] for r in rows}
    for name, de, wall, extra in rows:
        rel = wall / ias["orbits ias15"]
        print(f"   {name:16s} dE {de:9.2e}  wall {wall:8.3f} s  ({rel:5.2f} x our ias15) {extra}")
    print(f"   our trace / REBOUND trace time: "
          f"{ias['orbits trace'] / ias['REBOUND trace']:.2f}; REBOUND trace / its ias15: "
          f"{ias['REBOUND trace'] / ias['REBOUND ias15']:.2f}")
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--steps", type=int, default=200_000)
    ap.add_argument("--years", type=float, default=2000.0)
    ap.add_argument("--member", type=int, default=0)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--clock", choices=("wall", "cpu"), default="wall",
                    help="wall clock (default) or this process's CPU time")
    ap.add_argument("--monitors", choices=("default", "none"), default="default",
                    help="part 1 with the default monitors (default) or monitors=()")
    ap.add_argument("--lanes", choices=("on", "off"), default="on",
                    help="part 1's wh and trace with their planets in vector lanes (default) "
                         "or the scalar loops")
    args = ap.parse_args(argv)
    global _lanes
    _lanes = args.lanes
    clock = time.perf_counter if args.clock == "wall" else time.process_time
    if args.quick:
        args.repeats, args.steps, args.years = 3, 50_000, 200.0
    far = far_from_encounters(args.repeats, args.steps, clock, args.monitors)
    enc = encounters(args.repeats, clock)
    scat = scattering(args.years, args.member, clock)
    return {"far": far, "encounters": enc, "scattering": scat}


if __name__ == "__main__":
    main()
