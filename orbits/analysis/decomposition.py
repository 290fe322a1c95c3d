"""A quasi-periodic decomposition: the terms ``A exp(i (nu t + phi))`` (or
cosines) that :func:`~orbits.analysis.frequencies` finds, their periods, their
sum at any time, and their table."""

import dataclasses
import math

import astropy.units as u
import numpy as np

from ._sampling import to_float

__all__ = ["Frequencies"]


@dataclasses.dataclass(frozen=True, repr=False)
class Frequencies:
    """A quasi-periodic decomposition: what :func:`~orbits.analysis.frequencies` returns.

    For a complex signal ``f(t) ~ sum_k A_k exp(i (nu_k t + phi_k))``; for a
    real one ``f(t) ~ sum_k A_k cos(nu_k t + phi_k)`` with ``nu_k >= 0``.
    Terms are in order of decreasing amplitude.

    Attributes
    ----------
    frequencies : Quantity or ndarray, shape (n,)
        Angular frequencies ``nu_k``: rad per the unit of the times when they
        were a Quantity, plain floats (rad per unit of time) otherwise.
    amplitudes : Quantity or ndarray, shape (n,)
        ``A_k >= 0``, in the unit of the signal.
    phases : Quantity or ndarray, shape (n,)
        ``phi_k`` in (-pi, pi], at time zero of the times given (rad).
    real : bool
        Whether the signal was real (cosine terms, frequencies >= 0).

    Examples
    --------
    >>> from orbits.analysis import frequencies
    >>> t = np.arange(2000) * 0.5
    >>> fa = frequencies(t, 2 * np.cos(0.3 * t + 1), n=1)
    >>> len(fa), fa.real, round(float(fa.frequencies[0]), 12)
    (1, True, 0.3)
    >>> fa.evaluate(t[:2]).round(6)
    array([1.080605, 0.816975])
    """

    frequencies: object
    amplitudes: object
    phases: object
    real: bool

    def __len__(self):
        return len(self.frequencies)

    @property
    def periods(self):
        """``2 pi / |nu_k|``, shape (n,), in the unit of the times (inf for ``nu = 0``).

        Examples
        --------
        >>> from orbits.analysis import frequencies
        >>> t = np.arange(1000) * u.yr
        >>> frequencies(t, np.exp(-2j * np.pi * t.value / 50), n=1).periods.round(9)
        <Quantity [50.] yr>
        """
        nu = self.frequencies
        with np.errstate(divide="ignore"):
            if isinstance(nu, u.Quantity):
                return (2 * math.pi * u.rad / np.abs(nu)).to(1 / (nu.unit / u.rad))
            return 2 * math.pi / np.abs(nu)

    def evaluate(self, times):
        """The decomposition's sum at the given times.

        Parameters
        ----------
        times : Quantity or array_like, shape (m,)
            In a unit of the kind the frequencies are per (plain floats if
            the frequencies are).

        Returns
        -------
        Quantity or ndarray, shape (m,)
            Complex for a complex signal, real for a real one, in the unit of
            the amplitudes.

        Examples
        --------
        >>> from orbits.analysis import frequencies
        >>> t = np.linspace(0, 100, 1001)
        >>> f = np.exp(1.5j * t) + 0.1 * np.exp(-0.4j * t)
        >>> fa = frequencies(t, f, n=2)
        >>> bool(np.abs(fa.evaluate(t) - f).max() < 1e-10)
        True
        """
        nu, phi, amp = self.frequencies, self.phases, self.amplitudes
        if isinstance(nu, u.Quantity):
            t = u.Quantity(times).to_value(u.rad / nu.unit)
            nu = nu.value
        else:
            t = np.asarray(times, dtype=float)
        phi = phi.to_value(u.rad) if isinstance(phi, u.Quantity) else np.asarray(phi)
        unit = amp.unit if isinstance(amp, u.Quantity) else None
        a = amp.value if unit is not None else np.asarray(amp)
        arg = np.outer(np.atleast_1d(t), nu) + phi
        out = (np.cos(arg) @ a) if self.real else (np.exp(1j * arg) @ a)
        out = out.reshape(np.shape(t))
        return out if unit is None else out << unit

    def __repr__(self):
        nu = self.frequencies
        funit = f" [{nu.unit}]" if isinstance(nu, u.Quantity) else ""
        periods = self.periods
        punit = f" [{periods.unit}]" if isinstance(periods, u.Quantity) else ""
        amp = self.amplitudes
        aunit = f" [{amp.unit}]" if isinstance(amp, u.Quantity) and str(amp.unit) else ""
        kind = "real" if self.real else "complex"
        lines = [f"<Frequencies: {len(self)} term{'' if len(self) == 1 else 's'} of a "
                 f"{kind} signal",
                 f"{'':>4}{'frequency' + funit:>26}{'period' + punit:>20}"
                 f"{'amplitude' + aunit:>16}{'phase [rad]':>14}"]
        for k in range(len(self)):
            lines.append(f"{k:>4}{to_float(nu[k]):>26.14g}{to_float(periods[k]):>20.10g}"
                         f"{to_float(amp[k]):>16.8g}{to_float(self.phases[k]):>14.8f}")
        return "\n".join(lines) + ">"
