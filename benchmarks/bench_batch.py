"""Batch mode (systems in vector lanes) against one system at a time, per system-step.

The outer solar system (``orbits.scenes.outer_solar_system``, six bodies) at
two steps, each its own table: the tuned 10-day step (``short (tuned)``,
where one iteration of the Kepler solver always converges) and the users'
step, a twentieth of Jupiter's period (216.6 d, ``users' P_in/20``, as in
``bench_wh.py``).  At each, integrated by:

* our ``wh`` one system at a time, timed around ``Simulation.run`` with
  ``monitors=()`` and two outputs (as ``bench_wh.py`` does);
* the batch loop that ``Ensemble.run(..., batch=B)`` uses
  (:func:`orbits._kernels.wh_batch.advance_lanes`) on B = 1, 4, 8 and 16
  copies of it, each displaced by 1e-10 of its size, one core, timed around
  the compiled call; its time is divided by B and by the steps;
* REBOUND's WHFast (``safe_mode = 0``, no corrector, Jacobi coordinates), and
  WHFast512 where this CPU and REBOUND have it (probed as in ``bench_wh.py``;
  it needs AVX-512).

All are timed in turn in one process, ``--repeats`` times, ``n`` steps each
(``n`` chosen so that one REBOUND run lasts about ``--target`` seconds), with
a one-step run of ours before each REBOUND run (``vzeroupper``, see
``bench_wh.py``).  The table gives the median microseconds per system-step
and the medians of the paired ratios to our ``wh``, to WHFast and to
WHFast512.

Goal (issue 14): batch mode at most 0.25 of WHFast512's time per system-step
on the outer solar system, on one core, at the tuned step (the users' step
is printed beside it).  Where WHFast512 cannot run, the
script says why and gives the ratios to WHFast and to our ``wh`` instead.

Run ``python benchmarks/bench_batch.py`` (about a minute) or ``--quick``.
``--clock cpu`` times with the process's CPU time (see ``bench_wh.py``).
"""

import argparse
import pathlib
import statistics
import sys
import time

import astropy.units as u
import numpy as np

import orbits
from orbits._kernels import wh_batch

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import bench_wh  # noqa: E402 - its REBOUND set-up and WHFast512 probe

BATCHES = (1, 4, 8, 16)
WHFAST512_RATIO_GOAL = 0.25
DT = 10 * u.day


def lanes(bodies, b, dt, scale=1e-10, seed=1):
    """The arrays of ``advance_lanes`` for ``b`` displaced copies of ``bodies``
    at the step ``dt``, and the loop
    (:func:`orbits._kernels.wh_batch.advance_loop`)."""
    sim = orbits.Simulation(bodies, "wh", dt=dt, monitors=())
    st = sim.state
    m = sim.description().masses[st.order]
    rng = np.random.default_rng(seed)
    x = st.x[:, :, None] * (1 + scale * rng.standard_normal((len(m), 3, b)))
    v = np.repeat(st.v[:, :, None], b, axis=2)
    gm = np.ascontiguousarray(np.repeat((sim.units.G * m)[:, None], b, axis=1))
    xj, vj, eta = wh_batch.to_lanes(x, v, gm)
    n_active = int(np.count_nonzero(m > 0))
    return dict(xj=xj, vj=vj, gm=gm, eta=eta, n_active=n_active, owed=np.zeros(b),
                loop=wh_batch.advance_loop(len(m), n_active, b),
                live=np.ones(b), status=np.zeros(b, dtype=np.int64),
                good=np.zeros(b, dtype=np.int64), ws=wh_batch.lanes_workspace(len(m), b),
                dt=sim.dt.to_value(bodies.units.unit("time")))


def advance(state, n):
    s = state
    # the loop an ensemble runs: the kick written out for the systems' size
    # (wh_batch.advance_loop)
    lanes = wh_batch.Lanes(s["xj"], s["vj"], s["gm"], s["eta"], s["owed"], s["live"],
                           s["status"], s["good"])
    s["loop"](lanes, s["n_active"], s["dt"], n, s["ws"])


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--target", type=float, default=0.2)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--clock", choices=("wall", "cpu"), default="wall",
                    help="wall clock (default) or this process's CPU time")
    args = ap.parse_args(argv)
    clock = time.perf_counter if args.clock == "wall" else time.process_time
    if args.quick:
        args.repeats, args.target = 2, 0.02
    bodies = orbits.scenes.outer_solar_system()
    ok512, why512 = bench_wh.whfast512_status()
    users = bench_wh.inner_period(bodies) / 20 * u.day
    rows = []
    for dt, which in ((DT, bench_wh.SHORT), (users, bench_wh.USERS)):
        rows += table(bodies, dt, which, args, clock, ok512, why512)
    return rows


