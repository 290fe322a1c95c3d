"""Fixed-step speed against REBOUND: leapfrog and Verlet, per step and per pair.

What is measured
----------------
For each scene, REBOUND's ``leapfrog`` (drift-kick-drift, ``gravity="basic"``,
no collisions, advanced with ``sim.steps(n)``) and our ``leapfrog`` (the same
drift-kick-drift method) and ``verlet`` (kick-drift-kick, also one force
evaluation a step) take the same bodies, the same G and the same step.  Ours
run with ``monitors=()`` and ``outputs=2``, so both codes do only the steps;
ours is timed around the public ``Simulation.run`` call, so whatever a run
costs besides the steps is counted too, spread over the ``n`` steps.

The three are timed in turn in one process, ``--repeats`` times; ``n`` is set
so that one REBOUND measurement lasts about ``--target`` seconds (at least 2
steps for the large Plummer spheres).  A warm-up run excludes numba's
compilation.  The table gives the median microseconds per step and the ratio
ours / REBOUND as the median of the ratios of neighbouring measurements, which
cancels most of the noise from other load on the machine.  For the Plummer
spheres it adds pair interactions per second, ``N (N - 1) / 2 / t_step``.

A second table gives the cost of one ``run`` call of a single step (and of
REBOUND's ``steps(1)``): the fixed price per call that the long runs above
amortise, and what a loop of ``run`` calls pays for each (REBOUND's habit of
a Python loop of ``integrate`` calls): two bodies with ``leapfrog``, and the
outer solar system with ``wh`` and ``trace`` at the users' step (a twentieth
of Jupiter's period, 216.6 d), default options.

Start-up is measured in fresh processes with ``NUMBA_CACHE_DIR`` set to a new
empty directory: the first-call compile time is the time of the first short
run minus that of the second in the same process; then ``import orbits`` plus
a first short run, with the cache now warm, is timed from outside around
``subprocess.run`` (best of 3).

Goals, printed with PASS/MISS: per step at most 0.6 of REBOUND's time for
N <= 10 (our leapfrog against theirs); at least 5 times REBOUND's pair rate at
N = 4000; import plus first run under 2 s with a warm cache.

Run ``python benchmarks/bench_fixed_step.py`` (about two minutes) or with
``--quick`` for a smoke test.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import astropy.units as u
import numpy as np
import rebound

import orbits

#: goals checked at the end
SMALL_N_RATIO_GOAL = 0.6      # our time per step / REBOUND's, N <= 10
PAIR_RATE_GOAL = 5.0          # our pair rate / REBOUND's at N = 4000
STARTUP_GOAL = 2.0            # seconds: import plus a first short run, warm cache


def scenes():
    """(label, body set, step) for each benchmark scene."""
    s = orbits.scenes
    rows = [
        ("Kepler e=0.1", s.kepler(e=0.1), 1 * u.day),
        ("Earth-Moon", s.earth_moon(), 1 * u.hour),
        ("outer solar system", s.outer_solar_system(), 10 * u.day),
        ("Sun + 8 planets", s.solar_system(moon=False), 0.5 * u.day),
    ]
    for n in (1000, 4000):
        bodies = s.plummer(n, seed=1)
        rows.append((f"Plummer {n}", bodies, 1e-4 * bodies.units.unit("time")))
    return rows


def rebound_sim(bodies, dt_internal):
    sim = bodies.to_rebound()
    sim.integrator = "leapfrog"
    sim.gravity = "basic"
    sim.collision = "none"
    sim.dt = dt_internal
    return sim


def timed_rebound(sim, n):
    t0 = time.perf_counter()
    sim.steps(n)
    return time.perf_counter() - t0


def timed_ours(sim, n):
    until = sim.time + n * sim.dt
    t0 = time.perf_counter()
    res = sim.run(until=until, outputs=2, progress=False)
    elapsed = time.perf_counter() - t0
    if res.steps != n:
        raise RuntimeError(f"asked for {n} steps, the run took {res.steps}")
    return elapsed


def measure_scene(bodies, dt, repeats, target, min_steps):
    """Median seconds per step for REBOUND, our leapfrog and our Verlet, and paired ratios."""
    ours = {name: orbits.Simulation(bodies, integrator=name, dt=dt, monitors=())
            for name in ("leapfrog", "verlet")}
    dt_internal = ours["leapfrog"].dt.to_value(bodies.units.unit("time"))
    reb = rebound_sim(bodies, dt_internal)
    n_bodies = len(bodies)

    # warm-up (numba compiles or loads from its cache) and calibration
    for sim in ours.values():
        timed_ours(sim, 2)
    probe = max(2, int(2e5 / n_bodies ** 2))
    t_probe = timed_rebound(reb, probe) / probe
    n = max(min_steps, int(target / t_probe))
    for sim in ours.values():
        timed_ours(sim, max(2, n // 10))

    times = {"rebound": [], "leapfrog": [], "verlet": []}
    for _ in range(repeats):
        times["rebound"].append(timed_rebound(reb, n) / n)
        for name, sim in ours.items():
            times[name].append(timed_ours(sim, n) / n)
    med = {k: statistics.median(v) for k, v in times.items()}
    ratio = {name: statistics.median(a / b for a, b in zip(times[name], times["rebound"]))
             for name in ours}
    return n, med, ratio, ours["leapfrog"].parallel


def measure_call_overhead(repeats, calls):
    """Seconds per call of a one-step run, for two bodies.  The result makes
    its Quantities and monitor series when they are first read; the rows
    "every field read" also read them all after each call (what a run cost
    when it made them at once)."""
    bodies = orbits.scenes.kepler(e=0.1)
    dt = 1 * u.day
    ours = {
        "orbits run(1 step), monitors off": (orbits.Simulation(bodies, "leapfrog", dt=dt,
                                                               monitors=()), False),
        "  monitors off, every field read": (orbits.Simulation(bodies, "leapfrog", dt=dt,
                                                               monitors=()), True),
        "orbits run(1 step), default monitors": (orbits.Simulation(bodies, "leapfrog", dt=dt),
                                                 False),
        "  default monitors, every field read": (orbits.Simulation(bodies, "leapfrog",
                                                                   dt=dt), True),
    }
    outer = orbits.scenes.outer_solar_system()
    for name in ("wh", "trace"):
        ours[f"orbits run(1 step), {name}, outer solar system"] = (
            orbits.Simulation(outer, name, dt=216.6 * u.day), False)
    reb = rebound_sim(bodies, 1.0)
    out = {"REBOUND steps(1)": [], **{k: [] for k in ours}}
    for sim, read in ours.values():
        r = sim.run(until=sim.time + sim.dt, outputs=2, progress=False)
        if read:
            r.__getstate__()          # the monitors' compiled error kernels loaded
    for _ in range(repeats):
        t0 = time.perf_counter()
        for _ in range(calls):
            reb.steps(1)
        out["REBOUND steps(1)"].append((time.perf_counter() - t0) / calls)
        for name, (sim, read) in ours.items():
            t0 = time.perf_counter()
            for _ in range(calls):
                r = sim.run(until=sim.time + sim.dt, outputs=2, progress=False)
                if read:
                    r.__getstate__()      # makes every deferred field
            out[name].append((time.perf_counter() - t0) / calls)
    return {k: statistics.median(v) for k, v in out.items()}


_STARTUP_SCRIPT = """
import json, time
t0 = time.perf_counter()
import astropy.units as u
import orbits
orbits.Simulation, orbits.scenes     # imported on first use: the library itself
t_import = time.perf_counter() - t0
bodies = orbits.scenes.outer_solar_system()
def first_run():
    t = time.perf_counter()
    sim = orbits.Simulation(bodies, integrator="leapfrog", dt=10 * u.day)
    sim.run(until=10 * u.yr, outputs=10, progress=False)
    return time.perf_counter() - t
