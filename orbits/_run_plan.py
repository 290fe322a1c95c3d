"""A run's plan: where a run to a given time takes its outputs (a
:class:`~orbits.records.RunPlan`): evenly spaced times for an adaptive method,
the nearest step boundaries and a shortened last step for a fixed-step one,
with the checks that the outputs fit the run's steps, and of the run's limits
in wall-clock seconds.
"""

import math
import numbers
import warnings

from .errors import OrbitsWarning
from .records import RunPlan

__all__ = ["plan", "checked_seconds", "MAX_STEPS"]

#: The most steps one run may take: beyond 2**53 float64 no longer tells the
#: times of neighbouring steps apart.
MAX_STEPS = float(2 ** 53)


def checked_seconds(wall_limit, checkpoint_interval):
    """``wall_limit`` as a float (None: no limit), after checking it and
    ``checkpoint_interval``: a positive number of seconds, and one >= 0."""
    if wall_limit is not None and not _positive_number(wall_limit):
        raise ValueError(f"wall_limit must be a positive number of seconds, "
                         f"got {wall_limit!r}")
    if checkpoint_interval is not None and not (
            _positive_number(checkpoint_interval) or checkpoint_interval == 0):
        raise ValueError(f"checkpoint_interval must be a number of seconds >= 0, "
                         f"got {checkpoint_interval!r}")
    return None if wall_limit is None else float(wall_limit)


def _positive_number(value):
    return (isinstance(value, numbers.Real) and not isinstance(value, bool)
            and 0 < float(value) < math.inf)


def plan(sim, until_v, outputs, until, default_outputs):
    """Where a run of ``sim`` to ``until_v`` takes its outputs: a :class:`RunPlan`
    (``outputs`` None: ``default_outputs``, or fewer for a short fixed-step run)."""
    now = sim._now()
    shown = until if until is not None else until_v
    if not math.isfinite(until_v):
        raise ValueError(f"until must be a finite time, got {shown}")
    if until_v == now:
        raise ValueError(f"until = {shown} is the current time: there is nothing to run")
    sign = 1 if until_v > now else -1
    default = outputs is None
    if default:
        outputs = default_outputs
    if (isinstance(outputs, bool) or not isinstance(outputs, numbers.Integral)) and not (
            isinstance(outputs, numbers.Real) and float(outputs).is_integer()):
        raise ValueError(f"outputs must be a whole number >= 1, got {outputs!r}")
    outputs = int(outputs)
    if outputs < 1:
        raise ValueError(f"outputs must be a whole number >= 1, got {outputs}")
    if sim.integrator.adaptive:
        # outputs at exactly evenly spaced times, hit by shortening a step
        return RunPlan(until_v, outputs, 0.0, 0, False, sim.steps, now)
    ratio = abs(until_v - now) / sim._dt
    if not ratio < MAX_STEPS:
        raise ValueError(f"until = {shown} is {ratio:.3g} steps of dt = {sim.dt:.6g} "
                         f"away: more than the {MAX_STEPS:.3g} steps whose times float64 "
                         f"can tell apart; use a larger dt or a nearer until")
    n_full = int(round(ratio))
    if abs(ratio - n_full) > 1e-9 * max(1.0, ratio):
        n_full = int(math.floor(ratio))
    partial = sign * (until_v - _time_after(sim, n_full, sign))
    has_partial = partial > 1e-12 * max(abs(until_v - now), sim._dt)
    plan = RunPlan(until_v, outputs, ratio, n_full, bool(has_partial), sim.steps, now)
    total = plan.total_steps
    if default and outputs > total + 1:
        # one per step; a shortened last step leaves room for one fewer, as
        # outputs go to the nearest step boundary
        outputs = total + 1
        while outputs > 2 and not _marks_ok(plan._replace(outputs=outputs), total):
            outputs -= 1
        steps = f"{total} step" + ("" if total == 1 else "s")
        warnings.warn(f"the run has only {steps}: taking {outputs} outputs "
                      f"instead of the default {default_outputs}", OrbitsWarning,
                      stacklevel=5)
        plan = plan._replace(outputs=outputs)
    if outputs > total + 1 or not _marks_ok(plan, total):
        raise ValueError(f"outputs = {outputs} needs more steps than the run has "
                         f"({total}); ask for at most {total + 1} outputs or use a "
                         f"smaller dt")
    return plan


def _time_after(sim, n, sign=1):
    # the time after n more steps of dt in the direction sign, computed as
    # every step count is
    return sim._t_base + (sim._steps_since_base + sign * n) * sim._dt


def _marks_ok(plan, total):
    # the plan's marks are strictly increasing and below total, without
    # walking a million of them where arithmetic tells: marks are round(i s)
    # with s = ratio / (outputs - 1); within a quarter step of a whole k they
    # are i k exactly, and at s >= 2 consecutive ones are at least one apart
    o = plan.outputs
    if o > 2:
        s = plan.ratio / (o - 1)
        k = int(round(s))
        if (k >= 1 and abs(plan.ratio - k * (o - 1)) < 0.25) or s >= 2:
            return min(int(round((o - 2) * s)), plan.n_full) < total
    return _increasing(plan.marks(), total)


def _increasing(marks, total):
    last = 0
    for mark in marks:
        if mark <= last:
            return False
        last = mark
    return last < total or (last == 0 and total > 0)
