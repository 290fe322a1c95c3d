"""Second-order symmetric splittings: velocity Verlet and leapfrog."""

from . import tableaux
from .base import SplittingMethod

__all__ = ["Verlet", "Leapfrog"]


class Verlet(SplittingMethod):
    """Velocity Verlet, kick-drift-kick (Verlet 1967; Swope et al. 1982).

    Notes
    -----
    ::

        v_{n+1/2} = v_n + (h/2) a(x_n)
        x_{n+1}   = x_n + h v_{n+1/2}
        v_{n+1}   = v_{n+1/2} + (h/2) a(x_{n+1})

    Second order, symplectic and time-symmetric; one force evaluation a step
    (the closing kick's acceleration is reused by the next step).

    References
    ----------
    Hairer, Lubich & Wanner (2003), "Geometric numerical integration
    illustrated by the Störmer-Verlet method", Acta Numerica 12, 399.

    Examples
    --------
    Time-symmetric: a hundred steps forward and a hundred back end where they
    started, to rounding.

    >>> sim = orbits.Simulation(orbits.scenes.kepler(e=0.1), "verlet", dt=1 * u.day)
    >>> start = sim.bodies.positions
    >>> _ = sim.run(until=100 * u.day, outputs=2, progress=False)
    >>> _ = sim.run(until=0 * u.day, outputs=2, progress=False)
    >>> bool(abs(sim.bodies.positions - start).max() < 1e-14 * u.au)
    True
    """

    name = "verlet"
    order = 2
    summary = "velocity Verlet, kick-drift-kick"
    operators = tableaux.VELOCITY_VERLET


class Leapfrog(SplittingMethod):
    """Leapfrog in drift-kick-drift form, as REBOUND's ``leapfrog`` uses.

    Notes
    -----
    ::

        x_{n+1/2} = x_n + (h/2) v_n
        v_{n+1}   = v_n + h a(x_{n+1/2})
        x_{n+1}   = x_{n+1/2} + (h/2) v_{n+1}

    Second order, symplectic and time-symmetric, one force evaluation a step.

    Exactness with REBOUND.  REBOUND's ``leapfrog`` takes the same drift
    ``x += (h/2) v``, kick ``v += h a`` and drift, with its serial pair loop
    over j < i, and our drifts and kicks round as its do.  Its pair term is
    ``(G / ((r r) r)) m_j``; the default kernels form ``G m_j / (r^2
    sqrt(r^2))``, an ulp or so apart, so the trajectories part at rounding
    level (1e-11 au after 10,000 steps of the outer solar system).
    ``Simulation(..., rebound_arithmetic=True)`` switches to
    :func:`orbits._kernels.gravity.accelerate_pairwise_rebound`, which
    computes REBOUND's expression in REBOUND's order; from
    ``BodySet.to_rebound()``'s floats and G, ``leapfrog`` is then bit-identical
    to REBOUND after 1,000,000 steps of the outer solar system
    (tests/integrators/test_leapfrog_rebound.py), at 0.61 of REBOUND's time
    per step for N = 6 (0.59 with the default kernel).  No loop may contain a
    fused multiply-add: kernels are compiled with fastmath off, which keeps
    LLVM from contracting (tested on the compiled code).

    References
    ----------
    Hairer, Lubich & Wanner (2006), *Geometric Numerical Integration*, section I.3.1.
    Rein, H. & Liu, S.-F. 2012, "REBOUND: an open-source multi-purpose N-body
    code for collisional dynamics", A&A 537, A128.

    Examples
    --------
    Its table of operators, half drifts about a kick:

    >>> orbits.integrators.get("leapfrog").operators
    (('drift', 0.5), ('kick', 1.0), ('drift', 0.5))
    """

    name = "leapfrog"
    order = 2
    summary = "leapfrog, drift-kick-drift"
    operators = tableaux.LEAPFROG_DKD
