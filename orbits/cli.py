"""Command line: ``orbits run | resume | info | plot | elements | validate | scenes |
integrators | compile``.

``main(argv=None)`` only parses arguments and calls the library; the tests
call it with a list.  It returns the exit status: one of
:data:`EXIT_STATUSES`, or 128 + the signal number for a run stopped by
SIGINT or SIGTERM.

Building the parser and ``--help`` import neither numpy nor astropy nor tqdm
nor the library: each command's function imports what its work uses (the
function-level imports of this module), and a unit in a value (``10d``)
imports ``astropy.units`` when it is read.  ``tests/test_startup.py`` checks it
and ``benchmarks/bench_startup.py`` times it.
"""

import argparse
import copy
import csv
import math
import os
import re
import signal
import sys
import textwrap
import threading
import time
import traceback

from orbits import _integrator_options

__all__ = ["main", "parse_quantity", "EXIT_STATUSES", "EXIT_COMPLETED", "EXIT_STOPPED",
           "EXIT_USAGE", "EXIT_INPUT", "EXIT_FILE", "EXIT_RUN_FAILED", "EXIT_INTERNAL"]

EXIT_COMPLETED = 0
EXIT_STOPPED = 1
EXIT_USAGE = 2          # argparse's own
EXIT_INPUT = 3
EXIT_FILE = 4
EXIT_RUN_FAILED = 5
EXIT_INTERNAL = 70      # EX_SOFTWARE of sysexits.h

#: what each exit status of ``orbits`` means; ``orbits --help`` and the command
#: line's guide (docs/guides/cli.rst) list this table
EXIT_STATUSES = {
    EXIT_COMPLETED: "completed",
    EXIT_STOPPED: "the run was stopped by a stopping condition (an encounter, an escape, "
                  "a collision); its summary is printed, and --out holds it",
    EXIT_USAGE: "the command line cannot be parsed: an unknown option, a missing argument",
    EXIT_INPUT: "bad input: a scene, body-set file, integrator, option or value that "
                "cannot be used",
    EXIT_FILE: "a file that cannot be read or written: missing, damaged, written by "
               "another run, a symbolic link, or a full disk",
    EXIT_RUN_FAILED: "the run failed: the state became non-finite, the step size "
                     "collapsed, or a Newton iteration did not converge",
    EXIT_INTERNAL: "an error inside orbits itself (a bug): the traceback is printed",
}
_SIGNAL_STATUS = ("stopped by the signal N (130: SIGINT, Ctrl-C; 143: SIGTERM); with "
                  "--out, after a checkpoint from which 'orbits resume' finishes the run")


def _exit_help():
    """The exit statuses, as ``--help`` shows them."""
    rows = [*EXIT_STATUSES.items(), ("128+N", _SIGNAL_STATUS)]
    return "exit status:\n" + "\n".join(
        textwrap.fill(text, width=79, initial_indent=f"  {code:>5}  ",
                      subsequent_indent=" " * 9) for code, text in rows) + "\n"

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
    import astropy.units as u
    try:
        q = value * u.Unit(unit.strip())
    except ValueError:
        raise argparse.ArgumentTypeError(f"unknown unit {unit!r} in {text!r}") from None
    if q.unit.physical_type != physical_type:
        raise argparse.ArgumentTypeError(f"{text!r} is not a {physical_type}")
    return q


def _length(text):
    """An argparse type: a length with a unit, or a plain number in the scene's units."""
    return parse_quantity(text, "length")


def integrator_options():
    """Option name -> ``[(Option, integrator names), ...]``: the flags of ``orbits
    run``'s integrator options, one for each option an integrator declares
    (:mod:`orbits._integrator_options` reads the declarations without importing
    the integrators).

    Examples
    --------
    >>> from orbits.cli import integrator_options
    >>> [names for spec, names in integrator_options()["corrector"]]
    [('wh', 'saba2', 'saba3', 'saba4')]
    """
    return _integrator_options.taken_by(_integrator_options.declared())


def _option_help(takers):
    """The help of an integrator option's flag: what it is, the values it takes
    and its default, for each integrator that takes it."""
    parts = []
    for spec, names in takers:
        values = (f"; one of {', '.join(map(str, spec.choices))}" if spec.choices else "")
        unit = (f"; a {spec.unit} with a unit, or a plain number in the scene's units"
                if spec.unit else "")
        default = f"{spec.default:g}" if spec.kind is float else spec.default
        parts.append(f"{spec.help}{values}{unit} ({', '.join(names)}; default {default})")
    return "; ".join(parts)


