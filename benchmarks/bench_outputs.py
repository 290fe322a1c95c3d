"""What an output costs: a run with many outputs against the same run with two.

What is measured
----------------
The outer solar system (``orbits.scenes.outer_solar_system()``) with
``leapfrog`` (10-day step) and ``wh`` at the benchmark's 30-day step and at
the step people use, a twentieth of Jupiter's period (``P_in / 20``,
216.6 d; the ``which`` column says which step a row is), ``--outputs``
outputs (default 10^5) one every ``k`` steps (k = 1 and 10, and 10.4:
outputs that do not fall a whole number of steps apart, each on the step
nearest its time), default monitors (energy and angular momentum at each
output); ``wh`` with ``lanes="on"``, the loop of a long run and of every run
once it is compiled on the machine (its outputs are made beside the next
step's drift, in the lanes; ``--lanes off``: the scalar loop, which a
shorter run takes on a machine that has not compiled that one):

* ``memory``: ``Simulation.run(outputs=...)`` kept in memory, and every field
  of its result read (the result makes its Quantities and monitor series when
  first read);
* ``hdf5``: the same streamed to an HDF5 file (``output=``);
* ``REBOUND loop``: REBOUND (same floats, ``leapfrog`` or WHFast with
  ``safe_mode = 0``) advanced to each output time by ``sim.integrate`` in a
  Python loop that copies the positions and velocities out
  (``sim.serialize_particle_data``) and computes the energy, the way a
  REBOUND user records outputs.

And ``ias15`` (adaptive) with an output every 50 and 500 days: an adaptive
run lands on every output time, so its steps change with the outputs and an
output's cost cannot be told apart from its steps'; the table gives the
whole run's time per output, with the outputs recorded inside the loop,
taken between calls, and streamed, beside REBOUND's IAS15 advanced to each
output time (``exact_finish_time=1``) in the same Python loop.

The cost of an output is the run's time minus the same run with two
outputs, divided by the number of outputs, each run the quickest of
``--repeats`` (runs with and without outputs timed in turn, after a warm-up
that excludes compilation; REBOUND's the same way): other work on the
machine only adds time, so the quickest run is the least disturbed, where a
median of the pairs' differences moved by a tenth of a microsecond from run
to run at k = 10 (the outputs are a tenth of the run there, and a few per
cent of drift in the steps' speed passes for their cost).  The ``+-``
column is half the interquartile range of the pairs' differences in
memory: how far one pair's figure strays.
Memory: the peak resident size of a process that streams 10^6 outputs to a
file, against one that takes 10^4 (``--memory``), so that the difference is
what the outputs keep in memory.

Goals, printed with PASS/MISS: an output recorded in memory costs at most
0.5 us beyond its steps (``leapfrog`` and ``wh``, every row; issue 40),
streamed to HDF5 at most 2 us, and 10^6 streamed
outputs leave the peak memory within 50 MB of 10^4 (flat).

``--clock cpu`` times with the process's CPU time instead of the wall
clock, as ``bench_wh`` can: on a machine that other work shares, a run that
is descheduled does not count the other work's time (the HDF5 column then
leaves out any time spent waiting for the disk).

Run ``python benchmarks/bench_outputs.py`` (about three minutes of CPU time) or ``--quick``.
"""

import argparse
import os
import pathlib
import statistics
import sys
import tempfile
import textwrap
import time

import astropy.units as u
import numpy as np

import orbits

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import bench_wh  # noqa: E402 - the steps' names and the innermost period
from _child import run_child  # noqa: E402 - children import the package imported here

MEMORY_GOAL = 0.5
HDF5_GOAL = 2.0


def scenes():
    """(integrator, step in days, which step) of each row group."""
    users = bench_wh.inner_period(orbits.scenes.outer_solar_system()) / 20
    return [("leapfrog", 10.0, "benchmark's"), ("wh", 30.0, "benchmark's"),
            ("wh", users, bench_wh.USERS)]


#: the clock every run is timed with (``--clock``)
_clock = time.perf_counter


#: ``wh``'s lanes option (``--lanes``)
_lanes = "on"


def _ours(integrator, dt, n_out, k, path=None):
    if integrator == "wh":
        # the loop with the planets in vector lanes, or the scalar one (see
        # the module notes)
        integrator = orbits.integrators.get("wh", lanes=_lanes)
    sim = orbits.Simulation(orbits.scenes.outer_solar_system(), integrator, dt=dt * u.day)
    until = n_out * k * dt * u.day
    t0 = _clock()
    r = sim.run(until=until, outputs=n_out + 1, progress=False, output=path, overwrite=True)
    # the result makes its Quantities and monitor series when first read: read
    # them all, as the REBOUND loop has its copies and energies in hand
    r.__getstate__()
    return _clock() - t0