a = first_run()
b = first_run()
print(json.dumps({"import": t_import, "first": a, "second": b}))
"""


def measure_startup(runs):
    """Compile time with an empty numba cache, then import + first run with it warm."""
    with tempfile.TemporaryDirectory(prefix="orbits-numba-cache-") as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)

        def launch():
            t0 = time.perf_counter()
            proc = subprocess.run([sys.executable, "-c", _STARTUP_SCRIPT], env=env,
                                  capture_output=True, text=True, check=True)
            outside = time.perf_counter() - t0
            return outside, json.loads(proc.stdout.strip().splitlines()[-1])

        cold_outside, cold = launch()
        warm = [launch() for _ in range(runs)]
    best_outside, best_inside = min(warm, key=lambda w: w[0])
    return {
        "cold_process": cold_outside,
        "compile": cold["first"] - cold["second"],
        "cold_first_run": cold["first"],
        "warm_process": best_outside,
        "warm_import": best_inside["import"],
        "warm_first_run": best_inside["first"],
        "warm_second_run": best_inside["second"],
    }


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="short measurements, few repeats")
    parser.add_argument("--repeats", type=int, default=None,
                        help="interleaved repetitions per scene (default 5, quick 2)")
    parser.add_argument("--target", type=float, default=None,
                        help="seconds of REBOUND work per measurement (default 1, quick 0.1)")
    parser.add_argument("--no-startup", action="store_true",
                        help="skip the compile-time and start-up measurements")
    args = parser.parse_args(argv)
    repeats = args.repeats or (2 if args.quick else 5)
    target = args.target or (0.1 if args.quick else 1.0)
    t_start = time.perf_counter()

    import numba
    print(f"orbits {orbits.__version__}, REBOUND {rebound.__version__}, "
          f"numba {numba.__version__}, numpy {np.__version__}, "
          f"{numba.get_num_threads()} numba threads")
    print(f"median of {repeats} interleaved repetitions; ratio = median of paired ratios "
          f"ours/REBOUND (< 1: ours faster)")
    print()

    results = []
    for label, bodies, dt in scenes():
        min_steps = 2 if len(bodies) > 100 else 100
        n, med, ratio, parallel = measure_scene(bodies, dt, repeats, target, min_steps)
        results.append((label, len(bodies), n, med, ratio, parallel))

    print("Time per step")
    print(f"{'scene':<20} {'N':>5} {'steps':>9}  {'REBOUND us':>11} {'leapfrog us':>12} "
          f"{'verlet us':>10}  {'lf/REB':>6} {'vv/REB':>6}  goal")
    small_ratios = []
    for label, nb, n, med, ratio, parallel in results:
        goal = ""
        if nb <= 10:
            small_ratios.append(ratio["leapfrog"])
            goal = "PASS" if ratio["leapfrog"] <= SMALL_N_RATIO_GOAL else "MISS"
        print(f"{label:<20} {nb:>5} {n:>9}  {med['rebound'] * 1e6:>11.3f} "
              f"{med['leapfrog'] * 1e6:>12.3f} {med['verlet'] * 1e6:>10.3f}  "
              f"{ratio['leapfrog']:>6.3f} {ratio['verlet']:>6.3f}  {goal}")
    print(f"(goal for N <= 10: leapfrog at most {SMALL_N_RATIO_GOAL} of REBOUND's time)")
    print()

    print("Pair interactions per second, N (N - 1) / 2 / t_step")
    print(f"{'scene':<20} {'N':>5} {'threads':>7}  {'REBOUND':>10} {'leapfrog':>10} "
          f"{'verlet':>10}  {'lf rate/REB':>11}  goal")
    rate_4000 = None
    for label, nb, n, med, ratio, parallel in results:
        if nb <= 100:
            continue
        pairs = nb * (nb - 1) / 2
        rate_ratio = 1.0 / ratio["leapfrog"]
        goal = ""
        if nb == 4000:
            rate_4000 = rate_ratio
            goal = "PASS" if rate_ratio >= PAIR_RATE_GOAL else "MISS"
        print(f"{label:<20} {nb:>5} {'yes' if parallel else 'no':>7}  "
              f"{pairs / med['rebound']:>10.3e} {pairs / med['leapfrog']:>10.3e} "
              f"{pairs / med['verlet']:>10.3e}  {rate_ratio:>11.2f}  {goal}")
    print(f"(goal at N = 4000: at least {PAIR_RATE_GOAL:g} times REBOUND's pair rate; "
          f"REBOUND runs on one thread)")
    print()

    calls = 200 if args.quick else 1000
    overhead = measure_call_overhead(repeats, calls)
    print("Fixed cost of one call (one step; two bodies but where the row says)")
    for name, t in overhead.items():
        print(f"  {name:<47} {t * 1e6:>9.2f} us")
    print()

    startup = None
    if not args.no_startup:
        startup = measure_startup(runs=3)
        print("Start-up (fresh processes, NUMBA_CACHE_DIR in a new temporary directory)")
        print(f"  empty cache: whole process                {startup['cold_process']:>7.2f} s")
        print(f"  empty cache: first run - second run       {startup['compile']:>7.2f} s"
              f"   (compile time)")
        print(f"  warm cache: python -c 'import orbits; run' {startup['warm_process']:>7.2f} s"
              f"   (best of 3, timed from outside)")
        print(f"    of which import orbits                  {startup['warm_import']:>7.2f} s")
        print(f"    of which first run (10 yr, 365 steps)   {startup['warm_first_run']:>7.3f} s"
              f"   (second run {startup['warm_second_run'] * 1e3:.1f} ms)")
        print()

    print("Goals")
    worst = max(small_ratios) if small_ratios else float("nan")
    lines = [(f"N <= 10: leapfrog time/step <= {SMALL_N_RATIO_GOAL} x REBOUND",
              f"worst {worst:.3f}", worst <= SMALL_N_RATIO_GOAL)]
    if rate_4000 is not None:
        lines.append((f"N = 4000: pair rate >= {PAIR_RATE_GOAL:g} x REBOUND",
                      f"{rate_4000:.2f}x", rate_4000 >= PAIR_RATE_GOAL))
    if startup is not None:
        lines.append((f"import + first run (warm cache) < {STARTUP_GOAL:g} s",
                      f"{startup['warm_process']:.2f} s", startup["warm_process"] < STARTUP_GOAL))
    for goal, value, ok in lines:
        print(f"  {goal:<46} {value:>12}  {'PASS' if ok else 'MISS'}")
    print(f"[bench_fixed_step took {time.perf_counter() - t_start:.1f} s]")
    return 0


if __name__ == "__main__":
    sys.exit(main())
