"""The recorder of a run kept in memory: outputs and monitor rows collected as
the run takes them, and the :class:`~orbits.Result` made from them at its end.

A run that streams to a file uses :class:`orbits.io.hdf5.FileRecorder`
instead; both answer the calls of :meth:`orbits._driver.Driven.execute`.
"""

import functools

import numpy as np

from ._kernels import invariants as _inv
from .monitors import monitor_field_names, monitor_fields
from .result import Result

__all__ = ["Recorder"]


class Recorder:
    """Collects the outputs and monitor rows of one run in memory (the
    :class:`~orbits.Result` of :meth:`Simulation.run` without ``output``)."""

    def __init__(self, sim, initial=True, capacity=1):
        n = len(sim._m)
        self.inv = np.argsort(sim._order)
        self.order = sim._order
        # the outputs: their times, and rows of the monitors, then the
        # positions and velocities in the simulation's internal order (the
        # layout of the rows recorded inside the loop, which writes into
        # this array directly; it grows if a run takes more outputs)
        self.t = np.empty(capacity)
        self.rows = np.zeros((capacity, _inv.MONITOR_WIDTH + 6 * n))
        self.count = 0
        self.mon_t = []
        self.mon_rows = []
        self.steps0 = sim.steps
        self.forces0 = sim.force_evaluations
        self.rejected0 = sim.steps_rejected
        self.t0 = sim._now()
        self.n = n
        # the bodies at the start, whose columns the outputs keep when
        # collisions merge some of them away (then NaN) and change masses
        self.names0 = list(sim._names)
        self.m0, self.r0 = sim._m[self.inv].copy(), sim._r[self.inv].copy()
        self.version = sim._bodies_changed
        self.slot_of = {name: k for k, name in enumerate(sim._names_internal())}
        self.slots = None
        self.mass_rows = [] if sim._resolves_collisions else None
        if initial:
            self.output(sim)

    end_status = 0

    def close(self):
        """Nothing to release for a run kept in memory."""

    def checkpoint(self, finished=False):
        """Nothing to save for a run kept in memory."""

    def stopped(self, sim):
        """A run stopped early by a signal: its result ends where it stopped."""
        self.output(sim, final=True)

    def _room(self, k):
        # space for k more outputs
        if self.count + k > len(self.t):
            size = max(2 * len(self.t), self.count + k)
            self.t = np.resize(self.t, size)
            rows = np.zeros((size, self.rows.shape[1]))
            rows[:self.count] = self.rows[:self.count]
            self.rows = rows

    def output(self, sim, final=False):
        snap = sim.snapshot()
        self._room(1)
        i = self.count
        w, n = _inv.MONITOR_WIDTH, self.n
        self.t[i] = snap.t
        self.rows[i, :w] = snap.monitors
        if sim._bodies_changed != self.version:
            self.version = sim._bodies_changed
            self.slots = np.array([self.slot_of[name] for name in sim._names_internal()])
        if self.slots is None:
            self.rows[i, w:w + 3 * n] = snap.x[self.order].ravel()
            self.rows[i, w + 3 * n:] = snap.v[self.order].ravel()
        else:
            x = np.full((n, 3), np.nan)
            v = np.full((n, 3), np.nan)
            x[self.slots] = snap.x[sim._order]
            v[self.slots] = snap.v[sim._order]
            self.rows[i, w:w + 3 * n] = x.ravel()
            self.rows[i, w + 3 * n:] = v.ravel()
        if self.mass_rows is not None:
            mass = np.full(n, np.nan)
            if self.slots is None:
                mass[:] = sim._m
            else:
                mass[self.slots] = sim._m
            self.mass_rows.append(mass[self.inv])
        self.count += 1

    def row_buffer(self, k):
        """Where the compiled loop writes the next ``k`` outputs (see
        :meth:`orbits._driver.Driven.execute`)."""
        self._room(k)
        return self.rows[self.count:self.count + k]

    def output_rows(self, sim, steps, t, rows):
        """The loop wrote ``rows`` (from :meth:`row_buffer`) at times ``t``."""
        k = len(t)
        self.t[self.count:self.count + k] = t
        self.count += k

    def monitor_rows(self, t, rows):
        self.mon_t.append(t.copy())
        self.mon_rows.append(rows.copy())

    def result(self, sim, wall, status="completed"):
        U = sim.units
        q = U.quantity
        n_out = self.count
        fields = dict(
            names=list(self.names0),
            steps=sim.steps - self.steps0,
            force_evaluations=sim.force_evaluations - self.forces0, wall_time=wall,
            integrator=sim.integrator.info(), units=U, status=status,
            monitors=sim.monitors, steps_rejected=sim.steps_rejected - self.rejected0,
            forces=tuple(map(repr, sim.forces)), epoch=sim.epoch)
        if sim._n_tangent:
            fields["jacobian"] = sim.jacobian
            fields["tangent_vectors"] = sim.tangent_vectors
            fields["seed"] = sim._seed
        # the arrays with units and the monitor series are made when first
        # read (Result's deferred fields), from what is here now
        w, n = _inv.MONITOR_WIDTH, self.n
        t, rows = self.t[:n_out], self.rows[:n_out]
        inv, m0, r0, t0, dt = self.inv, self.m0, self.r0, self.t0, sim._dt

        def outputs():
            x = rows[:, w:w + 3 * n].reshape(-1, n, 3)
            v = rows[:, w + 3 * n:w + 6 * n].reshape(-1, n, 3)
            if not np.array_equal(inv, np.arange(n)):
                x, v = x[:, inv], v[:, inv]
            return dict(times=q(t, "time"), masses=q(m0, "mass"), radii=q(r0, "length"),
                        start_time=q(t0, "time"), dt=q(dt, "time"), positions=q(x, "length"),
                        velocities=q(v, "velocity"))

        deferred = [(("times", "masses", "radii", "start_time", "dt", "positions",
                      "velocities"), outputs)]
        if self.mass_rows is not None:
            masses = np.array(self.mass_rows).reshape(-1, n)
            deferred.append((("masses_at_outputs",),
                             lambda: {"masses_at_outputs": q(masses, "mass")}))
        # the monitor series of rows, against the reference row of now
        series = functools.partial(monitor_fields, monitors=sim.monitors,
                                   reference=sim._reference.copy(),
                                   scales=(sim._E_scale, sim._L_scale), units=U,
                                   work=sim._has_work)
        if sim._mask:
            block = rows[:, :w]
            deferred.append((monitor_field_names(sim.monitors, w, sim._has_work),
                             lambda: series(block)))
        if self.mon_t:
            mon_rows = np.concatenate(self.mon_rows)
            mon_t = np.concatenate(self.mon_t)

            def monitor():
                mon = series(mon_rows)
                mon["times"] = q(mon_t, "time")
                return {"monitor": mon}

            deferred.append((("monitor",), monitor))
        return Result(_deferred=deferred, **fields)

