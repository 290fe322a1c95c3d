"""Embedded Runge-Kutta pairs with adaptive steps: dopri5 and dop853."""

import numpy as np

from .._kernels import embedded as _embedded
from .._kernels import records
from . import dop853_coefficients as _dop853
from . import tableaux
from ._loops import loop_for
from .base import CompiledToleranceControlled

__all__ = ["EmbeddedRungeKutta", "Dopri5", "DOP853"]


class EmbeddedRungeKutta(CompiledToleranceControlled):
    """An embedded Runge-Kutta pair given by its table; one compiled loop serves all.

    Subclasses set ``A``, ``B``, ``C`` (the method), ``E`` (error weights over
    the stages and the first stage of the next step), optionally ``E3`` (a
    second estimator, as DOP853 has), ``order`` and ``error_estimator_order``.
    """

    A = B = C = E = E3 = None
    error_estimator_order = None

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if cls.B is not None:
            cls.forces_per_step = len(cls.B)

    def workspace(self, n, initial_step=0.0):
        s = len(self.B)
        return {"kx": np.zeros((s + 1, n, 3)), "kv": np.zeros((s + 1, n, 3)),
                "xs": np.zeros((n, 3)), "vs": np.zeros((n, 3)), "x1": np.zeros((n, 3)),
                "v1": np.zeros((n, 3)), "dt": np.array([float(initial_step)]),
                "fsal": np.zeros(1, dtype=np.int64), "info": np.full(2, -1, dtype=np.int64)}

    def _loop_call(self, ws, force):
        e3 = self.E3 if self.E3 is not None else np.zeros_like(self.E)
        loop = loop_for(_embedded.embedded_loop, force)
        method = _embedded.Method(self.A, self.B, self.C, self.E, e3,
                                  float(self.error_estimator_order), self.E3 is not None)
        return loop, (method,), records.work(_embedded.Work, ws)


class Dopri5(EmbeddedRungeKutta):
    """Dormand-Prince 5(4): fifth order, fourth-order error estimate, adaptive.

    Notes
    -----
    Seven stages, the last being the first of the next step, so six force
    evaluations a step.  The error of a step is kept below
    ``atol + rtol * |y|`` component by component (RMS norm).

    References
    ----------
    Dormand, J. R. & Prince, P. J. 1980, "A family of embedded Runge-Kutta
    formulae", J. Comput. Appl. Math. 6, 19; Hairer, Nørsett & Wanner (1993),
    *Solving ODEs I*, Table II.5.2.

    Examples
    --------
    >>> integ = orbits.integrators.get("dopri5", rtol=1e-10, atol=1e-12)
    >>> sim = orbits.Simulation(orbits.scenes.kepler(e=0.5), integrator=integ)
    >>> r = sim.run(until=10 * u.yr, outputs=11, progress=False)
    >>> bool(r.energy_error.max() < 1e-7)
    True
    """

    name = "dopri5"
    order = 5
    error_estimator_order = 4
    summary = "Dormand-Prince 5(4), adaptive (rtol, atol)"
    A, B, C, E = tableaux.DOPRI5


class DOP853(EmbeddedRungeKutta):
    """Dormand-Prince 8(5,3): eighth order with 5th- and 3rd-order estimates, adaptive.

    Notes
    -----
    Twelve stages plus the first of the next step; the error norm combines
    the two estimates as ``err5^2 / sqrt(err5^2 + 0.01 err3^2)`` (HNW II.10),
    which behaves like an eighth-order estimate.  Coefficients in
    :mod:`orbits.integrators.dop853_coefficients`.

    References
    ----------
    Prince & Dormand 1981, J. Comput. Appl. Math. 7, 67; Hairer, Nørsett &
    Wanner (1993), *Solving ODEs I*, section II.10.

    Examples
    --------
    >>> orbits.integrators.get("dop853", rtol=1e-12, atol=1e-14).config["rtol"]
    1e-12
    """

    name = "dop853"
    order = 8
    error_estimator_order = 7
    summary = "Dormand-Prince 8(5,3), adaptive (rtol, atol)"
    A = _dop853.A
    B = _dop853.B
    C = _dop853.C
    E = _dop853.E5
    E3 = _dop853.E3
