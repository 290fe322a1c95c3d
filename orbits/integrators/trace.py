"""``trace``: a time-reversible hybrid of the Wisdom-Holman map and an adaptive
integrator for close encounters (after Lu, Hernandez & Rein 2024)."""

import numpy as np

from .._kernels import records
from .._kernels import trace as _trace
from .._kernels import trace_lanes as _trace_lanes
from .._kernels.coordinates import from_democratic_heliocentric
from .._kernels.status import with_status
from .._kernels.stopping import ahead_pointer, stop_record
from ..errors import IntegratorOptionError
from . import dop853_coefficients as _dop853
from .base import RTOL_FLOOR, Integrator, Option
from .wisdom_holman import (LANES_MODES, lanes_choice, lanes_pay, lanes_ready,
                            lanes_scratch_in, note_lanes_ready, refuse_unkickable,
                            split_gravity, table_bound)

__all__ = ["Trace", "HILL", "SPEED", "PERICENTRE", "RTOL"]

#: Switching radius in mutual Hill radii: beyond three the pair's pull is a
#: small perturbation of the Kepler motion (its time scale is several orbital
#: time scales), the regime the Wisdom-Holman kick handles; the TRACE paper's
#: default too.
HILL = 3.0
#: Switching radius in steps of relative motion, ``|v_rel| |h|``: a flyby too
#: fast for the Hill criterion to see at a step's end (it could cross the Hill
#: sphere within one step) is flagged before it arrives.
SPEED = 1.0
#: A body whose step is long against its time scale about the central one,
#: ``PERICENTRE^2 h^2 ((v^2 + 3 rdot^2) / r^2 + G m_0 / r^3) > 1``, makes the
#: segment be integrated whole by the inner integrator: the jump's and the
#: kicks' error grows as that time scale falls towards the step.  1 flags a
#: circular orbit turning more than 0.71 rad a step, and a body falling
#: straight in from further out: Mercury's perihelion at a twentieth or a
#: fifteenth of its period (the usual Wisdom-Holman steps) stays outside,
#: and a sungrazing comet's energy error falls by three orders of magnitude
#: against no criterion (benchmarks/RESULTS.md has the sweep of this
#: factor).
PERICENTRE = 1.0
#: The inner integrator's relative tolerance per step, per body, in the
#: group's own frame (DOP853's error estimate): the stress suite's close
#: encounters end with energy errors of at most about 1e-10 at it
#: (benchmarks/RESULTS.md has the sweep of this tolerance).
RTOL = 1e-12


def _dop853_tables():
    e5 = np.ascontiguousarray(_dop853.E5, dtype=np.float64)
    e3 = np.ascontiguousarray(_dop853.E3, dtype=np.float64)
    return (np.ascontiguousarray(_dop853.A, dtype=np.float64),
            np.ascontiguousarray(_dop853.B, dtype=np.float64),
            np.ascontiguousarray(_dop853.C, dtype=np.float64), e5, e3)


