"""What the conservation monitors cost: the same leapfrog run with and without them.

What is measured
----------------
The outer solar system (``orbits.scenes.outer_solar_system()``) with ``leapfrog``
and a 10-day step, advanced ``--steps`` steps (default 10^6) in one
``Simulation.run`` call, in these configurations:

* ``bare loop``: the integrator's compiled loop with monitors off, called
  once for all steps the way ``run`` calls it for each chunk
  (``orbits._driver.advance_checked``), on the arrays a ``Simulation``
  prepared; nothing else of ``run``.  The floor.
* ``off, outputs=2`` and ``off, outputs=500``: ``monitors=()``.
* ``default``: energy and angular momentum at each of the 500 outputs (the
  defaults of ``Simulation`` and ``run``).
* ``default + every 1000`` and ``default + every 1``: the same plus
  ``monitor_every``, which records the monitors inside the compiled loop.

All configurations are timed in turn, ``--repeats`` times, after a warm-up
that excludes compilation; each figure is the median, and each overhead the
median of the paired ratios to its baseline, minus one.  Overheads are given
against ``off`` with the same number of outputs (the cost of the monitors
themselves) and against the bare loop (everything ``run`` adds).

Goals, printed with PASS/MISS: the default monitors cost under 5 % against
``off`` with the same outputs; ``off, outputs=2`` costs nothing against the
bare loop (within 2 %, the noise of this measurement).

Run ``python benchmarks/bench_monitors.py`` (under a minute) or with
``--quick`` for a smoke test.
"""

import argparse
import statistics
import sys
import time

import astropy.units as u
import numpy as np

import orbits
from orbits._driver import advance_checked

DEFAULT_GOAL = 0.05   # default monitors against off, same outputs
OFF_TOLERANCE = 0.02  # "costs nothing": within the noise of a run of this length


class BareLoop:
    """The compiled leapfrog loop on its own, monitors off.

    It takes the arrays, force and force arguments that a ``Simulation``
    prepares (private attributes, read here so that the floor is exactly the
    loop that ``run`` calls) and advances them with the same call that
    ``run`` makes for each chunk of steps, once for all the steps, with none
    of ``run``'s bookkeeping.
    """

    def __init__(self, bodies, dt):
        sim = orbits.Simulation(bodies, integrator="leapfrog", dt=dt, monitors=())
        self.sim = sim
        self.mon = (0, 0, sim._m, sim.units.G, sim._n_active, sim._eps2)
        self.t = 0.0
        self.step0 = 0

    def run(self, n):
        s = self.sim
        status, done, _, s._ws = advance_checked(
            s.integrator, s._ws, s._x, s._v, self.t, s._dt, n, s._force, s._fargs, self.mon,
            self.step0, np.empty(0), np.zeros((0, 11)))
        if status != 0 or done != n:
            raise RuntimeError(f"bare loop stopped with status {status} after {done} steps")
        self.t += n * s._dt
        self.step0 += n


def configurations(bodies, dt):
    """name -> callable(n) advancing n steps."""
    def sim_run(outputs, **kwargs):
        sim = orbits.Simulation(bodies, integrator="leapfrog", dt=dt, **kwargs)

        def run(n):
            res = sim.run(until=sim.time + n * sim.dt, outputs=outputs, progress=False)
            if res.steps != n:
                raise RuntimeError(f"asked for {n} steps, the run took {res.steps}")
        return run

    return {
        "bare loop": BareLoop(bodies, dt).run,
        "off, outputs=2": sim_run(2, monitors=()),
        "off, outputs=500": sim_run(500, monitors=()),
        "default (outputs=500)": sim_run(500),
        "default + every 1000": sim_run(500, monitor_every=1000),
        "default + every 1": sim_run(500, monitor_every=1),
    }


#: configuration -> the baseline its monitor overhead is measured against
BASELINES = {
    "off, outputs=2": "bare loop",
    "default (outputs=500)": "off, outputs=500",
    "default + every 1000": "off, outputs=500",
    "default + every 1": "off, outputs=500",
    "off, outputs=500": "off, outputs=2",
}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer steps and repeats")
    parser.add_argument("--steps", type=int, default=None,
                        help="steps per run (default 1e6, quick 1e5)")
    parser.add_argument("--repeats", type=int, default=None,
                        help="interleaved repetitions (default 11, quick 2)")
    args = parser.parse_args(argv)
    steps = args.steps or (100_000 if args.quick else 1_000_000)
    repeats = args.repeats or (2 if args.quick else 11)
    t_start = time.perf_counter()

    bodies = orbits.scenes.outer_solar_system()
    runs = configurations(bodies, 10 * u.day)
    for run in runs.values():       # compile or load from cache
        run(1000)
    times = {name: [] for name in runs}
    for _ in range(repeats):
        for name, run in runs.items():
            t0 = time.perf_counter()
            run(steps)
            times[name].append(time.perf_counter() - t0)

    def overhead(name, base):
        return statistics.median(a / b for a, b in zip(times[name], times[base])) - 1.0

    print(f"outer solar system ({len(bodies)} bodies), leapfrog, dt = 10 d, {steps} steps "
          f"a run; median of {repeats} interleaved repetitions")
    print()
    print(f"{'configuration':<24} {'run s':>8} {'ns/step':>8}  {'vs baseline':>12}  "
          f"{'baseline':<18} {'vs bare loop':>12}")
    for name, ts in times.items():
        med = statistics.median(ts)
        base = BASELINES.get(name)
        vs_base = f"{overhead(name, base) * 100:+.1f} %" if base else ""
        vs_bare = f"{overhead(name, 'bare loop') * 100:+.1f} %" if name != "bare loop" else ""
        print(f"{name:<24} {med:>8.3f} {med / steps * 1e9:>8.1f}  {vs_base:>12}  "
              f"{base or '':<18} {vs_bare:>12}")
    print()

    default = overhead("default (outputs=500)", "off, outputs=500")
    off = overhead("off, outputs=2", "bare loop")
    print("Goals")
    print(f"  default monitors < {DEFAULT_GOAL:.0%} over off (same outputs)   "
          f"{default * 100:+6.1f} %  {'PASS' if default < DEFAULT_GOAL else 'MISS'}")
    print(f"  off costs nothing (within {OFF_TOLERANCE:.0%} of the bare loop)  "
          f"{off * 100:+6.1f} %  {'PASS' if off < OFF_TOLERANCE else 'MISS'}")
    print(f"[bench_monitors took {time.perf_counter() - t_start:.1f} s]")
    return 0


if __name__ == "__main__":
    sys.exit(main())
