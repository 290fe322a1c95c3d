"""RK4 with step-doubling error control, the textbook adaptive baseline."""

import numpy as np

from .._kernels.status import with_status
from .._kernels import doubling as _doubling
from .._kernels import stepping as _stepping
from .._kernels.stopping import stop_record
from ._loops import loop_for
from .base import NO_MARK_STEPS, NO_MARKS, ToleranceControlled

__all__ = ["RK4Doubling"]


class RK4Doubling(ToleranceControlled):
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
    >>> import orbits
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

    def invalidate(self, ws):
        ws["fsal"][0] = 0

    #: outputs can be recorded inside the loop (``advance_to``'s ``marks``)
    records_marks = True

    def advance_to(self, ws, x, v, t, t_end, force, fargs, mon, step0, mon_t, mon_out, stop,
                   max_steps, marks=NO_MARKS, mark_steps=NO_MARK_STEPS):
        """Advance to ``t_end``; with ``marks`` (times, the last ``t_end``), land
        on each and record there a row of ``mon_out`` (monitors and state),
        its time in ``mon_t`` and its step count in ``mark_steps``."""
        loop = loop_for(_doubling.doubling_loop, force)
        fargs = _stepping.work_bound(force, fargs, ws)
        w = ws
        args = (x, v, t, t_end, w["k0x"], w["k0v"], w["kmx"], w["kmv"], w["kx"], w["kv"],
                w["xs"], w["vs"], w["xf"], w["vf"], w["xh"], w["vh"], w["x2"], w["v2"],
                w["dt"], w["fsal"], w["info"], fargs, mon, step0, mon_t, mon_out,
                *stop_record(stop), int(max_steps),
                float(self.config["rtol"]), float(self.config["atol"]))
        return with_status(*loop(*args, marks, mark_steps))
