"""Command line: ``orbits run | resume | info | plot | validate | scenes | integrators``.

``main(argv=None)`` only parses arguments and calls the library; the tests
call it with a list.
"""

import argparse
import re
import signal
import sys
import threading

import astropy.units as u
import numpy as np

__all__ = ["main", "parse_quantity"]

_QUANTITY = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*([A-Za-z_]\w*(?:\s*\S*)?)?\s*$")


def parse_quantity(text, physical_type="time"):
    """Read ``"10d"``, ``"1000 yr"``, ``"2.5e3 day"``; a bare number stays a float."""
    m = _QUANTITY.match(text)
    if not m:
        raise argparse.ArgumentTypeError(f"cannot read {text!r} as a number with a unit, "
                                         f"e.g. 10d or 1000yr")
    value, unit = float(m.group(1)), m.group(2)
    if not unit:
        return value
    try:
        q = value * u.Unit(unit.strip())
    except ValueError:
        raise argparse.ArgumentTypeError(f"unknown unit {unit!r} in {text!r}") from None
    if q.unit.physical_type != physical_type:
        raise argparse.ArgumentTypeError(f"{text!r} is not a {physical_type}")
    return q


def _dominant(bodies):
    return bodies.names[int(np.argmax(bodies.masses.value))]


#: ``--gr`` choice -> the term it adds for a body set
GR_TERMS = {
    "sun": lambda b: _forces().GR(_dominant(b)),
    "potential": lambda b: _forces().GRPotential(_dominant(b)),
    "full": lambda b: _forces().GRFull(),
}


def _forces():
    from orbits import forces
    return forces


def _parser():
    p = argparse.ArgumentParser(prog="orbits", description="N-body orbital mechanics.")
    sub = p.add_subparsers(dest="command", required=True)

    run = sub.add_parser("run", help="integrate a built-in scene and print a summary")
    run.add_argument("scene", help="scene name (see 'orbits scenes')")
    run.add_argument("--integrator", "-i", default="verlet",
                     help="integrator name (see 'orbits integrators'); default verlet")
    run.add_argument("--dt", type=parse_quantity, default=None,
                     help="step, with a unit (10d, 1h) or a plain number in the scene's "
                          "units; for adaptive integrators (ias15, dopri5, ...) the first "
                          "step, and optional")
    run.add_argument("--until", type=parse_quantity, required=True,
                     help="end time, e.g. 1000yr, or a plain number in the scene's units")
    run.add_argument("--outputs", type=int, default=None,
                     help="number of outputs (500, or one per step for a shorter run)")
    run.add_argument("--gr", choices=sorted(GR_TERMS),
                     help="general relativity: 'sun' (1PN correction from the most massive "
                          "body, velocity-dependent), 'potential' (its potential form, which "
                          "wh takes) or 'full' (Einstein-Infeld-Hoffmann among all bodies)")
    run.add_argument("--no-progress", action="store_true", help="no progress bar")
    run.add_argument("--out", help="stream outputs and checkpoints to this HDF5 file")
    run.add_argument("--force", action="store_true", help="overwrite an existing --out file")
    run.add_argument("--checkpoint-interval", type=float, default=None,
                     help="seconds between checkpoints in --out (default 60; 0: at every "
                          "output, about 2 ms each)")

    res = sub.add_parser("resume", help="finish an interrupted run, or continue a finished "
                                        "one, from its HDF5 file")
    res.add_argument("file")
    res.add_argument("--until", type=parse_quantity,
                     help="continue to this time after the interrupted run is finished")
    res.add_argument("--outputs", type=int, default=None,
                     help="outputs of the --until run (500)")
    res.add_argument("--no-progress", action="store_true")
    res.add_argument("--checkpoint-interval", type=float, default=None)

    info = sub.add_parser("info", help="say what an output file holds")
    info.add_argument("file")

    plot = sub.add_parser("plot", help="orbits in the x-y plane and the invariants' errors, "
                                       "as a PNG")
    plot.add_argument("file")
    plot.add_argument("-o", "--output", help="PNG path (default: next to the file)")

    val = sub.add_parser("validate", help="run the validation report (accuracy against "
                                          "REBOUND, work-precision, drift, stress suite) "
                                          "and write it as Markdown with plots")
    val.add_argument("--quick", action="store_true",
                     help="shorter runs and sweeps: a few minutes on two cores")
    val.add_argument("--out", default="validation-report",
                     help="folder for report.md and its PNGs (default ./validation-report)")
    val.add_argument("--workers", type=int, default=None,
                     help="worker processes (default: one per core; 1: this process only)")
    val.add_argument("--scheduler", default=None,
                     help="address of an existing Dask scheduler to run on")
    val.add_argument("--only", nargs="+", default=None, metavar="SECTION",
                     help="run only these sections: accuracy ephemeris work_precision drift "
                          "stress guide")
    val.add_argument("--no-progress", action="store_true")

    sub.add_parser("scenes", help="list the built-in scenes")
    sub.add_parser("integrators", help="list the integrators")
    return p


