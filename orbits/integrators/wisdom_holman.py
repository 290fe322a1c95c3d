"""The Wisdom-Holman map in Jacobi or democratic heliocentric coordinates, and
the SABA methods.

Planetary systems are nearly Keplerian: each planet moves on an ellipse about
the star, perturbed by the others.  The Wisdom-Holman map splits the motion
into exact Kepler drifts and kicks from the planets' mutual pull (see
:mod:`orbits._kernels.wisdom_holman` for the split and its formulas), so its
error is of order ``epsilon h^2`` with ``epsilon`` the planet-to-star mass
ratio instead of ``h^2``.  The SABA methods of Laskar & Robutel use the same
two operators with more stages, bringing the error to
``O(epsilon h^(2n) + epsilon^2 h^2)``.
"""

import math
import os
import warnings

import numpy as np

from .._kernels.status import with_status
from .._kernels import coordinates as _coordinates
from .._kernels import terms as _kterms
from .._kernels import records
from .._kernels import wisdom_holman as _wh
from .._kernels import wh_lanes as _lanes
from .._kernels import wh_tangent as _wht
from .._kernels.gravity import aligned_zeros
from .._kernels.kepler import _SHORT_STEP
from .._kernels.stumpff import _STUMPFF_MEDIUM_Z
from .._kernels import stepping as _stepping
from .._kernels.stepping import DRIFT, KICK, work_bound
from .._kernels.stopping import stop_record
from ..errors import IntegratorOptionError
from . import tableaux
from .base import Integrator, Option

__all__ = ["WisdomHolman", "SABA2", "SABA3", "SABA4", "NoDominantBodyWarning",
           "split_gravity", "refuse_unkickable", "lanes_pay", "lanes_ready", "lanes_choice",
           "note_lanes_ready", "lanes_scratch_in",
           "LANES_FROM_BODIES", "LANES_FROM_STEPS", "LANES_MODES",
           "MASS_RATIO_LIMIT", "COORDINATES", "CORRECTORS", "CORRECTOR_SPACING",
           "corrector_stages"]

#: Above this ratio of the largest other mass to the central one the split's
#: premise fails: the kicks are no longer small against the Kepler drifts and
#: the error, ``O(epsilon h^2)``, is no better than a leapfrog's.  (The giant
#: planets have 1e-3; a binary companion or a cluster member has ~1.)
MASS_RATIO_LIMIT = 0.01

#: coordinate systems of the split (see :mod:`orbits._kernels.wisdom_holman`)
COORDINATES = ("jacobi", "democratic-heliocentric")

#: Bodies from which a run without added terms steps with its planets in
#: vector lanes (:mod:`orbits._kernels.wh_lanes`; the same results bit for
#: bit).  Two planets fill too little of a vector register to pay for the
#: copies in and out; from three planets the lanes take less time a step on
#: the AVX2 machine and about as long on the AVX-512 machine, less from four
#: (benchmarks/RESULTS.md).
LANES_FROM_BODIES = 4

#: What a planet outside the lanes' domain costs a lanes' step, against what
#: the lanes save, which grows as the square of the number of bodies N (the
#: kick's pairs): the lanes are taken while ``LANES_COST_OF_DECLINED *
#: declined < N**2`` (:func:`lanes_pay`).  A declined planet (a step of more
#: than a radian of its orbit) is drifted by the scalar solver after the
#: lanes' passes.  Measured (benchmarks/RESULTS.md), the outer solar system
#: (N = 6) still gains 3-6 % from the lanes with two or three planets
#: declined (3000- and 6000-day steps) and breaks even with four (12000
#: days); the Sun and eight planets (N = 9) gain 23 % with two declined (40
#: days).  The results are the same either way.
LANES_COST_OF_DECLINED = 9

#: With ``lanes="auto"`` (the default), a run takes the lanes' loop where it
#: was compiled on this machine already (:func:`lanes_ready`), or where the
#: simulation's step count reaches this many steps by the run's end; shorter
#: runs take the scalar loop, with the same results bit for bit.  On an
#: empty cache the lanes' loop takes 27-29 CPU seconds to compile against the
#: scalar one's 12-13 (25 more where the scalar one is compiled already), and
#: saves 0.06-0.09 us a step on the outer solar system, 0.22-0.28 on the Sun
#: and eight planets (AVX-512; benchmarks/RESULTS.md): a run of the Sun and
#: eight planets repays it from 6e7 to 1e8 steps (the outer solar system
#: from 2e8 to 3e8), and a run that long steps for 20 s or more.
LANES_FROM_STEPS = 100_000_000

#: the values of the ``lanes`` option
LANES_MODES = ("auto", "on", "off")

#: The lanes' loops known to be compiled: in this process (their names), and
#: across processes by a marker file beside numba's cache (:func:`lanes_ready`)
_LANES_READY = set()


def _lanes_marker(name):
    # the marker of the lanes' loop `name` (whose name carries the kernels'
    # digest) compiled for this CPU, beside numba's cache
    from .._compiling import cache_dir, cpu_name
    return os.path.join(cache_dir(), f"{name}.{cpu_name()}.ready")


def lanes_ready(loop):
    """Whether the lanes' loop ``loop`` (a compiled loop of
    :func:`orbits._kernels.wisdom_holman.wh_loop`) is compiled on this
    machine: called in this process, or compiled (or loaded) by an earlier
    one, which left a marker beside numba's cache.  The marker carries the
    loop's name, which changes with the kernels' sources, and the CPU's."""
    name = loop.py_func.__qualname__
    if name in _LANES_READY:
        return True
    if os.path.exists(_lanes_marker(name)):
        _LANES_READY.add(name)
        return True
    return False


