"""Serial against threaded pairwise gravity: time per call, pair rate, crossover N.

What is measured
----------------
``orbits._kernels.gravity.accelerate_pairwise_lanes`` (one thread, the kernel
a simulation of 7 or more massive bodies takes there: each source's pull on
all bodies in vector lanes) against ``accelerate_pairwise_parallel`` (threads
over rows, each pair computed from both sides) on the same positions, for N
from 16 to 4000.  Each kernel is called ``k`` times from a small compiled
loop, so the figure is the cost of a call inside a compiled stepping loop
(thread start-up included) and not numba's Python dispatch.  ``k`` is chosen
so that one measurement lasts about ``--target`` seconds.

The two kernels are measured alternately, ``--repeats`` times each, after a
warm-up call that excludes compilation; the table gives the median time per
call, the pair rate ``N (N - 1) / 2 / t`` (unique pairs for both kernels,
although the threaded one does twice the arithmetic), and the speed-up
serial / threaded as the median of the paired ratios.

The crossover is the smallest N of the list from which the threaded kernel
wins at every larger N.  A second table (skip it with ``--no-sim``) makes the
same comparison through ``Simulation(parallel=False/True)`` with a whole
leapfrog step, where the O(N) drifts and kicks are part of the cost; its
crossover is the suggested ``PARALLEL_THRESHOLD`` of ``orbits/simulation.py``,
since that constant chooses the kernel for whole steps.

Run ``python benchmarks/bench_gravity.py`` (about two minutes) or
with ``--quick`` for a smoke test.
"""

import argparse
import math
import os
import statistics
import sys
import time


import numba
import numpy as np

from orbits._kernels import gravity
# the package's compile options (numpy's error model: a padded lane's 0/0 is
# a NaN that is never read, not an exception, and the loops vectorise)
from orbits._kernels._jit import njit
from orbits._kernels.gravity import accelerate_pairwise_lanes, accelerate_pairwise_parallel

SIZES = (16, 32, 48, 64, 96, 128, 192, 256, 512, 1000, 2000, 4000)
QUICK_SIZES = (16, 64, 128, 512, 1000)


@njit(cache=False)
def _repeat_serial_loop(x, gm, n_active, eps2, acc, work, k):
    for _ in range(k):
        accelerate_pairwise_lanes(x, gm, n_active, eps2, acc, work)


@njit(cache=False)
def _repeat_parallel_loop(x, gm, n_active, eps2, acc, work, k):
    for _ in range(k):
        accelerate_pairwise_parallel(x, gm, n_active, eps2, acc, work)


def _repeat_serial(args, k):
    _repeat_serial_loop(*args, k)


def _repeat_parallel(args, k):
    _repeat_parallel_loop(*args, k)


def _kernel_args(x, gm, acc, parallel):
    """The kernels' arguments, with the scratch array each one takes."""
    n = x.shape[0]
    return (x, gm, n, 0.0, acc, gravity.pair_workspace(n, n, parallel))


def _positions(n, seed=1):
    # The arithmetic does not depend on where the bodies are; a Gaussian cloud
    # keeps all distances well away from zero.
    rng = np.random.default_rng(seed)
    return np.ascontiguousarray(rng.normal(size=(n, 3))), np.full(n, 1.0 / n)


def _time_calls(repeat, args, k):
    t0 = time.perf_counter()
    repeat(args, k)
    return (time.perf_counter() - t0) / k


def measure_kernels(sizes, repeats, target):
    """Rows of (N, t_serial, t_parallel, speed-up) in seconds per call."""
    rows = []
    for n in sizes:
        x, gm = _positions(n)
        acc_s = np.zeros((n, 3))
        acc_p = np.zeros((n, 3))
        args_s = _kernel_args(x, gm, acc_s, False)
        args_p = _kernel_args(x, gm, acc_p, True)
        # warm-up (compiles on first use) and calibration
        _repeat_serial(args_s, 1)
        _repeat_parallel(args_p, 1)
        probe = max(1, int(2e5 / (n * n)))
        t_probe = min(_time_calls(_repeat_serial, args_s, probe),
                      _time_calls(_repeat_parallel, args_p, probe))
        k = max(1, int(target / max(t_probe, 1e-9)))
        if not np.allclose(acc_s, acc_p, rtol=1e-10, atol=0):
            raise RuntimeError(f"serial and threaded accelerations differ at N = {n}")
        ts, tp = [], []
        for _ in range(repeats):
            ts.append(_time_calls(_repeat_serial, args_s, k))
            tp.append(_time_calls(_repeat_parallel, args_p, k))
        speedup = statistics.median(a / b for a, b in zip(ts, tp))
        rows.append((n, statistics.median(ts), statistics.median(tp), speedup))
    return rows


