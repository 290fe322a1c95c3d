"""The divider's floor under a Wisdom-Holman step, beside WHFast512's whole step.

Every step of ``wh`` and of batch mode takes correctly rounded square roots
and divisions: a pair's ``1 / (r^2 sqrt(r^2))`` in the kick, and in each
planet's Kepler drift ``sqrt(r0^2)``, ``1 / r0`` and two more divisions (the
quartic iteration and the f and g functions).  On x86 both go to one
divider, whose throughput does not grow with the vector width: a 512-bit
vector takes about twice the cycles of a 256-bit one.  This script measures
that throughput here, per element, in loops that LLVM vectorises as it does
ours (fastmath off, so each result is the correctly rounded one):

* ``1 / (r sqrt r)`` (a pair's factor), ``1 / x`` and ``sqrt(x)``, ns per
  element over 64-element arrays;

and multiplies it by the operations a step takes, counted from the code:

* ``wh``, Jacobi coordinates, planets in lanes (``orbits._kernels.wh_lanes``):
  ``P`` columns (the planets padded to a multiple of the lane width); the
  drift takes ``P`` columns' square root and three divisions; the kick takes
  ``P`` Kepler terms, ``P`` pulls of the central body and ``P`` pulls of
  each other massive body (a pair is evaluated from both ends, so that each
  planet's sum keeps the scalar loop's order and the state is the scalar
  loop's bit for bit);
* ``wh``, democratic heliocentric: the drift as above, ``P`` pulls of each
  massive planet;
* batch mode (``orbits._kernels.wh_batch``), per system-step: each planet's
  drift, every pair but the central body and the first planet once, the
  Kepler terms from the second planet on.

The floor is the time these operations alone take; everything else (the
other arithmetic, the dependent chains of the drift, loads and stores) comes
on top, in part overlapped.  Beside it, REBOUND's WHFast512 per step on the
same scene, timed as in ``bench_wh.py`` (where the CPU has AVX-512).

Run ``python benchmarks/bench_divider.py`` (about 20 s).
"""

import argparse
import math
import pathlib
import statistics
import sys
import time

import numpy as np
from numba import njit

import orbits
from orbits._kernels.gravity import LANE_WIDTH, lane_columns

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import bench_wh  # noqa: E402 - its REBOUND set-up and WHFast512 probe


@njit(error_model="numpy")
def _factor(a, b, n):
    for _ in range(n):
        for k in range(a.shape[0]):
            b[k] = 1.0 / (a[k] * math.sqrt(a[k]))


@njit(error_model="numpy")
def _divide(a, b, n):
    for _ in range(n):
        for k in range(a.shape[0]):
            b[k] = 1.0 / a[k]


@njit(error_model="numpy")
def _root(a, b, n):
    for _ in range(n):
        for k in range(a.shape[0]):
            b[k] = math.sqrt(a[k])


def per_element(kernel, repeats, n=200_000):
    """Nanoseconds an element of ``kernel`` (best of ``repeats``, CPU time)."""
    a = 1.0 + np.random.default_rng(1).random(64)
    b = np.zeros(64)
    kernel(a, b, 10)
    best = math.inf
    for _ in range(repeats):
        t0 = time.process_time()
        kernel(a, b, n)
        best = min(best, time.process_time() - t0)
    return 1e9 * best / (n * a.size)


def counts(n, n_active, coordinates):
    """(pair factors, planet drifts) a ``wh`` step of ``n`` bodies computes in lanes."""
    p = lane_columns(n)
    if coordinates == "jacobi":
        return p * (n_active + 1), p
    return p * (n_active - 1), p


def batch_counts(n, n_active):
    """(pair factors, planet drifts) of a batch system-step (Jacobi)."""
    pairs = n_active * (n_active - 1) // 2 + (n - n_active) * n_active - 1
    return pairs + (n - 2), n - 1


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args(argv)
    if args.quick:
        args.repeats = 2
    factor = per_element(_factor, args.repeats)
    divide = per_element(_divide, args.repeats)
    root = per_element(_root, args.repeats)
    drift = root + 3 * divide
    print(f"lane width {LANE_WIDTH} doubles; ns per element: 1/(r sqrt r) {factor:.3f}, "
          f"1/x {divide:.3f}, sqrt {root:.3f}; a planet's drift {drift:.3f}")
    ok512, why = bench_wh.whfast512_status()
    if not ok512:
        print(f"WHFast512 not timed: {why}")
    scenes = [s for s in bench_wh.scenes() if len(s[1]) > 2]
    print(f"{'scene':36s} {'factors':>8s} {'drifts':>7s} {'floor us':>9s} "
          f"{'whfast512 us':>13s} {'floor/512':>10s}")
    for name, bodies, dt in scenes:
        sim = orbits.Simulation(bodies, "wh", dt=dt, monitors=())
        n = len(bodies)
        n_active = int(np.count_nonzero(bodies.masses.value > 0))
        w512 = math.nan
        if ok512:
            reb = bench_wh.rebound_sim(bodies, sim.dt.to_value(bodies.units.unit("time")),
                                       "whfast512")
            bench_wh.rebound_step_time(reb, 10_000, time.process_time)
            w512 = 1e6 * statistics.median(
                bench_wh.rebound_step_time(reb, 200_000, time.process_time)
                for _ in range(args.repeats))
        rows = [(f"{name} (wh)", *counts(n, n_active, "jacobi")),
                (f"{name} (wh DH)", *counts(n, n_active, "democratic-heliocentric")),
                (f"{name} (batch, a system)", *batch_counts(n, n_active))]
        for label, f, d in rows:
            floor = 1e-3 * (f * factor + d * drift)
            print(f"{label:36s} {f:8d} {d:7d} {floor:9.3f} {w512:13.3f} "
                  f"{floor / w512:10.2f}")
    print("goals (issue 14): wh <= 1.0 x WHFast512; batch <= 0.25 x WHFast512 a "
          "system-step: a floor/512 above the goal's ratio cannot be met with these "
          "operations")


if __name__ == "__main__":
    main()
