"""Force Jacobians: ``da/dx`` and ``da/dv`` of a force, for the implicit methods'
Newton iteration (:mod:`.implicit`) and the variational equations
(:mod:`.variational`).

A Jacobian kernel has the signature ``jacobian(x, v, t, fargs, jx, jv)`` and
writes ``da/dx`` and ``da/dv`` over the flattened (N, 3) state into the
(3N, 3N) arrays ``jx`` and ``jv``: :func:`gravity_jacobian` for pairwise
gravity, gravity's plus each added term's for gravity with terms (a term owns
its Jacobian, :mod:`.terms`), a user's function through :func:`user_jacobian`,
and central differences of the force otherwise
(:func:`finite_difference_jacobian`).  :func:`jacobian_for` chooses among
them for a :class:`~.stepping.ForceKernel`.
"""

import math

import numpy as np

from ._jit import njit, slots, specialize

# the names the templates below are written against, bound by specialize
force, VELOCITY, base_jacobian, extra, extra_reads, user_jac, differences = slots(
    "force", "VELOCITY", "base_jacobian", "extra", "extra_reads", "user_jac", "differences")

__all__ = ["gravity_jacobian", "user_jacobian", "user_jacobian_pointer", "user_jacobian_call",
           "POINTER_KEY",
           "finite_difference_jacobian", "jacobian_for",
           "central_differences", "FD_STEP"]

_EPS = 2.220446049250313e-16

#: relative step of the central differences, eps^(1/3): it balances the
#: truncation error (~ step^2) against round-off (~ eps / step), as in
#: scipy.optimize.approx_derivative's 3-point rule
FD_STEP = _EPS ** (1.0 / 3.0)


@njit
def gravity_jacobian(x, v, t, fargs, jx, jv):
    """``da/dx`` of pairwise gravity (``fargs`` as the gravity force's); ``jv`` untouched.

    Notes
    -----
    With ``r = x_i - x_j`` and ``s^2 = |r|^2 + eps2``, the block of body i's
    acceleration against body j's position is, for ``j != i``,

        dA_i/dx_j = G m_j (I / s^3 - 3 r r^T / s^5),

    and the diagonal block is minus the sum of the others in its row (the
    acceleration depends on differences of positions only).  Each pair is
    visited once, as in the force kernels: the block is symmetric in ``r``.
    Test particles (``i >= n_active``, zero mass) pair with the massive
    bodies only.
    """
    gm, n_active, eps2 = fargs[0], fargs[1], fargs[2]
    n = x.shape[0]
    m = 3 * n
    for p in range(m):
        for q in range(m):
            jx[p, q] = 0.0
    d = np.empty(3)
    for i in range(1, n):
        for j in range(min(i, n_active)):
            d[0] = x[i, 0] - x[j, 0]
            d[1] = x[i, 1] - x[j, 1]
            d[2] = x[i, 2] - x[j, 2]
            r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + eps2
            inv_r3 = 1.0 / (r2 * math.sqrt(r2))
            inv_r5 = inv_r3 / r2
            gj = gm[j]
            gi = gm[i] if i < n_active else 0.0
            for a in range(3):
                for b in range(3):
                    mab = -3.0 * d[a] * d[b] * inv_r5
                    if a == b:
                        mab += inv_r3
                    jx[3 * i + a, 3 * j + b] += gj * mab
                    jx[3 * i + a, 3 * i + b] -= gj * mab
                    if gi != 0.0:
                        jx[3 * j + a, 3 * i + b] += gi * mab
                        jx[3 * j + a, 3 * j + b] -= gi * mab


def _user_jacobian(x, v, t, fargs, jx, jv):
    # the user's (size, size) matrices fill the top-left of the (3N, 3N)
    # arrays; rows and columns of the padding stay zero.  fargs are the user
    # force's (size, shape, ...) (orbits._user_functions.force_args)
    size, shape = fargs[0], fargs[1]
    xu = x.ravel()[:size].reshape(shape)
    vu = v.ravel()[:size].reshape(shape)
    dadx, dadv = user_jac(xu, vu, t)
    jxu = np.asarray(dadx)
    jvu = np.asarray(dadv)
    for p in range(size):
        for q in range(size):
            jx[p, q] = jxu[p, q]
            jv[p, q] = jvu[p, q]


def _user_jacobian_pointer(x, v, t, fargs, jx, jv):
    # a user's compiled Jacobian through its pointer
    # (orbits._user_functions.jacobian_pointer): fargs = (size, shape, the
    # force's pointer, flag, the Jacobian's pointer)
    fargs[4](x, v, t, fargs[0], fargs[1], fargs[3], jx, jv)


#: :func:`jacobian_for`'s key of :func:`user_jacobian_pointer`, the one user
#: Jacobian whose loops are cached on disk
POINTER_KEY = "jac_pointer"

# the module of the Jacobians of forces with variations (not imported here:
# it imports this one)
_VARIATIONAL = __name__.rpartition(".")[0] + ".variational"


def user_jacobian_pointer():
    """The Jacobian kernel of a user's compiled ``jac`` called through its
    pointer, the last of the force's arguments: compiled once, cached, for
    every such function (as :func:`orbits._kernels.stepping.user_force`)."""
    return specialize(_user_jacobian_pointer, "user_pointer", inline=True)


def user_jacobian_call():
    """:func:`user_jacobian_pointer`'s kernel as a function that Python calls
    (``(x, v, t, fargs, jx, jv)``), compiled once, cached, for every such
    Jacobian."""
    return specialize(_user_jacobian_pointer, "user_pointer_call")