def table(bodies, dt, which, args, clock, ok512, why512):
    """The timings at the step ``dt`` (``which`` of bench_wh's names), printed."""
    # one system with lanes="on": the loop of a long run, its planets in lanes
    ours = orbits.Simulation(bodies, integrator=orbits.integrators.get("wh", lanes="on"),
                             dt=dt, monitors=())
    clear = orbits.Simulation(bodies, integrator="wh", dt=dt, monitors=())
    dt_v = ours.dt.to_value(bodies.units.unit("time"))
    rebs = {"whfast": bench_wh.rebound_sim(bodies, dt_v, "whfast")}
    if ok512:
        rebs["whfast512"] = bench_wh.rebound_sim(bodies, dt_v, "whfast512")
    batches = {b: lanes(bodies, b, dt) for b in BATCHES}

    vzeroupper = bench_wh.one_step(clear)

    def time_ours(n):
        return bench_wh.our_step_time(ours, n, clock)

    def time_batch(b, n):
        t0 = clock()
        advance(batches[b], n)
        return (clock() - t0) / (n * b)

    def time_reb(sim, n):
        return bench_wh.rebound_step_time(sim, n, clock, vzeroupper)

    # compile (or load) everything once, then size the runs from WHFast
    time_ours(10)
    for b in BATCHES:
        time_batch(b, 10)
    vzeroupper()
    probe = time_reb(rebs["whfast"], 10000)
    n = max(1000, int(args.target / probe))
    names = ["wh", *(f"batch {b}" for b in BATCHES), *rebs]
    times = {k: [] for k in names}
    for _ in range(args.repeats):
        times["wh"].append(time_ours(n))
        for b in BATCHES:
            # the same number of system-steps as one run of ours
            times[f"batch {b}"].append(time_batch(b, max(1, n // b)))
        for name, sim in rebs.items():
            times[name].append(time_reb(sim, n))
    if not all(batches[b]["live"].all() for b in BATCHES):
        raise RuntimeError("a lane turned non-finite: the timings are not of the map")

    def ratio(a, b):
        return statistics.median(x / y for x, y in zip(times[a], times[b]))

    refs = ["wh", *rebs]
    print(f"outer solar system, {len(bodies)} bodies, dt = {bench_wh.step_text(dt)} ({which}), "
          f"{n} system-steps a run, {args.repeats} repeats, clock: {args.clock}")
    print(f"{'integrator':14s} {'us/system-step':>15s} " + " ".join(
        f"{'/ ' + r:>12s}" for r in refs))
    rows = []
    for k in names:
        us = 1e6 * statistics.median(times[k])
        rows.append({"name": k, "which": which, "us": us,
                     **{f"ratio_{r}": ratio(k, r) for r in refs}})
        print(f"{k:14s} {us:15.4f} " + " ".join(f"{ratio(k, r):12.2f}" for r in refs))
    best = min((f"batch {b}" for b in BATCHES), key=lambda k: statistics.median(times[k]))
    if ok512:
        worst = max(ratio(f"batch {b}", "whfast512") for b in BATCHES if b >= 8)
        goal = ('PASS' if worst <= WHFAST512_RATIO_GOAL else 'MISS') if which == bench_wh.SHORT \
            else "(the goal is at the tuned step)"
        print(f"goal batch <= {WHFAST512_RATIO_GOAL} x whfast512 per system-step (B >= 8): "
              f"worst {worst:.2f} {goal}")
    else:
        print(f"goal batch <= {WHFAST512_RATIO_GOAL} x whfast512 per system-step: cannot be "
              f"checked here: whfast512 not run: {why512}")
        print(f"instead, the fastest batch ({best}): {ratio(best, 'whfast'):.2f} x whfast "
              f"(safe_mode 0), {ratio(best, 'wh'):.2f} x our wh one system at a time")
    print()
    return rows


if __name__ == "__main__":
    main()
