"""Frequency analysis of quasi-periodic signals and of planetary runs.

:func:`frequencies` is Laskar's numerical analysis of fundamental
frequencies (NAFF): it writes an evenly sampled signal, complex (``h + i k``,
``p + i q``) or real, as a sum of terms ``A exp(i (nu t + phi))`` and finds
the frequencies ``nu`` far more precisely than the peaks of a Fourier
transform.  :func:`secular_frequencies` applies it to a body's eccentricity
and inclination variables in a :class:`~orbits.Result` (the ``g`` and ``s``
frequencies of secular theory), and :func:`mean_motion_frequencies` to its
mean longitude or to a combination of mean longitudes, such as the great
inequality ``2 lambda_J - 5 lambda_S`` of Jupiter and Saturn.

The algorithm is in :mod:`orbits.analysis.naff`, the decomposition it returns
in :mod:`orbits.analysis.decomposition`, and the analyses of a run in
:mod:`orbits.analysis.planetary`; this package gives their public names.

Examples
--------
Jupiter and Saturn in the outer solar system over 200,000 years, with an
output every 200 years (500 steps of ``wh``):
>>> from orbits.analysis import mean_motion_frequencies, secular_frequencies
>>> sim = orbits.Simulation(orbits.scenes.outer_solar_system(), "wh", dt=146.1 * u.day)
>>> result = sim.run(until=2e5 * u.yr, outputs=1001, progress=False)
>>> sf = secular_frequencies(result, "Saturn", n=4)
>>> sf.body, sf.primary, sf.plane, len(sf.g), len(sf.s)
('Saturn', 'Sun', 'invariable', 4, 4)
>>> sf.g.frequencies[0].to(u.arcsec / u.yr).round(1)      # g6
<Quantity 28.3 arcsec / yr>
>>> sf.s.frequencies[0].to(u.arcsec / u.yr).round(1)      # s6
<Quantity -26.3 arcsec / yr>
>>> gi = mean_motion_frequencies(result, {"Jupiter": 2, "Saturn": -5}, n=3)
>>> gi.periods[0].to(u.yr).round(0)                       # the great inequality
<Quantity 891. yr>
>>> float(gi.amplitudes[0].round(2))
0.97
"""

from .decomposition import Frequencies
from .naff import SPACING_RTOL, frequencies
from .planetary import (PLANES, SecularFrequencies, mean_motion_frequencies,
                         secular_frequencies)

__all__ = ["Frequencies", "SecularFrequencies", "frequencies", "secular_frequencies",
           "mean_motion_frequencies", "SPACING_RTOL", "PLANES"]