def _ours_adaptive(n_out, k, path=None, between=False):
    # (seconds, steps) of ias15 with n_out outputs every k days; between: each
    # output in a call of its own (monitor_every switches the loop's off)
    sim = orbits.Simulation(orbits.scenes.outer_solar_system(), "ias15")
    if between:
        sim.monitor_every = 10 ** 9
    t0 = _clock()
    r = sim.run(until=n_out * k * u.day, outputs=n_out + 1, progress=False, output=path,
                overwrite=True)
    r.__getstate__()            # every field made, as in _ours
    return _clock() - t0, r.steps


def _rebound_adaptive(n_out, k):
    rsim = orbits.scenes.outer_solar_system().to_rebound()
    rsim.integrator = "ias15"
    n = rsim.N
    buf = np.empty((n, 3))
    t0 = _clock()
    for i in range(1, n_out + 1):
        rsim.integrate(i * k, exact_finish_time=1)
        rsim.serialize_particle_data(xyz=buf)
        rsim.serialize_particle_data(vxvyvz=buf)
        rsim.energy()
    return _clock() - t0, rsim.steps_done


def _adaptive_rows(n_out, repeats):
    # ias15 lands on every output, so its steps change with the outputs and
    # the cost of an output cannot be told from its steps' (shorter steps
    # converge in fewer iterations): the table gives the whole run's time per
    # output, recorded in the loop, between calls, streamed, and REBOUND's
    print(f"\nias15 (adaptive), outer solar system, {n_out} outputs; us per output, "
          f"whole run")
    print(f"{'every':>7s} {'steps':>7s} {'in loop':>8s} {'between':>8s} {'hdf5':>8s} "
          f"{'REB steps':>9s} {'REBOUND loop':>13s} {'REB/in loop':>12s}")
    for k in (50.0, 500.0):
        for f in (lambda: _ours_adaptive(100, k), lambda: _ours_adaptive(100, k, between=True)):
            f()
        path = os.path.join(tempfile.mkdtemp(), "bench_ias15.h5")
        _ours_adaptive(100, k, path)
        t_in, steps = min(_ours_adaptive(n_out, k) for _ in range(repeats))
        t_between, _ = min(_ours_adaptive(n_out, k, between=True) for _ in range(repeats))
        t_h5, _ = min(_ours_adaptive(n_out, k, path) for _ in range(repeats))
        try:
            rt, rsteps = min(_rebound_adaptive(n_out, k) for _ in range(repeats))
        except Exception as exc:  # REBOUND missing: say so, measure ours
            print(f"  REBOUND: {exc}")
            rt, rsteps = float("nan"), 0
        per = lambda t: t / n_out * 1e6  # noqa: E731
        print(f"{k:6.0f}d {steps:7d} {per(t_in):8.2f} {per(t_between):8.2f} {per(t_h5):8.2f} "
              f"{rsteps:9d} {per(rt):13.2f} {rt / t_in:12.1f}")


def _rebound(integrator, dt, n_out, k):
    import rebound
    sim = orbits.Simulation(orbits.scenes.outer_solar_system(), integrator, dt=dt * u.day)
    rsim = sim.bodies.to_rebound() if hasattr(sim.bodies, "to_rebound") else None
    if rsim is None:
        raise RuntimeError("BodySet.to_rebound is missing")
    rsim.integrator = "whfast" if integrator == "wh" else "leapfrog"
    if integrator == "wh":
        rsim.integrator.safe_mode = 0
    rsim.dt = dt
    n = rsim.N
    buf = np.empty((n, 3))
    t0 = _clock()
    for i in range(1, n_out + 1):
        rsim.integrate(i * k * dt, exact_finish_time=0)
        rsim.serialize_particle_data(xyz=buf)
        rsim.serialize_particle_data(vxvyvz=buf)
        rsim.energy()
    return _clock() - t0


def ok(passed):
    return "PASS" if passed else "MISS"


def _spread(costs):
    # half the interquartile range of the pairs' costs: how far the machine's
    # noise moves one pair's figure (at k = 10 a 3 % drift of the steps is
    # 0.1 us an output)
    if len(costs) < 2:
        return float("nan")
    q1, _, q3 = statistics.quantiles(costs, n=4)
    return (q3 - q1) / 2


def _best(f, repeats):
    return min(f() for _ in range(repeats))


