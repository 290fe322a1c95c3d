"""The checks of a sampled signal: plain values and their unit, evenly spaced
times, whole-number arguments, and angles reduced to one turn."""

import math
import numbers

import astropy.units as u
import numpy as np

__all__ = ["as_plain", "sampling_interval", "is_whole", "whole_number",
           "wrap_angle", "to_float"]

def as_plain(q, name):
    """Plain values and unit (None when not a Quantity)."""
    if isinstance(q, u.Quantity):
        return np.asarray(q.value), q.unit
    try:
        return np.asarray(q), None
    except Exception as exc:            # pragma: no cover - np.asarray takes nearly anything
        raise ValueError(f"{name}: expected an array, got {q!r}") from exc


def sampling_interval(t, rtol, hint=""):
    """The sampling interval of ``t``, evenly spaced to ``rtol`` of it; a ValueError
    otherwise (``hint``, on how to space them evenly, ends the message of uneven
    ones)."""
    d = np.diff(t.astype(float))
    mean = (t[-1] - t[0]) / (len(t) - 1)
    if np.any(d <= 0):
        k = int(np.argmax(d <= 0))
        raise ValueError(f"times: expected increasing times; times[{k + 1}] = {t[k + 1]:.10g} "
                         f"is not after times[{k}] = {t[k]:.10g}")
    if not mean > 0:
        raise ValueError("times: expected increasing times")
    spread = float(np.max(np.abs(d - mean))) / mean
    if spread > rtol:
        k = int(np.argmax(np.abs(d - mean)))
        raise ValueError(f"times: expected evenly spaced times (to {rtol:g} of the "
                         f"interval); interval {k} is {d[k]:.10g} against a mean of "
                         f"{mean:.10g} (relative difference {spread:.3g}){hint}")
    return float(mean)


def is_whole(value):
    """Whether ``value`` is a whole number: an integer, or a real number without a
    fractional part (not a bool)."""
    if isinstance(value, bool):
        return False
    return isinstance(value, numbers.Integral) or (
        isinstance(value, numbers.Real) and float(value).is_integer())


def whole_number(value, name, low, high, detail):
    """``value`` as an int from ``low`` to ``high`` (None: no bound); a ValueError
    naming ``name`` otherwise, ``detail`` ending the message of one out of range."""
    if not is_whole(value):
        raise ValueError(f"{name}: expected a whole number, got {value!r}")
    value = int(value)
    if value < low or (high is not None and value > high):
        bound = f">= {low}" if high is None else f"from {low} to {high}"
        raise ValueError(f"{name}: expected a whole number {bound}, got {value}{detail}")
    return value


def wrap_angle(angle):
    """Angles reduced to (-pi, pi]."""
    return -((-np.asarray(angle) + math.pi) % (2 * math.pi) - math.pi)


def to_float(x):
    """A Quantity's value, or a number, as a float."""
    return float(x.value) if isinstance(x, u.Quantity) else float(x)
