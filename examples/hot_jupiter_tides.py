"""
Tidal circularisation of a hot Jupiter
======================================

An inflated hot Jupiter (one Jupiter mass, twice Jupiter's radius) on an
orbit of 0.03 au and eccentricity 0.1 about a Sun-like star.  The star
raises a tide on the planet; :class:`orbits.forces.TidesConstantTimeLag`
makes the bulge lag by a constant time, so that each pericentre passage
dissipates a little energy, and the orbit circularises.  Beside the N-body
run are the orbit-averaged rates of Hut (1981), his equations 9 and 10 for
``da/dt`` and ``de/dt``, integrated from the same start.  ::

    python examples/hot_jupiter_tides.py                           # run and show the figure
    python examples/hot_jupiter_tides.py --png hot_jupiter_tides.png

How to read the figure:

* **top, the eccentricity** on a logarithmic axis: the N-body run's
  osculating ``e`` (solid) lies on Hut's curve (dashed) over the whole run;
  the dotted line is ``e0 exp(-t / tau_e)`` with the rate at the start, the
  textbook exponential: the orbit circularises faster than it, because the
  orbit shrinks and the tide grows steeply as the planet comes closer
  (``de/dt`` goes as ``a^-8``);
* **bottom, the semi-major axis**: it shrinks, as Hut's ``da/dt`` says.  The
  planet's spin is held fixed (the term does not follow it) at the starting
  mean motion.  Circularising at nearly constant angular momentum, which
  goes as ``sqrt(a (1 - e^2))``, shrinks the orbit; and once the planet
  orbits faster than it spins, the tide drags it inward as well, faster and
  faster.  A real planet's spin, which holds little angular momentum, would
  follow the orbit instead.

The time lag, 0.1 day, corresponds to a tidal quality factor ``Q ~ 1 / (n
tau)`` of about 3, some 10^4 times more dissipative than Jupiter's: the
circularisation that takes 16 years here would take some 10^5 years.  Both
rates are proportional to the lag, so a real planet's curves are these with
the time axis stretched.  The force reads velocities and dissipates energy:
the run uses ``ias15``.
"""

# %%
# Hut's orbit-averaged equations
# ------------------------------
# Hut (1981) eqs. 9 and 10, with his ``k`` written ``k2`` as in the term and
# ``(k / T) q (1 + q) (R / a)^8 = k2 tau n^2 q (R / a)^5`` for the
# distorted body of mass ``m`` and radius ``R``, ``q = M_star / m``.  They are
# integrated with a fixed-step fourth-order Runge-Kutta method, on the run's
# output times.

import argparse
import math

import astropy.units as u
import matplotlib.pyplot as plt
import numpy as np

import orbits
from orbits import forces

A0, E0 = 0.03 * u.au, 0.1
RADIUS = 2 * u.Rjup         # inflated, like the largest hot Jupiters
K2 = 0.5                    # Jupiter's Love number is about 0.5
LAG = 0.1 * u.day           # exaggerated: see the reading guide
#: Runge-Kutta steps between two outputs for Hut's equations: with an output
#: every 5 orbits, a step of about an orbit, where the rates change over thousands
SUBSTEPS = 4


def star_and_planet():
    b = orbits.BodySet()
    b.add("Star", mass=1 * u.Msun)
    b.add("Planet", mass=1 * u.Mjup, primary="Star", a=A0, e=E0)
    b.move_to_com()
    return b


def hut_rates(a, e, gm_total, q, k2, lag, radius, spin):
    """``(da/dt, de/dt)`` of Hut (1981), eqs. 9 and 10, in the units given."""
    n = math.sqrt(gm_total / a ** 3)
    e2 = e * e
    f1 = 1 + 31 / 2 * e2 + 255 / 8 * e2 ** 2 + 185 / 16 * e2 ** 3 + 25 / 64 * e2 ** 4
    f2 = 1 + 15 / 2 * e2 + 45 / 8 * e2 ** 2 + 5 / 16 * e2 ** 3
    f3 = 1 + 15 / 4 * e2 + 15 / 8 * e2 ** 2 + 5 / 64 * e2 ** 3
    f4 = 1 + 3 / 2 * e2 + 1 / 8 * e2 ** 2
    c = k2 * lag * n ** 2 * q * (radius / a) ** 5
    s = (1 - e2) ** 1.5 * spin / n
    dadt = -6 * c * a / (1 - e2) ** 7.5 * (f1 - s * f2)
    dedt = -27 * c * e / (1 - e2) ** 6.5 * (f3 - 11 / 18 * s * f4)
    return np.array([dadt, dedt])


def hut_solution(times, a0, e0, **params):
    """Hut's ``a`` and ``e`` at ``times`` (ascending, from 0), by fourth-order
    Runge-Kutta with :data:`SUBSTEPS` steps between two times."""
    y = np.array([a0, e0])
    out = [y]
    for t0, t1 in zip(times[:-1], times[1:]):
        h = (t1 - t0) / SUBSTEPS
        for _ in range(SUBSTEPS):
            s1 = hut_rates(*y, **params)
            s2 = hut_rates(*(y + h / 2 * s1), **params)
            s3 = hut_rates(*(y + h / 2 * s2), **params)
            s4 = hut_rates(*(y + h * s3), **params)
            y = y + h / 6 * (s1 + 2 * s2 + 2 * s3 + s4)
        out.append(y)
    return np.array(out).T