def _option_type(spec):
    """The argparse type of an integrator option: a quantity for one with a unit,
    else its declared type (a value outside its choices or range reaches the
    integrator's check, which names the valid ones)."""
    if spec.unit:
        return lambda text: parse_quantity(text, spec.unit)
    return spec.kind

#: Outputs of a run when ``--outputs`` is not given (orbits.simulation.DEFAULT_OUTPUTS,
#: written out here so that the help is built without importing the library;
#: tests/test_cli_run.py checks that the two agree).
DEFAULT_OUTPUTS = 500

#: The fewest and most intervals between outputs that :func:`default_outputs`
#: chooses for a fixed-step run of more steps than ``DEFAULT_OUTPUTS - 1``:
#: within a factor of five below and two above the default, so that a run keeps
#: enough outputs to plot and a file stays near its usual size.
OUTPUT_INTERVALS = (100, 1000)

OUTPUTS_HELP = (
    f"number of outputs, the start and the end included; default: for a fixed-step "
    f"integrator, one per step in a run of up to {DEFAULT_OUTPUTS - 1} steps, else the "
    f"count nearest {DEFAULT_OUTPUTS} (from {OUTPUT_INTERVALS[0] + 1} to "
    f"{OUTPUT_INTERVALS[1] + 1}) that puts the outputs a whole number of steps apart "
    f"(--dt 100d --until 1e5yr: 365250 steps, 488 outputs 750 steps apart), or "
    f"{DEFAULT_OUTPUTS} at "
    f"the nearest steps where the steps have no such divisor; {DEFAULT_OUTPUTS} for an "
    f"adaptive one")

RUN_EXAMPLES = """\
examples:
  orbits run outer-solar-system -i wh --dt 100d --until 1e5yr --com --out run.h5
  orbits run outer-solar-system -i ias15 --epsilon 1e-10 --until 1000yr
  orbits run pythagorean -i dop853 --rtol 1e-12 --until 100 --escape-distance 10

your own bodies, in system.toml (numbers with units; angles in deg or rad):

  [[body]]
  name = "Sun"
  mass = "1 Msun"

  [[body]]
  name = "Jupiter"
  mass = "1 Mjup"
  primary = "Sun"
  a = "5.2 au"
  e = 0.048
  inc = "1.3 deg"

  [[body]]
  name = "probe"
  mass = 0
  position = ["1 au", "0 au", "0 au"]
  velocity = ["0 km/s", "30 km/s", "0 km/s"]

  [run]                       # optional defaults; the options above override them
  integrator = "ias15"
  until = "100 yr"

then:
  orbits run system.toml --com
  orbits run system.toml -i wh --dt 10d --corrector 17 --until 1e4yr

A .csv file works too: a header 'name,mass [Msun],x [au],...,vz [km/s]' (or element
columns 'primary,a [au],e,inc [deg]'), a row per body; see orbits.systemfile.
"""


def _dominant(bodies):
    return bodies.names[int(bodies.masses.value.argmax())]


#: ``--gr`` choice -> the term it adds for a body set
GR_TERMS = {
    "sun": lambda b: _forces().GR(_dominant(b)),
    "potential": lambda b: _forces().GRPotential(_dominant(b)),
    "full": lambda b: _forces().GRFull(),
}


def _forces():
    from orbits import forces
    return forces


