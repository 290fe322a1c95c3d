"""Compiling the stepping loops ahead of time: ``orbits compile`` and
:func:`compile_ahead`, for clusters, containers and CI (see :mod:`._compiling`)."""

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
    """The integrators (configured) whose loops ``name`` compiles, each with
    whether it is the loop with the planets in vector lanes: one per set of
    coordinates for the methods that take them, and for those with a
    ``lanes`` option (``wh``, the SABA methods, ``trace``) the scalar loop
    and the lanes' one of each."""
    integ = integrators.get(name)
    options = type(integ).options
    coords = options.get("coordinates")
    if coords is None:
        if "lanes" in options:
            return [(integrators.get(name, lanes=mode), mode == "on") for mode in ("off", "on")]
        return [(integ, False)]
    order = [coords] + [c for c in COORDINATES if c != coords]
    if "lanes" not in options:
        return [(integrators.get(name, coordinates=c), False) for c in order]
    return [(integrators.get(name, coordinates=c, lanes=mode), mode == "on")
            for c in order for mode in ("off", "on")]


def compile_ahead(names=None, progress=None, report=None):
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
        prints a line with it).

    Returns
    -------
    list of (str, float)
        Each loop's name (:func:`loop_label`) and the seconds spent
        compiling it (0 for a loop that was loaded from the cache).

    Raises
    ------
    UnknownIntegratorError
        A name that is not registered (checked before anything compiles).

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
    loops = [(integ, lanes) for name in names for integ, lanes in _variants(name)
             if getattr(integ, "compiled", True)]
    if progress is None:
        progress = stderr_is_terminal()
    bar = None
    if progress:
        bar = tqdm(total=len(loops), unit="loop", desc="compiling", leave=False)
    bodies = scenes.outer_solar_system()
    done = []
    try:
        for integ, lanes in loops:
            label = loop_label(integ, lanes)
            if bar is not None:
                bar.set_postfix_str(label)
            dt = None if integ.adaptive else _AHEAD_DT_DAYS * u.day
            until = _AHEAD_STEPS * _AHEAD_DT_DAYS * u.day
            with CompileClock() as clock:
                sim = Simulation(bodies.copy(), integrator=integ, dt=dt)
                sim.run(until=until, outputs=3, progress=False)
            done.append((label, clock.seconds))
            if report is not None:
                report(label, clock.seconds)
            if bar is not None:
                bar.update(1)
    finally:
        if bar is not None:
            bar.close()
    return done
