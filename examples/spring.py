"""The spring oscillator of the classic integrator-choice guide, with every method.
=================================================================================

k = 100, m = 1, x0 = 1, v0 = 0, dt = 0.01, 1000 steps.  The exact energy is
E = v^2/2 + k x^2/2 = 50 for all time; the table prints how far each method's
energy has drifted at steps 100 and 999 and the largest drift over the run.
The force is a numba function of the user's own, integrated by
``orbits.integrate`` in the same compiled loops as gravity.  ::

    python examples/spring.py
"""

import numba
import numpy as np

import orbits

K, M, X0, V0, DT, STEPS = 100.0, 1.0, 1.0, 0.0, 0.01, 1000


@numba.njit
def spring(x, v, t):
    return -K / M * x


def energy(x, v):
    return 0.5 * M * v ** 2 + 0.5 * K * x ** 2


def main():
    e0 = energy(X0, V0)
    print(f"spring k = {K:g}, m = {M:g}, x0 = {X0:g}, dt = {DT:g}, {STEPS} steps; E0 = {e0:g}")
    print(f"{'method':18s} {'order':>5s} {'|dE/E| step 100':>16s} {'step 999':>12s} "
          f"{'largest':>12s}")
    for info in orbits.integrators.available():
        if info.adaptive:
            continue
        try:
            tr = orbits.integrate(spring, X0, V0, dt=DT, steps=STEPS, method=info.name)
            drift = np.abs(energy(tr.x, tr.v) / e0 - 1)
            print(f"{info.name:18s} {info.order:5d} {drift[100]:16.3e} {drift[999]:12.3e} "
                  f"{drift.max():12.3e}")
        except orbits.NonFiniteState as exc:
            print(f"{info.name:18s} {info.order:5d} failed: {exc}")
        except orbits.IntegratorOptionError as exc:
            # methods built for gravity alone (Wisdom-Holman) take no user force
            print(f"{info.name:18s} {info.order:5d} not applicable: {exc}")


if __name__ == "__main__":
    main()
