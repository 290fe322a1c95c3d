"""Force terms: their cost beside REBOUND + REBOUNDx, and beside our runs without them.

What is measured
----------------
Every row times both sides in turn in one process, ``--repeats`` times, after
a warm-up that excludes numba's compilation, and prints medians of the
process's CPU time.  REBOUND's IAS15 uses the global step criterion, as ours.  Ours runs
through the public ``Simulation.run`` with ``monitors=()`` and ``outputs=2``;
REBOUND's through ``sim.integrate`` (``sim.steps`` for WHFast) with the
REBOUNDx effect attached, the same floats, G and c.

1. ``ias15`` + :class:`~orbits.forces.GRFull` on the DE421 scene (Sun, eight
   planets, Moon, Pluto) for 10 years, against IAS15 + ``gr_full``.
   Goal: at most 0.3 of REBOUND's time.
2. The overhead of :class:`~orbits.forces.GR` on ``ias15`` (Sun + 8 planets):
   time per step with the term over time per step without.  Goal: <= 1.3.
   REBOUND's own overhead with ``gr`` is printed beside it.
3. The overhead of :class:`~orbits.forces.GRPotential` on ``wh`` (Sun + 8
   planets, 1-day step): goal <= 1.2; WHFast's with ``gr_potential`` beside it.
4. ``GR`` with 10^3 and 10^4 test particles (Sun, Jupiter and particles,
   ``ias15``, 30 days): the term's added time per particle must stay flat
   (O(N), not O(N^2)); REBOUND + ``gr`` beside it.

Run ``python benchmarks/bench_forces.py`` (about a minute; ``--quick``: less).
"""

import argparse
import statistics
import time

import astropy.constants as const
import astropy.units as u
import numpy as np
import rebound
import reboundx

import orbits
from orbits import forces

C_AU_DAY = const.c.to_value(u.au / u.day)


def _median_time(fn, repeats):
    # this process's CPU time: both codes run in it, single-threaded here, and
    # it is steadier than the wall clock on a shared machine
    fn()  # warm-up: compilation, caches
    times = []
    for _ in range(repeats):
        t0 = time.process_time()
        fn()
        times.append(time.process_time() - t0)
    return statistics.median(times)


def ours(bodies, integrator, until_days, terms, dt=None):
    # one simulation, continued by until_days a call: the time per step, without
    # the one-off cost of making the simulation
    sim = orbits.Simulation(bodies, integrator, dt=None if dt is None else dt * u.day,
                            forces=terms, monitors=())

    def run():
        sim.run(until=sim.time + until_days * u.day, outputs=2, progress=False)
    return run


def theirs(bodies, integrator, until_days, effect, dt=None, n_active=None):
    def run():
        sim = bodies.to_rebound()
        if n_active is not None:
            sim.N_active = n_active
        sim.integrator = integrator
        if integrator == "ias15":
            sim.integrator.adaptive_mode = "global"   # ours' default step criterion
        if effect:
            rebx = reboundx.Extras(sim)
            f = rebx.load_force(effect)
            rebx.add_force(f)
            f.params["c"] = C_AU_DAY
            sim.particles[0].params["gr_source"] = 1
        if dt is not None:
            sim.dt = dt
            sim.integrator.safe_mode = 0
            sim.steps(int(round(until_days / dt)))
        else:
            sim.integrate(until_days)
        run.steps = sim.steps_done
        run.keep = sim, (rebx if effect else None)
    return run