def _negative_values(argv):
    """``--dt -10d`` as ``--dt=-10d``: argparse would read ``-10d`` as an option."""
    out = []
    it = iter(argv)
    for tok in it:
        if tok in _TIME_OPTIONS:
            nxt = next(it, None)
            if nxt is not None and _QUANTITY.match(nxt) and nxt.startswith("-"):
                out.append(f"{tok}={nxt}")
                continue
            out.append(tok)
            if nxt is not None:
                out.append(nxt)
            continue
        out.append(tok)
    return out


_TIME_OPTIONS = ("--dt", "--until")


def _in_scene_units(value, bodies):
    """A plain number is read in the scene's unit of time, as the help says."""
    if value is None or isinstance(value, u.Quantity):
        return value
    return value * bodies.units.unit("time")


def _terminated(signum, frame):
    from orbits.errors import RunInterrupted
    raise RunInterrupted("SIGTERM", signal=signum)


def main(argv=None):
    """Entry point of the ``orbits`` command; returns the exit status."""
    argv = _negative_values(sys.argv[1:] if argv is None else list(argv))
    args = _parser().parse_args(argv)
    import orbits
    from orbits.errors import OrbitsError, RunInterrupted

    path = getattr(args, "out", None) or (args.file if args.command == "resume" else None)
    previous = None
    if args.command in ("run", "resume") and threading.current_thread() is \
            threading.main_thread():
        # SIGTERM (a batch scheduler's warning) stops the run like Ctrl-C does:
        # at a consistent state, with a checkpoint in the file
        previous = signal.signal(signal.SIGTERM, _terminated)
    try:
        return _main(args, orbits)
    except RunInterrupted as exc:
        name = signal.Signals(exc.signal or signal.SIGINT).name
        where = "" if exc.time is None else f" at t = {exc.time:.10g} (step {exc.step})"
        print(f"orbits: stopped by {name}{where}"
              + (f"; a checkpoint is in {path}: 'orbits resume {path}' finishes the run"
                 if path else "; nothing was written (no --out)"), file=sys.stderr)
        return 128 + int(exc.signal or signal.SIGINT)
    except (OrbitsError, ValueError, u.UnitsError) as exc:
        print(f"orbits: error: {exc}", file=sys.stderr)
        return 2
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


def _main(args, orbits):
    """The command's work; errors are reported by :func:`main`."""
    if args.command == "scenes":
        for name, text in orbits.scenes.describe():
            print(f"{name:22s} {text}")
    elif args.command == "integrators":
        print(f"{'name':18s} {'order':>5s}  {'symplectic':10s} {'adaptive':8s} summary")
        for info in orbits.integrators.available():
            print(f"{info.name:18s} {info.order:5d}  {str(info.symplectic):10s} "
                  f"{str(info.adaptive):8s} {info.summary}")
    elif args.command == "run":
        bodies = orbits.scenes.get(args.scene)
        forces = [] if args.gr is None else [GR_TERMS[args.gr](bodies)]
        integrator = orbits.integrators.get(args.integrator)
        if args.dt is None and not integrator.adaptive:
            raise ValueError(f"--dt is needed: {args.integrator!r} takes fixed steps "
                             f"(adaptive integrators such as ias15 choose their own)")
        sim = orbits.Simulation(bodies, integrator=integrator,
                                dt=_in_scene_units(args.dt, bodies), forces=forces)
        result = sim.run(until=_in_scene_units(args.until, bodies), outputs=args.outputs,
                         progress=False if args.no_progress else None,
                         output=args.out, overwrite=args.force,
                         checkpoint_interval=args.checkpoint_interval)
        print(f"scene           {args.scene}")
        print(result.summary())
        if args.out:
            print(f"written         {args.out}")
    elif args.command == "resume":
        sim = orbits.Simulation.from_file(args.file)
        progress = False if args.no_progress else None
        result = None
        if not sim.resume_point.finished:
            result = sim.resume(progress=progress,
                                checkpoint_interval=args.checkpoint_interval)
            print(f"finished the interrupted run in {args.file}")
        if args.until is not None:
            result = sim.run(until=_in_scene_units(args.until, sim.bodies),
                             outputs=args.outputs, progress=progress, output=args.file,
                             checkpoint_interval=args.checkpoint_interval)
        if result is None:
            print(f"{args.file}: its run is complete; give --until to continue it")
            return 0
        print(result.summary())
    elif args.command == "info":
        print(orbits.io.describe(args.file))
    elif args.command == "validate":
        return _validate(args)
    elif args.command == "plot":
        from orbits.plotting import plot_file
        path = plot_file(args.file, args.output)
        print(f"wrote {path}")
    return 0


def _validate(args):
    from orbits import validation
    client = None
    if args.scheduler:
        from distributed import Client
        client = Client(args.scheduler)
    try:
        path = validation.validate(out=args.out, quick=args.quick, n_workers=args.workers,
                                   client=client, progress=not args.no_progress,
                                   sections=args.only or validation.SECTIONS)
    except validation.ValidationError as exc:
        print(f"orbits: error: {exc}", file=sys.stderr)
        return 2
    finally:
        if client is not None:
            client.close()
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
