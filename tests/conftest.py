"""Shared fixtures."""

import signal
import threading

import numpy as np
import pytest

# the package first, before any test module imports numba: its numba settings
# (orbits/__init__.py) apply only to a numba imported after it
import orbits  # noqa: F401, I001


@pytest.fixture(scope="session", autouse=True)
def _ctrl_c_raises_as_at_a_terminal():
    """Ctrl-C raises KeyboardInterrupt in the test processes, as in a Python
    started at a terminal, however the test run was started: a shell starts
    a background job (``cmd &`` in a script, ``nohup``) with SIGINT ignored,
    and a run leaves an ignored signal ignored, so the tests of what Ctrl-C
    does would see nothing happen.  Put back after the session."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.getsignal(signal.SIGINT)
    if previous == signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    if previous == signal.SIG_IGN:
        signal.signal(signal.SIGINT, previous)


@pytest.fixture(scope="session")
def rng():
    return np.random.default_rng(20261121)


@pytest.fixture(scope="session", autouse=True)
def _kernels_compile_once_per_type():
    """After the session's tests: no kernel of the package was compiled twice
    for argument types that differ only in constants.  numba types a
    constant argument (``0``, ``True``) as a literal and compiles the callee
    again for each constant it meets, as long as the first compilation; the
    kernels pass constants to compiled functions with
    ``orbits._kernels._jit.value``.  Fails at the session's end (as an error
    in the last test's teardown), naming the kernel and its signatures."""
    yield
    import gc

    from numba.core import types
    from numba.core.registry import CPUDispatcher

    twice = []
    for obj in gc.get_objects():
        if not issubclass(type(obj), CPUDispatcher):  # (not a weak proxy)
            continue
        # (a function compiled from code run with exec, as the docs' blocks
        # are, has the module None)
        if not (getattr(obj.py_func, "__module__", None) or "").startswith("orbits"):
            continue
        seen = {}
        for sig in obj.signatures:
            key = str(tuple(types.unliteral(a) for a in sig))
            if key in seen:
                twice.append(f"{obj.py_func.__qualname__}: {seen[key]} and {sig}")
            seen[key] = sig
    assert not twice, "compiled once per constant:\n" + "\n".join(twice)
