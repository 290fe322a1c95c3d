"""Integrating a user's own force law: :func:`integrate`.

The same integrators and compiled loops as :class:`orbits.Simulation`, for
any acceleration ``accel(x, v, t)`` on plain arrays.  A numba-jitted
``accel`` runs inside the compiled loop; a plain Python function runs the same
loop as Python (slower, but the same numbers).
"""

import math
import time as _time
from typing import NamedTuple

import numba
import numpy as np

from . import _user_functions
from . import integrators as _integrators
from ._driver import FIRST_CHUNK, Driven
from ._kernels import jacobians as _jacobians
from ._kernels import stepping as _stepping
from ._kernels.status import Status
from .errors import (ConvergenceFailure, ForceTermError, IntegratorOptionError,
                     NonFiniteState, StepSizeUnderflow)
from .records import RunPlan

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
        function with a ``numba.njit`` ``accel`` runs compiled through a
        pointer, as ``accel`` does: one compiled loop, cached on disk,
        serves every such pair, and each function's pointer is cached for
        its code.  Without it the implicit
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
    ForceTermError
        A compiled ``accel`` or ``jacobian`` returned an array of another
        shape during the run.

    Examples
    --------
    >>> import numba
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

    # the compiled functions checked through the run's own pointers (loaded
    # from the cache in a new process); the functions' own calls name a cause
    pointed = _is_jitted(accel) and (jacobian is None or _is_jitted(jacobian))
    if not (pointed and _user_functions.pointers_run(accel, jacobian, x, v, t0, shape)):
        _check_accel(accel, x0, v0, t0, shape)
        if jacobian is not None:
            _check_jacobian(jacobian, x0, v0, t0, size)
    force = _stepping.user_force(accel, jit=_is_jitted(accel))
    fargs = (_user_functions.force_args(accel, shape) if _is_jitted(accel)
             else (size, tuple(int(s) for s in shape)))
    if jacobian is not None:
        if _is_jitted(accel) and _is_jitted(jacobian):
            # through its pointer, cached for its code: one loop for every Jacobian
            force = force._replace(jacobian=_jacobians.user_jacobian_pointer())
            fargs = fargs + (_user_functions.jacobian_pointer(jacobian, len(shape)),)
        else:
            force = force._replace(
                jacobian=_jacobians.user_jacobian(jacobian, _is_jitted(jacobian)),
                key=f"{force.key}_jac{id(jacobian)}")
    if velocity_dependent:
        force = force._replace(velocity_dependent=True)
    if integ.adaptive:
        ws = integ.workspace(rows, 0.0 if dt is None else float(dt))
        t0, until = float(t0), float(until)
        # outputs at evenly spaced times, the last exactly at until
        plan = RunPlan(until, int(outputs), 0.0, 0, False, 0, t0)
    else:
        ws = integ.workspace(rows)
        plan = _EveryPlan(steps, every)
    return _drive(integ, force, fargs, x, v, ws, shape, scalar, float(t0),
                  None if integ.adaptive else dt, plan)


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


