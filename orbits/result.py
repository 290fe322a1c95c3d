"""What a run returns: outputs as Quantities, monitor series, and a summary."""

import numpy as np

__all__ = ["Result"]


class Result:
    """Outputs of one :meth:`orbits.Simulation.run`.

    Attributes
    ----------
    times : Quantity, shape (n,)
        Times of the outputs (the first is the state the run started from).
    positions, velocities : Quantity, shape (n, N, 3)
        States at the outputs, bodies in the order of the body set.
    names : list of str
    masses : Quantity, shape (N,)
    energy : Quantity, shape (n,) or None
        Total energy at the outputs (None if the energy monitor is off).
    energy_error : ndarray, shape (n,) or None
        ``|E - E0| / |E0|`` against the energy when the simulation was made.
    angular_momentum : Quantity, shape (n, 3) or None
    angular_momentum_error : ndarray, shape (n,) or None
        ``|L - L0| / |L0|`` (see :func:`orbits.monitors.vector_relative_error`).
    momentum, center_of_mass : Quantity, shape (n, 3) or None
        When those monitors are on.
    monitor : dict or None
        Series recorded inside the compiled loop every ``monitor_every``
        steps: ``times`` and the same error arrays as above.
    steps : int
        Steps taken (accepted) in this run.  ``force_evaluations`` and
        ``steps_rejected`` (adaptive integrators) likewise; ``force_evaluations``
        is None where it was not recorded (files written by older versions).
    wall_time : float or None
        Seconds of wall-clock time the run took (None where not recorded).
    start_time : Quantity or None
        Time the run started from, where ``times`` may not begin there (a run
        written to a file returns only its last output).
    largest_errors : dict or None
        Largest relative errors of ``"energy"`` and ``"angular_momentum"`` over
        the whole run, where the series kept here do not hold all of it (a run
        written to a file); :meth:`max_energy_error` takes them into account.
    integrator : dict
        Name and options of the integrator.
    units : dict
        The unit system, with G and where it came from.
    status : str
        ``"completed"`` or the reason the run stopped.
    forces : tuple of str
        The force terms added to gravity, as written (``"GR(source='Sun')"``).
    """

    def __init__(self, **fields):
        self.monitor = None
        self.energy = self.energy_error = None
        self.angular_momentum = self.angular_momentum_error = None
        self.momentum = self.center_of_mass = None
        self.status = "completed"
        self.steps_rejected = 0
        self.forces = ()
        self.start_time = None
        self.largest_errors = None
        for k, v in fields.items():
            setattr(self, k, v)

    def __len__(self):
        return len(self.times)

    def __repr__(self):
        return (f"<Result: {len(self)} outputs of {len(self.names)} bodies, "
                f"{self.integrator['name']}, {self.status}>")

    def max_energy_error(self):
        """Largest relative energy error seen, at outputs or by the in-loop monitor."""
        return _largest(self.energy_error, self.monitor and self.monitor.get("energy_error"),
                        self._recorded("energy"))

    def max_angular_momentum_error(self):
        """Largest relative angular-momentum error seen."""
        return _largest(self.angular_momentum_error,
                        self.monitor and self.monitor.get("angular_momentum_error"),
                        self._recorded("angular_momentum"))

    def _recorded(self, name):
        value = (self.largest_errors or {}).get(name)
        return None if value is None else np.array([value])

    def summary(self):
        """A few lines for a person: what ran, how long, and how well it kept the invariants."""
        opts = ", ".join(f"{k[7:]}={v}" for k, v in self.integrator.items()
                         if k.startswith("option."))
        wall = self.wall_time
        if wall is None or not np.isfinite(wall):
            wall_text = "wall time not recorded"
        else:
            rate = self.steps / wall if wall > 0 else float("inf")
            wall_text = f"wall time {wall:.3g} s ({rate:.3g} steps/s)"
        forces = ("force evaluations not recorded" if self.force_evaluations is None
                  else f"{self.force_evaluations} force evaluations")
        if len(self.times):
            start = self.times[0] if self.start_time is None else self.start_time
            span = f"{start:.6g} -> {self.times[-1]:.6g}"
        else:
            span = "no outputs"
        lines = [
            f"integrator      {self.integrator['name']} (order {self.integrator['order']}"
            f"{', symplectic' if self.integrator['symplectic'] else ''})"
            + (f" [{opts}]" if opts else ""),
            f"bodies          {len(self.names)}: {', '.join(self.names[:6])}"
            + (", ..." if len(self.names) > 6 else ""),
            f"time            {span}, "
            + ("adaptive steps" if self.integrator.get("adaptive") else f"dt = {self.dt:.6g}"),
            f"steps           {self.steps} "
            + (f"(+{self.steps_rejected} rejected) " if self.integrator.get("adaptive") else "")
            + f"({forces}), {wall_text}",
            f"units           {self.units['name']}, G = {self.units['G']!r} "
            f"({self.units['G_source']})",
            f"forces          {' + '.join(['Newtonian gravity', *self.forces])}",
        ]
        e = self.max_energy_error()
        if e is not None:
            lines.append(f"energy          largest relative error {e:.3e}"
                         + _final(self.energy_error))
        lerr = self.max_angular_momentum_error()
        if lerr is not None:
            lines.append(f"ang. momentum   largest relative error {lerr:.3e}"
                         + _final(self.angular_momentum_error))
        lines.append(f"status          {self.status}")
        return "\n".join(lines)


def _final(series):
    return f", final {series[-1]:.3e}" if series is not None and len(series) else ""


def _largest(*series):
    vals = [np.max(s) for s in series if s is not None and len(s)]
    return float(max(vals)) if vals else None