class Trace(Integrator):
    """TRACE: the democratic heliocentric Wisdom-Holman map, switching to an
    adaptive integrator for close encounters, time-reversibly.

    Parameters
    ----------
    hill : float
        Switching radius in mutual Hill radii (default 3): a pair of
        non-central bodies closer than ``hill`` mutual Hill radii is in a
        close encounter.
    speed : float
        Switching radius in steps of relative motion (default 1): a pair
        closer than ``speed |v_i - v_j| |dt|`` is also in one (fast flybys).
        0 switches the term off.
    pericentre : float
        A body whose step is longer than ``1 / pericentre`` of its time
        scale about the central one, ``pericentre^2 dt^2 ((v^2 + 3 rdot^2) /
        r^2 + G m_0 / r^3) > 1`` (heliocentric distance, speed and radial
        speed), makes the whole segment be integrated by the adaptive
        integrator (default 1: a circular orbit turning more than 0.71 rad
        a step, a body falling straight in from further out; Mercury's
        perihelion at a fifteenth of its period is not flagged; 0 switches
        it off).
    rtol : float
        Relative tolerance of the adaptive integrator per step (default
        1e-12), measured per body in the frame of its group of encountering
        bodies.
    lanes : {"auto", "on", "off"}
        The steps far from encounters with the planets in vector lanes, the
        same results bit for bit (see the notes); ``"auto"`` (default) takes
        them for a run that reaches 1e8 steps, or once their loop is
        compiled on the machine.

    Notes
    -----
    The step is that of ``wh`` with ``coordinates="democratic-heliocentric"``
    (Duncan, Levison & Lee 1998)::

        Phi(h) = K(h/2) [J(h/2) I(h) J(h/2)] K(h/2)

    with Kepler drifts ``K`` about ``G m_0``, interaction kicks ``I`` and
    jumps ``J`` (see :mod:`orbits._kernels.wisdom_holman`).  Regrouped as
    kick-drift-kick segments ``I(h/2) J(h/2) K(h) J(h/2) I(h/2)``, each
    segment starts by flagging the pairs within the switching radius::

        |Q_i - Q_j| < max(hill R_H, speed |V_i - V_j| |h|),
        R_H = ((m_i + m_j) / (3 m_0))^(1/3) (|Q_i| + |Q_j|) / 2

    A flagged pair's pull leaves the kicks and joins the drift, which then
    integrates the bodies of each group of flagged pairs (Kepler motion plus
    their flagged pulls) with DOP853 in coordinates relative to the group's
    first body; the other bodies keep their Kepler drifts.  A body within the
    pericentre criterion makes the segment be integrated
    whole (every body and every pull, inertial coordinates).  The criterion
    is evaluated again at the segment's end; if it flags something the start
    did not, the segment is redone from its start with the union flagged, so
    that the segment and its reverse take the same flags (time reversibility
    up to ``rtol``).  Without flags the two half kicks between segments are
    the map's one kick, so that far from encounters ``trace`` is ``wh`` in
    democratic heliocentric coordinates bit for bit.

    Second order (that of the map) away from encounters; symplectic there,
    time-symmetric throughout up to the adaptive integrator's tolerance.
    Takes the stopping conditions and ``collisions=``.  Outputs see the state
    synchronised with the current segment's flags.  The stopping conditions
    are checked at the criterion points (half a step before each step's end,
    where the map's own state is synchronised) and at the end of each run
    call, so that they cost no synchronisation a step; a run that stops for
    one stops at the end of that step, and a collision's listed contact time
    is where the check found it.  Where the inner integrator's step
    collapses (two bodies meeting head-on: no step goes through a point
    mass), the run goes back to the start of that segment, the last state it
    reached whole (:meth:`behind`): with ``collisions=`` the pair whose
    two-body orbits touch within the segment is the collision (merged there,
    or halting with :class:`~orbits.errors.Collision`), otherwise the run
    stops with :class:`~orbits.errors.StepSizeUnderflow`.
    Only Newtonian gravity without softening, and the conservative force
    terms that depend on positions alone (``GRPotential``, ``ZonalHarmonics``),
    kicked with the interaction as ``wh`` kicks them (a segment integrated
    whole takes their half kicks at its ends); others are refused.
    A system whose largest other mass exceeds
    :data:`~orbits.integrators.wisdom_holman.MASS_RATIO_LIMIT` times the first
    runs with a :class:`~orbits.integrators.wisdom_holman.NoDominantBodyWarning`.

    Far from encounters, from four bodies on, a run without added terms or
    stopping conditions can take its steps with the planets in vector lanes
    (the drift, jumps and kick of ``wh``'s lanes, and the criterion tested
    there, :mod:`orbits._kernels.trace_lanes`), with the same results bit for
    bit; the ``lanes`` option chooses as ``wh``'s does (``"auto"``: a run of
    1e8 steps, or once that loop is compiled on the machine).

    The workspace's ``"counts"`` holds the segments with flags, the segments
    redone and the adaptive integrator's steps since it was made.

    References
    ----------
    Lu, T., Hernandez, D. M. & Rein, H. 2024, "TRACE: a time-reversible hybrid
    integrator for close encounters", MNRAS 533, 3708.  Duncan, M. J.,
    Levison, H. F. & Lee, M. H. 1998, AJ 116, 2067.  Chambers, J. E. 1999,
    MNRAS 304, 793 (the hybrid idea).  Hairer, Nørsett & Wanner (1993),
    *Solving ODEs I*, section II.10 (DOP853).

    Examples
    --------
    Two Earth-mass planets about a Sun-mass star, on nearly opposite orbits,
    that pass 1e-5 au apart at t = 5 days (their state at the pass, run back
    five days with ``ias15``), at a half-day step:

    >>> b = orbits.BodySet()
    >>> b.add("Star", mass=1 * u.Msun)
    >>> b.add("Planet 1", mass=1 * u.Mearth, primary="Star", a=1 * u.au)
    >>> b.add("Planet 2", mass=1 * u.Mearth, primary="Star", a=1.00001 * u.au,
    ...       inc=170 * u.deg)
    >>> meet = orbits.Simulation(b, "ias15")
    >>> _ = meet.run(until=-5 * u.day, progress=False)
    >>> sim = orbits.Simulation(meet.bodies, "trace", dt=0.5 * u.day)
    >>> result = sim.run(until=10 * u.day, outputs=2, progress=False)
    >>> bool(abs(result.energy_error[-1]) < 1e-9)      # 2e-12; wh: 3.1e-6
    True
    >>> int(sim._ws["counts"][0])                       # segments with a flagged pair
    7
    """

    #: outputs that do not fall a whole number of steps apart are recorded in the
    #: loop too (``every = -1``: the steps in ``mon_t``)
    records_step_marks = True
    #: its scalar loop takes the table of terms, an empty one for a run
    #: without terms (as wh's); the lanes' loop takes none
    terms_as_data = True
    table_in_force = False

    name = "trace"
    order = 2
    symplectic = False
    time_symmetric = True
    needs_central_body = True
    stop_conditions = True
    looks_ahead = True
    chaos_indicators = False
    option_specs = (
        Option("hill", float, HILL, "switching radius in mutual Hill radii",
               sign="positive"),
        Option("speed", float, SPEED, "switching radius in steps of relative motion "
               "(0: off)", sign="non-negative"),
        Option("pericentre", float, PERICENTRE, "a body whose step is longer than "
               "1/pericentre of its time scale about the central one makes the segment "
               "be integrated whole (0: off)", sign="non-negative"),
        Option("rtol", float, RTOL, "relative tolerance of the encounter integrator's step",
               sign="positive"),
        Option("lanes", str, "auto", "the steps far from encounters with the planets in "
               "vector lanes, the same results bit for bit: 'on' (4 bodies or more, no "
               "added terms, no stopping conditions), 'off', or 'auto': 'on' for a run "
               "that reaches 1e8 steps or once their loop is compiled on this machine",
               choices=LANES_MODES),
    )
    summary = ("TRACE: democratic heliocentric Wisdom-Holman map, adaptive DOP853 for close "
               "encounters, time-reversible switching")
    forces_per_step = 1

    def _check_options(self):
        if self.config["rtol"] >= 1.0:
            raise IntegratorOptionError(
                f"integrator {self.name!r}: option 'rtol' must be below 1, got "
                f"{self.config['rtol']!r}")
        if self.config["rtol"] < RTOL_FLOOR:
            raise IntegratorOptionError(
                f"integrator {self.name!r}: rtol = {self.config['rtol']:g} is below what "
                f"float64 arithmetic can deliver (at least {RTOL_FLOOR:.3g})")
        self._tabs = _dop853_tables()

    def workspace(self, n):
        """The internal state, the segment's start and flags, and the inner
        integrator's arrays, for ``n`` bodies.

        Examples
        --------
        >>> ws = orbits.integrators.get("trace").workspace(3)
        >>> ws["enc"].shape, ws["counts"].tolist()
        ((3, 3), [0, 0, 0])
        """
        stages = len(_dop853.B)
        inner = _trace.inner_arrays(n, stages)
        return {"xh": np.zeros((n, 3)), "vb": np.zeros((n, 3)),
                "xc": np.zeros((n, 3)), "vc": np.zeros((n, 3)),
                "xs": np.zeros((n, 3)), "vs": np.zeros((n, 3)), "acc": np.zeros((n, 3)),
                "w1": np.zeros((n, 3)), "w2": np.zeros((n, 3)),
                "gm": np.zeros(n), "eta": np.zeros(n), "hill": np.zeros(n), "r2": np.zeros(n),
                # [internal state current, system checked, segment opened at a
                # criterion point, segment integrated whole, segment has flags]
                "state": np.zeros(5, dtype=np.int64), "owed": np.zeros(1),
                # [time, 1] where the last step checked the stopping
                # conditions at its criterion point, [., 0] at its end
                "checked": np.zeros(2),
                "n_active": np.zeros(1, dtype=np.int64),
                "enc": np.zeros((n, n), dtype=np.uint8),
                "enc_new": np.zeros((n, n), dtype=np.uint8),
                **inner._asdict()}

    def _inner(self, ws):
        return records.work(_trace.Inner, ws)

    def check_terms(self, terms):
        """As ``wh``: only terms that depend on positions alone and have a
        potential join the interaction kicks (in the democratic heliocentric
        form of ``wh``); others are refused with the named error."""
        refuse_unkickable(self, terms)

    def bind(self, ws, force, fargs):
        """Keep the added terms' kernel and arguments beside the arrays (rebound
        from the simulation, not saved); refuse variational equations, so
        that a simulation asking for them is refused where it is made."""
        self._refuse_variations(force)
        if force.terms is not None:
            ws["terms"] = (force.terms, fargs[1])

    def _refuse_variations(self, force):
        if force.inner is not None:
            raise IntegratorOptionError(
                f"{self.name} does not integrate variational equations; use 'wh' or 'ias15'")

    def _check_system(self, ws, force, fargs):
        self._refuse_variations(force)
        gm, n_active = split_gravity(self.name, force, fargs)
        n = len(gm)
        ws["gm"][:n] = gm
        ws["eta"][:n] = gm[0]
        ws["hill"][:n] = np.cbrt(np.asarray(gm, dtype=float) / (3.0 * gm[0]))
        ws["n_active"][0] = n_active
        ws["state"][1] = 1

    def advance(self, ws, x, v, t, dt, nsteps, force, fargs, mon, step0, mon_t, mon_out,
                velocity_dependent=False, check_every=1, stop=None):
        """Advance ``nsteps`` steps of ``dt`` in the compiled loop (see
        :meth:`Integrator.advance`).

        Examples
        --------
        >>> from orbits import integrators
        >>> from orbits.integrators.base import around_a_circle
        >>> integ = integrators.get("trace")
        >>> status, steps, x, v, ws = around_a_circle(integ, 100)
        >>> integ.synchronize(ws, x, v)
        >>> status.name, np.round(x[1], 12) + 0.0       # a Kepler orbit is exact
        ('OK', array([1., 0., 0.]))
        """
        if force.opaque or force.inner is not None or ws["state"][1] == 0:
            self._check_system(ws, force, fargs)
        terms, targs = ws.get("terms", (None, ()))
        if force.terms is not None and terms is None:
            self.bind(ws, force, fargs)
            terms, targs = ws["terms"]
        c = self.config
        # far from encounters, the planets in vector lanes: a run without
        # stopping conditions (checked at every criterion point) or terms
        if "lanes_pay" not in ws:
            # chosen once for the workspace, at its first step, as wh chooses
            ws["lanes_pay"] = lanes_pay(x, v, ws["gm"], dt)
        lanes = (stop is None and terms is None and ws["lanes_pay"]
                 and self.lanes_wanted(ws, x.shape[0], force.recorder))
        if lanes:
            targs = lanes_scratch_in(ws, _trace_lanes.far_scratch_shape(x.shape[0]))
            loop = _trace.trace_loop(record=force.recorder, lanes=True)
        else:
            # one scalar loop with and without terms (table_bound)
            terms, targs, recorder, mon = table_bound(ws, x.shape[0], force.recorder, mon)
            loop = _trace.trace_loop(record=recorder, terms=terms)
        criteria = _trace.Criteria(float(c["hill"]), float(c["speed"]), float(c["pericentre"]),
                                   float(c["rtol"]))
        sargs, check = stop_record(stop)
        out = loop(x, v, float(t), float(dt), int(nsteps), records.work(_trace.Work, ws),
                   criteria, self._inner(ws), self._tabs,
                   records.outputs(mon, step0, mon_t, mon_out),
                   records.checks(check_every, sargs), check, ahead_pointer(stop is not None),
                   targs)
        if lanes:
            note_lanes_ready(loop)
        return with_status(*out)

    def loop(self, sim, lanes=False):
        """The compiled loop that the simulation ``sim`` steps in, the scalar
        one or, with ``lanes``, the one whose steps far from encounters take
        the planets in vector lanes: the same scalar loop for runs with and
        without force terms.

        Examples
        --------
        >>> tr = orbits.integrators.get("trace")
        >>> bodies = orbits.scenes.outer_solar_system()
        >>> plain = orbits.Simulation(bodies, tr, dt=20 * u.day)
        >>> gr = orbits.Simulation(bodies, tr, dt=20 * u.day,
        ...                        forces=[orbits.forces.GRPotential("Sun")])
        >>> tr.loop(plain) is tr.loop(gr)
        True
        """
        if lanes:
            return _trace.trace_loop(record=sim._force.recorder, lanes=True)
        # (before a first run binds the terms, the empty table's kernel and
        # recorder: a run with terms records with the same, stepping.with_terms)
        terms, _, recorder, _ = table_bound(sim._ws, len(sim._m), sim._force.recorder)
        return _trace.trace_loop(record=recorder, terms=terms)

    def lanes_wanted(self, ws, n, recorder=None):
        """Whether a run of ``n`` bodies takes its steps far from encounters
        with the planets in vector lanes, by the ``lanes`` option (see
        :func:`~orbits.integrators.wisdom_holman.lanes_choice`; ``recorder``
        the monitors' recorder, whose loop ``"auto"`` looks for).  Only the
        time differs: the results are the same bit for bit.

        Examples
        --------
        >>> tr = orbits.integrators.get("trace")
        >>> ws = tr.workspace(5)
        >>> tr.lanes_wanted({**ws, "steps_by_end": 10 ** 8}, 5), tr.lanes_wanted(ws, 3)
        (True, False)
        >>> orbits.integrators.get("trace", lanes="off").lanes_wanted(
        ...     {**ws, "steps_by_end": 10 ** 8}, 5)
        False
        """
        return lanes_choice(ws, self.config["lanes"], n, lambda: lanes_ready(
            _trace.trace_loop(record=_trace._record if recorder is None else recorder,
                              lanes=True)))

    def synchronize(self, ws, x, v):
        """Write the current inertial state into ``x``, ``v`` (the owed part of the
        segment's drift, on a copy); the internal state goes on unchanged."""
        if ws["state"][0]:
            _trace.trace_synchronize(
                ws["xh"], ws["vb"], ws["gm"], ws["eta"],
                int(ws["n_active"][0]), ws["enc"], ws["state"], float(ws["owed"][0]),
                ws["xs"], ws["vs"], x, v, ws["w1"], ws["w2"], self._inner(ws), self._tabs,
                self.config["rtol"])

    def checked_state(self, ws, t):
        """The criterion point where the last step's stopping conditions were
        checked (half a step before ``t``, synchronised by the map itself), or
        None where they were checked at ``t`` (an output, a call's last step)."""
        if not ws["state"][0] or ws["checked"][1] == 0.0:
            return None
        tc = float(ws["checked"][0])
        n = len(ws["gm"])
        x, v = np.zeros((n, 3)), np.zeros((n, 3))
        from_democratic_heliocentric(ws["xc"], ws["vc"], ws["gm"], x, v)
        return x, v, tc

    def behind(self, ws):
        """How far before the steps counted the state lies after a call whose
        inner integrator's step collapsed (bodies meeting head-on): the loop
        left ``x``, ``v`` at the start of the segment it could not finish, the
        last state it reached whole, half a step before the end of the last
        step done (0 otherwise).

        Examples
        --------
        >>> integ = orbits.integrators.get("trace")
        >>> integ.behind(integ.workspace(2))
        0.0
        """
        return float(ws["owed"][0]) if ws["state"][0] == 0 else 0.0

    def invalidate(self, ws):
        """The state was changed from outside (a merger, say): start again from
        ``x``, ``v``, with the body count and masses read again."""
        ws["state"][0] = 0
        ws["state"][1] = 0
        ws["owed"][0] = 0.0
