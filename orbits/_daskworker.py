"""The set-up of each worker process of :func:`orbits.ensemble.local_cluster`.

Dask runs :func:`dask_setup` as a preload (``distributed.worker.preload`` in
:data:`orbits.ensemble.WORKER_DASK_CONFIG`) when a worker starts.  Ctrl-C in a
terminal sends SIGINT to every process of the foreground group, the workers
too; each one stopping on its own would print about 60 lines of asyncio and
Dask tracebacks.  A worker ignores SIGINT instead: the process that started the
cluster is interrupted, and closes it.  Closing it cancels the runs in
progress, which the worker's state machine would report as a warning each; a
run that the sweep does again is no news, so those reports are left out.
"""

import logging
import multiprocessing
import signal
import threading

__all__ = ["dask_setup"]


def _not_a_cancelled_run(record):
    # "Async instruction for <Task cancelled name="execute(...)" ...> ended
    # with CancelledError": what closing the cluster under a running task logs
    return "ended with CancelledError" not in record.getMessage()


def dask_setup(worker):
    """Make this worker process ignore SIGINT, and leave out the reports of
    runs cancelled by the cluster's closing.

    Parameters
    ----------
    worker : distributed.Worker
    """
    if (multiprocessing.parent_process() is not None
            and threading.current_thread() is threading.main_thread()):
        # only in a worker process of its own: a worker started in the
        # process of the sweep must leave that process's Ctrl-C alone
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    logging.getLogger("distributed.worker.state_machine").addFilter(_not_a_cancelled_run)
