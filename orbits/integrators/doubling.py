"""RK4 with step-doubling error control, the textbook adaptive baseline."""

import numpy as np

from .._kernels import doubling as _doubling
from .._kernels import records
from ._loops import loop_for
from .base import CompiledToleranceControlled

__all__ = ["RK4Doubling"]


class RK4Doubling(CompiledToleranceControlled):
    """Classic RK4 made adaptive by step doubling.

    Notes
    -----
    Every step is done once with ``h`` and once as two steps of ``h/2``; the
    difference divided by 15 estimates the error of the two half steps,
    which are kept when that error is within ``atol + rtol * |y|`` (RMS
    norm).  Eleven force evaluations a step: the simple baseline that the
    embedded pairs (``dopri5``: six) improve on.

    References
    ----------
    Hairer, Nørsett & Wanner (1993), *Solving ODEs I*, section II.4
    ("Richardson extrapolation"); Press et al., *Numerical Recipes*, sect. 17.2.

    Examples
    --------
    >>> orbits.integrators.get("rk4-doubling", rtol=1e-8).order
    4
    """

    name = "rk4-doubling"
    order = 4
    summary = "RK4 with step doubling, adaptive (rtol, atol)"
    forces_per_step = 11

    def workspace(self, n, initial_step=0.0):
        z = lambda: np.zeros((n, 3))  # noqa: E731
        return {"k0x": z(), "k0v": z(), "kmx": z(), "kmv": z(), "kx": np.zeros((3, n, 3)),
                "kv": np.zeros((3, n, 3)), "xs": z(), "vs": z(), "xf": z(), "vf": z(),
                "xh": z(), "vh": z(), "x2": z(), "v2": z(),
                "dt": np.array([float(initial_step)]), "fsal": np.zeros(1, dtype=np.int64),
                "info": np.full(2, -1, dtype=np.int64)}

    def _loop_call(self, ws, force):
        return (loop_for(_doubling.doubling_loop, force), (_doubling.METHOD,),
                records.work(_doubling.Work, ws))