def user_jacobian(jac, jit):
    """A Jacobian kernel from a user's ``jac(x, v, t) -> (da/dx, da/dv)``.

    ``jac`` takes and returns arrays as the user's ``accel`` does: ``x`` and
    ``v`` of the shape of ``x0``, and two (size, size) matrices over the
    flattened (C-order) state.  Compiled if ``jac`` is a numba function.
    """
    return specialize(_user_jacobian, f"userjac{id(jac)}", jit=jit, cache=False,
                      user_jac=jac)


def central_differences(x, v, t, fargs, jx, jv, velocity, step, floor_x, floor_v, add):
    """Central differences of ``force`` (a slot), column by column: component
    q of the positions (then, with ``velocity``, of the velocities) moves by
    ``+-delta``, ``delta = step * max(|y_q|, floor)`` with the positions' or
    the velocities' ``floor``, and column q of ``jx`` (``jv``) becomes the
    difference of the two accelerations over the difference of the two
    perturbed values (exact in binary), or with ``add`` is added to it.  A
    template: :func:`finite_difference_jacobian` binds a force, and
    :func:`orbits._kernels.terms.row_difference_jacobian` one row of a
    table of terms."""
    n = x.shape[0]
    m = 3 * n
    xp = x.copy()
    vp = v.copy()
    ap = np.empty((n, 3))
    am = np.empty((n, 3))
    for half in range(2 if velocity else 1):
        src = x if half == 0 else v
        moved = xp if half == 0 else vp
        out = jx if half == 0 else jv
        floor = floor_x if half == 0 else floor_v
        for q in range(m):
            i = q // 3
            d = q % 3
            delta = step * max(abs(src[i, d]), floor)
            hi = src[i, d] + delta
            lo = src[i, d] - delta
            # zeros: a force may write only its own components (a user's,
            # not the padding), or add to them (a table's terms)
            ap[...] = 0.0
            am[...] = 0.0
            moved[i, d] = hi
            force(xp, vp, t, fargs, ap)
            moved[i, d] = lo
            force(xp, vp, t, fargs, am)
            moved[i, d] = src[i, d]
            inv = 1.0 / (hi - lo)
            for p in range(m):
                diff = (ap[p // 3, p % 3] - am[p // 3, p % 3]) * inv
                if add:
                    out[p, q] += diff
                else:
                    out[p, q] = diff


def _finite_difference_jacobian(x, v, t, fargs, jx, jv):
    # the relative step FD_STEP, of max(|y_q|, 1)
    differences(x, v, t, fargs, jx, jv, VELOCITY, FD_STEP, 1.0, 1.0, False)


def finite_difference_jacobian(force, velocity_dependent):
    """Central-difference Jacobian of a :class:`~.stepping.ForceKernel`'s force.

    Costs ``6N`` force evaluations (``12N`` with ``velocity_dependent``, which
    also differentiates in ``v``); the relative step is :data:`FD_STEP` times
    ``max(|y_q|, 1)`` for each state component ``y_q``.  Its error, about
    ``FD_STEP^2`` relative, only slows Newton's convergence: the converged
    solution does not depend on it.
    """
    key = f"fd_{force.key}{'_v' if velocity_dependent else ''}"
    differences = specialize(central_differences, force.key, jit=force.jit, cache=force.cache,
                             inline=True, force=force.kernel)
    return specialize(_finite_difference_jacobian, key, jit=force.jit, cache=force.cache,
                      differences=differences, VELOCITY=bool(velocity_dependent))


#: keys of the gravity forces (stepping.gravity_force)
_GRAVITY_KEYS = ("gravity_small", "gravity_serial", "gravity_parallel")


def _jacobian_with_terms(x, v, t, fargs, jx, jv):
    # whether the terms read velocities is their table's (data): one
    # Jacobian for every table
    base_jacobian(x, v, t, fargs[0], jx, jv)
    if extra_reads(fargs[1]):
        for p in range(jv.shape[0]):
            for q in range(jv.shape[1]):
                jv[p, q] = 0.0
    extra(x, v, t, fargs[1], jx, jv)


def jacobian_for(force, velocity_dependent):
    """The Jacobian kernel of a force and the key naming it.

    The force's own (``force.jacobian``, a user's) if it has one, the analytic
    one of gravity for the gravity forces, gravity's plus each added term's
    for gravity with terms, central differences otherwise.
    """
    if force.terms is not None:
        base, bkey = jacobian_for(force.base, False)
        key = f"{bkey}+{force.terms.key}"
        return specialize(_jacobian_with_terms, key, cache=force.cache, base_jacobian=base,
                          extra=force.terms.jacobian,
                          extra_reads=force.terms.reads_velocities), key
    own = getattr(force, "jacobian", None)
    if own is not None:
        # a user's compiled Jacobian through its pointer is one kernel for all
        # (its loops are cached, POINTER_KEY); the package's own compiled one
        # (a force with variations': orbits._kernels.variational) is a copy
        # named by its bindings, the same name in every process, so that the
        # loops that call it are cached too ("varied"); another is named by
        # its identity, and its loops are not cached
        if own is user_jacobian_pointer():
            return own, POINTER_KEY
        func = getattr(own, "py_func", None)
        if force.cache and func is not None and func.__module__ == _VARIATIONAL:
            return own, "varied"
        return own, f"own{id(own)}"
    if force.key in _GRAVITY_KEYS:
        return gravity_jacobian, "gravity"
    return finite_difference_jacobian(force, velocity_dependent), "fd"
