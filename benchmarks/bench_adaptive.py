"""dop853 and dopri5 against scipy's DOP853 and RK45 on the same problem and tolerance.

Both solve the outer solar system (Hairer, Lubich & Wanner) for the same time
span at the same rtol and atol, interleaved in one process after a warm-up
(numba compile time excluded).  Printed: steps, force evaluations, wall time,
the speed ratio (scipy / ours; goal for dop853: at least 10) and both
codes' final position error against a tight-tolerance reference.

    python benchmarks/bench_adaptive.py [--quick]
"""

import argparse
import statistics
import time

import astropy.units as u
import numpy as np

import orbits

PAIRS = (("dop853", "DOP853"), ("dopri5", "RK45"))


def scipy_run(bodies, method, t_end, rtol, atol):
    from scipy.integrate import solve_ivp
    n = len(bodies)
    gm = bodies.units.G * bodies.masses.value

    def rhs(t, y):
        x = y[:3 * n].reshape(n, 3)
        d = x[:, None, :] - x[None, :, :]
        r2 = np.einsum("ijk,ijk->ij", d, d)
        np.fill_diagonal(r2, np.inf)
        a = -np.einsum("j,ijk->ik", gm, d / r2[..., None] ** 1.5)
        return np.concatenate([y[3 * n:], a.ravel()])

    y0 = np.concatenate([bodies.positions.value.ravel(), bodies.velocities.value.ravel()])
    t0 = time.perf_counter()
    sol = solve_ivp(rhs, (0, t_end), y0, method=method, rtol=rtol, atol=atol)
    return time.perf_counter() - t0, sol.y[:3 * n, -1].reshape(n, 3), len(sol.t) - 1, sol.nfev


def ours_run(bodies, name, t_end, rtol, atol):
    integ = orbits.integrators.get(name, rtol=rtol, atol=atol)
    sim = orbits.Simulation(bodies, integrator=integ, monitors=())
    r = sim.run(until=t_end * u.day, outputs=2, progress=False)
    return r.wall_time, r.positions.value[-1], r.steps, r.force_evaluations


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args(argv)
    bodies = orbits.scenes.outer_solar_system()
    years = 200 if args.quick else 2000
    t_end = years * 365.25
    reps = 2 if args.quick else 3
    sim = orbits.Simulation(bodies, integrator=orbits.integrators.get("ias15", epsilon=1e-12),
                            monitors=())
    ref = sim.run(until=t_end * u.day, outputs=2, progress=False).positions.value[-1]
    print(f"outer solar system, {years} yr; median of {reps} interleaved runs; "
          f"reference: ias15 at epsilon 1e-12")
    print(f"{'ours':8s} {'scipy':7s} {'rtol':>7s} {'steps':>7s} {'scipy steps':>11s} "
          f"{'ours s':>8s} {'scipy s':>8s} {'speed-up':>8s} {'err ours':>9s} {'err scipy':>9s}")
    for name, method in PAIRS:
        for rtol in (1e-8, 1e-11):
            atol = rtol * 1e-3
            ours_run(bodies, name, 10.0, rtol, atol)        # compile
            to, ts = [], []
            for _ in range(reps):
                a = ours_run(bodies, name, t_end, rtol, atol)
                b = scipy_run(bodies, method, t_end, rtol, atol)
                to.append(a[0])
                ts.append(b[0])
            speed = statistics.median(ts) / statistics.median(to)
            print(f"{name:8s} {method:7s} {rtol:7.0e} {a[2]:7d} {b[2]:11d} "
                  f"{statistics.median(to):8.4f} {statistics.median(ts):8.3f} {speed:8.1f} "
                  f"{np.abs(a[1] - ref).max():9.1e} {np.abs(b[1] - ref).max():9.1e}")
    print("goal: dop853 at least 10 times faster than scipy's DOP853 at the same tolerance")


if __name__ == "__main__":
    main()
