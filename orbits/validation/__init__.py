"""The validation report: accuracy against REBOUND, the solar system against
the JPL DE421 ephemeris, the dissipative force terms against REBOUNDx and
their analytic rates, work against precision, long-horizon drift, a stress
suite, a check of a published guide, and MEGNO maps and secular frequencies
(chaos indicators beside REBOUND's, a map's wall time against REBOUND on a
process pool, frequencies against published values).

``orbits validate [--quick] [--out DIR]`` (or :func:`validate`) runs it on
this machine's cores and writes ``report.md`` with its PNG plots into ``DIR``.
REBOUND is needed (``pip install -e ".[test]"``), and matplotlib for the
plots; the ephemeris and dissipative-forces sections also run REBOUNDx where
it is installed.  The full report takes about ten minutes on two cores, the
quick one a few minutes; the committed full report is in the repository's
``validation/report/``.

Each section is a module with the same three members:

``TITLE``
    The section's heading.
``tasks(quick) -> list of Task``
    Its measurements (:class:`~orbits.validation._runner.Task`): small,
    independent, each timed on a core of its own.
``section(rows, out_dir, quick) -> str``
    Its Markdown, from the tasks' rows in order; plots are written to
    ``out_dir``.

All sections' tasks run together on one pool, longest first, so the cores
stay busy to the end.  Which integrators a problem takes, and why others are
left out, is declared in :mod:`~orbits.validation.cases`.
"""

import datetime as _dt
import importlib
import os
import pathlib
import platform
import time

import numba
import numpy

from .. import __version__
from ._runner import Pool, Task, run_tasks

__all__ = ["validate", "SECTIONS", "Task", "Pool", "run_tasks", "ValidationError"]

#: the report's sections, in order (module names in this package)
SECTIONS = ("accuracy", "ephemeris", "dissipative", "work_precision", "drift", "stress",
            "collisions", "guide", "chaos")


class ValidationError(RuntimeError):
    """The report cannot be made (REBOUND or matplotlib missing, bad arguments)."""


def _modules(names):
    unknown = [n for n in names if n not in SECTIONS]
    if unknown:
        raise ValidationError(f"unknown section(s) {', '.join(unknown)}; valid: "
                              f"{', '.join(SECTIONS)}")
    return [(n, importlib.import_module(f"{__name__}.{n}")) for n in names]


def _check_requirements():
    missing = []
    for mod in ("rebound", "matplotlib"):
        try:
            __import__(mod)
        except ImportError:
            missing.append(mod)
    if missing:
        raise ValidationError(f"the validation report needs {' and '.join(missing)}: "
                              f"pip install -e \".[test]\"")


def validate(out="validation-report", quick=False, n_workers=None, client=None,
             progress=True, sections=SECTIONS):
    """Run the validation report and write ``out/report.md`` with its plots.

    Parameters
    ----------
    out : str or path
        Folder for ``report.md`` and the PNGs (made if needed).
    quick : bool
        Shorter runs and sweeps (a few minutes on two cores) instead of the
        full report.
    n_workers : int, optional
        Worker processes of the local Dask cluster (default: one per core);
        1 runs everything in this process.
    client : distributed.Client, optional
        An existing Dask cluster to run on instead.
    progress : bool
        Show a progress bar.
    sections : sequence of str
        A subset of :data:`SECTIONS`.

    Returns
    -------
    pathlib.Path
        The report's path.
    """
    _check_requirements()
    out = pathlib.Path(out)
    out.mkdir(parents=True, exist_ok=True)
    modules = _modules(list(sections))
    wall0 = time.perf_counter()
    all_tasks, spans = [], []
    for name, mod in modules:
        ts = mod.tasks(quick)
        spans.append((name, mod, len(all_tasks), len(all_tasks) + len(ts)))
        all_tasks += ts
    with Pool(client=client, n_workers=n_workers) as pool:
        rows = run_tasks(all_tasks, pool, progress=progress, desc="validation")
        workers = pool.n_workers
    texts = []
    for name, mod, a, b in spans:
        texts.append(mod.section(rows[a:b], out, quick))
    elapsed = time.perf_counter() - wall0
    head = _header(quick, elapsed, workers, len(all_tasks), modules, rows, spans)
    path = out / "report.md"
    path.write_text(head + "\n\n".join(texts) + "\n" + _costs(all_tasks, rows),
                    encoding="utf-8")
    return path


#: how many of the costliest tasks the report's last paragraph names
COSTLIEST = 8


def _costs(tasks, rows):
    """The report's last lines: what its time went to."""
    timed = [(r.get("task_seconds", 0.0), t) for t, r in zip(tasks, rows)
             if isinstance(r, dict)]
    if not timed:
        return ""
    total = sum(s for s, _ in timed)
    timed.sort(key=lambda st: -st[0])
    lines = ["", "## What the report's time went to", "",
             f"{total:.0f} seconds of worker time in all (compilation included). "
             "The costliest measurements:", "", "| seconds | measurement |", "|---|---|"]
    for sec, task in timed[:COSTLIEST]:
        args = ", ".join(f"{k}={v}" for k, v in task.kwargs.items() if k != "quick")
        lines.append(f"| {sec:.1f} | {task.function.split('.')[-1]}({args}) |")
    return "\n".join(lines) + "\n"


def _cpu_name():
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as fh:
            for line in fh:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def _versions():
    out = {"orbits": __version__, "numpy": numpy.__version__,
           "numba": numba.__version__, "python": platform.python_version()}
    try:
        import rebound
        out["REBOUND"] = rebound.__version__
    except ImportError:  # pragma: no cover - checked before
        pass
    try:
        import scipy
        out["scipy"] = scipy.__version__
    except ImportError:  # pragma: no cover
        pass
    return out


def _header(quick, elapsed, workers, n_tasks, modules, rows, spans):
    now = _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    versions = ", ".join(f"{k} {v}" for k, v in _versions().items())
    mode = "quick" if quick else "full"
    lines = ["# orbits validation report", "",
             f"{mode.capitalize()} report, made {now} by `orbits validate"
             f"{' --quick' if quick else ''}` in {elapsed / 60:.1f} minutes: {n_tasks} "
             f"measured runs on {workers} worker process(es) of a {os.cpu_count()}-core "
             f"{_cpu_name()} ({versions}).", "",
             "Every run of ours and of REBOUND starts from the same floats with the same G. "
             "A run that fails is recorded with its named error (NonFiniteState, "
             "StepSizeUnderflow, ConvergenceFailure, WallTimeExceeded, ...) and its errors "
             "up to the last good state; nothing is dropped silently. Wall times are "
             "measured on one core per run, compilation excluded, while other runs use the "
             "other cores, so they compare runs of one report rather than machines.", "",
             "Contents:", ""]
    for name, mod, a, b in spans:
        anchor = mod.TITLE.lower().replace(" ", "-").replace(",", "").replace("'", "")
        lines.append(f"- [{mod.TITLE}](#{anchor})")
    summary = []
    for name, mod, a, b in spans:
        line = getattr(mod, "summary_line", None)
        if line is not None:
            text = line(rows[a:b])
            if text:
                summary.append(f"- {text}")
    if summary:
        lines += ["", "In brief:", ""] + summary
    return "\n".join(lines) + "\n\n"