def _parser(with_integrator_options=True):
    """The parser; ``with_integrator_options=False`` leaves out ``run``'s integrator
    options, whose declarations take about 15 ms to read, for a command line
    whose command is not ``run`` (see :func:`main`)."""
    p = argparse.ArgumentParser(prog="orbits", description="N-body orbital mechanics.",
                                epilog=_exit_help(),
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)

    run = sub.add_parser("run", help="integrate a built-in scene or your own body set "
                                     "and print a summary",
                         description="Integrate a built-in scene or a body set from a "
                                     "TOML or CSV file, and print a summary.",
                         epilog=RUN_EXAMPLES + "\n" + _exit_help(),
                         formatter_class=argparse.RawDescriptionHelpFormatter)
    run.add_argument("scene", help="scene name (see 'orbits scenes') or a body-set file "
                                   "ending in .toml or .csv")
    run.add_argument("--integrator", "-i", default=None,
                     help="integrator name or alias (see 'orbits integrators'); default: "
                          "the file's [run] integrator, else ias15")
    run.add_argument("--dt", type=parse_quantity, default=None,
                     help="step, with a unit (10d, 1h) or a plain number in the scene's "
                          "units; for adaptive integrators (ias15, dopri5, ...) the first "
                          "step, and optional")
    run.add_argument("--until", type=parse_quantity, default=None,
                     help="end time, e.g. 1000yr, or a plain number in the scene's units; "
                          "needed unless the file's [run] table gives it")
    run.add_argument("--outputs", type=int, default=None, help=OUTPUTS_HELP)
    run.add_argument("--gr", choices=sorted(GR_TERMS),
                     help="general relativity: 'sun' (1PN correction from the most massive "
                          "body, velocity-dependent), 'potential' (its potential form, which "
                          "wh takes) or 'full' (Einstein-Infeld-Hoffmann among all bodies)")
    opts = run.add_argument_group("integrator options", "passed only when given; an "
                                  "integrator that does not take one is an error")
    for option, takers in (integrator_options() if with_integrator_options else {}).items():
        spec = takers[0][0]
        opts.add_argument(spec.flag, dest=option, type=_option_type(spec), default=None,
                          help=_option_help(takers))
    stops = run.add_argument_group("stopping conditions", "checked after every step; the "
                                   f"run stops with exit status {EXIT_STOPPED} and prints "
                                   f"what it has")
    stops.add_argument("--encounter-distance", type=_length, default=None,
                       help="stop when two bodies come closer than this (0.01au, 1e5km)")
    stops.add_argument("--encounter-hill", type=float, default=None,
                       help="stop when two bodies other than the central one come within "
                            "this many mutual Hill radii")
    stops.add_argument("--escape-distance", type=_length, default=None,
                       help="stop when a body is farther than this from the centre of mass "
                            "(1000au)")
    stops.add_argument("--collisions", choices=("halt", "merge", "bounce"), default=None,
                       help="bodies with radii that touch: stop ('halt'), merge them, or "
                            "bounce them as hard spheres")
    stops.add_argument("--restitution", type=float, default=None,
                       help="coefficient of restitution of --collisions bounce (1: elastic)")
    run.add_argument("--com", action="store_true",
                     help="move the bodies to their centre-of-mass frame first (scenes in "
                          "a published frame, such as outer-solar-system, drift otherwise)")
    run.add_argument("--no-progress", action="store_true",
                     help="no progress bar, and no line when a loop starts to compile")
    run.add_argument("--out", help="stream outputs and checkpoints to this HDF5 file")
    run.add_argument("--force", action="store_true", help="overwrite an existing --out file")
    run.add_argument("--checkpoint-interval", type=float, default=None,
                     help="seconds between checkpoints in --out (default 60; 0: at every "
                          "output, about 2 ms each)")

    res = sub.add_parser("resume", help="finish an interrupted run, or continue a finished "
                                        "one, from its HDF5 file")
    res.add_argument("file")
    res.add_argument("--until", type=parse_quantity,
                     help="continue to this time after the interrupted run is finished; "
                          "it must be after the run's end (an --until the run has passed "
                          "is refused before anything is done, exit status "
                          f"{EXIT_INPUT})")
    res.add_argument("--outputs", type=int, default=None,
                     help="outputs of the --until run; default as for 'orbits run': a "
                          "whole number of steps apart for a fixed-step integrator")
    res.add_argument("--no-progress", action="store_true")
    res.add_argument("--checkpoint-interval", type=float, default=None)

    info = sub.add_parser("info", help="say what an output file holds")
    info.add_argument("file")

    plot = sub.add_parser("plot", help="orbits in the x-y plane and the invariants' errors, "
                                       "as a PNG")
    plot.add_argument("file")
    plot.add_argument("-o", "--output", help="PNG path (default: next to the file)")
    plot.add_argument("--frame", default=None, metavar="FRAME",
                      help="barycentric, heliocentric (about the most massive body) or a "
                           "body's name; default about the most massive body where it "
                           "holds most of the mass, else barycentric")

    elements = sub.add_parser("elements", help="the osculating orbital elements of a body "
                                               "at every output of a file, as a table")
    elements.add_argument("file")
    elements.add_argument("body", nargs="?", default=None, metavar="BODY",
                          help="the body's name")
    elements.add_argument("--body", dest="body_option", default=None, metavar="BODY",
                          help="the same, as an option (for scripts written before BODY "
                               "was positional)")
    elements.add_argument("--primary", default=None,
                          help="the body the orbit is about (default: the centre of mass "
                               "of the bodies before it in the set, as REBOUND's orbit())")
    elements.add_argument("--out", default=None,
                          help="write the table to this CSV file instead of printing it")

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
                     help="run only these sections: accuracy ephemeris dissipative "
                          "work_precision drift stress guide chaos")
    val.add_argument("--no-progress", action="store_true")

    sub.add_parser("scenes", help="list the built-in scenes")
    sub.add_parser("integrators", help="list the integrators")

    comp = sub.add_parser("compile", help="compile integrators' stepping loops now, so that "
                                          "later runs load them from numba's cache",
                          description="Compile the stepping loops of integrators now (a "
                                      "few steps of the outer solar system each, in both "
                                      "Wisdom-Holman coordinate systems, alone and with "
                                      "force terms, variations, both, and stopping "
                                      "conditions), "
                                      "so that later runs on this machine load them from "
                                      "numba's cache instead of compiling. The cache is "
                                      "per CPU and numba version: run it once where the "
                                      "runs will run "
                                      "(a cluster node, a container image, a CI job) "
                                      "before many processes start.",
                          epilog=COMPILE_EXAMPLES + "\n" + _exit_help(),
                          formatter_class=argparse.RawDescriptionHelpFormatter)
    comp.add_argument("integrators", nargs="*", metavar="INTEGRATOR",
                      help="integrator names (see 'orbits integrators'); default: "
                           + ", ".join(COMPILE_DEFAULT))
    comp.add_argument("--all", action="store_true",
                      help="every integrator with a compiled loop")
    comp.add_argument("--jobs", "-j", type=int, default=1, metavar="N",
                      help="compile in N processes at once (default 1; 0: one a core)")
    comp.add_argument("--plain", action="store_true",
                      help="only the loops of gravity alone: not those of runs with force "
                           "terms, variations or stopping conditions (about a third of the "
                           "time)")
    comp.add_argument("--no-progress", action="store_true", help="no progress bar")
    return p


