"""Compile time: measured, announced once, and paid ahead of time.

numba compiles a stepping loop the first time a process calls it and keeps
the machine code in its on-disk cache, per CPU and numba version; a later
process loads it in a fraction of a second.  A run measures the seconds it
spends compiling with a :class:`CompileClock` (numba's public event API, the
``"numba:compile"`` event, which numba broadcasts for a real compilation and
not for a load from its cache), so that its summary can part compiling from
stepping; the clock also prints one line on the standard error when a
stepping loop starts to compile, terminal or not, since a first run can
otherwise sit silent for half a minute.  :func:`orbits.compile_ahead`
(``orbits compile``, in :mod:`orbits._ahead`) compiles the loops ahead, for
clusters, containers and CI, where many processes would otherwise each
compile the same loops at once.
"""

import os
import sys
import threading
import time

from numba.core import config as _config
from numba.core import event as _event
from numba.core.dispatcher import Dispatcher

from ._kernels import stepping
from ._kernels._jit import cpu_name

__all__ = ["CompileClock", "FIRST_COMPILE_SECONDS", "NOTICE_FROM", "COMMON", "ADDED", "CHECKS",
           "OUTPUT_MONITORS",
           "TERMS",
           "loop_label",
           "notice", "cache_dir", "cpu_name", "stderr_is_terminal"]

#: Seconds a loop's first compile takes on an empty cache: the compiling
#: inside the first ``Simulation.run`` of the outer solar system.  Each is the
#: geometric middle of two 2-core AMD EPYC hosts' figures, a quiet Zen 4 with
#: AVX-512 and a busy Zen 3 with AVX2 that compiles 1.3-2.4 times slower, so
#: that the notice's "about" is within a factor of 1.6 of either
#: (``benchmarks/bench_first_compile.py`` measures each loop; the figures are
#: in benchmarks/RESULTS.md).  Keyed by :func:`loop_label`; only the notice's
#: estimate reads it.  The methods of a family share their loop (the SABA
#: methods wh's), so a family's first method compiles it.
FIRST_COMPILE_SECONDS = {
    "euler": 4.0, "symplectic-euler": 5.0, "verlet": 5.0, "leapfrog": 5.0,
    "rk2": 4.0, "rk4": 4.0, "yoshida4": 5.0, "yoshida6": 5.0, "yoshida8": 5.0,
    **{f"{name}{coords}{lanes}": seconds
       for name in ("wh", "saba2", "saba3", "saba4")
       for coords in ("", " democratic-heliocentric")
       for lanes, seconds in (("", 16.0), (" lanes", 37.0))},
    "dopri5": 10.0, "dop853": 11.0, "rk4-doubling": 10.0, "ias15": 12.0, "taylor": 6.0,
    "implicit-euler": 5.0, "implicit-midpoint": 5.0, "trace": 27.0, "trace lanes": 41.0,
    # the stopping conditions' checks, one for every integrator (:data:`CHECKS`):
    # 20-25 s, 1.1-1.6 s and 7.6 s on the Zen 3 (2026-11-30)
    "check of the stopping conditions": 22.0, "check of the escape conditions": 1.4,
    "look-ahead of the stopping conditions": 7.0,
    # the force terms' table (:data:`TERMS`): 9.3-11.2 s and 16 s on the Zen 3 (2026-11-30)
    "kernels of the force terms": 10.0, "Jacobians of the force terms": 16.0,
    # the splitting methods' kick of velocity-dependent terms (:data:`TERMS`):
    # 1.4-2.1 s on the Zen 3 (2026-11-30)
    "implicit kick of the force terms": 2.0,
    # the outputs' monitors (:data:`OUTPUT_MONITORS`): 1.3 s on the Zen 3 (2026-12-01)
    "monitors of the outputs": 1.3,
}

#: The check a run's stopping conditions take (a kind of
#: :func:`orbits._kernels.stopping.check_kind`), and ``trace``'s look-ahead
#: (:func:`orbits._kernels.stopping.ahead_pointer`), as the notice names them
#: and :data:`FIRST_COMPILE_SECONDS` keys them: each compiled once for every
#: integrator, and announced by itself (:meth:`CompileClock.part`).
CHECKS = {"escapes": "check of the escape conditions", "all": "check of the stopping conditions",
          "ahead": "look-ahead of the stopping conditions"}

#: The monitors of the outputs a loop records
#: (:func:`orbits._kernels.invariants.fill_kernel`), as the notice names
#: them and :data:`FIRST_COMPILE_SECONDS` keys them: compiled once for every
#: integrator, before the loop of a first run that records outputs in it.
OUTPUT_MONITORS = "monitors of the outputs"

#: The C callables of the force terms' table
#: (:func:`orbits._kernels.terms.table_pointer`), as the notice names them:
#: compiled once for every integrator, when a first simulation has terms, and
#: the Jacobians' when a first one reads them (implicit methods, variations);
#: and the splitting methods' implicit kick
#: (:func:`orbits._kernels.stepping.implicit_kick`), once for all of them,
#: when a first run has terms that read velocities.
TERMS = {"kernels": "kernels of the force terms", "jacobians": "Jacobians of the force terms",
         "kick": "implicit kick of the force terms"}