# %%
# The run and the figure
# ----------------------

def main(orbits_run=3000, outputs=601, png=None):
    """Run ``orbits_run`` orbital periods and draw the figure.

    Returns the run's :class:`~orbits.Result`, the N-body and Hut's
    semi-major axes [au] and eccentricities as ``{"a": (nbody, hut), "e":
    (nbody, hut)}``, and the figure (drawn into a pyplot figure); with
    ``png``, also writes it there.
    """
    bodies = star_and_planet()
    U = bodies.units
    m_star, m = bodies.masses.to_value(U.mass)
    gm_total = U.G * (m_star + m)
    n0 = math.sqrt(gm_total / A0.to_value(U.length) ** 3)
    tide = forces.TidesConstantTimeLag("Planet", k2=K2, time_lag=LAG, radius=RADIUS,
                                       spin=[0, 0, n0] * u.rad / U.time)
    sim = orbits.Simulation(bodies, "ias15", forces=[tide])
    period = 2 * math.pi / n0 * U.time
    result = sim.run(until=orbits_run * period, outputs=outputs, progress=False)

    el = result.elements("Planet", primary="Star")
    a, e = el["a"].to_value(U.length), el["e"].to_value(u.one)
    t = result.times.to_value(U.time)
    params = dict(gm_total=gm_total, q=m_star / m, k2=K2, lag=LAG.to_value(U.time),
                  radius=RADIUS.to_value(U.length), spin=n0)
    a_hut, e_hut = hut_solution(t, a[0], e[0], **params)
    tau_e = -e[0] / hut_rates(a[0], e[0], **params)[1]
    print(f"e: {e[0]:.3f} -> {e[-1]:.4f} in {orbits_run} orbits "
          f"({result.times[-1].to(u.yr):.1f}); Hut: {e_hut[-1]:.4f}; largest relative "
          f"difference over the run {np.abs(e / e_hut - 1).max():.1e}")
    print(f"a: {a[0]:.5f} -> {a[-1]:.5f} au; Hut: {a_hut[-1]:.5f} au; largest relative "
          f"difference {np.abs(a / a_hut - 1).max():.1e}")
    print(f"e-folding time at the start: {(tau_e * U.time).to(u.yr):.2f}")

    years = result.times.to_value(u.yr)
    fig, (ax_e, ax_a) = plt.subplots(2, 1, sharex=True, figsize=(8, 6.5),
                                     gridspec_kw={"height_ratios": [1.6, 1]})
    ax_e.semilogy(years, e, color="C0", lw=2.5, alpha=0.6, label="N-body (osculating)")
    ax_e.semilogy(years, e_hut, "k--", lw=1, label="Hut (1981), eqs. 9-10")
    ax_e.semilogy(years, e[0] * np.exp(-t / tau_e), "k:", lw=1,
                  label=r"$e_0 \exp(-t/\tau_e)$, the rate at the start")
    ax_e.set_ylabel("eccentricity")
    ax_e.legend()
    ax_a.plot(years, a, color="C1", lw=2.5, alpha=0.6, label="N-body (osculating)")
    ax_a.plot(years, a_hut, "k--", lw=1, label="Hut (1981)")
    ax_a.set_ylabel("a [au]")
    ax_a.set_xlabel("time [yr]")
    ax_a.legend()
    for ax in (ax_e, ax_a):
        ax.grid(True, which="both", alpha=0.3)
    fig.suptitle(f"a hot Jupiter circularising: tide on the planet, $k_2$ = {K2}, "
                 f"lag {LAG.to_value(u.day):g} d, R = {RADIUS.to_value(u.Rjup):g} $R_J$")
    fig.tight_layout()
    if png is not None:
        fig.savefig(png, dpi=90)
    return result, {"a": (a, a_hut), "e": (e, e_hut)}, fig


# %%
# Running it
# ----------
# Over 3000 orbits (16 years) ``e`` falls from 0.1 to 0.02 and the orbit
# shrinks by 6 %.  The run and Hut's equations agree to 2e-4 in ``a`` and to
# 7e-3 in ``e``: the osculating elements carry the short-period wobble of the
# tide's conservative part, some 5e-5 of the star's pull (``3 k2 (M / m)
# (R / a)^5``), a wobble of about 1e-4 in ``e`` itself, which at ``e = 0.02``
# is several parts in 1000 of it.  The documentation's build runs 1500 orbits.

if __name__ == "__main__":
    parser = argparse.ArgumentParser(description="A hot Jupiter's orbit circularising "
                                                 "under the tide raised on it.")
    parser.add_argument("--orbits", type=int, default=3000,
                        help="length of the run in orbital periods (3000)")
    parser.add_argument("--outputs", type=int, default=601)
    parser.add_argument("--png", metavar="PATH", help="also write the figure to PATH")
    args = parser.parse_args()
    main(args.orbits, args.outputs, args.png)
    plt.show()
