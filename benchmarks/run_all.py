"""Run every benchmark and write their tables to ``benchmarks/RESULTS.md``.

Each benchmark runs in its own process (``python benchmarks/NAME.py``), so
that one's threads, caches and compiled code do not affect the next; its
output is shown as it comes and collected into the report, under a header
that says when, on what machine and with which versions the numbers were
taken, and how loaded the machine was (the load average before and after:
timings from a machine that was busy with other work are noisy, the
threaded ones most of all).

``python benchmarks/run_all.py`` runs the full benchmarks (several minutes)
and writes ``RESULTS.md``; ``--quick`` runs the smoke-test versions and
writes nothing unless ``--output`` is given.
"""

import argparse
import datetime
import importlib.metadata
import os
import pathlib
import platform
import subprocess
import sys
import time

HERE = pathlib.Path(__file__).resolve().parent
BENCHMARKS = ("bench_fixed_step", "bench_gravity", "bench_monitors", "bench_ias15", "bench_wh",
              "bench_batch", "bench_divider", "bench_trace", "bench_adaptive", "bench_ensemble",
              "bench_forces", "bench_compile", "bench_startup")


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def cpu_flags():
    """The vector extensions that matter for the pair loops."""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("flags"):
                    flags = set(line.split(":", 1)[1].split())
                    return " ".join(x for x in ("avx2", "fma", "avx512f") if x in flags)
    except OSError:
        pass
    return "unknown"


def version(dist):
    try:
        return importlib.metadata.version(dist)
    except importlib.metadata.PackageNotFoundError:
        return "not installed"


def load_average():
    try:
        return "{:.2f} {:.2f} {:.2f}".format(*os.getloadavg())
    except OSError:
        return "unknown"


def git_revision():
    try:
        out = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=HERE,
                             capture_output=True, text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain"], cwd=HERE,
                               capture_output=True, text=True, check=True).stdout.strip()
        return out + (" (with uncommitted changes)" if dirty else "")
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def header(quick):
    import numba
    lines = [
        "# Benchmark results",
        "",
        f"- date: {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC",
        f"- mode: {'quick (smoke test, not for quoting)' if quick else 'full'}",
        f"- machine: {platform.machine()}, processor {platform.processor() or 'unknown'}, "
        f"{platform.platform()}",
        f"- CPU: {cpu_model()}, {os.cpu_count()} cores visible, "
        f"vector extensions: {cpu_flags()}",
        f"- numba threads: {numba.get_num_threads()}",
        f"- versions: Python {platform.python_version()}, orbits {version('orbits')}, "
        f"numba {version('numba')}, numpy {version('numpy')}, rebound {version('rebound')}, "
        f"astropy {version('astropy')}",
        f"- source: git {git_revision()}",
        f"- numba cache: {os.environ.get('NUMBA_CACHE_DIR') or 'next to the modules (default)'}",
        f"- load average (1, 5, 15 min) at start: {load_average()}",
    ]
    return lines


def run_one(name, quick):
    cmd = [sys.executable, str(HERE / f"{name}.py")] + (["--quick"] if quick else [])
    print(f"$ {' '.join(['python', f'benchmarks/{name}.py'] + cmd[2:])}", flush=True)
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    lines = []
    for line in proc.stdout:
        print(line, end="", flush=True)
        lines.append(line.rstrip("\n"))
    rc = proc.wait()
    elapsed = time.perf_counter() - t0
    print(flush=True)
    return rc, elapsed, lines


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="smoke-test versions")
    parser.add_argument("--only", nargs="+", choices=BENCHMARKS, default=BENCHMARKS,
                        help="run only these")
    parser.add_argument("--output", type=pathlib.Path, default=None,
                        help="report file (default benchmarks/RESULTS.md; "
                             "with --quick, none)")
    args = parser.parse_args(argv)
    output = args.output or (None if args.quick else HERE / "RESULTS.md")

    report = header(args.quick)
    sections = []
    failed = []
    for name in args.only:
        rc, elapsed, lines = run_one(name, args.quick)
        if rc != 0:
            failed.append(name)
        status = "" if rc == 0 else f", FAILED with exit status {rc}"
        sections += ["", f"## {name}", "",
                     f"`python benchmarks/{name}.py{' --quick' if args.quick else ''}` "
                     f"({elapsed:.0f} s{status})", "", "```", *lines, "```"]
    report.append(f"- load average at end: {load_average()}")
    report += sections
    if output is not None:
        output.write_text("\n".join(report) + "\n")
        print(f"wrote {output}")
    if failed:
        print(f"failed: {', '.join(failed)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
