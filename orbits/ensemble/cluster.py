"""The Dask cluster of a sweep: a local cluster of single-threaded worker
processes on the loopback interface, and the settings its workers get.

:meth:`orbits.Ensemble.run` starts one (:func:`local_cluster`) when it is given
no client, and closes it at the end.  Dask (``dask``, ``distributed``) is
imported only when a cluster is started.
"""

import contextlib
import logging
import os
import sys

from .errors import MissingMainGuard
from .guard import (_GUARD_ADVICE, _importing_main_in_a_child, _top_level_call,
                    _unguarded_main_call, _where)

__all__ = ["local_cluster", "WORKER_ENVIRONMENT", "WORKER_DASK_CONFIG"]

#: Set in every worker of :func:`local_cluster`.  One numba thread per worker
#: process: the workers already use every core, and threads on top of them
#: would only compete (the threaded gravity kernel starts at 128 bodies).
WORKER_ENVIRONMENT = {"NUMBA_NUM_THREADS": "1", "OMP_NUM_THREADS": "1",
                      "MKL_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}

#: Dask settings of :func:`local_cluster`'s scheduler and workers, given to
#: the workers as their configuration (a worker takes its nanny's, not its
#: environment's).  Dask's defaults wake each process many times a second on
#: the cores the runs use: the statistical profiler sampled the running task
#: every 10 ms from a thread of its own, the event loop's latency probe ran
#: every 20 ms (it only measures; Dask's own tests take 500 ms), the memory
#: monitor every 0.1 s (1 s still stops a worker whose memory runs away) and
#: the system monitor every 0.5 s.  Without the profiler a sweep's runs take
#: about 6 % less time, and with these settings idle workers and the scheduler
#: use about a fifth of the CPU they use with the profiler alone turned off
#: (benchmarks/RESULTS.md).  The preload (``orbits._daskworker``) has
#: each worker process ignore SIGINT, which Ctrl-C in a terminal sends to every
#: process of the foreground group: the process that started the cluster closes
#: it, instead of each worker stopping with its own tracebacks.
WORKER_DASK_CONFIG = {"distributed.worker.profile.enabled": False,
                      "distributed.admin.system-monitor.interval": "2s",
                      "distributed.admin.tick.interval": "500ms",
                      "distributed.worker.memory.monitor-interval": "1s",
                      "distributed.worker.preload": "orbits._daskworker"}


def local_cluster(n_workers=None):
    """A Dask client of a new cluster on this machine: ``n_workers`` processes
    (default ``os.cpu_count()``) of one thread each, on the loopback interface,
    without dashboard, each with :data:`~orbits.ensemble.cluster.WORKER_ENVIRONMENT`
    and :data:`~orbits.ensemble.cluster.WORKER_DASK_CONFIG`.  Close it with
    ``client.close(); client.cluster.close()`` (or use it in a ``with``).

    Raises :class:`~orbits.ensemble.MissingMainGuard` when called from the top
    level of a script that lacks ``if __name__ == "__main__":`` (the workers
    cannot start).

    Parameters
    ----------
    n_workers : int, optional
        Worker processes, >= 1.

    Returns
    -------
    distributed.Client

    Raises
    ------
    ValueError
        ``n_workers`` < 1.
    MissingMainGuard
        Called from the top level of an unguarded script.

    Examples
    --------
    >>> from orbits.ensemble import local_cluster
    >>> try:
    ...     local_cluster(n_workers=0)
    ... except ValueError as exc:
    ...     print(exc)
    n_workers must be >= 1, got 0
    >>> client = local_cluster(n_workers=2)     # doctest: +SKIP
    >>> client.close(); client.cluster.close()  # doctest: +SKIP
    """
    import dask
    from distributed import Client, LocalCluster

    n = os.cpu_count() if n_workers is None else int(n_workers)
    if n < 1:
        raise ValueError(f"n_workers must be >= 1, got {n_workers}")
    if _importing_main_in_a_child():
        # a worker importing an unguarded script: stop here with the reason, rather
        # than have this worker try to start a cluster of its own
        script, line = _top_level_call(sys.modules.get("__mp_main__")) or (None, None)
        raise MissingMainGuard(f"a new worker process, importing the main script again, "
                               f"reached {_where(script, line)}, which starts another "
                               f"cluster; {_GUARD_ADVICE}", script=script, line=line)
    # no dashboard; the scheduler's small HTTP endpoint (health, metrics) takes a
    # free loopback port rather than 8787, so that two sweeps at once do not clash
    try:
        with dask.config.set(WORKER_DASK_CONFIG):
            cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                   host="127.0.0.1", dashboard_address=None,
                                   scheduler_kwargs={"dashboard": False,
                                                     "dashboard_address": "127.0.0.1:0"},
                                   env=dict(WORKER_ENVIRONMENT))
    except Exception as exc:
        # Dask says only "Nanny failed to start."; name the usual cause when it is
        # this one, and leave every other failure as it was
        where = _unguarded_main_call(
            dask.config.get("distributed.worker.multiprocessing-method", "spawn"))
        if where is None:
            raise
        script, line = where
        raise MissingMainGuard(f"the workers of the local cluster could not start (Dask: "
                               f"{exc}) because {_where(script, line)} starts the cluster "
                               f"from the top level of the script, outside "
                               f"`if __name__ == \"__main__\":`; {_GUARD_ADVICE}",
                               script=script, line=line) from None
    return Client(cluster)


@contextlib.contextmanager
def _without_warnings(logger):
    """Leave out the records below ERROR of ``logger`` (a name) inside a ``with``."""
    log = logging.getLogger(logger)

    def keep(record):
        return record.levelno >= logging.ERROR
    log.addFilter(keep)
    try:
        yield
    finally:
        log.removeFilter(keep)

