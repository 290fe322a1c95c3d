"""numba on a worker: the threads a task may use, and what a task had to
compile, or load from numba's on-disk cache, before its runs could start.

Every row of a sweep says where it ran and how many compiled loops its task
compiled and loaded (``worker``, ``kernels_compiled``, ``kernels_loaded``):
:func:`_worker_fields` makes those columns.
"""

import os
import socket
import sys

import numba
from numba.core import config, event
from numba.core.dispatcher import Dispatcher
from numba.np.ufunc import parallel

from .._kernels import _jit

__all__ = []


_NUMBA_SYNCED = []


def _sync_numba_config():
    """Keep this task to the numba threads its environment allows.

    On a worker whose script imported orbits at the top, numba read its
    environment before the nanny set the worker's (``NUMBA_NUM_THREADS=1``):
    its thread pool has the machine's size, fixed at import.  Re-read the
    environment now, before the pool starts, or the first compilation after it
    started would fail on the changed setting; and use no more threads than the
    environment says.
    """
    if not _NUMBA_SYNCED:      # reading the environment costs 0.2 ms: once a process
        _NUMBA_SYNCED.append(True)
        try:
            config.reload_config()
        except RuntimeError:   # the pool already runs with another size: leave it
            return
    if config.NUMBA_NUM_THREADS < parallel.NUM_THREADS:
        numba.set_num_threads(config.NUMBA_NUM_THREADS)   # this thread's share


# kernel bookkeeping: what this task had to compile or load before it could run

_DISPATCHERS = [None, ()]


def _dispatchers():
    # walked again only when a module was imported or a loop specialised
    # since the last walk (a walk of sys.modules costs milliseconds, which
    # every member of a sweep would pay twice)
    state = (len(sys.modules), len(_jit._SPECIALISED))
    if _DISPATCHERS[0] == state:
        return _DISPATCHERS[1]
    found = [d for d in list(_jit._SPECIALISED.values()) if isinstance(d, Dispatcher)]
    for name, mod in list(sys.modules.items()):
        if name.startswith("orbits._kernels") and mod is not None:
            found.extend(d for d in vars(mod).values() if isinstance(d, Dispatcher))
    found = list({id(d): d for d in found}.values())
    # the dispatchers' own counters, which they keep for their lives: their
    # public ``stats`` builds a record and a cache path on every call, a
    # millisecond over the package's dispatchers, twice for every run
    counters = [getattr(d, "_cache_hits", None) for d in found]
    _DISPATCHERS[:] = [state, ([c for c in counters if c is not None],
                               [d for c, d in zip(counters, found) if c is None])]
    return _DISPATCHERS[1]


def _cache_loads():
    """Compiled functions of the package loaded from numba's disk cache so far."""
    counters, others = _dispatchers()
    # a counter holds one key for each signature loaded, counted once: a
    # dispatcher loads a signature only when it has none for it.  len() in
    # C (0.01 ms for the package's 225 dispatchers) instead of summing the
    # counts in Python (0.2 ms, twice a run)
    return (sum(map(len, counters))
            + sum(sum(d.stats.cache_hits.values()) for d in others))


class _CompileRecorder:
    """Counts numba compilations (not cache loads) inside a ``with``."""

    def __enter__(self):
        self._ctx = event.install_recorder("numba:compile")
        self.recorder = self._ctx.__enter__()
        return self

    def __exit__(self, *exc):
        return self._ctx.__exit__(*exc)

    @property
    def compiled(self):
        return sum(1 for _, ev in self.recorder.buffer if ev.is_start)


def _worker_fields(loaded0, log):
    compiled = log.compiled
    return {"worker": f"{socket.gethostname()}:{os.getpid()}",
            "kernels_compiled": compiled,
            "kernels_loaded": _cache_loads() - loaded0}
