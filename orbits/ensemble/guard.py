"""The ``__main__``-guard detector: whether a local cluster is being started from
the top level of a script that each worker process imports again.

Python starts a local cluster's workers by importing the main script afresh in
each of them (every start method but ``fork``).  A script that starts the sweep
from its top level, outside ``if __name__ == "__main__":``, has each worker
start another cluster.  :func:`orbits.ensemble.local_cluster` asks these
functions, before and after Dask tries, so that it can stop with
:class:`~orbits.ensemble.MissingMainGuard` and the line to move under the guard.
"""

import ast
import linecache
import multiprocessing
import sys

__all__ = []

_GUARD_ADVICE = ('each worker process of a local cluster imports the main script again and '
                'runs its top level: put the code that runs the sweep under '
                '`if __name__ == "__main__":` (as in the README\'s ensemble example), '
                'or run the sweep in this process with client="serial"')


def _importing_main_in_a_child():
    """Whether this is a new process of ``multiprocessing`` still importing the
    main script (the state in which multiprocessing itself refuses to start
    processes, "before the current process has finished its bootstrapping
    phase")."""
    return bool(getattr(multiprocessing.current_process(), "_inheriting", False))


def _unguarded_main_call(start_method):
    """``(script, line)`` when this call comes from the top level of the main
    script, outside any ``if`` that tests ``__name__``, and the workers re-import
    that script (``start_method``, Dask's, is not ``fork``); ``None`` otherwise
    (a notebook, ``python -c``, a call under the guard or from a function called
    under it)."""
    if start_method == "fork":
        return None
    main = sys.modules.get("__main__")
    if getattr(main, "__file__", None) is None and getattr(main, "__spec__", None) is None:
        return None   # nothing that a worker would import
    where = _top_level_call(main)
    if where is None:
        return None
    script, line = where
    try:
        tree = ast.parse("".join(linecache.getlines(script)))
    except (SyntaxError, ValueError):
        return None
    if not tree.body:
        return None   # the source is not at hand
    for node in ast.walk(tree):
        if (isinstance(node, ast.If) and node.lineno <= line <= node.end_lineno
                and any(isinstance(n, ast.Name) and n.id == "__name__"
                        for n in ast.walk(node.test))):
            return None
    return script, line


def _top_level_call(module):
    """``(file, line)`` of the statement of ``module``'s top level that is running
    now and led to this call; ``None`` when none is running."""
    if module is None:
        return None
    frame = sys._getframe(1)
    while frame is not None and not (frame.f_globals is vars(module)
                                     and frame.f_code.co_name == "<module>"):
        frame = frame.f_back
    return None if frame is None else (frame.f_code.co_filename, frame.f_lineno)


def _where(script, line):
    """``script`` and ``line`` in words, for a message."""
    return "the main script" if script is None else f"line {line} of {script}"