class _EveryPlan(NamedTuple):
    """The outputs of a fixed-step :func:`integrate`: every ``every`` steps and
    after the last (the plan interface of :class:`orbits._driver.Driven`)."""

    steps: int
    every: int
    start_step: int = 0
    has_partial: bool = False

    @property
    def n_full(self):
        return self.steps

    @property
    def total_steps(self):
        return self.steps

    def marks(self, first=0):
        for k in range(first + 1, -(-self.steps // self.every)):
            yield k * self.every


class _Samples:
    """The recorder of :func:`integrate`: the state at every output, in the user's shape."""

    end_status = 0

    def __init__(self, run):
        self.ts, self.xs, self.vs = [], [], []
        self.output(run)

    def output(self, run, final=False):
        self.ts.append(run._now())
        self.xs.append(run._x.ravel()[:run.size].copy())
        self.vs.append(run._v.ravel()[:run.size].copy())

    def stopped(self, run):
        self.output(run, final=True)

    def monitor_rows(self, t, rows):
        """No monitors for a user's system."""

    def checkpoint(self, finished=False):
        """Nothing to save for a run kept in memory."""

    def close(self):
        """Nothing to release."""

    def result(self, run, wall, status="completed"):
        out_shape = (len(self.ts),) + (() if run.scalar else run.shape)
        return Trajectory(np.array(self.ts), np.array(self.xs).reshape(out_shape),
                          np.array(self.vs).reshape(out_shape), run.steps, run.integrator.name,
                          wall, status)


class _UserRun(Driven):
    """A user's system as the run driver (:class:`orbits._driver.Driven`) sees it."""

    monitor_every = 0
    _stop = None

    def __init__(self, integ, force, fargs, x, v, ws, shape, scalar, t0, dt):
        self.integrator, self._force, self._fargs = integ, force, fargs
        self._x, self._v, self._ws = x, v, ws
        self._rows_x, self._rows_v = x, v
        self.shape, self.scalar, self.size = shape, scalar, int(np.prod(shape))
        self._t_base, self._steps_since_base = float(t0), 0
        self._dt = 0.0 if dt is None else float(dt)
        self.steps = self.steps_rejected = self.force_evaluations = 0
        self._chunk = FIRST_CHUNK
        self._stop_info = np.full(2, -1, dtype=np.int64)
        self._no_monitors = (0, 0, np.zeros(x.shape[0]), 0.0, 0, 0.0)

    def _now(self):
        return self._t_base + self._steps_since_base * self._dt

    @property
    def time(self):
        return self._now()

    def _mon(self, every):
        return self._no_monitors

    def _fail(self, status, rec, wall0):
        kind, label, text = _FAILURES.get(Status(status), _FAILURES[Status.NON_FINITE])
        rec.output(self, final=True)
        t = self._now()
        flag = self._fargs[3][0] if len(self._fargs) > 3 else 0
        if flag == _user_functions.FORCE_SIZE:
            _resize_error(ValueError(_stepping.USER_FORCE_SIZE), self.shape, t)
        if flag == _user_functions.JACOBIAN_SIZE:
            raise ForceTermError(f"jacobian(x, v, t) returned matrices of another shape "
                                 f"during the run (after t = {t:.10g}); expected two "
                                 f"({self.size}, {self.size}) arrays every call",
                                 term="jacobian", field="return value")
        if flag in (_user_functions.RAISED, _user_functions.JACOBIAN_RAISED):
            name = "accel" if flag == _user_functions.RAISED else "jacobian"
            raise ForceTermError(f"{name}(x, v, t) raised an exception during the run, "
                                 f"in the step after t = {t:.10g} (step {self.steps}, "
                                 f"the last good one); a compiled function's exception "
                                 f"does not leave the loop: call it from Python on that "
                                 f"state to see it", term=name, field="exception")
        raise kind(text.format(name=self.integrator.name, next=self.steps + 1, t=t,
                               steps=self.steps)
                   + f"; the trajectory up to the last good step {self.steps} is kept on "
                   f".result", time=t, step=self.steps,
                   result=rec.result(self, _time.perf_counter() - wall0, label))


def _drive(integ, force, fargs, x, v, ws, shape, scalar, t0, dt, plan):
    """:func:`integrate` through the package's one run driver: the compiled loop
    entered in chunks, SIGINT and SIGTERM acted on between them."""
    run = _UserRun(integ, force, fargs, x, v, ws, shape, scalar, t0, dt)
    if dt is not None and plan.steps == 0:
        return _Samples(run).result(run, 0.0)
    try:
        return run.execute(plan, _Samples(run), progress=False)
    except numba.core.errors.TypingError as exc:
        raise TypeError("accel(x, v, t) could not be compiled in the stepping loop; "
                        "it must take arrays x, v (shape of x0) and a float t and "
                        "return an array of the shape of x0. numba said:\n"
                        f"{exc}") from None
    except (ValueError, ForceTermError) as exc:
        _resize_error(exc, shape, run._now())


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
    if str(exc) != _stepping.USER_FORCE_SIZE and not (
            isinstance(exc, ForceTermError) and exc.field == "func"):
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
