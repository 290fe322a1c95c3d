"""Coefficient tables of the table-driven integrators.

Butcher tables (``A``, ``B``, ``C``) of explicit Runge-Kutta methods, from
Hairer, Nørsett & Wanner, *Solving Ordinary Differential Equations I* (1993),
section II.1; and operator tables of splitting methods.
"""

import numpy as np

__all__ = ["EULER", "MIDPOINT", "RK4", "SYMPLECTIC_EULER", "VELOCITY_VERLET",
           "LEAPFROG_DKD"]


def _butcher(A, B, C):
    return (np.ascontiguousarray(A, dtype=np.float64),
            np.ascontiguousarray(B, dtype=np.float64),
            np.ascontiguousarray(C, dtype=np.float64))


#: explicit Euler: y1 = y0 + h f(t0, y0)
EULER = _butcher([[0.0]], [1.0], [0.0])

#: explicit midpoint rule (Runge 1895), order 2
MIDPOINT = _butcher([[0.0, 0.0],
                     [0.5, 0.0]], [0.0, 1.0], [0.0, 0.5])

#: the classic fourth-order method of Kutta (1901)
RK4 = _butcher([[0.0, 0.0, 0.0, 0.0],
                [0.5, 0.0, 0.0, 0.0],
                [0.0, 0.5, 0.0, 0.0],
                [0.0, 0.0, 1.0, 0.0]],
               [1 / 6, 1 / 3, 1 / 3, 1 / 6], [0.0, 0.5, 0.5, 1.0])

#: semi-implicit (symplectic) Euler: kick with a(x_n), then drift with v_{n+1}
SYMPLECTIC_EULER = (("kick", 1.0), ("drift", 1.0))

#: velocity Verlet, kick-drift-kick
VELOCITY_VERLET = (("kick", 0.5), ("drift", 1.0), ("kick", 0.5))

#: leapfrog, drift-kick-drift
LEAPFROG_DKD = (("drift", 0.5), ("kick", 1.0), ("drift", 0.5))