def note_lanes_ready(loop):
    """Note that the lanes' loop ``loop`` has run in this process, and
    mark it for later processes (a folder that cannot be written leaves no
    marker; :func:`lanes_ready`)."""
    name = loop.py_func.__qualname__
    if name in _LANES_READY:
        return
    _LANES_READY.add(name)
    try:
        with open(_lanes_marker(name), "x"):
            pass
    except OSError:
        pass


def lanes_choice(ws, mode, n, ready):
    """Whether a run of ``n`` bodies steps in the vector lanes by the
    ``lanes`` option ``mode`` of ``wh`` or ``trace``: ``"on"``, ``"off"``,
    or with ``"auto"`` where the simulation reaches :data:`LANES_FROM_STEPS`
    steps by the run's end (``ws["steps_by_end"]``, set by the run) or
    ``ready()`` says the lanes' loop is compiled already
    (:func:`lanes_ready`); never below :data:`LANES_FROM_BODIES` bodies or
    with added terms bound (``ws["terms"]``).  Decided once a run (the
    run's driver asks first, for its notice, then every call of the loop):
    kept in the workspace under the run's length, the rows, the mode and
    whether terms are bound."""
    key = (ws.get("steps_by_end", 0), n, mode, "terms" in ws)
    memo = ws.get("lanes_wanted")
    if memo is not None and memo[0] == key:
        return memo[1]
    if n < LANES_FROM_BODIES or key[3] or mode == "off":
        wanted = False
    elif mode == "on" or key[0] >= LANES_FROM_STEPS:
        wanted = True
    else:
        wanted = ready()
    ws["lanes_wanted"] = (key, wanted)
    return wanted


def lanes_scratch_in(ws, shape):
    """The lanes' loop's ``targs``: a tuple of its scratch of ``shape``, kept
    in the workspace (``ws["lanes"]``; a tuple, not an array, so neither
    saved nor restored: what it carries from step to step only chooses
    between paths with the same results), made anew when the shape
    changes (a merger)."""
    targs = ws.get("lanes")
    if targs is None or targs[0].shape != shape:
        targs = ws["lanes"] = (aligned_zeros(shape),)
    return targs


def table_bound(ws, n, recorder=None, mon=None):
    """What a scalar or tangent loop of ``n`` bodies (``wh``'s, ``trace``'s,
    one loop with and without force terms) takes for the terms:
    ``(terms' kernel, table, recorder, mon)``.  The terms bound in ``ws``
    with the monitors' ``recorder`` and ``mon`` as they are; for a run
    without terms an empty table (made once and kept in ``ws``: a tuple,
    kept but not saved), with ``mon`` carrying it and the recorder of a run
    with terms (:func:`orbits._kernels.stepping.terms_recorder`), whose
    terms' energy is then 0."""
    if "terms" in ws:
        terms, tab = ws["terms"]
        return terms, tab, recorder, mon
    tab = ws.get("no_terms")
    if tab is None or tab.an.shape[0] != n:
        tab = ws["no_terms"] = _kterms.table((), np.zeros(n), np.zeros(n))
    return (_kterms.TABLE, tab, _stepping.terms_recorder(_kterms.TABLE),
            None if mon is None else mon + (tab,))


def lanes_pay(x, v, gm, dt):
    """Whether the lanes pay for a run of the bodies ``x``, ``v`` (row 0
    the central body, ``gm`` G times each mass) at the step ``dt``: few
    enough planets outside the lanes' domain
    (:data:`LANES_COST_OF_DECLINED`).  Each planet's heliocentric orbit
    gives the Stumpff argument its drift's starter would have,
    ``(mu / a) (dt / r)^2`` (the square of the step's eccentric anomaly,
    the universal anomaly being about ``dt / r``), against the lanes' bound,
    and ``|dt| |v| < r``.  An estimate from the first state: it chooses
    between two loops with the same results, not what a step computes."""
    n = len(x)
    r = np.sqrt(np.sum((x[1:] - x[0]) ** 2, axis=1))
    v2 = np.sum((v[1:] - v[0]) ** 2, axis=1)
    mu = gm[0] + gm[1:n]
    with np.errstate(divide="ignore", invalid="ignore"):
        z = (2.0 * mu / r - v2) * (dt / r) ** 2
        inside = ((np.abs(z) <= _STUMPFF_MEDIUM_Z) & (dt * dt * v2 < (_SHORT_STEP * r) ** 2)
                  & (mu > 0.0))
    declined = (n - 1) - int(np.count_nonzero(inside))
    return LANES_COST_OF_DECLINED * declined < n * n


#: Spacing of the corrector stages: stage i is ``Z(a_i h, b_i h)`` with
#: ``a_i = i * CORRECTOR_SPACING`` (Wisdom, Holman & Touma 1996; Wisdom 2006).
CORRECTOR_SPACING = math.sqrt(7.0 / 40.0)