#: what ``orbits compile`` compiles without names (orbits._compiling.COMMON,
#: written out here so that the help is built without importing numba;
#: tests/test_compiling.py checks that the two agree)
COMPILE_DEFAULT = ("leapfrog", "ias15", "wh")

COMPILE_EXAMPLES = """\
examples:
  orbits compile                      # leapfrog, ias15 and wh
  orbits compile --plain              # the same, gravity alone
  orbits compile dop853 trace         # these
  orbits compile --all                # every integrator (several minutes)
  orbits compile --all --jobs 0       # the same, in a process a core
  NUMBA_CACHE_DIR=/shared/numba orbits compile --all   # a cache the nodes share
"""


def _negative_values(argv):
    """``--dt -10d`` as ``--dt=-10d``: argparse would read ``-10d`` as an option."""
    numeric = _NUMBER_OPTIONS + (tuple(
        takers[0][0].flag for takers in integrator_options().values()
        if takers[0][0].kind in (int, float)) if _command(argv) == "run" else ())
    out = []
    it = iter(argv)
    for tok in it:
        if tok in numeric:
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


def _command(argv):
    """The command of a command line: its first word that is not an option."""
    return next((word for word in argv if not word.startswith("-")), None)


# options whose value may be negative, so that it reaches the checks (and the
# integrators' numeric options)
_NUMBER_OPTIONS = ("--dt", "--until", "--encounter-distance", "--encounter-hill",
                   "--escape-distance")


