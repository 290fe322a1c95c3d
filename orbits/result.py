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
        ``steps_rejected`` (adaptive integrators) likewise.
    wall_time : float
        Seconds of wall-clock time the run took.
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
        for k, v in fields.items():
            setattr(self, k, v)

    def __len__(self):
        return len(self.times)

    def __repr__(self):
        return (f"<Result: {len(self)} outputs of {len(self.names)} bodies, "
                f"{self.integrator['name']}, {self.status}>")

    def max_energy_error(self):
        """Largest relative energy error seen, at outputs or by the in-loop monitor."""
        return _largest(self.energy_error, self.monitor and self.monitor.get("energy_error"))

    def max_angular_momentum_error(self):
        """Largest relative angular-momentum error seen."""
        return _largest(self.angular_momentum_error,
                        self.monitor and self.monitor.get("angular_momentum_error"))

    def summary(self):
        """A few lines for a person: what ran, how long, and how well it kept the invariants."""
        opts = ", ".join(f"{k[7:]}={v}" for k, v in self.integrator.items()
                         if k.startswith("option."))
        rate = self.steps / self.wall_time if self.wall_time > 0 else float("inf")
        lines = [
            f"integrator      {self.integrator['name']} (order {self.integrator['order']}"
            f"{', symplectic' if self.integrator['symplectic'] else ''})"
            + (f" [{opts}]" if opts else ""),
            f"bodies          {len(self.names)}: {', '.join(self.names[:6])}"
            + (", ..." if len(self.names) > 6 else ""),
            f"time            {self.times[0]:.6g} -> {self.times[-1]:.6g}, "
            + ("adaptive steps" if self.integrator.get("adaptive") else f"dt = {self.dt:.6g}"),
            f"steps           {self.steps} "
            + (f"(+{self.steps_rejected} rejected) " if self.integrator.get("adaptive") else "")
            + f"({self.force_evaluations} force evaluations), "
            f"wall time {self.wall_time:.3g} s ({rate:.3g} steps/s)",
            f"units           {self.units['name']}, G = {self.units['G']!r} "
            f"({self.units['G_source']})",
            f"forces          {' + '.join(['Newtonian gravity', *self.forces])}",
        ]
        e = self.max_energy_error()
        if e is not None:
            lines.append(f"energy          largest relative error {e:.3e}, final "
                         f"{self.energy_error[-1]:.3e}")
        lerr = self.max_angular_momentum_error()
        if lerr is not None:
            lines.append(f"ang. momentum   largest relative error {lerr:.3e}, final "
                         f"{self.angular_momentum_error[-1]:.3e}")
        lines.append(f"status          {self.status}")
        return "\n".join(lines)


def _largest(*series):
    vals = [np.max(s) for s in series if s is not None and len(s)]
    return float(max(vals)) if vals else None
