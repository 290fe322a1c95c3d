"""A run's failures: a compiled loop's status other than OK (a non-finite state,
a step-size underflow, a stopping condition met, a Newton iteration that did
not converge, a user force of the wrong shape or that raised) turned into the named exception
of :mod:`orbits.errors`, which carries the result up to the last good state.
"""

import time as _time

from ._kernels.status import Status
from ._kernels.terms import TermTable, user_flag
from ._user_functions import RAISED
from .errors import (CloseEncounter, Collision, ConvergenceFailure, Escape, ForceTermError,
                     NonFiniteState, StepSizeUnderflow)

__all__ = ["fail"]


def fail(sim, status, rec, wall0):
    """End the run of ``sim`` that stopped at ``status`` (not ``Status.OK``): the
    last output recorded, the recorder closed, and the named exception raised
    with the result up to the last good state."""
    reason = {Status.NON_FINITE: "non-finite state",
              Status.STEP_UNDERFLOW: "step-size underflow",
              Status.CLOSE_ENCOUNTER: "close encounter",
              Status.ESCAPE: "escape",
              Status.COLLISION: "collision",
              Status.NO_CONVERGENCE: "no convergence"}.get(status, f"status {status!r}")
    rec.end_status = int(status)
    sim._drain_log(rec)
    rec.output(sim, final=True)
    rec.close()
    result = sim._with_log(rec.result(sim, _time.perf_counter() - wall0 if wall0 else 0.0,
                                       status=reason))
    t = sim.time
    failed = _user_function_failed(sim._fargs)
    if failed:
        what = ("raised an exception (a compiled function's exception does not "
                "leave the loop: call it from Python on that state to see it)"
                if failed == RAISED else
                "returned an array of another shape than during the check before the run")
        raise ForceTermError(
            f"a user force {what}, in step {sim.steps + 1} (from t = {t:.10g}); the "
            f"simulation was left at the last good state, step {sim.steps}",
            term="UserForce", field="func")
    if status == Status.NON_FINITE:
        raise NonFiniteState(
            f"the state became non-finite in step {sim.steps + 1} (from t = {t:.10g}); "
            f"the result up to the last good state, at step {sim.steps}, is kept on "
            f"this exception (.result) and the simulation was left there",
            time=t, step=sim.steps, result=result)
    if status == Status.NO_CONVERGENCE:
        raise ConvergenceFailure(
            f"the Newton iteration of {sim.integrator.name!r} did not converge in step "
            f"{sim.steps + 1} (from t = {t:.10g}); try a smaller dt; the result up to "
            f"the last good state is kept on .result", time=t, step=sim.steps,
            result=result)
    name = lambda k: sim._names[sim._order[k]]  # noqa: E731
    if status == Status.STEP_UNDERFLOW:
        # the bodies that drove it, where the method names them (not trace)
        who = [name(int(k)) for k in sim._ws.get("info", ()) if k >= 0]
        raise StepSizeUnderflow(
            f"the step size of {sim.integrator.name!r} collapsed at t = {t:.10g} "
            f"(step {sim.steps})" + (f", driven by {', '.join(map(repr, who))}"
                                       if who else "")
            + "; the result up to the last good state is kept on .result",
            time=t, step=sim.steps, result=result)
    i, j = (int(k) for k in sim._stop_info)
    if status == Status.CLOSE_ENCOUNTER:
        bodies = (name(i), name(j))
        tc, dist = (float(a) for a in sim._stop_hit[:2])
        raise CloseEncounter(f"close encounter of {bodies[0]!r} and {bodies[1]!r} "
                             f"(closest at t = {tc:.10g} {sim.units.time}, separation "
                             f"{dist:.6g} {sim.units.length}) in the step ending at "
                             f"t = {t:.10g} (step {sim.steps}); the result up to here "
                             f"is kept on .result", time=t, step=sim.steps,
                             result=result, bodies=bodies)
    if status == Status.COLLISION:
        bodies = (name(i), name(j))
        q = sim.units.quantity
        tc, dist, speed = (float(a) for a in sim._stop_hit)
        # after the state kept: a step the integrator could not finish (beyond
        # the rounding of a contact at a step's end)
        now = sim._now()
        inside = tc <= now + 1e-9 * abs(sim._dt) + 1e-15 * abs(now)
        where = (f"in the step ending at t = {t:.10g} (step {sim.steps})" if inside else
                 f"in a step the integrator could not finish; the run stopped at "
                 f"t = {t:.10g} (step {sim.steps}), the last state it reached whole")
        raise Collision(f"{bodies[0]!r} and {bodies[1]!r} collided "
                        f"({'closest' if inside else 'touching'} at t = {tc:.10g}, "
                        f"separation {dist:.6g} {sim.units.length}) "
                        f"{where}; the result up to here is kept on .result",
                        time=t, step=sim.steps,
                        result=result, bodies=bodies, contact_time=q(tc, "time"),
                        distance=q(dist, "length"),
                        speed=q(speed, "length") / sim.units.time)
    if status == Status.ESCAPE:
        bodies = (name(i),)
        raise Escape(f"{bodies[0]!r} escaped at t = {t:.10g} (step {sim.steps}); the "
                     f"result up to here is kept on .result", time=t, step=sim.steps,
                     result=result, bodies=bodies)
    raise RuntimeError(f"unexpected status {status!r}")  # pragma: no cover


def _user_function_failed(fargs):
    """The flag of a user term of a table in ``fargs`` (nested tuples) that
    returned the wrong shape or raised (see :mod:`orbits._user_functions`);
    0 where none did."""
    if isinstance(fargs, TermTable):
        return user_flag(fargs.user)
    if isinstance(fargs, tuple):
        return max((_user_function_failed(f) for f in fargs), default=0)
    return 0
