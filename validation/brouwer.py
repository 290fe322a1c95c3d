"""Brouwer's law for ias15: how the energy error grows over 1e4 orbits, beside REBOUND.

What is measured
----------------
An ensemble of runs of one scene (default: the Hairer-Lubich-Wanner outer
solar system, 1e4 orbits of Jupiter = 1.186e5 yr) whose initial positions
differ by a relative ``perturbation`` (member 0 is unperturbed).  Both codes
start every member from the same floats, with the same G and ``epsilon``.
At ``points`` output times spaced evenly in ``log t`` the relative energy
error ``dE/E0`` of each member is computed by one function for both codes
(:func:`orbits._kernels.invariants.energy`, a compensated sum, accurate to a
few 1e-17 here), from the positions and velocities each code holds.

From the ensemble come, at each time, the RMS of ``dE/E0`` over the members
and its mean (the part common to all members: a bias of the method or of its
rounding), with ``z``, the mean at the end over its standard error.  The
growth exponent is the slope of ``log RMS`` against ``log t`` fitted over
the late part of the run only (``fit_from`` of the span on: the first orbits
are dominated by the bounded, periodic error of each step, not by
accumulated rounding).  Its uncertainty is the standard
deviation of the exponent over bootstrap resamplings of the members.

Rounding errors that are independent from step to step make the energy error
a random walk: exponent 0.5 (Brouwer 1937).  An error with a sign common to
all steps (truncation, or rounding with a bias) grows linearly: exponent 1.

    python validation/brouwer.py [--members 16] [--orbits 1e4] [--frame com|published]
"""

import argparse
import time

import astropy.units as u
import numpy as np

import orbits
from orbits._kernels.invariants import energy as _energy
from orbits.monitors import ensemble_growth_exponent

__all__ = ["JUPITER_PERIOD_YEARS", "log_times", "perturbed", "ours_energy_errors",
           "rebound_energy_errors", "fit_exponent", "measure",
           "main"]

#: Jupiter's orbital period in years: the "orbit" that Rein & Spiegel (2015) count
JUPITER_PERIOD_YEARS = 11.86
#: ours -> REBOUND's name of the matching step criterion
REBOUND_MODE = {"global": "global", "prs24": "prs23"}
#: The fit leaves out this fraction of the log-time range at the start: with
#: outputs from 1 to 1e4 orbits it starts at 40 orbits, where the ensemble RMS
#: (~7e-16) is already a few times the bounded error of a single step and the
#: energy's own rounding (1.2e-16).
FIT_FROM = 0.4


def log_times(t_end, points, t_first):
    """``points`` output times spread evenly in log t from ``t_first`` to ``t_end``."""
    return np.geomspace(t_first, t_end, points)


def perturbed(bodies, members, perturbation, seed=0):
    """``members`` copies of ``bodies``; member k > 0 has every position
    coordinate multiplied by ``1 + perturbation * N(0, 1)``."""
    rng = np.random.default_rng(seed)
    out = [bodies.copy()]
    for _ in range(members - 1):
        b = bodies.copy()
        b._x = b._x * (1.0 + perturbation * rng.standard_normal(b._x.shape))
        out.append(b)
    return out


def _energy_of(bodies, x, v):
    return _energy(np.ascontiguousarray(x), np.ascontiguousarray(v), bodies._m,
                   bodies.units.G, int(np.count_nonzero(bodies._m > 0)), 0.0)


def ours_energy_errors(bodies, times, mode="global", epsilon=1e-9, **sim_options):
    """Relative energy error of our ias15 at ``times`` (internal units), and the
    steps; ``sim_options`` go to :class:`orbits.Simulation`."""
    integ = orbits.integrators.get("ias15", epsilon=epsilon, adaptive_mode=mode)
    sim = orbits.Simulation(bodies, integrator=integ, monitors=(), **sim_options)
    e0 = _energy_of(bodies, bodies._x, bodies._v)
    q = bodies.units.quantity
    err = np.empty(len(times))
    for k, t in enumerate(times):
        r = sim.run(until=q(t, "time"), outputs=1, progress=False)
        x = r.positions[-1].to_value(bodies.units.unit("length"))
        v = r.velocities[-1].to_value(bodies.units.unit("velocity"))
        err[k] = _energy_of(bodies, x, v) / e0 - 1.0
    return err, sim.steps


def rebound_energy_errors(bodies, times, mode="prs23", epsilon=1e-9):
    """The same for REBOUND's IAS15 (``mode`` is REBOUND's ``adaptive_mode``)."""
    sim = bodies.to_rebound()
    sim.integrator = "ias15"
    sim.integrator.epsilon = epsilon
    sim.integrator.adaptive_mode = mode
    sim.exact_finish_time = 1
    n = sim.N
    x = np.zeros((n, 3))
    v = np.zeros((n, 3))
    e0 = _energy_of(bodies, bodies._x, bodies._v)
    err = np.empty(len(times))
    for k, t in enumerate(times):
        sim.integrate(t)
        sim.serialize_particle_data(xyz=x, vxvyvz=v)
        err[k] = _energy_of(bodies, x, v) / e0 - 1.0
    return err, sim.steps_done


def fit_exponent(times, rms, t_from):
    """Slope of ``log rms`` against ``log t`` for ``t >= t_from``."""
    sel = (times >= t_from) & (rms > 0)
    return float(np.polyfit(np.log(times[sel]), np.log(rms[sel]), 1)[0])


