"""Coefficient tables of the table-driven integrators.

Butcher tables (``A``, ``B``, ``C``) of explicit Runge-Kutta methods, from
Hairer, Nørsett & Wanner, *Solving Ordinary Differential Equations I* (1993),
section II.1; and operator tables of splitting methods: the leapfrog, its
compositions of higher order (Yoshida 1990) and, for the Kepler + perturbation
split of :mod:`orbits.integrators.wisdom_holman`, the SABA methods (Laskar &
Robutel 2001).

References
----------
.. [1] Yoshida, H. 1990, "Construction of higher order symplectic integrators",
   Phys. Lett. A 150, 262.
.. [2] Laskar, J. & Robutel, P. 2001, "High order symplectic integrators for
   perturbed Hamiltonian systems", Celest. Mech. Dyn. Astron. 80, 39.
"""

import math

import numpy as np

__all__ = ["EULER", "MIDPOINT", "RK4", "DOPRI5", "SYMPLECTIC_EULER", "VELOCITY_VERLET",
           "LEAPFROG_DKD", "compose_leapfrog", "YOSHIDA4", "YOSHIDA6", "YOSHIDA8",
           "YOSHIDA4_WEIGHTS", "YOSHIDA6_WEIGHTS", "YOSHIDA8_WEIGHTS", "WH_DKD", "SABA2",
           "SABA3", "SABA4"]


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


# -- compositions of the leapfrog (Yoshida 1990) -------------------------------------------
#
# A symmetric composition S(w_m h) ... S(w_1 h) S(w_0 h) S(w_1 h) ... S(w_m h) of the
# drift-kick-drift leapfrog S raises its order from 2 to 2n when the weights w_k solve
# Yoshida's order conditions.  Written out, neighbouring half drifts merge, so a
# composition of s leapfrogs is s kicks and s + 1 drifts.

def _nudge_to_one(values, indices):
    """Move ``values[i]`` for ``i in indices`` by whole ulps, keeping the palindrome,
    until the left-to-right float sum is exactly one (the consistency condition holds
    in floating point, not only to rounding)."""
    values = list(values)
    for _ in range(64):
        s = sum(values)
        if s == 1.0:
            return values
        step = 1.0 if s < 1.0 else -1.0
        for i in indices:
            values[i] = float(np.nextafter(values[i], values[i] + step))
    raise ValueError("could not make the coefficients sum to one")  # pragma: no cover


def compose_leapfrog(weights):
    """The operator table of a symmetric composition of drift-kick-drift leapfrogs.

    Parameters
    ----------
    weights : sequence of float
        ``w_1 ... w_m`` of the outer leapfrogs, from the outside in; the central
        weight is ``w_0 = 1 - 2 (w_1 + ... + w_m)``.

    Returns
    -------
    tuple of (str, float)
        ``("drift", c)`` and ``("kick", d)`` pairs: a palindrome whose drift
        and kick coefficients each sum to exactly one in floating point.
    """
    outer = [float(w) for w in weights]
    w0 = 1.0 - 2.0 * math.fsum(outer)
    ws = outer + [w0] + outer[::-1]
    kicks = _nudge_to_one(ws, [len(outer)])
    drifts = [0.5 * ws[0]] + [0.5 * (a + b) for a, b in zip(ws[:-1], ws[1:])] + [0.5 * ws[-1]]
    mid = len(drifts) // 2
    drifts = _nudge_to_one(drifts, [mid - 1, mid])
    ops = []
    for c, d in zip(drifts[:-1], kicks):
        ops += [("drift", c), ("kick", d)]
    ops.append(("drift", drifts[-1]))
    return tuple(ops)


#: Yoshida (1990), eq. (4.12): the fourth-order triple jump, w_1 = 1 / (2 - 2^(1/3))
YOSHIDA4_WEIGHTS = (1.0 / (2.0 - 2.0 ** (1.0 / 3.0)),)

