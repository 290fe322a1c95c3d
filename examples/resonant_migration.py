"""
Resonant capture: two planets migrate into the 2:1 resonance
============================================================

A Saturn-mass planet ``b`` at 1 au and a half-Saturn ``c`` outside it, with a
period ratio of 2.25, as a protoplanetary disc might leave them.  The disc
is represented by :class:`orbits.forces.Migration`: ``c`` migrates inward on
``tau_a`` = 20 000 years and both planets' eccentricities are damped on
``tau_e`` = 1000 years.  The orbits converge, and when the period ratio
reaches 2 the planets are caught in the 2:1 mean-motion resonance and
migrate on together, ``c`` pushing ``b`` inward.  ::

    python examples/resonant_migration.py                          # run and show the figure
    python examples/resonant_migration.py --png resonant_migration.png

How to read the figure, top to bottom:

* **semi-major axes**: ``c`` moves in steadily; ``b`` stays put until the
  capture, then moves in too, pushed by ``c`` through the resonance;
* **period ratio** ``P_c / P_b``: falls from 2.25 and stops at 2, where it
  stays while the pair migrates (osculating periods, so it wobbles a little);
* **eccentricities**: damped at first; at the capture the resonance pumps
  ``b``'s up, to an equilibrium where the pumping balances the damping;
* **the resonant angle** ``phi = 2 lambda_c - lambda_b - varpi_b`` (mean
  longitudes ``lambda = Omega + omega + M``, longitude of pericentre
  ``varpi = Omega + omega``, from :meth:`orbits.Result.elements`): before
  the capture it takes every value (it circulates, the dots fill the panel);
  after it, it stays in a narrow band near 0 (it librates): the planets'
  conjunctions keep happening near ``b``'s apocentre, which is what holds
  the resonance.  The band widens slowly: with eccentricity damping the
  libration is overstable (Goldreich & Schlichting 2014, AJ 147, 32), and
  given long enough a pair can leave the resonance.

The capture needs the migration to be slow compared with the resonance's
own libration (adiabatic): with ``tau_a`` ten times shorter, or with
Earth-mass planets, the pair runs through 2:1 without being caught.
:class:`~orbits.forces.Migration` reads velocities and dissipates energy, so
the run uses ``ias15``; the Wisdom-Holman methods refuse it.
"""

# %%
# The run
# -------
# ``Migration`` acts on one body, relative to its primary (by default the
# most massive other body, here the star), so each planet gets its own term.

import argparse

import astropy.units as u
import matplotlib.pyplot as plt
import numpy as np

import orbits
from orbits import forces

TAU_A = 2e4 * u.yr          # the outer planet's migration time scale
TAU_E = 1e3 * u.yr          # both planets' eccentricity damping time scale
PERIOD_RATIO_0 = 2.25       # outside the 2:1 (and the weaker 7:3 at 2.33)


def planets():
    """The star and the two planets, ``c`` at period ratio 2.25 outside ``b``."""
    b = orbits.BodySet()
    b.add("Star", mass=1 * u.Msun)
    b.add("b", mass=0.3 * u.Mjup, primary="Star", a=1 * u.au, e=0.02)
    b.add("c", mass=0.15 * u.Mjup, primary="Star", a=PERIOD_RATIO_0 ** (2 / 3) * u.au,
          e=0.02, omega=1 * u.rad, M=2 * u.rad)
    b.move_to_com()
    return b


def wrap(angle):
    """An angle (rad) in [-pi, pi)."""
    return (np.asarray(angle) + np.pi) % (2 * np.pi) - np.pi


def resonant_angle(result):
    """``phi = 2 lambda_c - lambda_b - varpi_b`` at every output, rad in [-pi, pi)."""
    el = {name: result.elements(name) for name in ("b", "c")}
    varpi = {name: (e["Omega"] + e["omega"]).to_value(u.rad) for name, e in el.items()}
    lam = {name: varpi[name] + e["M"].to_value(u.rad) for name, e in el.items()}
    return wrap(2 * lam["c"] - lam["b"] - varpi["b"])


