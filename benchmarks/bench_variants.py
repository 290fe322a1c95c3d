"""Compile time of variants: what a new combination of force terms, or a
user's force, costs once an integrator's loops are compiled.

What is measured
----------------
One numba cache directory (a new, empty one), and a new process for each row
in turn, so that each row starts from what the rows above left in the cache.
Each process imports the package, makes the outer solar system with the
row's integrator and terms, and runs it for ten steps; the row reports the
CPU seconds of making the simulation and that run (the import excluded),
nearly all of it compiling or loading compiled code.

The rows: the integrator alone (its loop compiled), then with ``GR``
(the loop for gravity with terms compiled once, for every combination), then
other combinations of built-in terms, then a :class:`~orbits.forces.UserForce`
from an importable module (its pointer compiled once), then the same again in
a new process (loaded), then each stopping condition, collision mode,
``encounter_log`` and a chaos monitor (MEGNO) added to the integrator alone,
then the variational equations of the state and the masses (``variations="all"``:
one loop serves every kind of variations and the chaos monitors), then
``GRPotential`` with MEGNO (the loop of terms with variations: one more,
for every table of terms and every kind of variations);
for ``wh``, an ensemble in batch mode of 4 systems (the batch loop
compiled) and then of 8 (a new size: the kick written out for it alone).
Goals (issue "Start in seconds"): a combination of built-in terms after the
first, a user force in a new process, and each of the later rows cost <= 1 s.

The stopping conditions are data for one loop per integrator, checked
through one compiled pointer (:mod:`orbits._kernels.stopping`), which the
first condition on an empty cache compiles, once for every integrator.
``--shared-cache`` keeps one cache for all the integrators named, so that
the rows of the second show what a condition costs an integrator with that
pointer already in the cache.

``--ahead`` first fills each new cache with ``orbits compile INTEGRATOR``
(the integrator compiled: its loops alone and with terms, variations, both
and stopping conditions; the line gives its CPU seconds), so that every row
shows what the addition costs an integrator already compiled: each row but
the first ``UserForce`` (which compiles the user's own function) and the
batch rows is then held to the goal of <= 1 s, ``none`` and ``GR`` too.

Run ``python benchmarks/bench_variants.py [INTEGRATOR ...]`` (default
``leapfrog ias15``; a minute or two each).
"""

import argparse
import contextlib
import json
import os
import pathlib
import sys
import tempfile
import textwrap

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from _child import run_child  # noqa: E402 - children import the package imported here

_USER_MODULE = textwrap.dedent("""
    import numba

    @numba.njit
    def drag(x, v, t, m):
        return -1e-12 * v
""")

_CHILD = textwrap.dedent("""
    import json, sys, time
    import astropy.units as u
    import orbits
    from orbits import forces as F
    integrator, combo = sys.argv[1], sys.argv[2]
    made = {
        "none": lambda: [],
        "GR": lambda: [F.GR("Sun")],
        "GRPotential + J2": lambda: [F.GRPotential("Sun"),
                                     F.ZonalHarmonics("Sun", 0.00465 * u.au, J2=2e-7)],
        "GR + migration": lambda: [F.GR("Sun"), F.Migration("Neptune", tau_a=1e7 * u.yr)],
    }
    all_options = {
        "encounter_distance": dict(encounter_distance=0.01 * u.au),
        "collisions merge": dict(collisions="merge"),
        "encounter_log": dict(encounter_log=0.1 * u.au),
        "escape_distance": dict(escape_distance=1000 * u.au),
        "monitors megno": dict(monitors=("energy", "megno")),
        "variations all": dict(variations="all"),
    }
    # a term with the chaos monitors: the loop of terms with variations
    all_options["GRPotential + monitors megno"] = dict(monitors=("energy", "megno"))
    options = all_options.get(combo, {})
    if combo.startswith("batch"):
        # an ensemble of B copies in batch mode (integrator wh): its loop,
        # then, at a new B, the kick written out for that size
        nb = int(combo.split()[1])
        t0 = time.process_time()
        ens = orbits.Ensemble(
            lambda k: orbits.Simulation(orbits.scenes.outer_solar_system(), "wh",
                                        dt=30 * u.day), [{"k": k} for k in range(nb)])
        ens.run(until=300 * u.day, client="serial", progress=False, outputs=3, batch=nb)
        print(json.dumps({"cpu": time.process_time() - t0}))
        sys.exit(0)
    if combo.startswith("UserForce") or combo in all_options:
        import benchuser
        terms = ([F.UserForce(benchuser.drag, velocity_dependent=True)]
                 if combo.startswith("UserForce") else
                 [F.GRPotential("Sun")] if combo.startswith("GRPotential") else [])
    else:
        terms = made[combo]()
    adaptive = orbits.integrators.get(integrator).adaptive
    kw = {} if adaptive else dict(dt=30 * u.day)
    t0 = time.process_time()
    bodies = orbits.scenes.outer_solar_system()
    if combo == "collisions merge":
        # the scene with sizes, which collisions need (a thousandth of an au each)
        bodies = orbits.BodySet.from_arrays(bodies.masses, bodies.positions, bodies.velocities,
                                            names=bodies.names, units=bodies.units,
                                            radii=[1e-3] * len(bodies) * u.au)
    try:
        sim = orbits.Simulation(bodies, integrator, forces=terms, **kw, **options)
    except orbits.errors.IntegratorOptionError as exc:
        # what the integrator does not take (wh: velocity-dependent terms,
        # stopping conditions other than escapes)
        print(json.dumps({"refused": str(exc).split(";")[0]}))
        sys.exit(0)
    sim.run(until=300 * u.day, outputs=3, progress=False)
    print(json.dumps({"cpu": time.process_time() - t0}))
""")