def default_outputs(steps):
    """The number of outputs of a fixed-step run of ``steps`` steps when none is
    asked for: outputs a whole number of steps apart.

    Parameters
    ----------
    steps : float
        The run's length in steps of dt, ``(until - start) / dt`` (a fraction
        where a shortened last step ends it).

    Returns
    -------
    int or None
        ``n + 1`` for the divisor ``n`` of the steps (rounded to a whole
        number) nearest ``DEFAULT_OUTPUTS - 1`` by ratio, from
        :data:`OUTPUT_INTERVALS`; every step for a run of at most
        ``DEFAULT_OUTPUTS - 1`` steps; None (the library's default, spread
        over the nearest steps) where there is no such divisor or no whole
        step.  Output ``k`` then falls after ``k * steps / n`` steps: the run's
        plan puts it at the nearest step, which is exact, and only the last,
        at the end, follows a shortened step.

    Examples
    --------
    >>> from orbits.cli import default_outputs
    >>> default_outputs(365250.0)      # 1e5 yr at 100 d: 488 outputs, 750 steps apart
    488
    >>> default_outputs(3652.5)        # 100 yr at 10 d: 3652 steps (and a half one)
    333
    >>> default_outputs(73.05), default_outputs(1009.0), default_outputs(0.3)
    (74, None, None)
    """
    whole = int(round(steps))
    if whole < 1:
        return None
    wanted = DEFAULT_OUTPUTS - 1
    if whole <= wanted:
        return whole + 1
    lo, hi = OUTPUT_INTERVALS
    found = [n for n in range(lo, min(hi, whole) + 1) if whole % n == 0]
    if not found:
        return None
    # nearest by ratio; between two as near, the more outputs
    best = min(found, key=lambda n: (abs(math.log(n / wanted)), -n))
    return best + 1


def _outputs_for(sim, until, outputs):
    """``outputs`` as given, else :func:`default_outputs` for a fixed-step run from
    ``sim``'s time to ``until`` (None for an adaptive one: the library's default)."""
    if outputs is not None or sim.integrator.adaptive:
        return outputs
    steps = float(((until - sim.time) / sim.dt).decompose())
    return default_outputs(abs(steps)) if math.isfinite(steps) else None


def _in_scene_units(value, bodies, kind="time"):
    """A plain number is read in the scene's unit of time (or ``kind``), as the help says."""
    import astropy.units as u
    if value is None or isinstance(value, u.Quantity):
        return value
    return value * bodies.units.unit(kind)


def _terminated(signum, frame):
    from orbits.errors import RunInterrupted
    raise RunInterrupted("SIGTERM", signal=signum)