def libration(phi):
    """Centre and half-width (rad) of an angle's excursions about its circular
    mean: a half-width near pi means the angle circulates."""
    centre = np.angle(np.mean(np.exp(1j * phi)))
    return centre, float(np.abs(wrap(phi - centre)).max())


def main(until=1e4 * u.yr, outputs=4001, png=None):
    """Migrate the pair for ``until`` and draw the figure.

    Returns the run's :class:`~orbits.Result` and the figure (drawn into a
    pyplot figure, so that ``plt.show()`` and the gallery show it); with
    ``png``, also writes it there.
    """
    terms = [forces.Migration("c", tau_a=TAU_A, tau_e=TAU_E),
             forces.Migration("b", tau_e=TAU_E)]
    sim = orbits.Simulation(planets(), "ias15", forces=terms)
    result = sim.run(until=until, outputs=outputs, progress=False)

    t = result.times.to_value(u.yr)
    el = {name: result.elements(name) for name in ("b", "c")}
    ratio = (el["c"]["P"] / el["b"]["P"]).to_value(u.one)
    phi = resonant_angle(result)
    last = slice(3 * len(t) // 4, None)
    centre, half = libration(phi[last])
    print(f"period ratio: {ratio[0]:.3f} at the start, {ratio[last].mean():.3f} over the "
          f"last quarter of the run")
    state = "librating" if half < np.pi / 2 else "circulating"
    print(f"phi over the last quarter: {np.degrees(centre):+.0f} deg "
          f"+/- {np.degrees(half):.0f} deg ({state})")
    print(f"b moved from {el['b']['a'][0]:.3f} to {el['b']['a'][-1]:.3f}, "
          f"e_b = {el['b']['e'][last].mean():.3f}")

    fig, axes = plt.subplots(4, 1, sharex=True, figsize=(8, 9),
                             gridspec_kw={"height_ratios": [1, 1, 1, 1.4]})
    for name, colour in (("b", "C0"), ("c", "C1")):
        axes[0].plot(t, el[name]["a"].to_value(u.au), color=colour, label=name)
        axes[2].plot(t, el[name]["e"].to_value(u.one), color=colour, lw=0.8, label=name)
    axes[0].set_ylabel("a [au]")
    axes[0].legend(loc="center right")
    axes[1].plot(t, ratio, color="k", lw=0.8)
    axes[1].axhline(2, color="C3", ls=":", lw=1)
    axes[1].text(t[0], 2, " 2:1", color="C3", ha="left", va="top")
    axes[1].set_ylabel("$P_c / P_b$")
    axes[2].set_ylabel("e")
    axes[2].legend(loc="center right")
    axes[3].plot(t, np.degrees(phi), ".", ms=1.5, color="k")
    axes[3].set_ylim(-180, 180)
    axes[3].set_yticks([-180, -90, 0, 90, 180])
    axes[3].set_ylabel(r"$\phi = 2\lambda_c - \lambda_b - \varpi_b$ [deg]")
    axes[3].set_xlabel("time [yr]")
    for ax in axes:
        ax.grid(True, alpha=0.3)
    fig.suptitle(f"convergent migration into the 2:1 resonance "
                 f"($\\tau_a$ = {TAU_A.to_value(u.yr):g} yr, $\\tau_e$ = "
                 f"{TAU_E.to_value(u.yr):g} yr)")
    fig.tight_layout()
    if png is not None:
        fig.savefig(png, dpi=90)
    return result, fig


# %%
# Running it
# ----------
# The period ratio reaches 2 after about 1500 years; from then on the angle
# librates (+/- 15 degrees at first, +/- 54 by 10 000 years), ``b``'s
# eccentricity settles near 0.07 and the two planets move in together, ``b``
# from 1 to 0.85 au.  The documentation's build runs 4000 years.

if __name__ == "__main__":
    parser = argparse.ArgumentParser(description="Two planets migrating into the 2:1 "
                                                 "resonance.")
    parser.add_argument("--years", type=float, default=1e4, help="length of the run (1e4)")
    parser.add_argument("--outputs", type=int, default=4001)
    parser.add_argument("--png", metavar="PATH", help="also write the figure to PATH")
    args = parser.parse_args()
    main(args.years * u.yr, args.outputs, args.png)
    plt.show()