#: symplectic correctors (Wisdom, Holman & Touma 1996; Wisdom 2006): order ->
#: the stage weights ``b_i`` (i = 1, 2, ...).  The corrector of order
#: ``n = 2m + 1`` has m stages whose first-order generator
#: ``sum_i 2 b_i sinh(a_i L)`` (``L = h ad_{H_Kepler}``) matches that of the
#: conjugating map, ``1 / (2 sinh(L/2)) - 1/L = -L/24 + 7 L^3/5760 - ...``,
#: through ``L^(2m-1)``: a Vandermonde system in the ``a_i^(2k-1)``, solved in
#: 60-digit arithmetic (tests/integrators/test_wisdom_holman.py checks it).
CORRECTORS = {
    0: (),
    3: (-0.0498011920555997349987,),
    5: (-0.0830019867593328916645, 0.0166003973518665783329),
    7: (-0.107928798186254997444, 0.0365418464934042629561, -0.00498536228538442115581),
    11: (-0.145186789497685477349, 0.0762432273625773010173, -0.0246181571840398926351,
         0.00469744305845907083766, -0.000407231592957093026033),
    17: (-0.186112207542851917183, 0.130385727152755787317, -0.0648443977294271605874,
         0.0241435216446845821249, -0.0066265154138761311311, 0.00127199966151635317966,
         -0.000152872710455871476726, 0.00000866948309467471603813),
}


_ESCAPES = {}
_CORRECTORS = {}


def _loop_escape(loop, conditions, make):
    """The ``escape`` argument of the Wisdom-Holman ``loop`` without lanes:
    the escape check where the run has stopping ``conditions``, else a
    pointer of its type that is never called
    (``orbits._kernels.wisdom_holman.escape_pointer``), ``make(conditions)``
    made once a loop and process: the types it is made for (those of the
    stopping record and of the loop's synchronisation's arguments) are the
    loop's."""
    found = _ESCAPES.get((loop, conditions))
    if found is None:
        found = _ESCAPES[loop, conditions] = make(conditions)
    return found


def _sync_of(system, ws, x, v, targs, correct):
    # the synchronisation's arguments as the loop hands them on (their
    # types; the drift owed and the corrector's step are the loop's own)
    return _wh.Sync(system.gm, system.eta, 0.0, ws["xs"], ws["vs"], x, v, ws["acc"],
                    system.n_active, system.corrector, 0.0, targs, correct)


def refuse_unkickable(integ, terms):
    """Refuse, with :class:`~orbits.errors.IntegratorOptionError`, a force term
    that the interaction kick of ``integ`` (a map of the Wisdom-Holman family)
    cannot take: one that depends on velocities or has no potential."""
    for term in terms:
        if not term.wisdom_holman:
            raise IntegratorOptionError(
                f"{integ.name} cannot take the force term {term!r}: its interaction "
                f"step takes only conservative terms that depend on positions alone "
                f"({term.why_not_wisdom_holman}). Use 'ias15', 'leapfrog', "
                "'yoshida4', an embedded method such as 'dop853', or, for GR, the "
                f"term GRPotential, which {integ.name!r} takes.")


def corrector_stages(order):
    """The corrector of ``order`` as an array of ``(a_i, b_i)`` rows, shape (m, 2),
    in units of the step (no rows for order 0)."""
    b = CORRECTORS[order]
    return np.array([[(i + 1) * CORRECTOR_SPACING, bi] for i, bi in enumerate(b)],
                    dtype=np.float64).reshape(len(b), 2)


class NoDominantBodyWarning(UserWarning):
    """The Wisdom-Holman split is used on a system without one dominant mass."""


def split_gravity(name, force, fargs, alternative="'ias15'"):
    """The ``(G m, N_active)`` of the gravity a Wisdom-Holman split (method
    ``name``) takes apart, after the checks it needs: Newtonian gravity, with
    or without position-only terms (a user's function replacing it is refused,
    pointing to ``alternative``), unsoftened, a massive first body, and a
    :class:`NoDominantBodyWarning` where another mass is above
    :data:`MASS_RATIO_LIMIT` of it."""
    if force.terms is not None:
        force, fargs = force.base, fargs[0]
    if force.opaque:
        raise IntegratorOptionError(
            f"{name} splits Newtonian gravity into Kepler drifts and kicks and "
            f"cannot integrate another force; use a general method such as {alternative}")
    gm, n_active, eps2 = fargs[0], fargs[1], fargs[2]
    if eps2 != 0.0:
        raise IntegratorOptionError(
            f"{name} needs unsoftened gravity (its Kepler drifts are exact "
            "two-body orbits); use 'leapfrog' or 'verlet' with softening")
    if n_active < 1 or not gm[0] > 0.0:
        raise IntegratorOptionError(
            f"{name} needs a massive central body first; the first body has no mass")
    if n_active > 2:
        ratio = float(np.max(gm[1:n_active]) / gm[0])
        if ratio > MASS_RATIO_LIMIT:
            warnings.warn(
                f"{name}: no dominant central body (the largest other mass is "
                f"{ratio:.3g} times the first body's, above {MASS_RATIO_LIMIT}): the "
                "Wisdom-Holman split treats the pull between the other bodies as a "
                "small perturbation of Kepler orbits about the first, which it is "
                "not here, so the error will be large. Use an integrator that "
                "does not split the motion, such as 'ias15' (adaptive, for close "
                "encounters) or 'verlet'/'leapfrog' with a small step.",
                NoDominantBodyWarning, stacklevel=5)
    return gm, n_active