def main(argv=None):
    """Entry point of the ``orbits`` command; returns the exit status
    (:data:`EXIT_STATUSES`; argparse exits with :data:`EXIT_USAGE` itself)."""
    argv = _negative_values(sys.argv[1:] if argv is None else list(argv))
    parser = _parser(with_integrator_options=_command(argv) == "run")
    args = parser.parse_args(argv)
    if args.command == "compile" and args.all and args.integrators:
        parser.error("compile: give integrator names or --all, not both")
    if args.command == "compile" and args.jobs < 0:
        parser.error(f"compile: --jobs must be >= 0 (0: one process a core), got {args.jobs}")
    if args.command == "elements":
        _elements_body(parser, args)
    import astropy.units as u
    import orbits
    from orbits.errors import OrbitsError, RunError, RunInterrupted, SimulationStopped
    from orbits.units import format_time

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
        where = ("" if exc.time is None
                 else f" at t = {format_time(exc.time, digits=10)} (step {exc.step})")
        print(f"orbits: stopped by {name}{where}"
              + (f"; a checkpoint is in {path}: 'orbits resume {path}' finishes the run"
                 if path else "; nothing was written (no --out)"), file=sys.stderr)
        return 128 + int(exc.signal or signal.SIGINT)
    except SimulationStopped as exc:
        if exc.result is not None:
            print(exc.result.summary())
        print(f"stopped         {exc}")
        if path:
            print(f"written         {path}")
        return EXIT_STOPPED
    except RunError as exc:
        if exc.result is not None:
            print(exc.result.summary())
        if path:
            print(f"written         {path}")
        print(f"orbits: the run failed: {exc}", file=sys.stderr)
        return EXIT_RUN_FAILED
    except OSError as exc:          # OrbitsFileError, and the system's own
        print(f"orbits: error: {exc}", file=sys.stderr)
        return EXIT_FILE
    except (OrbitsError, ValueError, u.UnitsError) as exc:
        print(f"orbits: error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    except Exception:
        traceback.print_exc()
        print(f"orbits: internal error (exit status {EXIT_INTERNAL}): the traceback above is "
              f"of a bug in orbits; please report it", file=sys.stderr)
        return EXIT_INTERNAL
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
            also = f" (also: {', '.join(info.aliases)})" if info.aliases else ""
            print(f"{info.name:18s} {info.order:5d}  {str(info.symplectic):10s} "
                  f"{str(info.adaptive):8s} {info.summary}{also}")
    elif args.command == "run":
        return _run(args, orbits)
    elif args.command == "resume":
        return _resume(args, orbits)
    elif args.command == "info":
        print(orbits.io.describe(args.file))
    elif args.command == "validate":
        return _validate(args)
    elif args.command == "plot":
        from orbits.plotting import plot_file
        path = plot_file(args.file, args.output, frame=args.frame)
        print(f"wrote {path}")
    elif args.command == "elements":
        _elements(args, orbits)
    elif args.command == "compile":
        _compile(args, orbits)
    return 0


def _compile(args, orbits):
    """``orbits compile``: a line per loop, then the total and where the cache is."""
    from tqdm import tqdm
    from orbits import _compiling

    names = ([i.name for i in orbits.integrators.available()] if args.all
             else args.integrators or None)
    skipped = [name for name in (names or ()) if not orbits.integrators.get(name).compiled]

    def report(label, seconds):
        done = f"{seconds:6.1f} s compiling" if seconds >= 0.05 else "   loaded from the cache"
        tqdm.write(f"{label:62s} {done}", file=sys.stdout)

    t0 = time.perf_counter()
    loops = orbits.compile_ahead(names, progress=False if args.no_progress else None,
                                 report=report, jobs=args.jobs, plain=args.plain)
    wall = time.perf_counter() - t0
    if skipped and not args.all:
        print(f"{', '.join(skipped)}: run in Python, nothing to compile")
    compiling = sum(seconds for _, seconds in loops)
    print(f"{len(loops)} loop{'' if len(loops) == 1 else 's'} ready in {wall:.1f} s "
          f"({compiling:.1f} s compiling) for {_compiling.cpu_name()}; "
          f"numba's cache: {_compiling.cache_dir()}")


def _elements_body(parser, args):
    """``orbits elements FILE BODY``, or ``FILE --body BODY`` as before; not both."""
    if args.body is not None and args.body_option is not None:
        parser.error(f"elements: give the body once, as BODY or --body, not both "
                     f"({args.body!r} and {args.body_option!r})")
    if args.body is None:
        args.body = args.body_option
    if args.body is None:
        parser.error("elements: give the body, as in 'orbits elements FILE Jupiter'")


def _elements(args, orbits):
    result = orbits.load(args.file)
    if not len(result):
        raise orbits.io.OrbitsFileError(f"{args.file}: holds no outputs ({result.status})")
    columns, table = result.elements_table(args.body, primary=args.primary)
    if args.out:
        with open(args.out, "w", newline="") as f:
            writer = csv.writer(f)
            writer.writerow(columns)
            writer.writerows([repr(float(v)) for v in row] for row in table)
        print(f"wrote {args.out} ({len(table)} rows: {', '.join(columns)})")
        return
    try:
        print("  ".join(f"{c:>17s}" for c in columns))
        for row in table:
            print("  ".join(f"{v:17.10g}" for v in row))
        sys.stdout.flush()
    except BrokenPipeError:
        # the reader stopped (``| head``): no traceback; Python's documented remedy
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())


