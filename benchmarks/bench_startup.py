"""Start-up: CPU seconds of ``import orbits`` and of ``orbits --help``, warm.

What is measured
----------------
Each figure is the best of several fresh ``python`` processes, started from
the repository root (so this checkout's package is the one imported), after
one unmeasured process has filled the operating system's and Python's caches
(``__pycache__``; numba compiles nothing here).  CPU seconds, user plus
system, are the measure: on a shared host they scatter less than the wall
time.

- ``import orbits``: ``time.process_time()`` around the import, inside the
  process, as ``python -c "import time; t=time.process_time(); import orbits;
  print(time.process_time()-t)"`` prints it.  Goal: at most 0.5 s.
- ``orbits --help``: the whole process (the interpreter's own start
  included), as the ``orbits`` script runs it (``from orbits.cli import main;
  sys.exit(main())``), from the children's resource usage.  Goal: at most 0.3 s.

For comparison, not against a goal: the bare interpreter (``python -c pass``),
``python -m orbits.cli --help``, and the first use of the library
(``import orbits; orbits.Simulation``: astropy, numba and the kernels), which a
script that integrates pays once.

Run ``python benchmarks/bench_startup.py`` (about 20 s) or ``--quick``.
"""

import argparse
import pathlib
import resource
import subprocess
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]

IMPORT_GOAL = 0.5   # CPU seconds of ``import orbits`` (issue 37)
HELP_GOAL = 0.3     # CPU seconds of the whole ``orbits --help`` process (issue 37)

_INSIDE = ("import time; t = time.process_time(); {stmt}; "
           "print(time.process_time() - t)")

#: label -> (arguments of python, whether the figure is the child's own
#: process_time around ``stmt`` rather than the whole process)
CASES = {
    "python -c pass": (["-c", "pass"], False),
    "import orbits": (["-c", _INSIDE.format(stmt="import orbits")], True),
    "import orbits, whole process": (["-c", "import orbits"], False),
    "orbits --help": (["-c", "import sys; from orbits.cli import main; sys.exit(main())",
                       "--help"], False),
    "python -m orbits.cli --help": (["-m", "orbits.cli", "--help"], False),
    "import orbits; orbits.Simulation": (
        ["-c", _INSIDE.format(stmt="import orbits; orbits.Simulation")], True),
}


def cpu_seconds(args, inside):
    """CPU seconds of one fresh process: its own figure, or the whole process's."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    proc = subprocess.run([sys.executable, *args], cwd=ROOT, capture_output=True, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode != 0:
        raise RuntimeError(f"python {' '.join(args)} failed:\n{proc.stderr}")
    if inside:
        return float(proc.stdout.strip().splitlines()[-1])
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="best of 2 instead of 5")
    parser.add_argument("--repeats", type=int, default=None,
                        help="measured processes per case (default 5, quick 2)")
    args = parser.parse_args(argv)
    repeats = args.repeats or (2 if args.quick else 5)
    t_start = time.perf_counter()

    where = subprocess.run([sys.executable, "-c", "import orbits; print(orbits.__file__)"],
                           cwd=ROOT, capture_output=True, text=True, check=True)
    print(f"package: {pathlib.Path(where.stdout.strip()).parent}")
    print(f"CPU seconds (user + system), best of {repeats} fresh processes after one "
          f"unmeasured")
    print()

    best = {}
    for label, (case_args, inside) in CASES.items():
        cpu_seconds(case_args, inside)               # fills the caches
        times = [cpu_seconds(case_args, inside) for _ in range(repeats)]
        best[label] = min(times)
        print(f"  {label:<36} {best[label]:>7.3f} s   "
              f"(all: {', '.join(f'{t:.3f}' for t in times)})")
    print()

    print("Goals")
    for goal, value, limit in (
            (f"import orbits <= {IMPORT_GOAL:g} s", best["import orbits"], IMPORT_GOAL),
            (f"orbits --help <= {HELP_GOAL:g} s", best["orbits --help"], HELP_GOAL)):
        print(f"  {goal:<46} {value:>9.3f} s  {'PASS' if value <= limit else 'MISS'}")
    print(f"[bench_startup took {time.perf_counter() - t_start:.1f} s]")
    return 0


if __name__ == "__main__":
    sys.exit(main())
