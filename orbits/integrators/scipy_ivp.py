"""Reference solvers from scipy: ``radau`` and ``lsoda`` through ``solve_ivp``.

These are scipy's implementations (Radau IIA of order 5, Hairer & Wanner
1996; LSODA, Petzold 1983), wrapped in the integrator contract so that a stiff
user problem or a check of our own methods can use them through the same API.
They run in Python and are slow; they are references, not workhorses.

Each ``advance_to`` call starts scipy's solver afresh from the current state
(with the last step size as its first step) and steps it to the next output,
so a run resumed from a file continues exactly as an uninterrupted one.  A
step that no longer moves the time (a collision ahead) ends the run with
:class:`~orbits.errors.StepSizeUnderflow`.  ``scipy`` must be installed.

With non-conservative force terms the ODE's state gets one more component,
the work ``W`` with ``W' = -P`` (see :mod:`orbits._kernels.stepping`), which
scipy's solver integrates (and controls the error of) with the rest, so that
``E + W`` is conserved to the solver's tolerance.
"""

import numpy as np

from .._kernels import stepping as _stepping
from .._kernels._jit import compiled_for
from .._kernels.status import Status
from ..errors import IntegratorOptionError
from .base import ToleranceControlled

__all__ = ["ScipyIntegrator", "Radau", "LSODA"]

_EPS = float(np.finfo(float).eps)


class ScipyIntegrator(ToleranceControlled):
    """A ``scipy.integrate.solve_ivp`` method behind the integrator contract.

    In-loop monitors (``monitor_every``) and stopping conditions are not
    available with these; outputs and their monitors are.  ``steps`` counts
    scipy's accepted steps; it does not report rejected ones.
    """

    method = None
    stop_conditions = False
    chaos_indicators = False
    compiled = False

    def workspace(self, n, initial_step=0.0):
        return {"dt": np.array([float(initial_step)]), "info": np.full(2, -1, dtype=np.int64)}

    def advance_to(self, ws, x, v, t, t_end, force, fargs, mon, step0, mon_t, mon_out, stop,
                   max_steps):
        try:
            from scipy import integrate
        except ImportError:  # pragma: no cover - scipy is a test dependency
            raise IntegratorOptionError(f"integrator {self.name!r} needs scipy "
                                        "(pip install scipy)") from None
        if mon[0]:
            raise IntegratorOptionError(f"integrator {self.name!r} records no in-loop "
                                        "monitors; drop monitor_every")
        n = x.shape[0]
        acc = np.zeros((n, 3))      # a user state pads its last row: those entries stay 0
        work = force.dissipative
        if work:
            fargs = _stepping.work_bound(force, fargs, ws)
        # the force (and the work rate) as compiled for these arguments' types,
        # typed once here rather than at each of scipy's evaluations (a table
        # with a user's term took milliseconds an evaluation to type); the
        # states handed on below are C-contiguous float64 (n, 3) as these are
        xc = np.ascontiguousarray(x, dtype=np.float64)
        vc = np.ascontiguousarray(v, dtype=np.float64)
        accel = compiled_for(force.kernel, xc, vc, float(t), fargs, acc)
        if work:
            rate = compiled_for(_stepping.work_kernels(force)["work_rate"], xc, vc, float(t),
                                fargs)

        def rhs(time, y):
            xs = np.ascontiguousarray(y[:3 * n].reshape(n, 3), dtype=np.float64)
            vs = np.ascontiguousarray(y[3 * n:6 * n].reshape(n, 3), dtype=np.float64)
            time = float(time)
            accel(xs, vs, time, fargs, acc)
            parts = [y[3 * n:6 * n], acc.ravel()]
            if work:
                parts.append([-rate(xs, vs, time, fargs)])
            return np.concatenate(parts)

        y0 = np.concatenate([x.ravel(), v.ravel()] + ([[0.0]] if work else []))
        first = float(ws["dt"][0])
        kw = {"first_step": min(first, abs(t_end - t))} if first > 0 else {}
        solver = getattr(integrate, self.method)(rhs, t, y0, t_end, rtol=self.config["rtol"],
                                                 atol=self.config["atol"], **kw)
        steps = 0
        last_step = 0.0
        floor = 4.0 * _EPS * max(abs(t), abs(t_end))
        while solver.status == "running":
            solver.step()
            if solver.status == "failed" or not np.all(np.isfinite(solver.y)):
                return Status.STEP_UNDERFLOW, t, 0, 0, int(solver.nfev), 0
            steps += 1
            last_step = abs(solver.t - solver.t_old)
            if solver.status == "running" and last_step <= floor:
                # the steps no longer move t: a collision or a singularity ahead
                return Status.STEP_UNDERFLOW, t, 0, 0, int(solver.nfev), 0
        x[...] = solver.y[:3 * n].reshape(n, 3)
        v[...] = solver.y[3 * n:6 * n].reshape(n, 3)
        if work:
            _add_work(ws["work"], float(solver.y[-1]))
        if last_step > 0:
            ws["dt"][0] = last_step     # the size; the direction is t_end's
        return Status.OK, t_end, steps, 0, int(solver.nfev), 0


def _add_work(box, dw):
    # W += dw, compensated as the compiled loops do it (stepping._work_add)
    s = float(box[0])
    t = s + dw
    box[1] += ((s - t) + dw) if abs(s) >= abs(dw) else ((dw - t) + s)
    box[0] = t


class Radau(ScipyIntegrator):
    """Radau IIA (order 5), implicit, for stiff problems, from scipy.

    References
    ----------
    Hairer & Wanner (1996), *Solving ODEs II*, section IV.8; scipy's
    ``solve_ivp(method="Radau")``.

    Examples
    --------
    >>> orbits.integrators.get("radau", rtol=1e-10).order
    5
    """

    name = "radau"
    order = 5
    method = "Radau"
    summary = "Radau IIA via scipy.solve_ivp (reference, stiff)"


class LSODA(ScipyIntegrator):
    """LSODA (Adams/BDF with automatic stiffness switching), from scipy.

    References
    ----------
    Petzold (1983), SIAM J. Sci. Stat. Comput. 4, 136; scipy's
    ``solve_ivp(method="LSODA")``.

    Examples
    --------
    >>> orbits.integrators.get("lsoda").adaptive
    True
    """

    name = "lsoda"
    order = 12
    method = "LSODA"
    summary = "LSODA via scipy.solve_ivp (reference, switches to BDF when stiff)"