class WisdomHolman(Integrator):
    """Wisdom-Holman map in Jacobi or democratic heliocentric coordinates, with
    lazy synchronisation.

    Parameters
    ----------
    coordinates : {"jacobi", "democratic-heliocentric"}
        The split.  ``"jacobi"`` (default): each body orbits the interior
        mass ``G eta_i`` of the bodies before it; a two-body problem is
        exact.  ``"democratic-heliocentric"`` (Duncan, Levison & Lee 1998):
        heliocentric positions, barycentric velocities, every body orbits
        ``G m_0``, and the perturbation adds a "jump" of the positions by
        the planets' total momentum over ``m_0``; every body is treated
        alike whatever its order, but a massive companion's own Kepler
        problem is no longer exact (error proportional to its mass ratio).
        On the outer solar system at 1/20 of Jupiter's period the energy
        error is about that of Jacobi coordinates (1.9e-6 against 2.4e-6),
        the position error after 200 steps four times larger, and the
        corrected energy error levels off higher (1.4e-8 against 4e-9).
    corrector : {0, 3, 5, 7, 11, 17}
        Order of the symplectic corrector (0: none; only for ``wh`` itself,
        not SABA).  The map then runs from ``C^-1`` of the initial state and
        every output and monitor sees ``C`` of the mapping state, computed on
        a copy, so the trajectory of the map is the same however often it is
        looked at.  On the outer solar system at 1/20 of Jupiter's period
        the energy error falls from 2.4e-6 to 1.5e-7 (3), 1.9e-8 (5) and
        4e-9 (7 to 17), where the ``epsilon^2 h^2`` error that a first-order
        corrector cannot remove is left.  The corrector costs ``4 m`` Kepler
        drift sets and ``2 m`` kicks an output (``m = (order - 1) / 2``),
        nothing a step.  A step of another size (a shorter last step) passes
        through the corrected state, which moves the mapping state by the
        correctors' second-order difference.
        In democratic heliocentric coordinates the same correctors apply,
        to first order in the mass ratio as in Jacobi ones, because the
        perturbation step is the exact flow of the whole perturbation
        (interaction and jump commute; Wisdom 2006): there the energy error
        falls from 1.9e-6 to 1.3e-7 (3), 2.1e-8 (5) and 1.4e-8 (7 to 17).

    Notes
    -----
    With the Kepler drift ``K(h)`` (every Jacobi coordinate on its two-body
    orbit about ``G eta_i``, the centre of mass in a straight line) and the
    interaction kick ``I(h)``, one step is::

        Phi(h) = K(h/2) I(h) K(h/2)

    In democratic heliocentric coordinates ``K(h)`` moves every body on its
    orbit about ``G m_0`` and ``I(h)`` becomes ``J(h/2) I(h) J(h/2)``, the
    planet-planet kick between two half jumps (the order REBOUND's WHFast
    uses; the jump and the kick commute, so this is the exact flow of both).

    Symplectic, time-symmetric, second order in ``h`` with an error
    proportional to the mass ratio ``epsilon`` of the perturbers to the
    central body.  One force evaluation and N - 1 Kepler drifts a step.

    The bodies are taken in the simulation's order (massive first) and the
    first one is the central body; ``needs_central_body`` is True, and a
    system whose largest other mass exceeds :data:`MASS_RATIO_LIMIT` times the
    first runs with a :class:`NoDominantBodyWarning`.  Only Newtonian gravity
    without softening can be split this way.

    State kept between calls (lazy synchronisation, Rein & Tamayo 2015): the
    Jacobi (or democratic heliocentric) positions and velocities, the closing
    half drift still owed and the step the corrector was built for.
    Consecutive steps merge their half drifts into one, and the inertial
    state in ``x``, ``v`` is brought up to date only by :meth:`synchronize`
    (which outputs and monitors call), on a copy, so that the merged drifts
    go on.  :meth:`invalidate` makes the next step start again from ``x``, ``v``.

    From :data:`LANES_FROM_BODIES` bodies on, a run without added force terms
    drifts its planets together in vector lanes (structure of arrays, one
    planet a lane, a Kepler solver without branches; WHFast512's layout on
    AVX2 or AVX-512, :mod:`orbits._kernels.wh_lanes`), bit for bit the
    scalar drift: a planet outside the branch-free solver's domain (a high
    eccentricity near pericentre, a hyperbola, a long step) is drifted by
    the scalar solver.  Where the step is long enough for so many planets
    to leave that domain that the lanes would cost more than they save
    (:func:`lanes_pay`, decided at the first step), the run takes the
    scalar loop, with the same results.  The interaction kick's pulls are summed in the
    lanes too, bit for bit the scalar sums, and between outputs the state
    stays in the lanes, as WHFast512 keeps it in its registers (written
    back to the workspace for an output, a non-finite state and the end of
    a call).

    The lanes' loop takes some 15 CPU seconds more to compile than the
    scalar one, which a run of fewer than some 1e8 steps does not win back.
    So the ``lanes`` option, ``"auto"`` by default, takes it for a run that
    reaches :data:`LANES_FROM_STEPS` steps, and for every run once it is
    compiled on the machine (by such a run, ``lanes="on"`` or ``orbits
    compile``; :func:`lanes_ready`); other runs take the scalar loop.
    ``"on"`` and ``"off"`` choose.  The results do not depend on it.

    Stopping conditions: ``escape_distance`` (and ``escape_unbound``) of
    :class:`~orbits.Simulation`, checked after every step on the inertial
    state as an output sees it, :class:`~orbits.errors.Escape` naming the
    step at whose end a body is beyond the distance, the simulation left at
    that state.  The state is synchronised for the check only where a body
    may be beyond it (:func:`orbits._kernels.wisdom_holman.may_escape`, a
    bound from each row's Kepler orbit; always with a corrector), and such a
    run drifts without the vector lanes: on the outer solar system at 30
    days, 0.35 us a step against 0.22 without the condition (0.29 without it
    and without the lanes), and 0.79 against 0.72 with the chaos indicators.
    The steps are bit for bit those of a run without it.  Encounters and
    collisions, which the split cannot follow, are not checked (``ias15``,
    ``trace``).

    Variational equations (a force with variations, ``force.inner`` set;
    :mod:`orbits._kernels.variational`): the tangent vectors in the rows
    after the bodies' are carried through the exact derivative of every
    operator, the map's own tangent as in WHFast (Rein & Tamayo 2016; see
    :mod:`orbits._kernels.wh_tangent`), in both coordinate systems, with the
    correctors and for SABA; the workspace's internal state then holds the
    tangent rows too.  Mass variations are taken (not together with added
    force terms).  With the chaos indicators, tangent vector 0 is
    synchronised to the inertial frame after every step, as for an output.
    The bodies' rows are bit for bit those of a run without variations.

    References
    ----------
    Wisdom, J. & Holman, M. 1991, "Symplectic maps for the N-body problem",
    AJ 102, 1528.  Rein, H. & Tamayo, D. 2015, "WHFAST: a fast and unbiased
    implementation of a symplectic Wisdom-Holman integrator", MNRAS 452, 376.
    Wisdom, J., Holman, M. & Touma, J. 1996, "Symplectic correctors", Fields
    Inst. Commun. 10, 217.  Wisdom, J. 2006, "Symplectic correctors for
    canonical heliocentric coordinates", AJ 131, 2294.  Duncan, M. J.,
    Levison, H. F. & Lee, M. H. 1998, AJ 116, 2067 (democratic heliocentric
    coordinates).  Rein, H. & Tamayo, D. 2016, "Second-order variational
    equations for N-body simulations", MNRAS 459, 2275 (the tangent map).

    Examples
    --------
    >>> sim = orbits.Simulation(orbits.scenes.outer_solar_system(), integrator="wh",
    ...                         dt=200 * u.day)
    >>> result = sim.run(until=10_000 * u.yr, outputs=11, progress=False)
    >>> bool(result.energy_error.max() < 1e-5)
    True
    """

    #: outputs that do not fall a whole number of steps apart are recorded in the
    #: loop too (``every = -1``: the steps in ``mon_t``)
    records_step_marks = True
    #: its scalar loop and the tangent loop of the variations take the table
    #: of terms, an empty one (its own: :func:`table_bound`) for a run
    #: without terms; the lanes' loop takes none
    terms_as_data = True
    table_in_force = False

    name = "wh"
    order = 2
    symplectic = True
    time_symmetric = True
    needs_central_body = True
    option_specs = (
        Option("coordinates", str, "jacobi", "the coordinates of the Kepler split",
               choices=COORDINATES),
        Option("corrector", int, 0, "order of the symplectic corrector of the map K(h/2) "
               "I(h) K(h/2) (Wisdom, Holman & Touma 1996; SABA: 0 only); 0: none",
               choices=tuple(CORRECTORS)),
        Option("lanes", str, "auto", "the planets' drifts and kicks in vector lanes, the "
               "same results bit for bit: 'on' wherever they pay (4 bodies or more, no "
               "added terms), 'off', or 'auto': 'on' for a run that reaches 1e8 steps or "
               "once their loop is compiled on this machine (it takes some 15 s more "
               "to compile)", choices=LANES_MODES),
    )
    summary = ("Wisdom-Holman map, Kepler drifts and interaction kicks in Jacobi or "
               "democratic heliocentric coordinates")
    #: the step as a table of Kepler drifts ("drift") and interaction kicks ("kick")
    operators = tableaux.WH_DKD
    forces_per_step = 1
    #: the loop checks escapes after every step, on the synchronised state;
    #: encounters and collisions, which its Kepler split cannot resolve, are
    #: left to ias15 or trace
    stop_conditions = ("escape_distance", "escape_unbound")

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        cls._prepare_table()

    @property
    def batchable(self):
        """True for ``wh`` itself with its default options (Jacobi coordinates,
        no corrector): the map that :mod:`orbits._kernels.wh_batch` advances
        for many systems at once, bit for bit as this class does for one.

        Examples
        --------
        >>> orbits.integrators.get("wh").batchable
        True
        >>> orbits.integrators.get("wh", corrector=3).batchable
        False
        """
        return (self.operators == tableaux.WH_DKD and self.config["coordinates"] == "jacobi"
                and self.config["corrector"] == 0)

    @classmethod
    def _prepare_table(cls):
        ops = tuple(cls.operators)
        if ops != ops[::-1] or ops[0][0] != "drift":
            raise TypeError(f"{cls.__name__}: a Kepler-split table must be a palindrome "
                            "that starts and ends with a drift")
        codes = {"drift": DRIFT, "kick": KICK}
        cls._kinds = np.array([codes[k] for k, _ in ops], dtype=np.int64)
        cls._coefs = np.array([float(c) for _, c in ops])
        cls.forces_per_step = sum(1 for k, _ in ops if k == "kick")

    def _check_options(self):
        corr = self.config["corrector"]
        if corr and self.operators != tableaux.WH_DKD:
            raise IntegratorOptionError(
                f"{self.name}: the symplectic correctors belong to the Wisdom-Holman "
                "map K(h/2) I(h) K(h/2); use 'wh', or corrector=0")
        self._corr = corrector_stages(corr)

    def workspace(self, n):
        return {"xj": np.zeros((n, 3)), "vj": np.zeros((n, 3)),
                "xs": np.zeros((n, 3)), "vs": np.zeros((n, 3)), "acc": np.zeros((n, 3)),
                "gm": np.zeros(n), "eta": np.zeros(n),
                # [internal state current, system checked]
                "state": np.zeros(2, dtype=np.int64),
                "owed": np.zeros(1),
                # the step whose corrector the Jacobi state carries, and N_active
                "cdt": np.zeros(1), "n_active": np.zeros(1, dtype=np.int64)}

    def check_terms(self, terms):
        """Only terms that depend on positions alone and have a potential join the
        interaction step; the map is then still symplectic."""
        refuse_unkickable(self, terms)

    def bind(self, ws, force, fargs):
        """Keep the added terms' kernel and arguments in the workspace (not an
        array, so neither saved nor restored: rebound from the simulation), and
        for a force with variations its tangent arguments."""
        if force.inner is not None:
            self._bind_tangent(ws, force, fargs)
            force, fargs = force.inner, fargs[0]
        if force.terms is not None:
            ws["terms"] = (force.terms, fargs[1])

    def _bind_tangent(self, ws, force, fargs):
        # the tangent arguments tp of orbits._kernels.wh_tangent, kept with the
        # force (neither is an array: rebound, not saved); the chaos box in tp
        # is the one fargs brings, replaced by the workspace's in advance
        inner, (inner_fargs, vargs) = force.inner, fargs
        n, dm, jx, jv, box, (G, eps2, chaos, _) = vargs
        dm = np.ascontiguousarray(dm, dtype=np.float64)
        k = dm.shape[0]
        if dm.shape != (k, n):
            raise ValueError(f"{self.name}: mass variations of shape {dm.shape}, "
                             f"expected ({k}, {n})")
        masses = bool(np.any(dm != 0.0))
        if masses and inner.terms is not None:
            raise IntegratorOptionError(
                f"{self.name}: mass variations together with added force terms are not "
                "supported (the terms' dependence on the masses is not differentiated); "
                "use 'ias15'")
        dgm = G * dm
        if self.config["coordinates"] == "jacobi":
            # each row's Kepler G M is the interior mass G eta_i
            deta = np.cumsum(dgm, axis=1)
        else:
            # every row orbits G m_0
            deta = np.repeat(dgm[:, :1], n, axis=1)
        ws["tangent"] = (force, n, (dgm, np.ascontiguousarray(deta), k, masses, jx, jv, box,
                                    chaos))

    def _check_system(self, ws, force, fargs):
        gm, n_active = split_gravity(self.name, force, fargs, "'leapfrog' or 'yoshida4'")
        # (a run with variations has a workspace of more rows than bodies: the
        # rows after the bodies' are not used)
        ws["gm"][:len(gm)] = gm
        ws["n_active"][0] = n_active
        if self.config["coordinates"] == "jacobi":
            _coordinates.interior_gm(gm, ws["eta"])
        else:
            # every body orbits the central one alone (row 0 is not a Kepler orbit)
            ws["eta"][:] = gm[0]
        ws["state"][1] = 1

    def advance(self, ws, x, v, t, dt, nsteps, force, fargs, mon, step0, mon_t, mon_out,
                velocity_dependent=False, check_every=1, stop=None):
        """Advance by ``nsteps`` steps in the compiled loop (see
        :meth:`Integrator.advance`); with ``stop`` (the stopping arguments of
        :mod:`orbits._kernels.stopping`, escapes only), the loop checks
        escapes: it looks at the synchronised state after every step where a
        body may be beyond the escape distance
        (:func:`orbits._kernels.wisdom_holman.may_escape`), and drifts its
        planets without the vector lanes."""
        if force.inner is not None:
            return self._advance_tangent(ws, x, v, t, dt, nsteps, force, fargs, mon, step0,
                                         mon_t, mon_out, check_every, stop)
        if ws["state"][1] == 0:
            self._check_system(ws, force, fargs)
        gravity = fargs if ws.get("terms", (None,))[0] is None else fargs[0]
        gm, n_active = gravity[0], gravity[1]
        if "lanes_pay" not in ws:
            # chosen once for the workspace, at its first step: a shorter
            # last step does not switch loops
            ws["lanes_pay"] = lanes_pay(x, v, gm, dt)
        lanes = (stop is None and self.lanes_wanted(ws, x.shape[0], force.recorder)
                 and ws["lanes_pay"])
        # (the lanes' state is not in xj, vj between steps: a run with
        # stopping conditions takes the scalar loop, bit for bit the same steps)
        loop, terms, targs, mon = self._loop(ws, force, x.shape[0], lanes, mon)
        sargs, check = stop_record(stop)
        system = _wh.System(gm, ws["eta"], int(n_active), self._corr, self._kinds, self._coefs)
        correct = self._corrector(ws, loop, terms, lanes, gm, targs)
        # the lanes' loop checks no escapes: it takes a number it never reads
        escape = 0 if lanes else _loop_escape(
            loop, stop is not None, lambda conditions: _wh.loop_escape(
                self.config["coordinates"], terms, (sargs, check),
                _sync_of(system, ws, x, v, targs, correct), conditions))
        out = loop(x, v, t, dt, nsteps, system, records.work(_wh.Work, ws),
                   records.outputs(mon, step0, mon_t, mon_out),
                   records.checks(check_every, sargs), check, escape, correct, targs)
        if lanes:
            note_lanes_ready(loop)
        return with_status(*out)

    def _corrector(self, ws, loop, terms, lanes, gm, targs):
        # the loop's corrector pointer (orbits._kernels.wisdom_holman's
        # corrector_pointer: compiled only where the method has a corrector),
        # once a loop and process, as the escape check's; kept in the
        # workspace (not an array: neither saved nor restored) for the
        # synchronisation outside the loop
        corrected = self._corr.shape[0] > 0
        found = _CORRECTORS.get((loop, corrected))
        if found is None:
            found = _CORRECTORS[loop, corrected] = _wh.corrector_pointer(
                self.config["coordinates"], terms, lanes, _wh.corrector_signature(
                    ws["xj"], gm, ws["eta"], self._corr, targs), corrected)
        ws["corrector"] = found
        return found

    def _loop(self, ws, force, n, lanes, mon=None):
        # (the compiled loop, the terms' kernel, the loop's targs, the
        # monitors) of a run of n rows with force (table_bound)
        terms, targs = self._loop_terms(ws, n, lanes)
        recorder = force.recorder
        if not lanes:
            _, _, recorder, mon = table_bound(ws, n, recorder, mon)
        loop = _wh.wh_loop(self.config["coordinates"], terms, recorder, lanes)
        return loop, terms, targs, mon

    def loop(self, sim, lanes=False):
        """The compiled loop that the simulation ``sim`` steps in: with
        variations (or chaos monitors) the tangent loop, else the scalar one
        or, with ``lanes``, the lanes' one.  The scalar and the tangent loop
        are the same for runs with and without force terms.

        Examples
        --------
        >>> wh = orbits.integrators.get("wh")
        >>> bodies = orbits.scenes.outer_solar_system()
        >>> plain = orbits.Simulation(bodies, wh, dt=30 * u.day)
        >>> gr = orbits.Simulation(bodies, wh, dt=30 * u.day,
        ...                        forces=[orbits.forces.GRPotential("Sun")])
        >>> wh.loop(plain) is wh.loop(gr)
        True
        """
        if sim._force.inner is not None:
            return _wht.wh_tangent_loop(self.config["coordinates"],
                                        table_bound(sim._ws, len(sim._m))[0], sim._force)
        return self._loop(sim._ws, sim._force, len(sim._m), lanes)[0]

    def lanes_wanted(self, ws, n, recorder=None):
        """Whether a run of ``n`` bodies steps in the vector lanes (where
        they pay, :func:`lanes_pay`), by the ``lanes`` option: ``"on"``,
        ``"off"``, or with ``"auto"`` where the simulation reaches
        :data:`LANES_FROM_STEPS` steps by the run's end (``ws["steps_by_end"]``,
        set by the run) or the lanes' loop (for ``recorder``, the monitors'
        recorder) is compiled already (:func:`lanes_ready`).  Only the time
        differs: the results are the same bit for bit.

        Examples
        --------
        >>> wh = orbits.integrators.get("wh")
        >>> ws = wh.workspace(5)
        >>> wh.lanes_wanted({**ws, "steps_by_end": 10 ** 8}, 5), wh.lanes_wanted(ws, 3)
        (True, False)
        >>> orbits.integrators.get("wh", lanes="on").lanes_wanted(ws, 5)
        True
        """
        return lanes_choice(ws, self.config["lanes"], n, lambda: lanes_ready(_wh.wh_loop(
            self.config["coordinates"], None, _wh._record if recorder is None else recorder,
            True)))

    @staticmethod
    def _loop_terms(ws, n, lanes):
        # (terms, the loop's targs) for n rows: the added terms' kernel and
        # arguments, or, for the lanes' loop, the lanes' scratch; the loop and
        # the synchronisation take the same targs, so that what they share
        # compiles once.  The scratch is kept in the workspace as a tuple: not
        # an array, so neither saved nor restored (what it carries from step
        # to step, a count of drifts left to the scalar solver, only chooses
        # between two paths with the same results).  The choice is kept for
        # the synchronisation (ws["lanes_taken"])
        ws["lanes_taken"] = lanes
        if lanes:
            return None, lanes_scratch_in(ws, _lanes.lanes_scratch_shape(n))
        # the scalar loop serves runs with and without terms (table_bound)
        return table_bound(ws, n)[:2]

    def _advance_tangent(self, ws, x, v, t, dt, nsteps, force, fargs, mon, step0, mon_t,
                         mon_out, check_every, stop=None):
        # a force with variations (force.inner the gravity, fargs = (its
        # fargs, vargs)): x, v hold the bodies and then the tangent vectors
        # (orbits._kernels.wh_tangent), and the loop carries the tangent of
        # every operator
        fargs = work_bound(force, fargs, ws)
        if ws["state"][1] == 0:
            self._check_system(ws, force.inner, fargs[0])
        if ws.get("tangent", (None,))[0] is not force:
            self.bind(ws, force, fargs)
        _, n, tp = ws["tangent"]
        if x.shape[0] != n * (1 + tp[2]):
            raise ValueError(f"{self.name}: {x.shape[0]} state rows for {n} bodies and "
                             f"{tp[2]} tangent vectors")
        tp = tp[:6] + (fargs[1][4],) + tp[7:]
        gravity = fargs[0] if "terms" not in ws else fargs[0][0]
        gm, n_active = gravity[0], gravity[1]
        terms, targs, _, mon = table_bound(ws, n, None, mon)
        loop = _wht.wh_tangent_loop(self.config["coordinates"], terms, force)
        sargs, check = stop_record(stop)
        system = _wh.System(gm, ws["eta"][:n], int(n_active), self._corr, self._kinds,
                            self._coefs)
        # (the tangent loop compiles its corrector in, and takes 0 for the
        # pointer of the loops without variations)
        escape = _loop_escape(loop, stop is not None, lambda conditions: _wht.tangent_loop_escape(
            self.config["coordinates"], terms, force, (sargs, check),
            _sync_of(system, ws, x, v, (targs, tp), 0), conditions))
        return with_status(*loop(x, v, t, dt, nsteps, system, records.work(_wh.Work, ws),
                                 records.outputs(mon, step0, mon_t, mon_out),
                                 records.checks(check_every, sargs), check, escape, 0,
                                 (targs, tp)))

    def synchronize(self, ws, x, v):
        """Write the current inertial state into ``x``, ``v``; the Jacobi state and
        its owed drift are kept, so that the following steps go on unchanged."""
        if ws["state"][0] and "tangent" in ws:
            force, n, tp = ws["tangent"]
            terms, targs = table_bound(ws, n)[:2]
            sync = _wht.tangent_synchronizer(self.config["coordinates"], terms, force)
            sync(ws["xj"], ws["vj"], ws["gm"][:n], ws["eta"][:n], ws["owed"][0], ws["xs"],
                 ws["vs"], x, v, ws["acc"], int(ws["n_active"][0]), self._corr, ws["cdt"][0],
                 (targs, tp), 0)
        elif ws["state"][0]:
            lanes = ws.get("lanes_taken", False)
            terms, targs = self._loop_terms(ws, x.shape[0], lanes)
            sync = _wh.synchronizer(self.config["coordinates"], terms, lanes)
            correct = ws.get("corrector")
            if correct is None:
                # a workspace read back from a file: the pointer of the loop
                # it steps in (which that loop will take too)
                correct = self._corrector(ws, _wh.wh_loop(self.config["coordinates"], terms,
                                                          lanes=lanes), terms, lanes,
                                          ws["gm"], targs)
            sync(ws["xj"], ws["vj"], ws["gm"], ws["eta"], ws["owed"][0], ws["xs"], ws["vs"],
                 x, v, ws["acc"], int(ws["n_active"][0]), self._corr, ws["cdt"][0], targs,
                 correct)

    def invalidate(self, ws):
        """The state was changed from outside: start again from ``x``, ``v``."""
        ws["state"][0] = 0
        ws["owed"][0] = 0.0


