"""Wisdom-Holman speed against REBOUND's WHFast and WHFast512, per step.

For each scene our ``wh`` (no corrector) and REBOUND's ``whfast``
(``safe_mode = 0``, corrector 0) take the same bodies, G and step, first in
Jacobi coordinates (where this REBOUND has it, with ``whfast512`` beside
them), then in democratic heliocentric ones (rows marked "DH"); they are timed in turn in one
process, ``--repeats`` times, ``n`` steps each (``n`` chosen so that one
REBOUND run lasts about ``--target`` seconds).  Ours is timed around the
public ``Simulation.run`` with ``monitors=()`` and two outputs.  The table
gives median microseconds per step and the median of the paired ratios.

After ``whfast512`` has run, REBOUND's other integrators run about twice as
slow until an AVX ``vzeroupper`` executes (the 512-bit registers are left
dirty); any numba call executes one, so a one-step run of ours is made before
each timed REBOUND run to put every measurement on the same footing.

WHFast512 works in democratic heliocentric coordinates only, so it is timed
beside both kinds of row; the DH rows compare the same splitting, and the
script prints their worst ratio apart.

Goals, printed with PASS/MISS: at most 0.5 of ``whfast``'s time per step
(issue 14; it was 0.6 in issue 4); at most 1.0 times ``whfast512``'s (issue
14; it was 1.5 in issue 4), which runs only on a CPU with AVX-512.

Run ``python benchmarks/bench_wh.py`` (about half a minute) or ``--quick``.
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

WHFAST_RATIO_GOAL = 0.5
WHFAST512_RATIO_GOAL = 1.0


def scenes():
    s = orbits.scenes
    return [("Kepler e=0.1", s.kepler(e=0.1), 1 * u.day),
            ("Earth-Moon", s.earth_moon(), 1 * u.hour),
            ("outer solar system", s.outer_solar_system(), 10 * u.day),
            ("Sun + 8 planets", s.solar_system(moon=False), 0.5 * u.day)]


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
    ok512, why512 = whfast512_status()
    rebound_names = ["whfast"] + (["whfast512"] if ok512 else [])
    rows = []
    cases = [(label, bodies, dt, coords) for coords in COORDINATES
             for label, bodies, dt in scenes()]
    for label, bodies, dt, coords in cases:
        wh = orbits.integrators.get("wh", coordinates=coords)
        ours = orbits.Simulation(bodies, integrator=wh, dt=dt, monitors=())
        clear = orbits.Simulation(bodies, integrator="wh", dt=dt, monitors=())
        dt_v = ours.dt.to_value(bodies.units.unit("time"))
        rebs = {}
        for name in rebound_names:
            try:
                rebs[name] = rebound_sim(bodies, dt_v, name, coords)
            except Exception:
                pass
        if coords != "jacobi":
            label += " (DH)"

        def vzeroupper():
            clear.run(until=clear.time + clear.dt, outputs=1, progress=False)

        def time_ours(n):
            until = ours.time + n * ours.dt
            t0 = clock()
            ours.run(until=until, outputs=2, progress=False)
            return (clock() - t0) / n

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
        row = {"scene": label, "N": len(bodies),
               **{k: 1e6 * statistics.median(v) for k, v in times.items()}}
        for name in rebs:
            row[f"ratio_{name}"] = statistics.median(
                a / b for a, b in zip(times["wh"], times[name]))
        rows.append(row)
    print(f"{'scene':26s} {'N':>3s} {'wh us':>8s} " + " ".join(
        f"{k + ' us':>13s} {'ratio':>6s}" for k in rebound_names))
    for r in rows:
        print(f"{r['scene']:26s} {r['N']:3d} {r['wh']:8.3f} " + " ".join(
            f"{r.get(k, float('nan')):13.3f} {r.get('ratio_' + k, float('nan')):6.2f}"
            for k in rebound_names))
    worst = max(r["ratio_whfast"] for r in rows)
    print(f"goal wh <= {WHFAST_RATIO_GOAL} x whfast: worst {worst:.2f} "
          f"{'PASS' if worst <= WHFAST_RATIO_GOAL else 'MISS'}")
    if "whfast512" in rebound_names:
        worst = max(r.get("ratio_whfast512", 0.0) for r in rows)
        print(f"goal wh <= {WHFAST512_RATIO_GOAL} x whfast512: worst {worst:.2f} "
              f"{'PASS' if worst <= WHFAST512_RATIO_GOAL else 'MISS'}")
        same = max(r.get("ratio_whfast512", 0.0) for r in rows if r["scene"].endswith("(DH)"))
        print(f"  in whfast512's own coordinates (DH rows): worst {same:.2f} "
              f"{'PASS' if same <= WHFAST512_RATIO_GOAL else 'MISS'}")
    else:
        print(f"whfast512: not run: {why512}")
    return rows


if __name__ == "__main__":
    main()
