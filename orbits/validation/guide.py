"""A widely copied integrator-choice guide, checked against measurement.

The guide's spring oscillator: k = 100, m = 1, x0 = 1, v0 = 0, dt = 0.01,
1000 steps, energy E = v^2/2 + k x^2/2 = 50.  It claims that explicit Euler's
energy drifts 8.2 % by step 100 and 103.4 % by step 999, and that
semi-implicit (symplectic) Euler stays under 1 % throughout.

Explicit Euler on this oscillator multiplies the energy by exactly
``1 + k dt^2 / m`` every step (``x' = x + dt v``, ``v' = v - dt k x`` give
``v'^2 + k x'^2 = (1 + k dt^2)(v^2 + k x^2)`` for m = 1), so its drift after n
steps is ``(1.01)^n - 1``: 170 % at step 100 and about 2e6 % at step 999.
Symplectic Euler conserves a modified energy; the true energy oscillates
about it with a relative amplitude near ``omega dt / 2`` = 5 % at
``omega dt = 0.1``.  The section measures every method that takes a user
force and sets the measured figures beside the claimed ones and these.
"""

import math
import pathlib

import numba
import numpy as np

from .. import integrators
from ..custom import integrate
from ..errors import OrbitsError, RunError
from ._format import fmt_err
from ._runner import Task

__all__ = ["TITLE", "tasks", "section", "measure", "K", "DT", "STEPS", "CLAIMS",
           "euler_theory"]

TITLE = "The integrator-choice guide, checked"

K, M, X0, V0, DT, STEPS = 100.0, 1.0, 1.0, 0.0, 0.01, 1000

#: the guide's figures: method -> {step: relative energy drift}, and the
#: bound it gives for symplectic Euler over the whole run
CLAIMS = {"euler": {100: 0.082, 999: 1.034}, "symplectic-euler": {"max": 0.01}}


def euler_theory(n):
    """Explicit Euler's exact relative energy drift after ``n`` steps."""
    return (1 + K * DT ** 2 / M) ** n - 1


def measure():
    """Every fixed-step method that takes a user force, on the spring (one task)."""
    k_over_m = K / M

    @numba.njit
    def spring(x, v, t):
        return -k_over_m * x

    e0 = 0.5 * M * V0 ** 2 + 0.5 * K * X0 ** 2
    rows = []
    for info in integrators.available():
        if info.adaptive:
            continue
        row = {"method": info.name, "order": info.order, "symplectic": info.symplectic,
               "outcome": "completed", "message": "", "drift": None}
        try:
            tr = integrate(spring, X0, V0, dt=DT, steps=STEPS, method=info.name)
        except RunError as exc:
            row.update(outcome=type(exc).__name__, message=str(exc))
            tr = exc.result
        except OrbitsError as exc:
            row.update(outcome="not applicable", message=str(exc))
            rows.append(row)
            continue
        energy = 0.5 * M * tr.v ** 2 + 0.5 * K * tr.x ** 2
        row["drift"] = np.abs(energy / e0 - 1)
        rows.append(row)
    return {"rows": rows}


def tasks(quick):
    return [Task("orbits.validation.guide:measure", {}, 1.0)]


def _at(drift, n):
    if drift is None or len(drift) <= n:
        return math.nan
    return float(drift[n])


def _pct(x):
    if not math.isfinite(x):
        return "–"
    return f"{100 * x:.4g} %"


def section(results, out_dir, quick):
    rows = results[0]["rows"]
    out_dir = pathlib.Path(out_dir)
    by = {r["method"]: r for r in rows}
    eu, se = by.get("euler"), by.get("symplectic-euler")
    lines = [f"## {TITLE}", "",
             f"The guide's spring oscillator: k = {K:g}, m = {M:g}, x0 = {X0:g}, v0 = {V0:g}, "
             f"dt = {DT:g}, {STEPS} steps (omega dt = {math.sqrt(K / M) * DT:g}), through "
             "`orbits.integrate` with a compiled force. Drift is |E/E0 − 1|.", "",
             "| claim | claimed | measured | exact theory |", "|---|---|---|---|",
             f"| explicit Euler, step 100 | {_pct(CLAIMS['euler'][100])} | "
             f"{_pct(_at(eu and eu['drift'], 100))} | {_pct(euler_theory(100))} |",
             f"| explicit Euler, step 999 | {_pct(CLAIMS['euler'][999])} | "
             f"{_pct(_at(eu and eu['drift'], 999))} | {_pct(euler_theory(999))} |",
             f"| semi-implicit Euler, largest over the run | under "
             f"{_pct(CLAIMS['symplectic-euler']['max'])} | "
             f"{_pct(float(se['drift'].max()) if se and se['drift'] is not None else math.nan)}"
             f" | about omega dt / 2 = {_pct(math.sqrt(K / M) * DT / 2)} |", ""]
    verdict = []
    if eu and eu["drift"] is not None:
        ok = abs(_at(eu["drift"], 100) / euler_theory(100) - 1) < 1e-9
        verdict.append(
            "Explicit Euler's measured drift is the exact factor (1 + k dt²)ⁿ − 1"
            + (" to nine digits" if ok else " (NOT matched: see the table)")
            + f"; the guide's 8.2 % and 103.4 % are {euler_theory(100) / 0.082:.0f} and "
            f"{euler_theory(999) / 1.034:.0f} times too small.")
    if se and se["drift"] is not None:
        mx = float(se["drift"].max())
        verdict.append(
            f"Semi-implicit Euler stays bounded, as the guide says, but at {_pct(mx)}, "
            f"{'not' if mx >= 0.01 else 'indeed'} under 1 %.")
    lines += [" ".join(verdict), "",
              "Every fixed-step method on the same spring:", "",
              "| method | order | symplectic | drift at step 100 | at step 999 | largest | "
              "outcome |", "|---|---|---|---|---|---|---|"]
    for r in rows:
        d = r["drift"]
        lines.append(f"| {r['method']} | {r['order']} | {'yes' if r['symplectic'] else 'no'} "
                     f"| {fmt_err(_at(d, 100))} | {fmt_err(_at(d, 999))} | "
                     f"{fmt_err(float(np.max(d)) if d is not None else math.nan)} | "
                     f"{r['outcome']} |")
    name = "guide_spring.png"
    _plot(rows, out_dir / name)
    lines += ["", f"![energy drift of the spring oscillator]({name})", ""]
    return "\n".join(lines)


def _plot(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 5))
    n = np.arange(STEPS + 1)
    for r in rows:
        d = r["drift"]
        if d is None or r["method"] not in ("euler", "symplectic-euler", "verlet", "rk2",
                                           "rk4", "yoshida4"):
            continue
        ok = d > 0
        ax.semilogy(n[:len(d)][ok], d[ok], label=r["method"], lw=1)
    ax.semilogy(n[1:], euler_theory(n[1:]), "k:", lw=1, label="(1 + k dt²)ⁿ − 1")
    ax.plot([100, 999], [CLAIMS["euler"][100], CLAIMS["euler"][999]], "rx", ms=10,
            label="the guide's claims for Euler")
    ax.axhline(CLAIMS["symplectic-euler"]["max"], color="r", ls="--", lw=0.8,
               label="the guide's 1 % bound for semi-implicit Euler")
    ax.set_xlabel("step")
    ax.set_ylabel("relative energy drift |E/E0 − 1|")
    ax.legend(fontsize=8)
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
