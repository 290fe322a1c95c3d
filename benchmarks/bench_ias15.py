"""IAS15 speed against REBOUND's IAS15: per step, steps per orbit, wall time per year.

What is measured
----------------
For each scene both codes integrate the same bodies with the same G, the same
``epsilon`` (1e-9) and the same step criterion (``adaptive_mode="global"``,
and ``prs24`` against REBOUND's ``prs23`` in a second table), starting from
the same first step, over the same span.  Ours runs through the public
``Simulation.run`` with ``monitors=()`` and ``outputs=2``; REBOUND's through
``sim.integrate`` with ``exact_finish_time = 1``.  The two are timed in turn
in one process, ``--repeats`` times, after a warm-up that excludes numba's
compilation.  The table gives medians of: microseconds per accepted step,
steps per orbit of the innermost body, wall-clock milliseconds per simulated
year, and the ratio ours / REBOUND of the wall time per year (the median of
the paired ratios).

Goal, printed with PASS/MISS: no more wall time per simulated year than REBOUND
(ratio <= 1) on every scene.

Run ``python benchmarks/bench_ias15.py`` (under a minute) or with ``--quick``.
"""

import argparse
import statistics
import time

import astropy.units as u
import numpy as np
import rebound

import orbits

EPSILON = 1e-9
MODES = (("global", "global"), ("prs24", "prs23"))


def scenes():
    """(name, bodies, innermost orbital period in days, span in years)."""
    kepler = orbits.scenes.kepler(e=0.5)
    return [
        ("Kepler e=0.5", kepler, 365.25 / np.sqrt(1.001), 20.0),
        ("Earth-Moon", orbits.scenes.earth_moon(), 27.32, 2.0),
        ("outer solar system", orbits.scenes.outer_solar_system(), 4332.6, 2000.0),
        ("Sun + 8 planets", orbits.scenes.solar_system(moon=False), 87.97, 20.0),
    ]


def _days(bodies):
    return (1 * u.day).to_value(bodies.units.time)


def timed_rebound(bodies, mode, dt0, t_end):
    sim = bodies.to_rebound()
    sim.integrator = "ias15"
    sim.integrator.epsilon = EPSILON
    sim.integrator.adaptive_mode = mode
    sim.exact_finish_time = 1
    sim.dt = dt0
    t0 = time.perf_counter()
    sim.integrate(t_end)
    return time.perf_counter() - t0, sim.steps_done


def timed_ours(bodies, mode, dt0, t_end):
    integ = orbits.integrators.get("ias15", epsilon=EPSILON, adaptive_mode=mode)
    sim = orbits.Simulation(bodies, integrator=integ,
                            dt=bodies.units.quantity(dt0, "time"), monitors=())
    t0 = time.perf_counter()
    sim.run(until=bodies.units.quantity(t_end, "time"), outputs=2, progress=False)
    return time.perf_counter() - t0, sim.steps


def measure(bodies, period_days, years, ours_mode, reb_mode, repeats):
    day = _days(bodies)
    t_end = years * 365.25 * day
    dt0 = 1e-3 * period_days * day           # the same first step for both
    timed_ours(bodies, ours_mode, dt0, t_end / 100)         # compile / warm up
    rows = []
    for _ in range(repeats):
        wr, nr = timed_rebound(bodies, reb_mode, dt0, t_end)
        wo, no = timed_ours(bodies, ours_mode, dt0, t_end)
        rows.append((wo, no, wr, nr))
    med = lambda k: statistics.median(r[k] for r in rows)  # noqa: E731
    orbits_done = years * 365.25 / period_days
    return {
        "us_step_ours": 1e6 * med(0) / med(1), "us_step_reb": 1e6 * med(2) / med(3),
        "steps_orbit_ours": med(1) / orbits_done, "steps_orbit_reb": med(3) / orbits_done,
        "ms_year_ours": 1e3 * med(0) / years, "ms_year_reb": 1e3 * med(2) / years,
        "ratio": statistics.median(r[0] / r[2] for r in rows),
    }


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=None)
    parser.add_argument("--quick", action="store_true", help="short spans, 2 repeats")
    args = parser.parse_args(argv)
    repeats = args.repeats or (2 if args.quick else 5)
    ok = True
    print(f"IAS15 against REBOUND {rebound.__version__} IAS15, epsilon = {EPSILON:g}; "
          f"median of {repeats} interleaved repetitions")
    for ours_mode, reb_mode in MODES:
        print(f"\nadaptive_mode: ours {ours_mode!r}, REBOUND {reb_mode!r}")
        print(f"{'scene':20s} {'us/step':>15s} {'steps/orbit':>15s} "
              f"{'ms/sim. year':>17s} {'ratio':>6s}")
        print(f"{'':20s} {'ours':>7s} {'reb':>7s} {'ours':>7s} {'reb':>7s} "
              f"{'ours':>8s} {'reb':>8s}")
        for name, bodies, period, years in scenes():
            if args.quick:
                years = years / 10
            r = measure(bodies, period, years, ours_mode, reb_mode, repeats)
            good = r["ratio"] <= 1.0
            ok &= good
            print(f"{name:20s} {r['us_step_ours']:7.2f} {r['us_step_reb']:7.2f} "
                  f"{r['steps_orbit_ours']:7.1f} {r['steps_orbit_reb']:7.1f} "
                  f"{r['ms_year_ours']:8.3f} {r['ms_year_reb']:8.3f} {r['ratio']:6.2f} "
                  f"{'PASS' if good else 'MISS'}")
    print(f"\ngoal: wall time per simulated year at most REBOUND's: "
          f"{'PASS' if ok else 'MISS'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