def measure_simulation(sizes, repeats, target):
    """Rows of (N, t_serial, t_parallel, speed-up) in seconds per leapfrog step."""
    import orbits
    rows = []
    for n in sizes:
        x, gm = _positions(n)
        bodies = orbits.BodySet.from_arrays(gm, x, np.zeros((n, 3)),
                                            units=orbits.UnitSystem.nbody())
        # softening keeps a long run of a cold cloud free of close encounters
        sims = [orbits.Simulation(bodies, integrator="leapfrog", dt=1e-4, monitors=(),
                                  softening=0.1, parallel=p) for p in (False, True)]

        def run(sim, steps):
            t0 = time.perf_counter()
            sim.run(until=sim.time + steps * sim.dt, outputs=2, progress=False)
            return (time.perf_counter() - t0) / steps

        for sim in sims:
            run(sim, 2)
        t_probe = min(run(sim, max(2, int(2e5 / (n * n)))) for sim in sims)
        steps = max(2, int(target / t_probe))
        ts, tp = [], []
        for _ in range(repeats):
            ts.append(run(sims[0], steps))
            tp.append(run(sims[1], steps))
        speedup = statistics.median(a / b for a, b in zip(ts, tp))
        rows.append((n, statistics.median(ts), statistics.median(tp), speedup))
    return rows


def crossover(rows):
    """Smallest N from which the threaded version wins at every larger N (None if never)."""
    best = None
    for n, _, _, speedup in reversed(rows):
        if speedup > 1.0:
            best = n
        else:
            break
    return best


def interpolated_crossover(rows):
    """N where the speed-up crosses 1, interpolated in log N between measured sizes."""
    n0 = crossover(rows)
    if n0 is None:
        return None
    i = [r[0] for r in rows].index(n0)
    if i == 0:
        return float(n0)
    (na, _, _, sa), (nb, _, _, sb) = rows[i - 1], rows[i]
    la, lb = math.log(na), math.log(nb)
    frac = (0.0 - math.log(sa)) / (math.log(sb) - math.log(sa))
    return math.exp(la + frac * (lb - la))


def print_table(title, unit_label, rows, scale):
    print(title)
    print(f"{'N':>6}  {'serial ' + unit_label:>16}  {'threaded ' + unit_label:>18}  "
          f"{'serial pairs/s':>15}  {'threaded pairs/s':>16}  {'speed-up':>8}  faster")
    for n, ts, tp, sp in rows:
        pairs = n * (n - 1) / 2
        print(f"{n:>6}  {ts * scale:>16.3f}  {tp * scale:>18.3f}  {pairs / ts:>15.3e}  "
              f"{pairs / tp:>16.3e}  {sp:>8.2f}  {'threaded' if sp > 1 else 'serial'}")
    n0 = crossover(rows)
    if n0 is None:
        print("crossover: the threaded version never wins at the largest sizes measured")
    else:
        print(f"crossover: threaded is faster from N = {n0} on in this list "
              f"(speed-up 1 interpolated at N ~ {interpolated_crossover(rows):.0f})")
    print()


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="few sizes, short measurements")
    parser.add_argument("--repeats", type=int, default=None,
                        help="alternating repetitions per size (default 7, quick 3)")
    parser.add_argument("--target", type=float, default=None,
                        help="seconds per measurement (default 0.25, quick 0.05)")
    parser.add_argument("--no-sim", action="store_true",
                        help="skip the whole-step check through Simulation")
    args = parser.parse_args(argv)
    repeats = args.repeats or (3 if args.quick else 7)
    target = args.target or (0.05 if args.quick else 0.25)
    sizes = QUICK_SIZES if args.quick else SIZES

    t0 = time.perf_counter()
    rows = measure_kernels(sizes, repeats, target)
    print(f"numba {numba.__version__}, {numba.get_num_threads()} threads "
          f"({numba.threading_layer()} layer), {os.cpu_count()} CPUs; "
          f"median of {repeats} alternating repetitions of ~{target:g} s")
    print()
    print_table("Gravity kernel, one call inside a compiled loop", "us/call", rows, 1e6)
    n_kernel = crossover(rows)
    if args.no_sim:
        print(f"suggested PARALLEL_THRESHOLD = {n_kernel}  (orbits/simulation.py; "
              f"from the kernels alone)")
    else:
        sim_sizes = [n for n in sizes if n <= (512 if args.quick else 1000)]
        sim_rows = measure_simulation(sim_sizes, repeats, target)
        print_table("Whole leapfrog step through Simulation(parallel=False/True)",
                    "us/step", sim_rows, 1e6)
        # the threshold chooses the kernel for whole steps, so that table decides
        print(f"suggested PARALLEL_THRESHOLD = {crossover(sim_rows)}  (orbits/simulation.py; "
              f"from whole steps, the kernels alone give {n_kernel})")
    print(f"[bench_gravity took {time.perf_counter() - t0:.1f} s]")
    return 0


if __name__ == "__main__":
    sys.exit(main())
