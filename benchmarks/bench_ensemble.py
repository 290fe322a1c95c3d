"""Sweeps on Dask: throughput with 1 and 2 workers, and the cost of a task.

What is measured
----------------
Every run is the Sun, a Jupiter and a 10-Earth-mass planet on a stable
circular orbit at 8 au (``leapfrog``, 30-day step, the close-encounter and
escape checks on, 100 outputs), built on the worker by a module-level
function, as a user's sweep would be.

* **Throughput**: ``--tasks`` runs (default 8), each lasting ``--task-seconds``
  (default 1 s; the end time is calibrated in this process first), on a local
  cluster of 1 worker and on one of 2 workers (:func:`orbits.ensemble.local_cluster`:
  processes of one thread).  Both clusters are started, and their workers have
  loaded the kernels, before anything is timed; the two are timed in turn,
  ``--repeats`` times, and the figures are medians.  Runs per second =
  runs / wall time of ``Ensemble.run``, which includes sending the tasks,
  collecting the rows and building the DataFrame.  The speed-up is the median
  of the paired ratios.  Goal (issue 7): at least 1.8 times the 1-worker
  throughput with 2 workers.
* **Overhead per task**: ``--tiny`` runs of 10 steps (2 outputs) on the
  2-worker cluster; overhead = (wall time x workers - the runs' own time) /
  runs, i.e. what a task costs a worker beyond integrating: scheduling,
  sending, building the simulation, elements, the row.  The same tiny runs
  in this process (``client="serial"``) show how much of that is Dask's.
* Also checked: the 1- and 2-worker sweeps give the same rows, bit for bit.

Cluster start-up is reported separately.  On a 2-core machine the client and
scheduler share the cores with the workers; a machine busy with other work
makes every figure here worse, the speed-up most of all (the load average is
printed).

Run ``python benchmarks/bench_ensemble.py`` (about a minute) or with
``--quick`` for a smoke test.
"""

import argparse
import os
import statistics
import sys
import time

import astropy.units as u

import orbits
from orbits.ensemble import Ensemble, local_cluster

SPEEDUP_GOAL = 1.8
WHERE = ["wall_time_s", "worker", "kernels_compiled", "kernels_loaded"]


def planet(a):
    b = orbits.BodySet()
    b.add("Sun", mass=1 * u.Msun)
    b.add("Jupiter", mass=1 * u.Mjup, primary="Sun", a=5.2 * u.au)
    b.add("planet", mass=10 * u.Mearth, primary="Sun", a=a * u.au, f=2 * u.rad)
    b.move_to_com()
    return orbits.Simulation(b, integrator="leapfrog", dt=30 * u.day, encounter_hill=3.0,
                             escape_distance=100 * u.au)


def calibrate(seconds):
    """The end time at which one run takes about ``seconds`` here."""
    planet(8.0).run(100 * u.yr, progress=False)            # compile or load
    until = 1e4 * u.yr
    for _ in range(3):
        t0 = time.perf_counter()
        planet(8.0).run(until, outputs=100, progress=False)
        took = time.perf_counter() - t0
        until = until * (seconds / took)
    return until.to(u.yr).round()


def sweep(n, a0=8.0):
    # slightly different orbits, all stable over the runs timed here
    return Ensemble(planet, [{"a": a0 + 1e-3 * i} for i in range(n)])


def timed(ens, until, client, outputs=100):
    t0 = time.perf_counter()
    df = ens.run(until, client=client, outputs=outputs, progress=False)
    return time.perf_counter() - t0, df


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--tasks", type=int, default=8)
    p.add_argument("--task-seconds", type=float, default=1.0)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--tiny", type=int, default=400)
    p.add_argument("--quick", action="store_true", help="smoke test: short runs, one repeat")
    args = p.parse_args(argv)
    if args.quick:
        args.tasks, args.task_seconds, args.repeats, args.tiny = 4, 0.1, 1, 40

    print(f"cores: {os.cpu_count()}, load average before: "
          f"{', '.join(f'{x:.2f}' for x in os.getloadavg())}")
    until = calibrate(args.task_seconds)
    print(f"runs of {until:g} ({args.task_seconds:g} s each in this process)")

    t0 = time.perf_counter()
    c1 = local_cluster(1)
    t1 = time.perf_counter()
    c2 = local_cluster(2)
    t2 = time.perf_counter()
    print(f"cluster start-up: 1 worker {t1 - t0:.2f} s, 2 workers {t2 - t1:.2f} s")
    try:
        for c in (c1, c2):   # every worker loads its kernels before anything is timed
            sweep(8).run(1 * u.yr, client=c, outputs=2, progress=False)
        rates = {1: [], 2: []}
        run_time = {1: [], 2: []}
        busy = {1: [], 2: []}
        ratios = []
        same = True
        for _ in range(args.repeats):
            frames = {}
            for workers, client in ((1, c1), (2, c2)):
                wall, df = timed(sweep(args.tasks), until, client)
                frames[workers] = df
                rates[workers].append(args.tasks / wall)
                run_time[workers].append(df.wall_time_s.mean())
                busy[workers].append(df.wall_time_s.sum() / (wall * workers))
            ratios.append(rates[2][-1] / rates[1][-1])
            same &= frames[1].drop(columns=WHERE).equals(frames[2].drop(columns=WHERE))
        med = statistics.median
        speedup = med(ratios)
        print(f"\n{args.tasks} runs, {args.repeats} repeats, medians:")
        print("             runs/s   one run (s)   workers busy integrating")
        for w in (1, 2):
            print(f"  {w} worker{'s' if w > 1 else ' '}  {med(rates[w]):7.3f}   "
                  f"{med(run_time[w]):9.3f}     {med(busy[w]):6.1%}")
        verdict = "PASS" if speedup >= SPEEDUP_GOAL else "MISS"
        print(f"  speed-up   {speedup:7.3f}  (goal >= {SPEEDUP_GOAL}: {verdict})")
        print("  (a run that takes longer on 2 workers than on 1 is the cores being shared "
              "with other work;\n   idle worker time is the sweep's own overhead)")
        print(f"  1- and 2-worker rows bit-identical: {'yes' if same else 'NO'}")

        tiny = sweep(args.tiny)
        ten_steps = 300 * u.day
        wall, df = timed(tiny, ten_steps, c2, outputs=2)
        own = df.wall_time_s.sum()
        overhead = (wall * 2 - own) / args.tiny
        t0 = time.perf_counter()
        ser = tiny.run(ten_steps, client="serial", outputs=2, progress=False)
        serial = (time.perf_counter() - t0 - ser.wall_time_s.sum()) / args.tiny
        print(f"\n{args.tiny} runs of 10 steps on 2 workers: {args.tiny / wall:.0f} runs/s")
        print(f"  overhead per task   {overhead * 1e3:7.2f} ms  (worker time beyond the "
              f"integration itself)")
        print(f"  same runs serially  {serial * 1e3:7.2f} ms  (building, elements, row: "
              f"no Dask)")
        print(f"  Dask's share        {(overhead - serial) * 1e3:7.2f} ms")
    finally:
        for c in (c1, c2):
            c.close()
            c.cluster.close()
    print(f"\nload average after: {', '.join(f'{x:.2f}' for x in os.getloadavg())}")
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