#: ``orbits compile INTEGRATOR`` in a new process, its CPU seconds (import included)
_AHEAD = textwrap.dedent("""
    import json, sys, time
    t0 = time.process_time()
    import orbits
    orbits.compile_ahead([sys.argv[1]], progress=False)
    print(json.dumps({"cpu": time.process_time() - t0}))
""")

ROWS = ["none", "GR", "GRPotential + J2", "GR + migration", "UserForce",
        "UserForce (new process)", "encounter_distance", "escape_distance", "collisions merge",
        "encounter_log", "monitors megno", "variations all", "GRPotential + monitors megno"]
#: the rows of wh alone: batch mode at one size of ensemble, then at another
BATCH_ROWS = ["batch 4", "batch 8"]
#: rows held to the goal of <= 1 s: the combinations after the first, the user force loaded
GOAL_ROWS = {"GRPotential + J2": 1.0, "GR + migration": 1.0, "UserForce (new process)": 1.0,
             "encounter_distance": 1.0, "escape_distance": 1.0, "collisions merge": 1.0,
             "encounter_log": 1.0, "monitors megno": 1.0, "variations all": 1.0}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("integrators", nargs="*", default=["leapfrog", "ias15"])
    parser.add_argument("--rows", help="comma-separated rows to run after 'none' "
                        f"(default: all of {', '.join(ROWS[1:])})")
    parser.add_argument("--shared-cache", action="store_true",
                        help="one numba cache for all the integrators, not one each")
    parser.add_argument("--ahead", action="store_true",
                        help="fill each cache with 'orbits compile INTEGRATOR' first, and hold "
                             "every row after it to the goal")
    args = parser.parse_args(argv)
    print(f"outer solar system, 10 steps; one new numba cache "
          f"{'for all' if args.shared_cache else 'an integrator'}, one new process a row; "
          "CPU s of making and running (import excluded)")
    ok = True
    shared = tempfile.TemporaryDirectory() if args.shared_cache else None
    for integrator in args.integrators:
        own = tempfile.TemporaryDirectory() if shared is None else contextlib.nullcontext(
            shared.name)
        with own as cache, tempfile.TemporaryDirectory() as mod:
            with open(os.path.join(mod, "benchuser.py"), "w") as f:
                f.write(_USER_MODULE)
            env = dict(os.environ, NUMBA_CACHE_DIR=cache,
                       PYTHONPATH=mod + os.pathsep + os.environ.get("PYTHONPATH", ""))
            rows = ROWS if not args.rows else ["none"] + args.rows.split(",")
            if integrator == "wh" and not args.rows:
                rows = rows + BATCH_ROWS
            held = dict(GOAL_ROWS)
            if args.ahead:
                held.update({row: 1.0 for row in ROWS if row != "UserForce"})
                out = run_child(["-c", _AHEAD, integrator], env=env, capture_output=True,
                                text=True)
                if out.returncode:
                    print(f"{integrator:10s} orbits compile failed:\n{out.stderr}", flush=True)
                    ok = False
                    continue
                cpu = json.loads(out.stdout.strip().splitlines()[-1])["cpu"]
                print(f"{integrator:10s} {'orbits compile ' + integrator:30s} {cpu:7.2f} s",
                      flush=True)
            for row in rows:
                out = run_child(["-c", _CHILD, integrator, row], env=env,
                                capture_output=True, text=True)
                if out.returncode:
                    print(f"{integrator:10s} {row:30s} failed:\n{out.stderr}", flush=True)
                    ok = False
                    continue
                got = json.loads(out.stdout.strip().splitlines()[-1])
                if "refused" in got:
                    print(f"{integrator:10s} {row:30s} not taken: {got['refused'][:60]}",
                          flush=True)
                    continue
                cpu = got["cpu"]
                goal = held.get(row)
                verdict = ""
                if goal is not None:
                    verdict = f"goal <= {goal:.0f} s: {'PASS' if cpu <= goal else 'MISS'}"
                    ok = ok and cpu <= goal
                print(f"{integrator:10s} {row:30s} {cpu:7.2f} s  {verdict}", flush=True)
    if shared is not None:
        shared.cleanup()
    print("all goals met" if ok else "some goals missed")


if __name__ == "__main__":
    main()