def _gr_kernel_ns(n, calls=None):
    """Nanoseconds per particle of one call of the GR kernel (Sun, Jupiter, n particles)."""
    import numba
    from orbits._kernels import terms as kt

    @numba.njit
    def repeat(x, v, args, acc, k):
        for _ in range(k):
            kt.gr_accel(x, v, 0.0, args, acc)

    b = _with_particles(n)
    x = np.ascontiguousarray(b.positions.value)
    v = np.ascontiguousarray(b.velocities.value)
    gm = b.units.G * b.masses.value
    acc = np.zeros_like(x)
    args = (0, gm, 1.0 / C_AU_DAY ** 2)
    calls = calls or max(10, 2_000_000 // n)
    repeat(x, v, args, acc, 2)
    best = min(_timed(repeat, x, v, args, acc, calls) for _ in range(5))
    return best / calls / n * 1e9


def _timed(fn, *a):
    t0 = time.perf_counter()
    fn(*a)
    return time.perf_counter() - t0


def _with_particles(n, seed=1):
    """Sun, Jupiter and ``n`` massless particles on circular orbits at 0.5-4 au."""
    b = orbits.BodySet()
    b.add("Sun", mass=1 * u.Msun)
    b.add("Jupiter", mass=1 * u.Mjup, primary="Sun", a=5.2 * u.au)
    rng = np.random.default_rng(seed)
    a = rng.uniform(0.5, 4.0, n)
    phase = rng.uniform(0, 2 * np.pi, n)
    vc = np.sqrt(b.units.G / a)
    x = np.stack([a * np.cos(phase), a * np.sin(phase), np.zeros(n)], axis=1)
    v = np.stack([-vc * np.sin(phase), vc * np.cos(phase), np.zeros(n)], axis=1)
    return orbits.BodySet.from_arrays(
        np.concatenate([b.masses.value, np.zeros(n)]) * u.Msun,
        np.vstack([b.positions.value, x]) * u.au,
        np.vstack([b.velocities.value, v]) * u.au / u.day,
        names=["Sun", "Jupiter"] + [f"p{k}" for k in range(n)])


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--repeats", type=int, default=7)
    p.add_argument("--quick", action="store_true")
    args = p.parse_args(argv)
    rep = 3 if args.quick else args.repeats
    years = 2 if args.quick else 10
    ok = True

    print("1. ias15 + GRFull on the DE421 scene, "
          f"{years} years (goal: <= 0.3 of IAS15 + REBOUNDx gr_full)")
    de = orbits.scenes.de421()
    span = years * 365.25
    a = _median_time(ours(de, "ias15", span, [forces.GRFull()]), rep)
    b = _median_time(theirs(de, "ias15", span, "gr_full"), rep)
    ratio = a / b
    ok &= ratio <= 0.3
    print(f"   ours {a * 1e3:9.1f} ms   REBOUND+REBOUNDx {b * 1e3:9.1f} ms   "
          f"ratio {ratio:.3f}   {'PASS' if ratio <= 0.3 else 'MISS'}")

    planets = orbits.scenes.solar_system(moon=False)
    print("\n2. GR's overhead on ias15, Sun + 8 planets, 20 years (goal: <= 1.3)")
    span = (4 if args.quick else 20) * 365.25
    o0 = _median_time(ours(planets, "ias15", span, []), rep)
    o1 = _median_time(ours(planets, "ias15", span, [forces.GR("Sun")]), rep)
    r0 = _median_time(theirs(planets, "ias15", span, None), rep)
    r1 = _median_time(theirs(planets, "ias15", span, "gr"), rep)
    ok &= o1 / o0 <= 1.3
    print(f"   ours {o0 * 1e3:8.2f} -> {o1 * 1e3:8.2f} ms  x{o1 / o0:.3f}   "
          f"REBOUND {r0 * 1e3:8.2f} -> {r1 * 1e3:8.2f} ms  x{r1 / r0:.3f}   "
          f"with GR ours/REBOUND {o1 / r1:.3f}   {'PASS' if o1 / o0 <= 1.3 else 'MISS'}")

    print("\n3. GRPotential's overhead on wh, Sun + 8 planets, dt = 1 d, "
          "100 years (goal: <= 1.2)")
    span = (20 if args.quick else 100) * 365.25
    # wh alone with lanes="on" (the loop of a long run, the planets in lanes;
    # a run with terms takes the scalar loop)
    o0 = _median_time(ours(planets, orbits.integrators.get("wh", lanes="on"), span, [],
                           dt=1.0), rep)
    o1 = _median_time(ours(planets, "wh", span, [forces.GRPotential("Sun")], dt=1.0), rep)
    r0 = _median_time(theirs(planets, "whfast", span, None, dt=1.0), rep)
    r1 = _median_time(theirs(planets, "whfast", span, "gr_potential", dt=1.0), rep)
    ok &= o1 / o0 <= 1.2
    print(f"   ours {o0 * 1e3:8.2f} -> {o1 * 1e3:8.2f} ms  x{o1 / o0:.3f}   "
          f"WHFast {r0 * 1e3:8.2f} -> {r1 * 1e3:8.2f} ms  x{r1 / r0:.3f}   "
          f"with GR ours/WHFast {o1 / r1:.3f}   {'PASS' if o1 / o0 <= 1.2 else 'MISS'}")

    print("\n4. GR with test particles: Sun, Jupiter and N massless particles, ias15, "
          "30 days")
    per = []
    for n in ((300, 3000) if args.quick else (1000, 10000)):
        full = _with_particles(n)
        t0 = _median_time(ours(full, "ias15", 30.0, []), rep)
        t1 = _median_time(ours(full, "ias15", 30.0, [forces.GR("Sun")]), rep)
        r0 = _median_time(theirs(full, "ias15", 30.0, None, n_active=2), rep)
        r1 = _median_time(theirs(full, "ias15", 30.0, "gr", n_active=2), rep)
        per.append((t1 - t0) / n)
        print(f"   N = {n:6d}: ours {t0 * 1e3:8.1f} -> {t1 * 1e3:8.1f} ms (x{t1 / t0:.2f})   "
              f"REBOUND {r0 * 1e3:8.1f} -> {r1 * 1e3:8.1f} ms (x{r1 / r0:.2f})   "
              f"GR adds {per[-1] * 1e6:.2f} us per particle (ours)")
    print(f"   our GR's added run time per particle at 10x the particles: "
          f"x{per[1] / per[0]:.2f} (the substeps' velocity prediction and the arrays "
          f"leaving the caches included)")
    kernel = [_gr_kernel_ns(n) for n in (1000, 10000, 100000)]
    flat = kernel[2] / kernel[0]
    ok &= flat < 2.0
    print("   the GR kernel alone, ns per particle at N = 10^3, 10^4, 10^5: "
          + ", ".join(f"{k:.2f}" for k in kernel)
          + f"   (O(N): flat; x{flat:.2f} from 10^3 to 10^5)   "
          f"{'PASS' if flat < 2.0 else 'MISS'}")
    print("\nall goals met" if ok else "\nsome goals missed")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