def _run(args, orbits):
    """``orbits run``: a scene or a body-set file, the file's [run] defaults under the
    command line's options."""
    bodies, defaults = _bodies(args.scene, orbits)

    def given(key):
        value = getattr(args, key)
        return defaults.get(key) if value is None else value

    name = args.integrator or defaults.get("integrator", orbits.integrators.DEFAULT)
    options = dict(defaults.get("options", {}))
    for option, takers in integrator_options().items():
        value, unit = getattr(args, option), takers[0][0].unit
        if value is not None:
            options[option] = (value if not unit else
                               _in_scene_units(value, bodies, unit).to_value(
                                   bodies.units.unit(unit)))
    integrator = orbits.integrators.get(name, **options)
    dt, until = given("dt"), given("until")
    if dt is None and not integrator.adaptive:
        raise ValueError(f"--dt is needed: {name!r} takes fixed steps (the adaptive "
                         f"integrators choose their own: "
                         f"{', '.join(orbits.integrators.adaptive_names())})")
    if until is None:
        raise ValueError("--until is needed: the end time, such as 1000yr (a body-set "
                         "file may give it as 'until' in its [run] table)")
    if args.com or defaults.get("com"):
        bodies.move_to_com()
    forces = [] if args.gr is None else [GR_TERMS[args.gr](bodies)]
    stops = {"encounter_distance": _in_scene_units(given("encounter_distance"), bodies,
                                                   "length"),
             "encounter_hill": args.encounter_hill,
             "escape_distance": _in_scene_units(given("escape_distance"), bodies, "length"),
             "collisions": args.collisions, "restitution": args.restitution}
    sim = orbits.Simulation(bodies, integrator=integrator,
                            dt=_in_scene_units(dt, bodies), forces=forces,
                            **{k: v for k, v in stops.items() if v is not None})
    print(f"scene           {args.scene}")
    until = _in_scene_units(until, bodies)
    result = sim.run(until=until, outputs=_outputs_for(sim, until, given("outputs")),
                     progress=False if args.no_progress else None,
                     output=args.out, overwrite=args.force,
                     checkpoint_interval=args.checkpoint_interval)
    print(result.summary())
    if args.out:
        print(f"written         {args.out}")
    return 0


def _resume(args, orbits):
    """``orbits resume``: finish the interrupted run, then continue to ``--until``;
    the summary covers every run in the file.  An ``--until`` that the run has
    already passed is refused before anything is done."""
    from orbits.errors import RunError
    from orbits.units import format_time
    sim = orbits.Simulation.from_file(args.file)
    point = sim.resume_point
    until = None
    if args.until is not None:
        until = _in_scene_units(args.until, sim.bodies)
        _check_continues(args.file, point, sim, until)
    elif point.finished:
        print(f"{args.file}: its run is complete; give --until to continue it")
        return 0
    progress = False if args.no_progress else None
    time0, steps0 = sim.time, sim.steps
    try:
        if not point.finished:
            result = sim.resume(progress=progress,
                                checkpoint_interval=args.checkpoint_interval)
            print(f"finished the interrupted run in {args.file}")
        if until is not None:
            result = sim.run(until=until, outputs=_outputs_for(sim, until, args.outputs),
                             progress=progress, output=args.file,
                             checkpoint_interval=args.checkpoint_interval)
    except RunError as exc:
        # a stop or a failure: main() prints its result's summary, of the whole run too
        if exc.result is not None:
            exc.result = _whole_run(exc.result, args.file, orbits)
        raise
    print(_whole_run(result, args.file, orbits).summary())
    print(f"this command    {sim.steps - steps0} of these steps, from t = "
          f"{format_time(time0, digits=10)}")
    return 0


def _check_continues(path, point, sim, until):
    """An ``--until`` at or before the end of the run in the file (at or after it,
    for a run backwards) is an error, raised before any work."""
    from orbits.units import format_time
    if point.finished:
        end, what = sim.time, "the end of the run"
    else:
        end = sim.units.quantity(point.plan.until, "time")
        what = "the end of the interrupted run"
    forward = point.plan.until >= point.plan.start_time
    if (until > end) if forward else (until < end):
        return
    raise ValueError(
        f"--until {format_time(until, digits=10)} is not {'after' if forward else 'before'} "
        f"{what} in {path} (t = {format_time(end, digits=10)}); give a "
        f"{'later' if forward else 'earlier'} time"
        + ("" if point.finished else ", or none to only finish the run"))


def _whole_run(result, path, orbits):
    """``result`` (the last output of a run written into ``path``) with the steps,
    time span, work and largest errors of every run in the file."""
    whole = copy.copy(result)
    vars(whole).update(orbits.io.h5md.whole_run(path))
    return whole


def _bodies(scene, orbits):
    """A built-in scene (no defaults), or a body-set file and its [run] table."""
    if scene.lower().endswith((".toml", ".csv")):
        from orbits import systemfile
        if not os.path.isfile(scene):
            raise ValueError(f"no such file: {scene}")
        sf = systemfile.read(scene)
        return sf.bodies, sf.run
    try:
        return orbits.scenes.get(scene), {}
    except ValueError as exc:
        raise ValueError(f"{exc}; or give a body-set file ending in .toml or .csv") from None


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
        return EXIT_INPUT
    finally:
        if client is not None:
            client.close()
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
