"""Stopping conditions checked inside the compiled loops.

A check has the signature ``check(x, v, sargs) -> status`` and, when it
fires, writes the bodies concerned into ``sargs[-1]`` (an int64 array of two:
the pair for an encounter; the body and -1 for an escape).  Loops are compiled
with :func:`no_stop` when a simulation asks for no condition, which inlines to
nothing, so such a scene pays nothing for the feature.

``sargs = (mask, distance2, hill_k, escape2, gm, central, info)``:

* ``mask``: bits :data:`ENCOUNTER_DISTANCE`, :data:`ENCOUNTER_HILL`,
  :data:`ESCAPE`, :data:`UNBOUND`;
* ``distance2``: squared encounter distance;
* ``hill_k``: encounter at ``k`` mutual Hill radii,
  ``R_H = ((m_i + m_j) / (3 m_c))^(1/3) (r_i + r_j) / 2`` with ``r`` the
  distances from the central (most massive) body ``c`` (Chambers 1996);
* ``escape2``: squared escape distance from the centre of mass; with
  :data:`UNBOUND` a body beyond it counts only if its energy about the centre
  of mass, ``v^2/2 - G M / r``, is positive;
* ``gm``: G times the masses; ``central``: index of the central body.
"""

import math

from ._jit import njit
from .status import Status

__all__ = ["no_stop", "check_stop", "ENCOUNTER_DISTANCE", "ENCOUNTER_HILL", "ESCAPE",
           "UNBOUND"]

ENCOUNTER_DISTANCE = 1
ENCOUNTER_HILL = 2
ESCAPE = 4
UNBOUND = 8


@njit(inline="always")
def no_stop(x, v, sargs):
    """No condition: always carries on."""
    return 0


@njit
def check_stop(x, v, sargs):
    """The conditions in ``sargs`` (see the module docstring); 0 to carry on."""
    mask, d2, hill_k, esc2, gm, central, info = sargs
    # the bodies' rows (a run with variations has tangent rows after them)
    n = min(x.shape[0], gm.shape[0])
    if mask & (ENCOUNTER_DISTANCE | ENCOUNTER_HILL):
        third_gmc = 1.0 / (3.0 * gm[central])
        for i in range(1, n):
            for j in range(i):
                dx = x[i, 0] - x[j, 0]
                dy = x[i, 1] - x[j, 1]
                dz = x[i, 2] - x[j, 2]
                r2 = dx * dx + dy * dy + dz * dz
                hit = (mask & ENCOUNTER_DISTANCE) != 0 and r2 < d2
                if not hit and (mask & ENCOUNTER_HILL) and i != central and j != central:
                    mu = gm[i] + gm[j]
                    if mu > 0.0:
                        ri = math.sqrt((x[i, 0] - x[central, 0]) ** 2
                                       + (x[i, 1] - x[central, 1]) ** 2
                                       + (x[i, 2] - x[central, 2]) ** 2)
                        rj = math.sqrt((x[j, 0] - x[central, 0]) ** 2
                                       + (x[j, 1] - x[central, 1]) ** 2
                                       + (x[j, 2] - x[central, 2]) ** 2)
                        rh = (mu * third_gmc) ** (1.0 / 3.0) * 0.5 * (ri + rj)
                        hit = r2 < (hill_k * rh) ** 2
                if hit:
                    info[0] = j
                    info[1] = i
                    return Status.CLOSE_ENCOUNTER
    if mask & ESCAPE:
        mt = 0.0
        cx = cy = cz = 0.0
        ux = uy = uz = 0.0
        for i in range(n):
            mt += gm[i]
            cx += gm[i] * x[i, 0]
            cy += gm[i] * x[i, 1]
            cz += gm[i] * x[i, 2]
            ux += gm[i] * v[i, 0]
            uy += gm[i] * v[i, 1]
            uz += gm[i] * v[i, 2]
        cx /= mt
        cy /= mt
        cz /= mt
        ux /= mt
        uy /= mt
        uz /= mt
        for i in range(n):
            r2 = (x[i, 0] - cx) ** 2 + (x[i, 1] - cy) ** 2 + (x[i, 2] - cz) ** 2
            if r2 > esc2:
                if mask & UNBOUND:
                    w2 = (v[i, 0] - ux) ** 2 + (v[i, 1] - uy) ** 2 + (v[i, 2] - uz) ** 2
                    if 0.5 * w2 - mt / math.sqrt(r2) <= 0.0:
                        continue
                info[0] = i
                info[1] = -1
                return Status.ESCAPE
    return 0
