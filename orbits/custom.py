"""Integrating a user's own force law: :func:`integrate`.

The same integrators and compiled loops as :class:`orbits.Simulation`, for
any acceleration ``accel(x, v, t)`` on plain arrays.  A numba-jitted
``accel`` runs inside the compiled loop; a plain Python function runs the same
loop as Python (slower, but the same numbers).
"""

import math
import time as _time

import numba
import numpy as np

from . import integrators as _integrators
from ._driver import advance_checked
from ._kernels import stepping as _stepping
from ._kernels.status import Status
from .errors import IntegratorOptionError, NonFiniteState

__all__ = ["integrate", "Trajectory"]


class Trajectory:
    """What :func:`integrate` returns.

    Attributes
    ----------
    t : ndarray, shape (n,)
    x, v : ndarray, shape (n,) + shape of ``x0``
    steps : int
    method : str
    wall_time : float
    status : str
    """

    def __init__(self, t, x, v, steps, method, wall_time, status="completed"):
        self.t, self.x, self.v = t, x, v
        self.steps, self.method, self.wall_time, self.status = steps, method, wall_time, status

    def __repr__(self):
        return f"<Trajectory: {len(self.t)} samples, {self.method}, {self.status}>"


def _is_jitted(func):
    return isinstance(func, numba.core.registry.CPUDispatcher)


def integrate(accel, x0, v0, *, dt, steps, method="verlet", t0=0.0, every=1,
              velocity_dependent=False):
    """Integrate ``x'' = accel(x, v, t)`` with a registered fixed-step method.

    Parameters
    ----------
    accel : callable
        ``accel(x, v, t)`` returning an array of the shape of ``x``.  A
        ``numba.njit`` function runs at compiled speed; a Python function works too.
    x0, v0 : float or array_like
        Initial position and velocity (any shape, the same for both; a scalar
        is passed to ``accel`` as an array of shape (1,)).
    dt : float
        Step (may be negative to integrate backwards).
    steps : int
        Number of steps.
    method : str
        Registry name, e.g. ``"euler"``, ``"symplectic-euler"``, ``"verlet"``, ``"rk4"``.
    t0 : float
    every : int
        Record every this many steps (the initial state is always recorded).
    velocity_dependent : bool
        Say True if ``accel`` depends on ``v`` (drag, ...): splitting methods
        then re-evaluate it after every kick instead of reusing it.

    Returns
    -------
    Trajectory
        ``t`` of shape (n,), ``x`` and ``v`` of shape (n,) + shape of ``x0``.

    Raises
    ------
    NonFiniteState
        The state became NaN or infinite; ``.result`` is the trajectory up to
        the last good step, which it ends with.

    Examples
    --------
    >>> import numba, orbits
    >>> @numba.njit
    ... def spring(x, v, t):
    ...     return -100.0 * x
    >>> tr = orbits.integrate(spring, 1.0, 0.0, dt=0.01, steps=1000, method="verlet")
    >>> tr.x.shape
    (1001,)
    """
    integ = _integrators.get(method)
    if integ.adaptive:
        raise IntegratorOptionError(f"integrate() takes fixed-step methods; {integ.name!r} "
                                    "is adaptive")
    x0 = np.asarray(x0, dtype=np.float64)
    v0 = np.asarray(v0, dtype=np.float64)
    if x0.shape != v0.shape:
        raise ValueError(f"x0 and v0 must have the same shape, got {x0.shape} and {v0.shape}")
    for name, arr in (("x0", x0), ("v0", v0)):
        if not np.all(np.isfinite(arr)):
            raise ValueError(f"{name} must be finite, got {arr}")
    dt = float(dt)
    if not (math.isfinite(dt) and dt != 0.0):
        raise IntegratorOptionError(f"dt must be finite and non-zero, got {dt}")
    if int(steps) != steps or steps < 0:
        raise ValueError(f"steps must be a whole number >= 0, got {steps}")
    if int(every) != every or every < 1:
        raise ValueError(f"every must be a whole number >= 1, got {every}")
    steps, every = int(steps), int(every)
    scalar = x0.ndim == 0
    shape = (1,) if scalar else x0.shape
    size = int(np.prod(shape))
    # the loops work on (rows, 3) arrays; the user's values fill them in order
    rows = max(1, -(-size // 3))
    x = np.zeros((rows, 3))
    v = np.zeros((rows, 3))
    x.ravel()[:size] = x0.ravel()
    v.ravel()[:size] = v0.ravel()

    force = _stepping.user_force(accel, jit=_is_jitted(accel))
    fargs = (size, tuple(int(s) for s in shape))
    ws = integ.workspace(rows)
    mon = (0, 0, np.zeros(rows), 0.0, 0, 0.0)
    ts, xs, vs = [t0], [x.ravel()[:size].copy()], [v.ravel()[:size].copy()]
    wall0 = _time.perf_counter()
    done = 0

    def trajectory(status):
        out_shape = (len(ts),) + (() if scalar else shape)
        return Trajectory(np.array(ts), np.array(xs).reshape(out_shape),
                          np.array(vs).reshape(out_shape), done, integ.name,
                          _time.perf_counter() - wall0, status)

    while done < steps:
        n = min(every, steps - done)
        try:
            status, good, _, ws = advance_checked(
                integ, ws, x, v, t0 + done * dt, dt, n, force, fargs, mon, done,
                np.empty(0), np.zeros((0, 10)), velocity_dependent)
        except numba.core.errors.TypingError as exc:
            raise TypeError("accel(x, v, t) could not be compiled in the stepping loop; it "
                            "must take arrays x, v (shape of x0) and a float t and return "
                            f"an array of the shape of x0. numba said:\n{exc}") from None
        done += good
        if status != Status.OK:
            ts.append(t0 + done * dt)
            xs.append(x.ravel()[:size].copy())
            vs.append(v.ravel()[:size].copy())
            t_bad = t0 + done * dt
            raise NonFiniteState(
                f"the state became non-finite in step {done + 1} (from t = {t_bad:.10g}); "
                f"the trajectory up to the last good step {done} is kept on .result",
                time=t_bad, step=done, result=trajectory("non-finite state"))
        ts.append(t0 + done * dt)
        xs.append(x.ravel()[:size].copy())
        vs.append(v.ravel()[:size].copy())
    return trajectory("completed")