def _peak_rss(n_out):
    child = textwrap.dedent(f"""
        import resource, tempfile, os, astropy.units as u, orbits
        sim = orbits.Simulation(orbits.scenes.outer_solar_system(), "leapfrog", dt=10 * u.day)
        path = os.path.join(tempfile.mkdtemp(), "run.h5")
        sim.run(until={n_out} * 10 * u.day, outputs={n_out} + 1, output=path, progress=False)
        print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)
    """)
    out = run_child(["-c", child], capture_output=True, text=True, check=True)
    return int(out.stdout.split()[-1]) / 1024.0     # MB (ru_maxrss in kB on Linux)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--outputs", type=int, default=100_000)
    p.add_argument("--repeats", type=int, default=7)
    p.add_argument("--quick", action="store_true")
    p.add_argument("--memory", action="store_true", help="also measure peak memory")
    p.add_argument("--clock", choices=("wall", "cpu"), default="wall",
                   help="wall clock (default) or this process's CPU time")
    p.add_argument("--lanes", choices=("on", "off"), default="on",
                   help="wh's loop with the planets in vector lanes (default) or the "
                        "scalar one, which a shorter run takes on a machine that has not "
                        "compiled the lanes' loop")
    args = p.parse_args(argv)
    global _clock, _lanes
    _clock = time.perf_counter if args.clock == "wall" else time.process_time
    _lanes = args.lanes
    n_out = 20_000 if args.quick else args.outputs
    repeats = 1 if args.quick else args.repeats
    path = os.path.join(tempfile.mkdtemp(), "bench.h5")
    print(f"outer solar system, {n_out} outputs, best of {repeats}; "
          f"us per output beyond its steps ({args.clock} clock)")
    print(f"{'integrator':10s} {'step':>7s} {'which':14s} {'k':>4s} {'steps us':>9s} "
          f"{'memory':>7s} {'+-':>6s} {'goal':>9s} {'hdf5':>7s} {'REBOUND loop':>12s} "
          f"{'REB/memory':>10s}")
    worst = {"memory": (0.0, ""), "hdf5": (0.0, "")}
    for integrator, dt, which in scenes():
        for k in (1, 10, 10.4):
            for f in (lambda: _ours(integrator, dt, 100, k),
                      lambda: _ours(integrator, dt, 100, k, path)):
                f()                                   # compile, warm the caches
            # each run with outputs beside the same run without, in turn, and
            # the best of each: other work on the machine only ever adds time,
            # so the quickest of several runs is the one it disturbed least
            # (at k = 10 an output is a tenth of the run, and a few per cent
            # of drift in the steps' speed would pass for the outputs' cost)
            pairs = [(_ours(integrator, dt, 1, k * n_out), _ours(integrator, dt, n_out, k),
                      _ours(integrator, dt, 1, k * n_out, path),
                      _ours(integrator, dt, n_out, k, path)) for _ in range(repeats)]
            base = min(p[0] for p in pairs)
            mem = min(p[1] for p in pairs)
            base_path = min(p[2] for p in pairs)
            h5 = min(p[3] for p in pairs)
            try:
                reb_base = _best(lambda: _rebound(integrator, dt, 1, k * n_out), repeats)
                reb = _best(lambda: _rebound(integrator, dt, n_out, k), repeats)
                reb_cost = (reb - reb_base) / n_out * 1e6
            except Exception as exc:  # REBOUND missing: say so, measure ours
                print(f"  REBOUND: {exc}")
                reb_cost = float("nan")
            mem_cost = (mem - base) / n_out * 1e6
            h5_cost = (h5 - base_path) / n_out * 1e6
            where = f"{integrator}, {dt:.4g} d ({which}), k = {k:g}"
            worst["memory"] = max(worst["memory"], (mem_cost, where))
            worst["hdf5"] = max(worst["hdf5"], (h5_cost, where))
            print(f"{integrator:10s} {dt:5.4g} d {which:14s} {k:4g} "
                  f"{base / (k * n_out) * 1e6:9.3f} {mem_cost:7.3f} "
                  f"{_spread([(p[1] - p[0]) / n_out * 1e6 for p in pairs]):6.3f} "
                  f"{'<=' + str(MEMORY_GOAL) + ' ' + ok(mem_cost <= MEMORY_GOAL):>9s} "
                  f"{h5_cost:7.3f} {reb_cost:12.3f} {reb_cost / mem_cost:10.1f}")

    print(f"\nworst output in memory: {worst['memory'][0]:.3f} us at {worst['memory'][1]} "
          f"(goal <= {MEMORY_GOAL}) {ok(worst['memory'][0] <= MEMORY_GOAL)}")
    print(f"worst output streamed to HDF5: {worst['hdf5'][0]:.3f} us at {worst['hdf5'][1]} "
          f"(goal <= {HDF5_GOAL:g}) {ok(worst['hdf5'][0] <= HDF5_GOAL)}")
    _adaptive_rows(min(n_out, 20_000), repeats)
    if args.memory:
        small, large = _peak_rss(10_000), _peak_rss(1_000_000)
        print(f"peak memory streaming 1e4 outputs: {small:.0f} MB, 1e6 outputs: {large:.0f} MB "
              f"(goal: within 50 MB) {ok(large - small <= 50)}")


if __name__ == "__main__":
    main()