#: Yoshida (1990), table 1, solution A: sixth order, seven leapfrogs (w_3, w_2, w_1 from
#: the outside in; the paper lists w_1, w_2, w_3)
YOSHIDA6_WEIGHTS = (0.784513610477560, 0.235573213359357, -1.17767998417887)

#: Yoshida (1990), table 2, solution D: eighth order, fifteen leapfrogs (w_7 ... w_1)
YOSHIDA8_WEIGHTS = (0.914844246229740, 0.253693336566229, -1.44485223686048,
                    -0.158240635368243, 1.93813913762276, -1.96061023297549,
                    0.102799849391985)

#: fourth order, three leapfrogs (Yoshida 1990; also Forest & Ruth 1990, Candy & Rozmus 1991)
YOSHIDA4 = compose_leapfrog(YOSHIDA4_WEIGHTS)

#: sixth order, seven leapfrogs (Yoshida 1990, solution A)
YOSHIDA6 = compose_leapfrog(YOSHIDA6_WEIGHTS)

#: eighth order, fifteen leapfrogs (Yoshida 1990, solution D)
YOSHIDA8 = compose_leapfrog(YOSHIDA8_WEIGHTS)


# -- Kepler + perturbation splittings (Wisdom & Holman 1991; Laskar & Robutel 2001) --------
#
# Here "drift" is an exact Kepler drift and "kick" the interaction kick of
# orbits._kernels.wisdom_holman.

#: the Wisdom-Holman map, drift-kick-drift (SABA_1 of Laskar & Robutel)
WH_DKD = (("drift", 0.5), ("kick", 1.0), ("drift", 0.5))

_S3 = math.sqrt(3.0)
_S15 = math.sqrt(15.0)
_S30 = math.sqrt(30.0)
_A = math.sqrt(525.0 + 70.0 * _S30)
_B = math.sqrt(525.0 - 70.0 * _S30)

#: Laskar & Robutel (2001), table 1: SABA_2 (drift nodes from Gauss-Legendre quadrature)
SABA2 = (("drift", 0.5 - _S3 / 6.0), ("kick", 0.5), ("drift", _S3 / 3.0), ("kick", 0.5),
         ("drift", 0.5 - _S3 / 6.0))

#: Laskar & Robutel (2001), table 1: SABA_3
SABA3 = (("drift", 0.5 - _S15 / 10.0), ("kick", 5.0 / 18.0), ("drift", _S15 / 10.0),
         ("kick", 4.0 / 9.0), ("drift", _S15 / 10.0), ("kick", 5.0 / 18.0),
         ("drift", 0.5 - _S15 / 10.0))

#: Laskar & Robutel (2001), table 1: SABA_4
SABA4 = (("drift", 0.5 - _A / 70.0), ("kick", 0.25 - _S30 / 72.0),
         ("drift", (_A - _B) / 70.0), ("kick", 0.25 + _S30 / 72.0),
         ("drift", _B / 35.0), ("kick", 0.25 + _S30 / 72.0),
         ("drift", (_A - _B) / 70.0), ("kick", 0.25 - _S30 / 72.0),
         ("drift", 0.5 - _A / 70.0))


#: Dormand & Prince (1980) 5(4) pair; E = b - b_hat over the 6 stages and the
#: first stage of the next step (HNW 1993, Table II.5.2)
_DP_A = [[0, 0, 0, 0, 0, 0],
         [1 / 5, 0, 0, 0, 0, 0],
         [3 / 40, 9 / 40, 0, 0, 0, 0],
         [44 / 45, -56 / 15, 32 / 9, 0, 0, 0],
         [19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729, 0, 0],
         [9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656, 0]]
_DP_B = [35 / 384, 0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84]
_DP_BHAT = [5179 / 57600, 0, 7571 / 16695, 393 / 640, -92097 / 339200, 187 / 2100, 1 / 40]
DOPRI5 = (*_butcher(_DP_A, _DP_B, [0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1]),
          np.array(_DP_B + [0.0]) - np.array(_DP_BHAT))
