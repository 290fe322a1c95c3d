"""Compile time: measured, announced once, and paid ahead of time.

numba compiles a stepping loop the first time a process calls it and keeps
the machine code in its on-disk cache, per CPU and numba version; a later
process loads it in a fraction of a second.  A run measures the seconds it
spends compiling with a :class:`CompileClock` (numba's public event API, the
``"numba:compile"`` event, which numba broadcasts for a real compilation and
not for a load from its cache), so that its summary can part compiling from
stepping; the clock also prints one line on the standard error when a
stepping loop starts to compile, terminal or not, since a first run can
otherwise sit silent for half a minute.  :func:`compile`
(``orbits.integrators.compile``, ``orbits compile``) compiles the loops
ahead, for clusters, containers and CI, where many processes would otherwise
each compile the same loops at once.
"""

import os
import sys
import threading
import time

from numba.core import event as _event

__all__ = ["CompileClock", "FIRST_COMPILE_SECONDS", "NOTICE_FROM", "COMMON", "loop_label",
           "notice", "compile", "cache_dir"]

#: Seconds a loop's first compile takes on an empty cache: the compiling
#: inside the first ``Simulation.run`` of the outer solar system, on the
#: reference machine (2-core AMD EPYC, AVX2, a busy host, where the same
#: figure scatters by up to a factor of two from run to run; measured with
#: ``benchmarks/bench_first_compile.py``, which prints this table anew, and
#: recorded in benchmarks/RESULTS.md).  Keyed by :func:`loop_label`; only the
#: notice's estimate reads it.
FIRST_COMPILE_SECONDS = {
    "euler": 4.0, "symplectic-euler": 5.0, "verlet": 4.0, "leapfrog": 4.0,
    "rk2": 3.0, "rk4": 4.0, "yoshida4": 4.0, "yoshida6": 4.0, "yoshida8": 4.0,
    "wh": 45.0, "wh democratic-heliocentric": 35.0,
    "saba2": 35.0, "saba2 democratic-heliocentric": 40.0,
    "saba3": 45.0, "saba3 democratic-heliocentric": 35.0,
    "saba4": 35.0, "saba4 democratic-heliocentric": 45.0,
    "dopri5": 5.0, "dop853": 8.0, "rk4-doubling": 6.0, "ias15": 8.0, "taylor": 6.0,
    "implicit-euler": 4.0, "implicit-midpoint": 4.0, "trace": 35.0,
}

#: What the notice says of a loop missing from :data:`FIRST_COMPILE_SECONDS`.
UNKNOWN_ESTIMATE = "a few seconds"

#: Seconds: a loop expected to compile in less than this is not announced.
NOTICE_FROM = 1.0

#: The integrators ``orbits compile`` compiles when none is named.
COMMON = ("leapfrog", "ias15", "wh")

#: The compile event numba broadcasts (numba.core.event's documented kinds).
_KIND = "numba:compile"


def loop_label(integrator):
    """The name of an integrator's stepping loop, as the notice and the table
    of :data:`FIRST_COMPILE_SECONDS` give it: its registry name, and its
    coordinates where they are not its default (each set of coordinates is a
    loop of its own).

    Examples
    --------
    >>> from orbits import integrators
    >>> from orbits._compiling import loop_label
    >>> loop_label(integrators.get("wh")), loop_label(integrators.get(
    ...     "wh", coordinates="democratic-heliocentric"))
    ('wh', 'wh democratic-heliocentric')
    """
    coords = integrator.config.get("coordinates")
    if coords is None or coords == type(integrator).options.get("coordinates"):
        return integrator.name
    return f"{integrator.name} {coords}"


def notice(label):
    """The line printed when ``label``'s loop starts to compile, or None
    when it is expected to take less than :data:`NOTICE_FROM`.

    Examples
    --------
    >>> from orbits._compiling import notice
    >>> notice("wh")
    'orbits: compiling the wh loop for this CPU, once (about 45 s; `orbits compile` does it ahead)'
    """
    seconds = FIRST_COMPILE_SECONDS.get(label)
    if seconds is not None and seconds < NOTICE_FROM:
        return None
    about = UNKNOWN_ESTIMATE if seconds is None else f"about {float(f'{seconds:.2g}'):g} s"
    return (f"orbits: compiling the {label} loop for this CPU, once ({about}; "
            f"`orbits compile` does it ahead)")