def measure(code, mode, ensemble, times, epsilon=1e-9, fit_from=FIT_FROM, **sim_options):
    """Run ``ensemble`` with ``code`` ("orbits" or "rebound") and summarise.

    Returns a dict: ``errors`` (members, times), ``rms``, ``mean``, the fitted
    ``exponent`` with its bootstrap ``spread``, the exponent of ``|mean|``
    (``bias_exponent``), ``steps`` per member, ``wall`` seconds.
    ``fit_from`` is the fraction of the log-time range left out at the start.
    ``z`` is the mean at the last time over its standard error (the spread of
    the members there over the square root of their number): a method whose
    members' errors are independent random walks keeps it within a few units
    of zero.
    """
    run = ours_energy_errors if code == "orbits" else rebound_energy_errors
    t0 = time.perf_counter()
    errors, steps = [], []
    for b in ensemble:
        e, s = run(b, times, mode, epsilon, **sim_options)
        errors.append(e)
        steps.append(s)
    wall = time.perf_counter() - t0
    errors = np.array(errors)
    lt = np.log(times)
    t_from = float(np.exp(lt[0] + fit_from * (lt[-1] - lt[0])))
    p, spread = ensemble_growth_exponent(times, errors, t_from)
    mean = errors.mean(axis=0)
    sem = float(errors[:, -1].std() / np.sqrt(len(errors)))
    return {"code": code, "mode": mode, "errors": errors, "times": times,
            "rms": np.sqrt(np.mean(errors ** 2, axis=0)), "mean": mean,
            "exponent": p, "spread": spread, "t_from": t_from,
            "z": float(mean[-1] / sem) if sem > 0 else float("nan"),
            "bias_exponent": fit_exponent(times, np.abs(mean), t_from),
            "steps": int(np.median(steps)), "wall": wall}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--members", type=int, default=16)
    ap.add_argument("--orbits", type=float, default=1e4, help="Jupiter orbits")
    ap.add_argument("--points", type=int, default=120, help="log-spaced outputs")
    ap.add_argument("--fit-from", type=float, default=FIT_FROM,
                    help="fraction of the log-time range left out of the fit at the start")
    ap.add_argument("--perturbation", type=float, default=1e-12)
    ap.add_argument("--seed", type=int, default=0, help="of the perturbations")
    ap.add_argument("--epsilon", type=float, default=1e-9)
    ap.add_argument("--frame", choices=("com", "published"), default="com")
    ap.add_argument("--modes", default="global,prs24")
    ap.add_argument("--codes", default="orbits,rebound")
    ap.add_argument("--save", help="write the errors of every run to this .npz file")
    ap.add_argument("--write", action="store_true",
                    help="append the table to validation/brouwer.md")
    args = ap.parse_args(argv)

    bodies = orbits.scenes.outer_solar_system(com=args.frame == "com")
    year = (1 * u.yr).to_value(bodies.units.time)
    span = args.orbits * JUPITER_PERIOD_YEARS * year
    times = log_times(span, args.points, JUPITER_PERIOD_YEARS * year)
    ensemble = perturbed(bodies, args.members, args.perturbation, args.seed)
    fit_orbits = args.orbits ** args.fit_from
    years = args.orbits * JUPITER_PERIOD_YEARS
    lines = [
        f"outer solar system ({args.frame} frame), {args.members} members perturbed at "
        f"{args.perturbation:g}, {args.orbits:g} Jupiter orbits ({years:.3g} yr), "
        f"epsilon {args.epsilon:g}, {args.points} outputs "
        f"log-spaced from 1 orbit, fit of log RMS(dE/E) against log t from "
        f"{fit_orbits:.0f} orbits on; +- is the bootstrap spread over members",
        f"{'code':8s} {'mode':7s} {'exponent':>14s} {'|mean| exp':>10s} {'RMS end':>9s} "
        f"{'|mean| end':>10s} {'z':>6s} {'steps':>8s} {'wall s':>7s}"]
    for line in lines:
        print(line)
    results = []
    for mode in args.modes.split(","):
        for code in args.codes.split(","):
            m = mode if code == "orbits" else REBOUND_MODE[mode]
            r = measure(code, m, ensemble, times, args.epsilon, args.fit_from)
            results.append(r)
            lines.append(f"{code:8s} {m:7s} {r['exponent']:7.2f} +- {r['spread']:4.2f} "
                         f"{r['bias_exponent']:10.2f} {r['rms'][-1]:9.2e} "
                         f"{abs(r['mean'][-1]):10.2e} {r['z']:6.2f} {r['steps']:8d} "
                         f"{r['wall']:7.1f}")
            print(lines[-1], flush=True)
    if args.write:
        import pathlib
        import rebound
        path = pathlib.Path(__file__).resolve().parent / "brouwer.md"
        cmd = "python validation/brouwer.py " + " ".join(argv if argv is not None
                                                          else __import__("sys").argv[1:])
        with open(path, "a") as f:
            f.write(f"`{cmd.strip()}` (REBOUND {rebound.__version__})\n\n```\n"
                    + "\n".join(lines) + "\n```\n\n")
    if args.save:
        np.savez(args.save, times=times, **{f"{r['code']}_{r['mode']}": r["errors"]
                                            for r in results})
    return results


if __name__ == "__main__":
    main()