WisdomHolman._prepare_table()


class SABA2(WisdomHolman):
    """SABA_2 of Laskar & Robutel (2001): two interaction kicks a step.

    Notes
    -----
    ``K(c_1 h) I(h/2) K(c_2 h) I(h/2) K(c_1 h)`` with
    ``c_1 = 1/2 - sqrt(3)/6``, ``c_2 = sqrt(3)/3`` (the drifts end at the
    Gauss-Legendre nodes).  Error ``O(epsilon h^4 + epsilon^2 h^2)``: fourth
    order while ``epsilon h^2`` dominates, second order in general.  Options,
    state and requirements as :class:`WisdomHolman` (correctors: only 0).

    References
    ----------
    Laskar, J. & Robutel, P. 2001, "High order symplectic integrators for
    perturbed Hamiltonian systems", Celest. Mech. Dyn. Astron. 80, 39, table 1.

    SABA_3 and SABA_4 (:class:`SABA3`, :class:`SABA4`) are the same with three
    and four kicks a step, of error ``O(epsilon h^6 + epsilon^2 h^2)`` and
    ``O(epsilon h^8 + epsilon^2 h^2)``; their tables are in
    :mod:`orbits.integrators.tableaux`.

    Examples
    --------
    A kick a step more with each, and one more drift:

    >>> [(orbits.integrators.get(name).forces_per_step,
    ...   len(orbits.integrators.get(name).operators)) for name in ("saba2", "saba3", "saba4")]
    [(2, 5), (3, 7), (4, 9)]
    """

    name = "saba2"
    summary = "SABA_2 (Laskar & Robutel 2001): Kepler drifts, two kicks a step"
    operators = tableaux.SABA2


class SABA3(WisdomHolman):
    """SABA_3 of Laskar & Robutel (2001, table 1): three interaction kicks a
    step, error ``O(epsilon h^6 + epsilon^2 h^2)``; see :class:`SABA2`."""

    name = "saba3"
    summary = "SABA_3 (Laskar & Robutel 2001): Kepler drifts, three kicks a step"
    operators = tableaux.SABA3


class SABA4(WisdomHolman):
    """SABA_4 of Laskar & Robutel (2001, table 1): four interaction kicks a
    step, error ``O(epsilon h^8 + epsilon^2 h^2)``; see :class:`SABA2`."""

    name = "saba4"
    summary = "SABA_4 (Laskar & Robutel 2001): Kepler drifts, four kicks a step"
    operators = tableaux.SABA4
