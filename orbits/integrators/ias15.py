"""IAS15: Everhart's Gauss-Radau integrator with Rein & Spiegel's step control."""

import numpy as np

from .._kernels import ias15 as _k
from .._kernels import records
from .._kernels.stepping import work_bound
from ._loops import loop_for
from .base import MIN_DT, NO_MARK_STEPS, NO_MARKS, AdaptiveIntegrator, Option

__all__ = ["IAS15"]

#: adaptive_mode values: how the next step is chosen
ADAPTIVE_MODES = {"global": _k.MODE_GLOBAL, "prs24": _k.MODE_PRS24}


class IAS15(AdaptiveIntegrator):
    """15th-order implicit Gauss-Radau integrator with adaptive steps (IAS15).

    Parameters
    ----------
    epsilon : float
        Accuracy parameter, > 0 (default 1e-9, Rein & Spiegel's value, at which
        the error per step is below double-precision rounding for smooth
        problems).
    min_dt : float
        Smallest allowed step (internal time unit), >= 0 (default 0).  A run
        whose step control asks for less stops with
        :class:`~orbits.errors.StepSizeUnderflow`; so does one whose step no
        longer changes the time in floating point.
    adaptive_mode : {"global", "prs24"}
        ``"global"`` (default): ``dt_next = dt (epsilon / b6~)^(1/7)`` with
        ``b6~ = max|b6| / max|a|`` over all bodies (Rein & Spiegel 2015).
        ``"prs24"``: the per-body timescale from acceleration, jerk and snap of
        Pham, Rein & Spiegel (2024).

    Notes
    -----
    Over a step ``dt`` the acceleration is a polynomial of degree 7 in
    ``h = (t - t0) / dt``, ``a(h) = a0 + b0 h + ... + b6 h^7``, fitted at the
    Gauss-Radau spacings ``h_1 .. h_7`` and integrated twice::

        x(1) = x0 + dt v0 + dt^2 (a0/2 + b0/6 + b1/12 + ... + b6/72)
        v(1) = v0 + dt (a0 + b0/2 + b1/3 + ... + b6/8)

    The ``b`` are found by a predictor-corrector iteration (7 force
    evaluations per iteration, two or three iterations, plus one at the start
    of the step), run to rounding; at a loose ``epsilon`` (above 1e-7) only
    until its change falls below ``1e-2 epsilon**2``, far below the step's
    truncation error, which saves up to half the force evaluations there.
    The step is accepted unless the step it implies is below ``0.25 dt``; the
    next step is at most ``4 dt``.  Positions, velocities and
    the time are summed with compensation, and the ``b`` a step ends with are
    computed from that step's forces alone (not carried over from the
    prediction), so the rounding errors of successive steps are independent
    and the energy error of a smooth problem grows as their random walk, as
    ``t^0.5`` (Brouwer's law; ``validation/brouwer.py`` measures it beside
    REBOUND).  The update equations and step control are written out in
    :mod:`orbits._kernels.ias15`.

    The workspace holds, besides the coefficients ``b``, ``g`` and the
    extrapolation ``e``, ``br``, ``er``, the compensation terms ``csx``,
    ``csv`` and ``tc`` (of the time), the acceleration ``a0`` at the current
    state, the proposed step ``dt`` and the reference step ``ref``: everything
    a bit-exact restart needs.

    References
    ----------
    .. [1] Everhart, E. 1985, "An efficient integrator that uses Gauss-Radau
       spacings", IAU Colloq. 83, Dynamics of Comets, p. 185.
    .. [2] Rein, H. & Spiegel, D. S. 2015, "IAS15: a fast, adaptive,
       high-order integrator for gravitational dynamics, accurate to machine
       precision over a billion orbits", MNRAS 446, 1424.
    .. [3] Pham, D., Rein, H. & Spiegel, D. S. 2024, "A new timestep criterion
       for N-body simulations", Open Journal of Astrophysics 7.

    Examples
    --------
    >>> from orbits.integrators import get
    >>> from orbits._kernels.gravity import gravity_args
    >>> from orbits._kernels.stepping import gravity_force
    >>> integ = get("ias15", epsilon=1e-9)
    >>> x = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])   # G = 1, circular orbit
    >>> v = np.array([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    >>> gm = np.array([1.0, 0.0])
    >>> ws = integ.workspace(2)
    >>> status, t, *_ = integ.advance_to(
    ...     ws, x, v, 0.0, 2 * np.pi, gravity_force("small"),
    ...     gravity_args(1.0, gm, 1, 0.0), (0, 0, gm, 1.0, 1, 0.0), 0,
    ...     np.empty(0), np.zeros((0, 11)), None, 10**6)
    >>> int(status), t == 2 * np.pi, bool(np.allclose(x[1], [1.0, 0.0, 0.0], atol=1e-12))
    (0, True, True)
    """

    terms_as_data = True

    name = "ias15"
    order = 15
    option_specs = (
        Option("epsilon", float, 1e-9, "precision: the step keeps the last term of the "
               "acceleration's series below epsilon times the acceleration", sign="positive"),
        MIN_DT,
        Option("adaptive_mode", str, "global", "how the next step is chosen: from the "
               "largest last term over all bodies, or per body (Pham, Rein & Spiegel "
               "2024)", choices=tuple(ADAPTIVE_MODES)),
    )
    summary = "IAS15, adaptive 15th-order Gauss-Radau predictor-corrector (Rein & Spiegel 2015)"
    forces_per_step = 15

    def workspace(self, n, initial_step=0.0):
        """The state of a run of ``n`` bodies; ``initial_step`` is the first step
        tried (0: chosen from the initial accelerations)."""
        coef = lambda: np.zeros((7, n, 3))  # noqa: E731
        return {
            "dt": np.array([float(initial_step)]),          # next step (signed)
            "info": np.full(2, -1, dtype=np.int64),         # bodies behind a failure
            "a0": np.zeros((n, 3)),                         # acceleration at (x, v)
            "b": coef(), "g": coef(),                       # this step's polynomial
            "e": coef(),                                    # its first guess
            "br": coef(), "er": coef(),                     # reference step: b and guess
            "csx": np.zeros((n, 3)), "csv": np.zeros((n, 3)),  # compensation of x, v
            "ref": np.zeros(2),            # reference step length, time since its start
            "tc": np.zeros(2),             # time reached, and its compensation
            # a0 is current; a reference step exists
            "flags": np.zeros(2, dtype=np.int64),
            # scratch: substep state and force, extrapolation matrix, counters
            "xs": np.zeros((n, 3)), "vs": np.zeros((n, 3)), "acc": np.zeros((n, 3)),
            "P": np.zeros((7, 7)), "counts": np.zeros(3, dtype=np.int64),
        }

    #: outputs can be recorded inside the loop (``advance_to``'s ``marks``)
    records_marks = True

    def advance_to(self, ws, x, v, t, t_end, force, fargs, mon, step0, mon_t, mon_out,
                   stop, max_steps, marks=NO_MARKS, mark_steps=NO_MARK_STEPS):
        """Advance to ``t_end``; with ``marks`` (times, the last ``t_end``), land
        on each and record there a row of ``mon_out`` (monitors and state),
        its time in ``mon_t`` and its step count in ``mark_steps``."""
        loop = loop_for(_k.ias15_loop, force)
        fargs = work_bound(force, fargs, ws)
        control = _k.Control(float(self.config["epsilon"]),
                             ADAPTIVE_MODES[self.config["adaptive_mode"]])
        return self._counted_call(loop, (x, v, float(t), control, records.work(_k.Work, ws),
                                         fargs),
                                  ws, mon, step0, mon_t, mon_out, t_end, max_steps, marks,
                                  mark_steps, stop)

    def invalidate(self, ws):
        """The state was changed from outside: recompute the force, forget the
        extrapolation and the compensation terms."""
        ws["flags"][:] = 0
        ws["csx"][...] = 0.0
        ws["csv"][...] = 0.0