class CompileClock(_event.Listener):
    """Seconds numba spends compiling in this thread inside a ``with`` block,
    and the notice of a stepping loop's first compile.

    Compilations nest (a loop compiles the kernels it calls that are not
    loaded yet); the clock counts the outermost ones, so each second once.
    Around each call of a compiled loop, :meth:`loop` arms the notice: the
    first compilation that starts inside it prints :func:`notice` of
    ``label`` on the standard error, a terminal or a log file alike.  A
    loop loaded from numba's cache, or already compiled in this process,
    compiles nothing and says nothing, so the line appears once per process
    and loop.

    Parameters
    ----------
    label : str, optional
        The loop's name (:func:`loop_label`); None announces nothing.
    quiet : bool
        Measure only (a run with ``progress=False``).
    stream : file, optional
        Where the notice goes; default ``sys.stderr`` at the time it is printed.

    Attributes
    ----------
    seconds : float
        Seconds spent compiling so far, loads from the cache not included.
    compiled : int
        Outermost compilations so far.

    Examples
    --------
    >>> import numba
    >>> from orbits._compiling import CompileClock
    >>> with CompileClock() as clock:
    ...     _ = numba.njit(lambda a: a + 1)(1)
    >>> clock.compiled, clock.seconds > 0
    (1, True)
    """

    def __init__(self, label=None, quiet=False, stream=None):
        self.label = label
        self.quiet = quiet or label is None
        self.stream = stream
        self.seconds = 0.0
        self.compiled = 0
        self._depth = 0
        self._start = 0.0
        self._thread = None
        self._armed = False
        self._window = _LoopWindow(self)

    def __enter__(self):
        self._thread = threading.get_ident()
        _event.register(_KIND, self)
        return self

    def __exit__(self, *exc):
        _event.unregister(_KIND, self)
        return False

    def loop(self):
        """A context manager around one call of a compiled loop: a
        compilation starting inside it is the loop's, and is announced."""
        return self._window

    def on_start(self, event):
        if threading.get_ident() != self._thread:
            return
        self._depth += 1
        if self._depth > 1:
            return
        self._start = time.perf_counter()
        if self._armed:
            self._armed = False     # one line for a loop and the kernels it compiles
            line = notice(self.label)
            if line is not None:
                stream = self.stream or sys.stderr
                try:
                    print(line, file=stream, flush=True)
                except (OSError, ValueError):   # a closed or broken stream: say nothing
                    pass

    def on_end(self, event):
        if threading.get_ident() != self._thread or self._depth == 0:
            return
        self._depth -= 1
        if self._depth == 0:
            self.seconds += time.perf_counter() - self._start
            self.compiled += 1


class _LoopWindow:
    """:meth:`CompileClock.loop`: arms the notice for one call (made once per
    clock: a call of the loop allocates nothing for it)."""

    __slots__ = ("clock",)

    def __init__(self, clock):
        self.clock = clock

    def __enter__(self):
        self.clock._armed = not self.clock.quiet

    def __exit__(self, *exc):
        self.clock._armed = False
        return False


#: The step of the fixed-step runs that compile a loop ahead, in days.
_AHEAD_DT_DAYS = 10.0
#: Steps of each such run (enough for the loop's in-loop outputs to be used).
_AHEAD_STEPS = 10


def _variants(name):
    """The integrators (configured) whose loops ``name`` compiles: one per
    set of coordinates for the methods that take them."""
    from . import integrators      # which imports this module
    integ = integrators.get(name)
    coords = type(integ).options.get("coordinates")
    if coords is None:
        return [integ]
    from .integrators.wisdom_holman import COORDINATES
    return [integ] + [integrators.get(name, coordinates=c) for c in COORDINATES if c != coords]


def compile(names=None, progress=None, report=None):
    """Compile the stepping loops of ``names`` now, so that later runs load them.

    ``orbits compile`` on the command line.

    Each integrator runs the outer solar system
    (:func:`orbits.scenes.outer_solar_system`) for a few steps, in both
    Wisdom-Holman coordinate systems where it takes them, which compiles its
    loop and the kernels it calls into numba's cache (:func:`cache_dir`).
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
    >>> import orbits
    >>> [label for label, _ in orbits.integrators.compile(["leapfrog"], progress=False)]
    ['leapfrog']

    ``wh`` (and ``saba2`` to ``saba4``) compile a loop for each set of
    coordinates: ``['wh', 'wh democratic-heliocentric']``.
    """
    import astropy.units as u

    from . import scenes
    from .simulation import Simulation   # the run driver imports this module

    names = COMMON if names is None else tuple(names)
    loops = [integ for name in names for integ in _variants(name)
             if getattr(integ, "compiled", True)]
    if progress is None:
        progress = _stderr_is_terminal()
    bar = None
    if progress:
        from tqdm.auto import tqdm
        bar = tqdm(total=len(loops), unit="loop", desc="compiling", leave=False)
    bodies = scenes.outer_solar_system()
    done = []
    try:
        for integ in loops:
            label = loop_label(integ)
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


def cache_dir():
    """The folder numba keeps the package's compiled loops in.

    ``NUMBA_CACHE_DIR`` when it is set; otherwise ``__pycache__`` beside the
    kernels' sources, or numba's user-wide cache where the package's folder
    is not writable.

    Examples
    --------
    >>> import os
    >>> from orbits._compiling import cache_dir
    >>> os.path.isabs(cache_dir())
    True
    """
    from numba.core import config
    from numba.core.dispatcher import Dispatcher

    if config.CACHE_DIR:
        return os.path.abspath(config.CACHE_DIR)
    from ._kernels import stepping
    for value in vars(stepping).values():
        if isinstance(value, Dispatcher) and value.stats.cache_path:
            return value.stats.cache_path   # numba's choice: beside the source, or user-wide
    return os.path.join(os.path.dirname(os.path.abspath(stepping.__file__)), "__pycache__")


def _stderr_is_terminal():
    try:
        return sys.stderr.isatty()
    except (AttributeError, ValueError):
        return False
