"""Compiling the stepping loops ahead of time: ``orbits compile`` and
:func:`compile_ahead`, for clusters, containers and CI (see :mod:`._compiling`)."""

import os

import astropy.units as u
from tqdm.auto import tqdm

from . import integrators, scenes
from ._compiling import COMMON, CompileClock, loop_label, stderr_is_terminal
from .integrators.wisdom_holman import COORDINATES
from .simulation import Simulation

__all__ = ["compile_ahead"]


#: The step of the fixed-step runs that compile a loop ahead, in days.
_AHEAD_DT_DAYS = 10.0
#: Steps of each such run (enough for the loop's in-loop outputs to be used).
_AHEAD_STEPS = 10


def _variants(name):
    """The loops ``name`` compiles, as ``(name, options, lanes)``: the options
    of :func:`orbits.integrators.get` that configure each, and whether it is
    the loop with the planets in vector lanes: one per set of coordinates for
    the methods that take them, and for those with a ``lanes`` option
    (``wh``, the SABA methods, ``trace``) the scalar loop and the lanes' one
    of each."""
    options = type(integrators.get(name)).options
    coords = options.get("coordinates")
    modes = ("off", "on") if "lanes" in options else (None,)

    def loop(extra, mode):
        opts = dict(extra) if mode is None else dict(extra, lanes=mode)
        return (name, opts, mode == "on")

    if coords is None:
        return [loop({}, mode) for mode in modes]
    order = [coords] + [c for c in COORDINATES if c != coords]
    return [loop({"coordinates": c}, mode) for c in order for mode in modes]


def _compile_loop(name, options, lanes):
    """Compile one loop in this process (a few steps of the outer solar
    system): ``(its label, the seconds spent compiling)``."""
    integ = integrators.get(name, **options)
    label = loop_label(integ, lanes)
    dt = None if integ.adaptive else _AHEAD_DT_DAYS * u.day
    until = _AHEAD_STEPS * _AHEAD_DT_DAYS * u.day
    with CompileClock() as clock:
        sim = Simulation(scenes.outer_solar_system(), integrator=integ, dt=dt)
        sim.run(until=until, outputs=3, progress=False)
    return label, clock.seconds


def _check_jobs(jobs):
    """``jobs`` as a number of processes (0: one a core); a named error for
    anything else."""
    if isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 0:
        raise ValueError(f"jobs must be a whole number >= 0 (0: one process a core), "
                         f"got {jobs!r}")
    return (os.cpu_count() or 1) if jobs == 0 else jobs


def _pool(jobs):
    """A pool of ``jobs`` new processes (each imports the package afresh: no
    numba state is forked), or a named error where they would import an
    unguarded main script again."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    from .ensemble.guard import _unguarded_main_call, _where
    where = _unguarded_main_call("spawn")
    if where is not None:
        raise RuntimeError(
            f"compile_ahead(jobs={jobs}) was called from {_where(*where)}, outside "
            f'`if __name__ == "__main__":`: each of its processes imports the main script '
            f"again and would run it; put the call under the guard, or use jobs=1")
    return ProcessPoolExecutor(max_workers=jobs,
                               mp_context=multiprocessing.get_context("spawn"))


def compile_ahead(names=None, progress=None, report=None, jobs=1):
    """Compile the stepping loops of ``names`` now, so that later runs load them.

    ``orbits compile`` on the command line.

    Each integrator runs the outer solar system
    (:func:`orbits.scenes.outer_solar_system`) for a few steps, in both
    Wisdom-Holman coordinate systems where it takes them, which compiles its
    loop and the kernels it calls into numba's cache (:func:`orbits._compiling.cache_dir`).
    Integrators that run in Python (scipy's ``radau`` and ``lsoda``) have
    nothing to compile and are skipped.  The cache is per CPU and numba
    version: compile on the machine (or image) that runs, before many
    processes start at once.

    Parameters
    ----------
    names : sequence of str, optional
        Registry names; default ``leapfrog``, ``ias15`` and ``wh``
        (:data:`COMMON`).  All of them:
        ``[i.name for i in orbits.integrators.available()]``.
    progress : bool, optional
        A progress bar over the loops on the standard error: shown on a
        terminal by default.
    report : callable, optional
        Called with ``(label, seconds)`` after each loop (``orbits compile``
        prints a line with it), in the order the loops are done.
    jobs : int, optional
        Processes that compile at once (default 1, this one; 0: one a core).
        With more, the first loop is compiled here, so that the kernels every
        loop shares are in the cache, and the others in that many new
        processes, which share numba's cache: the wall time falls with the
        cores, for a little more CPU time (a kernel that two loops share may
        be compiled in both).  From a script, call it under ``if __name__ ==
        "__main__":`` (each new process imports the main script again).

    Returns
    -------
    list of (str, float)
        Each loop's name (:func:`loop_label`) and the seconds spent
        compiling it (0 for a loop that was loaded from the cache), in the
        order of ``names``.

    Raises
    ------
    UnknownIntegratorError
        A name that is not registered (checked before anything compiles).
    ValueError
        ``jobs`` not a whole number >= 0.
    RuntimeError
        ``jobs`` > 1 from the top level of a script without the
        ``__main__`` guard.

    Examples
    --------
    >>> [label for label, _ in orbits.compile_ahead(["leapfrog"], progress=False)]
    ['leapfrog']

    ``wh`` (and ``saba2`` to ``saba4``) compile a loop for each set of
    coordinates, and each of them with the planets in vector lanes (which
    runs take by the ``lanes`` option): ``['wh', 'wh lanes', 'wh
    democratic-heliocentric', 'wh democratic-heliocentric lanes']``;
    ``trace`` its loop and the one with its steps far from encounters in
    vector lanes: ``['trace', 'trace lanes']``.
    """
    names = COMMON if names is None else tuple(names)
    jobs = _check_jobs(jobs)
    loops = [spec for name in names if getattr(integrators.get(name), "compiled", True)
             for spec in _variants(name)]
    if progress is None:
        progress = stderr_is_terminal()
    bar = None
    if progress:
        bar = tqdm(total=len(loops), unit="loop", desc="compiling", leave=False)
    done = [None] * len(loops)

    def note(i, result):
        done[i] = result
        if report is not None:
            report(*result)
        if bar is not None:
            bar.set_postfix_str(result[0])
            bar.update(1)

    try:
        if jobs == 1 or len(loops) <= 1:
            for i, spec in enumerate(loops):
                note(i, _compile_loop(*spec))
        else:
            from concurrent.futures import as_completed
            with _pool(min(jobs, len(loops) - 1)) as pool:
                # the first loop here, so that the kernels the loops share
                # (the monitors, the Kepler drift) are in the cache before
                # the processes start
                note(0, _compile_loop(*loops[0]))
                futures = {pool.submit(_compile_loop, *spec): i
                           for i, spec in enumerate(loops) if i > 0}
                for future in as_completed(futures):
                    note(futures[future], future.result())
    finally:
        if bar is not None:
            bar.close()
    return done
