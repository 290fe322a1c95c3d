"""Integrating a user's own force law: :func:`integrate`.

The same integrators and compiled loops as :class:`orbits.Simulation`, for
any acceleration ``accel(x, v, t)`` on plain arrays.  A numba-jitted
``accel`` runs inside the compiled loop; a plain Python function runs the same
loop as Python (slower, but the same numbers).
"""

import math
import signal as _signal
import time as _time

import numba
import numpy as np

from . import integrators as _integrators
from ._driver import Signals, advance_checked, restored_on_error
from ._kernels import implicit as _implicit
from ._kernels import stepping as _stepping
from ._kernels.status import Status
from .errors import (ConvergenceFailure, ForceTermError, IntegratorOptionError,
                     NonFiniteState, RunInterrupted, StepSizeUnderflow)

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

    Examples
    --------
    >>> import numpy as np
    >>> import orbits
    >>> tr = orbits.integrate(lambda x, v, t: -x, 1.0, 0.0, dt=np.pi / 100, steps=200,
    ...                       method="rk4", every=100)
    >>> tr
    <Trajectory: 3 samples, rk4, completed>
    >>> tr.t.round(6).tolist(), tr.x.round(6).tolist(), tr.steps
    ([0.0, 3.141593, 6.283185], [1.0, -1.0, 1.0], 200)
    """

    def __init__(self, t, x, v, steps, method, wall_time, status="completed"):
        self.t, self.x, self.v = t, x, v
        self.steps, self.method, self.wall_time, self.status = steps, method, wall_time, status

    def __repr__(self):
        return f"<Trajectory: {len(self.t)} samples, {self.method}, {self.status}>"


def _is_jitted(func):
    return isinstance(func, numba.core.registry.CPUDispatcher)


def integrate(accel, x0, v0, *, dt=None, steps=None, method="verlet", t0=0.0, every=1,
              velocity_dependent=False, jacobian=None, until=None, outputs=101):
    """Integrate ``x'' = accel(x, v, t)`` with any registered method.

    Fixed-step methods take ``dt`` and ``steps``; adaptive ones (``dop853``,
    ``ias15``, ``radau``, ``lsoda``, ...; configure them with
    ``orbits.integrators.get(name, rtol=...)``) take ``until`` and ``outputs``,
    and ``dt`` as their first step if given.

    Parameters
    ----------
    accel : callable
        ``accel(x, v, t)`` returning an array of the shape of ``x``.  A
        ``numba.njit`` function runs at compiled speed; a Python function works too.
    x0, v0 : float or array_like
        Initial position and velocity (any shape, the same for both; a scalar
        is passed to ``accel`` as an array of shape (1,)).
    dt : float
        Step (may be negative to integrate backwards); for adaptive methods
        the first step to try (optional).
    steps : int
        Number of steps (fixed-step methods).
    method : str
        Registry name, e.g. ``"euler"``, ``"symplectic-euler"``, ``"verlet"``, ``"rk4"``.
    t0 : float
    every : int
        Record every this many steps (the initial state is always recorded).
    velocity_dependent : bool
        Say True if ``accel`` depends on ``v`` (drag, ...): splitting methods
        then re-evaluate it after every kick instead of reusing it.
    jacobian : callable, optional
        For the implicit methods (``"implicit-euler"``, ``"implicit-midpoint"``;
        the others ignore it): ``jacobian(x, v, t)`` returning the pair
        ``(da/dx, da/dv)``, each a 2-D array of shape ``(x0.size, x0.size)``
        over the flattened (C-order) state: entry ``[p, q]`` is the derivative
        of component ``p`` of ``accel(x, v, t).ravel()`` with respect to
        component ``q`` of ``x.ravel()`` (or ``v.ravel()``).  Return zeros for
        ``da/dv`` if ``accel`` does not depend on ``v``.  A ``numba.njit``
        function runs compiled, like ``accel``.  Without it the implicit
        methods use central differences of ``accel`` (relative step
        ``eps**(1/3)``, see :mod:`orbits._kernels.implicit`), which cost
        ``2 x0.size`` evaluations of ``accel`` (twice that with
        ``velocity_dependent``) per Jacobian.

    until : float
        End time (adaptive methods).
    outputs : int
        Number of evenly spaced times, ``t0`` and ``until`` included, at which
        an adaptive method records the state (hit exactly).

    Returns
    -------
    Trajectory
        ``t`` of shape (n,), ``x`` and ``v`` of shape (n,) + shape of ``x0``.

    Raises
    ------
    NonFiniteState
        The state became NaN or infinite; ``.result`` is the trajectory up to
        the last good step, which it ends with.
    ConvergenceFailure
        An implicit method's Newton iteration did not converge in a step;
        ``.result`` as for ``NonFiniteState``.

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
    x0 = np.asarray(x0, dtype=np.float64)
    v0 = np.asarray(v0, dtype=np.float64)
    if x0.shape != v0.shape:
        raise ValueError(f"x0 and v0 must have the same shape, got {x0.shape} and {v0.shape}")
    for name, arr in (("x0", x0), ("v0", v0)):
        if not np.all(np.isfinite(arr)):
            raise ValueError(f"{name} must be finite, got {arr}")
    if integ.adaptive:
        if until is None or not (math.isfinite(float(until)) and float(until) > t0):
            raise ValueError(f"{integ.name!r} is adaptive: give until (> t0 = {t0}), and "
                             f"optionally outputs and a first step dt; got until={until}")
        if int(outputs) != outputs or outputs < 2:
            raise ValueError(f"outputs must be a whole number >= 2, got {outputs}")
        if dt is not None and not (math.isfinite(float(dt)) and float(dt) > 0):
            raise IntegratorOptionError(f"dt (the first step) must be positive, got {dt}")
    else:
        if dt is None or steps is None:
            raise IntegratorOptionError(f"{integ.name!r} takes fixed steps: give dt and steps")
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

    _check_accel(accel, x0, v0, t0, shape)
    force = _stepping.user_force(accel, jit=_is_jitted(accel))
    if jacobian is not None:
        _check_jacobian(jacobian, x0, v0, t0, size)
        force = force._replace(jacobian=_implicit.user_jacobian(jacobian, _is_jitted(jacobian)),
                               key=f"{force.key}_jac{id(jacobian)}")
    fargs = (size, tuple(int(s) for s in shape))
    if integ.adaptive:
        ws = integ.workspace(rows, 0.0 if dt is None else float(dt))
        t0, until = float(t0), float(until)
        # outputs at evenly spaced times, the last exactly at until
        marks = [until if k == outputs - 1 else t0 + k * (until - t0) / (outputs - 1)
                 for k in range(1, int(outputs))]
    else:
        ws = integ.workspace(rows)
        marks = [min(k * every, steps) for k in range(1, -(-steps // every) + 1)]
    return _drive(integ, force, fargs, x, v, ws, shape, scalar, float(t0),
                  None if integ.adaptive else dt, marks, velocity_dependent)


#: what a failed status raises in :func:`integrate`
_FAILURES = {
    Status.NO_CONVERGENCE: (ConvergenceFailure, "no convergence",
                            "the Newton iteration of {name!r} did not converge in step "
                            "{next} (from t = {t:.10g}); try a smaller dt"),
    Status.STEP_UNDERFLOW: (StepSizeUnderflow, "step-size underflow",
                            "the step size of {name!r} collapsed at t = {t:.10g} (step "
                            "{steps})"),
    Status.NON_FINITE: (NonFiniteState, "non-finite state",
                        "the state became non-finite in step {next} (from t = {t:.10g})"),
}


def _drive(integ, force, fargs, x, v, ws, shape, scalar, t0, dt, marks, velocity_dependent):
    """The one driver of :func:`integrate`: outputs at ``marks`` (step counts for a
    fixed step ``dt``, times for an adaptive method), the compiled loop entered
    once per output, SIGINT and SIGTERM acted on between outputs."""
    size = int(np.prod(shape))
    rows = x.shape[0]
    mon = (0, 0, np.zeros(rows), 0.0, 0, 0.0)
    no_t, no_rows = np.empty(0), np.zeros((0, 10))
    ts, xs, vs = [t0], [x.ravel()[:size].copy()], [v.ravel()[:size].copy()]
    wall0 = _time.perf_counter()
    t, steps = t0, 0

    def trajectory(status):
        out_shape = (len(ts),) + (() if scalar else shape)
        return Trajectory(np.array(ts), np.array(xs).reshape(out_shape),
                          np.array(vs).reshape(out_shape), steps, integ.name,
                          _time.perf_counter() - wall0, status)

    def keep():
        ts.append(t)
        xs.append(x.ravel()[:size].copy())
        vs.append(v.ravel()[:size].copy())

    with Signals() as signals:
        for mark in marks:
            status = Status.OK
            try:
                if dt is not None:
                    status, good, _, ws = advance_checked(
                        integ, ws, x, v, t, dt, mark - steps, force, fargs, mon, steps,
                        no_t, no_rows, velocity_dependent)
                    steps += good
                    t = t0 + steps * dt
                else:
                    while t < mark and status == Status.OK:
                        with restored_on_error(x, v, ws):
                            status, t, acc, _, _, _ = integ.advance_to(
                                ws, x, v, t, mark, force, fargs, mon, steps, no_t, no_rows,
                                None, 1 << 40)
                        steps += int(acc)
            except numba.core.errors.TypingError as exc:
                raise TypeError("accel(x, v, t) could not be compiled in the stepping loop; "
                                "it must take arrays x, v (shape of x0) and a float t and "
                                "return an array of the shape of x0. numba said:\n"
                                f"{exc}") from None
            except ValueError as exc:
                _resize_error(exc, shape, t)
            keep()
            if status != Status.OK:
                kind, label, text = _FAILURES.get(Status(status),
                                                  _FAILURES[Status.NON_FINITE])
                raise kind(text.format(name=integ.name, next=steps + 1, t=t, steps=steps)
                           + f"; the trajectory up to the last good step {steps} is kept on "
                           f".result", time=t, step=steps, result=trajectory(label))
            if signals.caught is not None:
                name = _signal.Signals(signals.caught).name
                raise RunInterrupted(f"{name} at t = {t:.10g} (step {steps}); the trajectory "
                                     f"up to there is kept on .result", signal=signals.caught,
                                     time=t, step=steps, result=trajectory(f"stopped by {name}"))
    return trajectory("completed")


def _describe(value):
    if value is None:
        return "None"
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        return f"a {type(value).__name__}, not numbers"
    return "a scalar" if arr.ndim == 0 else f"an array of shape {arr.shape}"


def _check_accel(accel, x0, v0, t0, shape):
    """One call up front: a return of the wrong shape is a named error, not garbage."""
    x = x0.reshape(shape).copy()
    v = v0.reshape(shape).copy()
    try:
        a = accel(x, v, float(t0))
    except numba.core.errors.TypingError as exc:
        raise TypeError("accel(x, v, t) could not be compiled; it must take arrays x, v "
                        f"(shape {shape}) and a float t. numba said:\n{exc}") from None
    try:
        arr = np.asarray(a, dtype=np.float64)
    except (TypeError, ValueError):
        arr = None
    ok = arr is not None and (arr.shape == tuple(shape)
                              or (arr.ndim == 0 and int(np.prod(shape)) == 1))
    if not ok:
        raise ForceTermError(f"accel(x, v, t) returned {_describe(a)} at t0 = {t0:g}; "
                             f"expected an array of shape {tuple(shape)}, the shape of x0",
                             term="accel", field="return value")


def _resize_error(exc, shape, t):
    if str(exc) != _stepping.USER_FORCE_SIZE and not isinstance(exc, ForceTermError):
        raise exc
    raise ForceTermError(f"accel(x, v, t) returned a different number of values during the "
                         f"run (after t = {t:.10g}); expected an array of shape "
                         f"{tuple(shape)}, the shape of x0, every call",
                         term="accel", field="return value") from None


def _check_jacobian(jacobian, x0, v0, t0, size):
    # one call up front, so that a wrong shape is a clear error and not an
    # index error (or silent garbage) inside the compiled loop
    shape = x0.shape if x0.ndim else (1,)
    try:
        out = jacobian(x0.reshape(shape).copy(), v0.reshape(shape).copy(), float(t0))
        dadx, dadv = (np.asarray(a, dtype=np.float64) for a in out)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"jacobian(x, v, t) must return a pair (da/dx, da/dv) of "
                        f"({size}, {size}) arrays: {exc}") from None
    for name, arr in (("da/dx", dadx), ("da/dv", dadv)):
        if arr.shape != (size, size):
            raise ValueError(f"jacobian(x, v, t) returned {name} of shape {arr.shape}; "
                             f"expected ({size}, {size}), over the flattened state")
