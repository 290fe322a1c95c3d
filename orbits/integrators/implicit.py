"""Implicit one-stage methods of fixed step: implicit Euler and the implicit midpoint rule.

Both are the one-leg theta-method ``y1 = y0 + h f(t0 + theta h, y0 + theta (y1 - y0))``
over one compiled Newton loop (:mod:`orbits._kernels.implicit`); a method is
its ``theta``.  They are for stiff problems, where every explicit method's step
is bounded by the fastest time scale: implicit Euler is L-stable and damps
what it cannot resolve, the implicit midpoint rule is A-stable, symplectic
and symmetric and keeps every quadratic invariant (a linear oscillator's
energy, angular momentum) to round-off.  A step costs a few force and one or
more Jacobian evaluations and LU factorisations of a (3N, 3N) matrix, so
O(N^3) work: they are meant for a few bodies, or for a user's force through
:func:`orbits.integrate`.
"""

import numpy as np

from .._kernels.status import Status
from .._kernels import implicit, records, stepping
from .._kernels.stopping import stop_record
from .base import Integrator

__all__ = ["ImplicitOneLeg", "ImplicitEuler", "ImplicitMidpoint"]


class ImplicitOneLeg(Integrator):
    """An implicit one-leg theta-method, solved by Newton's method.

    Subclasses set ``theta``.  The Jacobian of the force is the analytic one
    for gravity, the user's (``orbits.integrate(..., jacobian=)``) or central
    differences; see :mod:`orbits._kernels.implicit` for the iteration and its
    convergence test.  If Newton's method does not converge within
    ``NEWTON_MAX_ITER`` iterations the run ends with
    :class:`~orbits.errors.ConvergenceFailure` at the last good step.
    """

    #: outputs that do not fall a whole number of steps apart are recorded in the
    #: loop too (``every = -1``: the steps in ``mon_t``)
    records_step_marks = True

    theta = None
    stop_conditions = True
    reads_jacobians = True
    terms_as_data = True
    # counted as in the loop's usual case: two Newton iterations of one force each
    forces_per_step = 2

    def workspace(self, n):
        m = 3 * n
        return {"w": np.zeros((n, 3)), "dw": np.zeros((n, 3)), "xs": np.zeros((n, 3)),
                "vs": np.zeros((n, 3)), "acc": np.zeros((n, 3)),
                "cache": np.zeros(1, dtype=np.int64),
                "jx": np.zeros((m, m)), "jv": np.zeros((m, m)), "lu": np.zeros((m, m)),
                "piv": np.zeros(m, dtype=np.int64),
                "newton_iterations": np.zeros(1, dtype=np.int64)}

    def advance(self, ws, x, v, t, dt, nsteps, force, fargs, mon, step0, mon_t, mon_out,
                velocity_dependent=False, check_every=1, stop=None):
        velocity_dependent = bool(velocity_dependent or force.velocity_dependent)
        loop = implicit.implicit_loop(force, velocity_dependent)
        fargs = stepping.work_bound(force, fargs, ws)
        sargs, check = stop_record(stop)
        status, done, n_mon = loop(x, v, t, dt, nsteps, float(self.theta),
                                   records.work(implicit.Work, ws), fargs,
                                   bool(velocity_dependent),
                                   records.outputs(mon, step0, mon_t, mon_out),
                                   records.checks(check_every, sargs), check)
        return Status(status), done, n_mon

    def invalidate(self, ws):
        ws["cache"][0] = 0


class ImplicitEuler(ImplicitOneLeg):
    """Implicit (backward) Euler, first order, L-stable.

    Notes
    -----
    With ``W = v1 - v0`` the velocity increment,

    ``v1 = v0 + h a(x1, v1, t0 + h)``,  ``x1 = x0 + h v1``,

    solved by Newton's method for ``W`` (3N unknowns; ``x1`` follows from
    ``v1``) with the Jacobian ``I - h^2 da/dx - h da/dv``.  Its stability
    function ``1 / (1 - z)`` tends to zero for stiff components, so a spring
    of any stiffness is damped rather than amplified; an orbit loses energy at
    a rate proportional to ``h``.

    References
    ----------
    Hairer & Wanner (1996), *Solving Ordinary Differential Equations II*,
    2nd ed., sections IV.3 (stability function, L-stability) and IV.8
    (Newton's method for implicit methods).

    Examples
    --------
    >>> import numba
    >>> @numba.njit
    ... def stiff(x, v, t):
    ...     return -1.0e4 * x
    >>> tr = orbits.integrate(stiff, 1.0, 0.0, dt=0.1, steps=100, method="implicit-euler")
    >>> bool(abs(tr.x[-1]) < 1e-50)
    True
    """

    name = "implicit-euler"
    order = 1
    summary = "implicit (backward) Euler, L-stable; Newton with analytic/user/FD Jacobian"
    theta = 1.0


class ImplicitMidpoint(ImplicitOneLeg):
    """The implicit midpoint rule, second order, symplectic and symmetric.

    Notes
    -----
    With ``W = v1 - v0``,

    ``v1 = v0 + h a(x_m, v_m, t0 + h/2)``,  ``x1 = x0 + h v_m``,
    ``x_m = (x0 + x1)/2``,  ``v_m = (v0 + v1)/2``,

    solved by Newton's method for ``W`` with the Jacobian
    ``I - (h^2/4) da/dx - (h/2) da/dv``.  It is the one-stage Gauss
    collocation method: symplectic, symmetric (time-reversible), A-stable,
    and it conserves every quadratic first integral exactly, such as the
    angular momentum of an N-body system or the energy of a linear spring,
    whatever the step (up to the Newton tolerance and round-off).

    References
    ----------
    Hairer, Lubich & Wanner (2006), *Geometric Numerical Integration*, 2nd
    ed., sections I.1.2 and II.1 (the method), IV.2 (quadratic invariants),
    VI.3 (symplecticity) and VIII.5 (solving the implicit equations); Hairer
    & Wanner (1996), *Solving ODEs II*, section IV.8.

    Examples
    --------
    >>> import numba, numpy as np, orbits
    >>> @numba.njit
    ... def stiff(x, v, t):
    ...     return -1.0e4 * x
    >>> tr = orbits.integrate(stiff, 1.0, 0.0, dt=0.1, steps=100, method="implicit-midpoint")
    >>> E = 0.5 * tr.v ** 2 + 0.5e4 * tr.x ** 2
    >>> bool(np.max(np.abs(E / E[0] - 1)) < 1e-12)
    True
    """

    name = "implicit-midpoint"
    order = 2
    symplectic = True
    time_symmetric = True
    summary = "implicit midpoint rule: symplectic, symmetric, A-stable; Newton iteration"
    theta = 0.5