#: What the notice says of a loop missing from :data:`FIRST_COMPILE_SECONDS`.
UNKNOWN_ESTIMATE = "a few seconds"

#: What a run adds to gravity, as the loop's label names it: a loop of its
#: own (variations) or kernels compiled once for every integrator (the
#: terms', the stopping conditions' check) for a run that adds it first;
#: ``orbits compile`` compiles each ahead.
ADDED = {"terms": "with force terms", "variations": "with variations",
         "terms+variations": "with force terms and variations",
         "checks": "with stopping conditions"}

#: What the notice says of a loop for force terms, variations or both: such
#: loops took 12-40 s to compile for leapfrog, ias15 and wh on the 2-core
#: AMD EPYC with Zen 3 (``orbits compile``, 2026-11-30; benchmarks/RESULTS.md).
ADDED_ESTIMATE = "10-40 s"

#: Seconds: a loop expected to compile in less than this is not announced.
NOTICE_FROM = 1.0

#: The integrators ``orbits compile`` compiles when none is named.
COMMON = ("leapfrog", "ias15", "wh")

#: The compile event numba broadcasts (numba.core.event's documented kinds).
_KIND = "numba:compile"


def loop_label(integrator, lanes=False, adds=""):
    """The name of an integrator's stepping loop, as the notice and the table
    of :data:`FIRST_COMPILE_SECONDS` give it: its registry name, its
    coordinates where they are not its default (each set of coordinates is a
    loop of its own), "lanes" for the loop with its planets in vector
    lanes (``lanes``; see the ``lanes`` option of ``wh`` and ``trace``), and
    what the run adds to gravity (``adds``, a key of :data:`ADDED`).

    Examples
    --------
    >>> from orbits import integrators
    >>> from orbits._compiling import loop_label
    >>> loop_label(integrators.get("wh")), loop_label(integrators.get(
    ...     "wh", coordinates="democratic-heliocentric"), lanes=True)
    ('wh', 'wh democratic-heliocentric lanes')
    >>> loop_label(integrators.get("ias15"), adds="terms")
    'ias15 with force terms'
    """
    coords = integrator.config.get("coordinates")
    label = integrator.name
    if coords is not None and coords != type(integrator).options.get("coordinates"):
        label = f"{label} {coords}"
    if lanes:
        label = f"{label} lanes"
    return f"{label} {ADDED[adds]}" if adds else label


def notice(label):
    """The line printed when ``label``'s loop starts to compile, or None
    when it is expected to take less than :data:`NOTICE_FROM`.

    Examples
    --------
    >>> from orbits._compiling import notice
    >>> notice("wh")
    'orbits: compiling the wh loop for this CPU, once (about 16 s; `orbits compile` does it ahead)'
    >>> notice("check of the stopping conditions")[:65]
    'orbits: compiling the check of the stopping conditions for this C'
    """
    seconds = FIRST_COMPILE_SECONDS.get(label)
    if seconds is not None and seconds < NOTICE_FROM:
        return None
    if seconds is not None:
        about = f"about {float(f'{seconds:.2g}'):g} s"
    elif any(label.endswith(" " + added) for added in ADDED.values()):
        about = f"about {ADDED_ESTIMATE}"
    else:
        about = UNKNOWN_ESTIMATE
    parts = (*CHECKS.values(), *TERMS.values(), OUTPUT_MONITORS)
    what = label if label in parts else f"{label} loop"
    return (f"orbits: compiling the {what} for this CPU, once ({about}; "
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
        self._armed_label = label
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

    def part(self, label):
        """A context manager around the compiling of a part of the run that
        is not its loop (the stopping conditions' check, :data:`CHECKS`): a
        compilation starting inside it is announced as ``label``'s."""
        return _LoopWindow(self, label)

    def on_start(self, event):
        if threading.get_ident() != self._thread:
            return
        self._depth += 1
        if self._depth > 1:
            return
        self._start = time.perf_counter()
        if self._armed:
            self._armed = False     # one line for a loop and the kernels it compiles
            line = notice(self._armed_label)
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
    """:meth:`CompileClock.loop` (made once per clock: a call of the loop
    allocates nothing for it) and :meth:`CompileClock.part`: arms the notice
    of ``label`` (the clock's own: its loop) for one call."""

    __slots__ = ("clock", "label")

    def __init__(self, clock, label=None):
        self.clock = clock
        self.label = label

    def __enter__(self):
        clock = self.clock
        clock._armed = not clock.quiet
        clock._armed_label = clock.label if self.label is None else self.label

    def __exit__(self, *exc):
        self.clock._armed = False
        return False


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
    if _config.CACHE_DIR:
        return os.path.abspath(_config.CACHE_DIR)
    for value in vars(stepping).values():
        if isinstance(value, Dispatcher) and value.stats.cache_path:
            return value.stats.cache_path   # numba's choice: beside the source, or user-wide
    return os.path.join(os.path.dirname(os.path.abspath(stepping.__file__)), "__pycache__")


def stderr_is_terminal():
    """Whether the standard error is a terminal (False where it cannot say)."""
    try:
        return sys.stderr.isatty()
    except (AttributeError, ValueError):
        return False
