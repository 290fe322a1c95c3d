"""Taylor's method: the series of the orbits to a high order, with Jorba & Zou's step."""

import numpy as np

from .._kernels import records
from .._kernels import taylor as _k
from ..errors import IntegratorOptionError
from ._loops import loop_for
from .base import MIN_DT, NO_MARK_STEPS, NO_MARKS, AdaptiveIntegrator, Option

__all__ = ["Taylor"]

#: the default tolerance: float64's epsilon, ``np.finfo(float).eps`` (order 20)
TOLERANCE = 2.220446049250313e-16


class Taylor(AdaptiveIntegrator):
    """Taylor's method for Newtonian gravity: each step sums the orbits' Taylor
    series, computed to a fixed order by automatic differentiation, with the
    step set by the series' radius of convergence (Jorba & Zou 2005).

    Parameters
    ----------
    tol : float
        Tolerance, > 0 (default 2.2e-16, float64's epsilon): the truncation
        error a step aims at, relative to the largest coordinate.  It sets
        the order, ``ceil(-ln(tol) / 2 + 1)`` (20 at the default, 13 at
        1e-10, 7 at 1e-5), unless ``order`` is given.
    order : int
        The order of the series, >= 2; 0 (default): from ``tol``.
    min_dt : float
        Smallest allowed step (internal time unit), >= 0 (default 0); a run
        whose series ask for less stops with
        :class:`~orbits.errors.StepSizeUnderflow`.

    Notes
    -----
    Over a step ``h`` from the current state every position and velocity is
    the truncated series ``x(t + h) = sum_{k=0..p} x[k] h^k``.  The
    coefficients come from ``x[k+1] = v[k] / (k + 1)``, ``v[k+1] = a[k] /
    (k + 1)`` and, for the pull of each pair, the recurrences of the
    products and of the power ``r^-3 = (r^2)^(-3/2)``, written out in
    :mod:`orbits._kernels.taylor`; a step costs about ``p^2 / 2`` passes over
    the pairs.  The step is ``h = rho / e^2 exp(-0.7 / (p - 1))``, with
    ``rho`` the smaller of ``(|x|_max / |x[k]|_max)^(1/k)`` for ``k = p - 1,
    p``: the radius of convergence estimated from the last two orders,
    relative to the largest coordinate; it follows the orbits' own time
    scales (pericentre passages, close encounters), and no step is
    rejected.  Positions, velocities and time are summed with compensation
    as in ``ias15``.

    The method takes Newtonian gravity (softened or not, with test
    particles) and nothing else: no added force terms, no user force, no
    variational equations; it refuses them with
    :class:`~orbits.errors.IntegratorOptionError`.  Its memory grows as the
    number of pairs times the order (``(p + 1) (5 P + 6 N)`` doubles), so it
    is meant for systems of a few to a few hundred bodies.

    ``force_evaluations`` in results counts ``p`` a step: one pass of the
    recurrences per order.

    References
    ----------
    .. [1] Jorba, A. & Zou, M. 2005, "A software package for the numerical
       integration of ODEs by means of high-order Taylor methods",
       Experimental Mathematics 14, 99.
    .. [2] Biscani, F. & Izzo, D. 2021, "Revisiting high-order Taylor methods
       for astrodynamics and celestial mechanics", MNRAS 504, 2614.

    Examples
    --------
    >>> sim = orbits.Simulation(orbits.scenes.kepler(e=0.5), "taylor", monitors=["energy"])
    >>> res = sim.run(until=10 * u.yr, outputs=3, progress=False)
    >>> bool(abs(res.energy_error[-1]) < 1e-13)
    True
    >>> orbits.integrators.get("taylor", tol=1e-10).order_used
    13
    """

    name = "taylor"
    order = 20
    option_specs = (
        Option("tol", float, TOLERANCE, "tolerance of a step's truncation error, relative "
               "to the largest coordinate; it sets the order (20 at the default, 13 at "
               "1e-10)", sign="positive"),
        Option("order", int, 0, "the order of the series, at least 2 (0: from tol)",
               sign="non-negative"),
        MIN_DT,
    )
    summary = "Taylor series by automatic differentiation, order from tol (Jorba & Zou 2005)"
    chaos_indicators = False
    #: outputs can be recorded inside the loop (``advance_to``'s ``marks``)
    records_marks = True

    def _check_options(self):
        if self.config["order"] == 1:
            raise IntegratorOptionError(
                f"integrator {self.name!r}: option 'order' must be a whole number >= 2 "
                f"(or 0: from tol), got 1")

    @property
    def order_used(self):
        """The order of the series: the ``order`` option, else the one ``tol`` sets."""
        return self.config["order"] or _k.order_for(self.config["tol"])

    @property
    def forces_per_step(self):
        """One pass of the recurrences per order, counted as a force evaluation."""
        return self.order_used

    def info(self):
        """As every integrator's, with ``order`` the order used."""
        return {**super().info(), "order": self.order_used}

    def check_terms(self, terms):
        """Every added term is refused: the recurrences are those of Newtonian
        gravity alone."""
        if terms:
            raise IntegratorOptionError(
                f"{self.name} cannot take the force term {terms[0]!r}: its series are "
                "computed by recurrences written for Newtonian gravity alone. Use 'ias15' "
                "(adaptive, as accurate) or an embedded method such as 'dop853'.")

    def bind(self, ws, force, fargs):
        """Refuse a force other than gravity; allocate the pairs' series (not
        saved: they are rebuilt from the state every step)."""
        if force.opaque or force.terms is not None or force.inner is not None:
            what = ("a user's force function" if force.opaque else
                    "variational equations" if force.inner is not None else "added force terms")
            raise IntegratorOptionError(
                f"{self.name} computes the series of Newtonian gravity only and cannot "
                f"integrate {what}; use 'ias15' or 'dop853'")
        ws["series"] = _k.series_arrays(self.order_used, ws["csx"].shape[0], int(fargs[1]))

    def workspace(self, n, initial_step=0.0):
        """The state of a run of ``n`` bodies.  ``initial_step`` is kept as the
        proposed step but not used: every step is set by the series."""
        return {
            "dt": np.array([float(initial_step)]),          # the last step's proposal
            "info": np.full(2, -1, dtype=np.int64),         # bodies behind a stop
            "csx": np.zeros((n, 3)), "csv": np.zeros((n, 3)),  # compensation of x, v
            "tc": np.zeros(2),             # time reached, and its compensation
            "counts": np.zeros(3, dtype=np.int64),
        }

    def advance_to(self, ws, x, v, t, t_end, force, fargs, mon, step0, mon_t, mon_out,
                   stop, max_steps, marks=NO_MARKS, mark_steps=NO_MARK_STEPS):
        """Advance to ``t_end``; with ``marks`` (times, the last ``t_end``), land
        on each and record there a row of ``mon_out`` (monitors and state),
        its time in ``mon_t`` and its step count in ``mark_steps``."""
        series = ws.get("series")
        if (series is None or series.X.shape != (self.order_used + 1, 3, x.shape[0])
                or series.PI.shape[0] < _k.pair_count(x.shape[0], int(fargs[1]))):
            # a workspace not bound yet, or bound for other bodies (the kernel
            # writes as many pairs as the massive bodies make)
            self.bind(ws, force, fargs)
        loop = loop_for(_k.taylor_loop, force)
        return self._counted_call(loop, (x, v, float(t), int(self.order_used), ws["series"],
                                         records.work(_k.Work, ws), fargs),
                                  ws, mon, step0, mon_t, mon_out, t_end, max_steps, marks,
                                  mark_steps, stop)

    def invalidate(self, ws):
        """The state was changed from outside: forget the compensation terms."""
        ws["csx"][...] = 0.0
        ws["csv"][...] = 0.0
