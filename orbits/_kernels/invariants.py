"""Conserved quantities, summed with compensation.

Energy is the difference of two nearly equal sums on long runs, so its terms
are added with Neumaier's compensated summation (Neumaier 1974), which keeps
the sum to about one rounding error whatever N is.
"""

import math

import numpy as np

from ._jit import njit

__all__ = ["energy", "angular_momentum", "momentum", "center_of_mass",
           "monitor_row", "fill_monitors", "fill_kernel", "holds_state", "FILLED",
           "MONITOR_COLUMNS", "MONITOR_WIDTH", "WORK_COLUMN", "ENERGY",
           "ANGULAR_MOMENTUM", "MOMENTUM", "CENTER_OF_MASS", "relative_errors",
           "vector_errors", "error_kernels"]

# Bits of the ``which`` mask of monitor_row, and the columns they fill.
ENERGY = 1
ANGULAR_MOMENTUM = 2
MOMENTUM = 4
CENTER_OF_MASS = 8
#: the chaos indicators (not computed by monitor_row; see MONITOR_COLUMNS)
MEGNO = 16
LYAPUNOV = 32
FLI = 64
#: column layout of a monitor row; "work" is W, the energy the non-conservative
#: force terms have taken out since the simulation was made (written by the
#: loops that integrate it, not by :func:`monitor_row`: it is not a function of
#: the state), so that E + W is the conserved quantity; "megno", "lyapunov"
#: and "fli" are the chaos indicators of a run with them (written by the
#: loops too, from the tangent vector: orbits._kernels.variational).  Each
#: column belongs to one monitor's spec (orbits._monitor_specs, checked
#: against this layout and these bits when it is imported)
MONITOR_COLUMNS = ("energy", "Lx", "Ly", "Lz", "px", "py", "pz", "comx", "comy", "comz",
                   "work", "megno", "lyapunov", "fli")
#: columns of a monitor row
MONITOR_WIDTH = len(MONITOR_COLUMNS)
#: the column of the work
WORK_COLUMN = MONITOR_COLUMNS.index("work")


@njit
def _add(s, c, term):
    # Neumaier's variant of Kahan summation: returns the new (sum, compensation).
    # Both roundings are computed and one is selected, without a branch that
    # the processor would mispredict whenever the terms outgrow the sum.
    # A call, not inlined by numba: LLVM inlines it where it is called, and
    # each of the sums below would otherwise carry a copy of its statements
    # through numba's typing and lowering (benchmarks/RESULTS.md, bench_compile)
    t = s + term
    big = (s - t) + term
    small = (term - t) + s
    return t, c + (big if abs(s) >= abs(term) else small)


# energy, angular_momentum, momentum and center_of_mass are inlined into
# monitor_row, which every run's monitors call: one compilation instead of
# five, each with numba's fixed cost of a function (about 0.2 s)

@njit(inline="always")
def energy(x, v, m, G, n_active, eps2):
    """Total energy, kinetic plus pairwise potential (softened if ``eps2 > 0``).

    Parameters
    ----------
    x, v : ndarray, shape (N, 3)
    m : ndarray, shape (N,)
    G : float
    n_active : int
        Massive bodies come first; pairs of massless bodies contribute nothing.
    eps2 : float
    """
    n = x.shape[0]
    s = 0.0
    c = 0.0
    for i in range(n):
        s, c = _add(s, c, 0.5 * m[i] * (v[i, 0] * v[i, 0] + v[i, 1] * v[i, 1]
                                        + v[i, 2] * v[i, 2]))
    for i in range(n_active):
        for j in range(i):
            dx = x[i, 0] - x[j, 0]
            dy = x[i, 1] - x[j, 1]
            dz = x[i, 2] - x[j, 2]
            s, c = _add(s, c, -G * m[i] * m[j] / math.sqrt(dx * dx + dy * dy + dz * dz + eps2))
    return s + c


@njit(inline="always")
def angular_momentum(x, v, m, out):
    """Total angular momentum ``sum m x cross v`` into ``out`` (shape (3,))."""
    s0 = c0 = s1 = c1 = s2 = c2 = 0.0
    for i in range(x.shape[0]):
        s0, c0 = _add(s0, c0, m[i] * (x[i, 1] * v[i, 2] - x[i, 2] * v[i, 1]))
        s1, c1 = _add(s1, c1, m[i] * (x[i, 2] * v[i, 0] - x[i, 0] * v[i, 2]))
        s2, c2 = _add(s2, c2, m[i] * (x[i, 0] * v[i, 1] - x[i, 1] * v[i, 0]))
    out[0] = s0 + c0
    out[1] = s1 + c1
    out[2] = s2 + c2


@njit(inline="always")
def momentum(v, m, out):
    """Total linear momentum into ``out`` (shape (3,))."""
    for k in range(3):
        s = 0.0
        c = 0.0
        for i in range(v.shape[0]):
            s, c = _add(s, c, m[i] * v[i, k])
        out[k] = s + c


@njit(inline="always")
def center_of_mass(x, m, out):
    """Centre-of-mass position into ``out`` (shape (3,))."""
    mt = 0.0
    for i in range(m.shape[0]):
        mt += m[i]
    for k in range(3):
        s = 0.0
        c = 0.0
        for i in range(x.shape[0]):
            s, c = _add(s, c, m[i] * x[i, k])
        out[k] = (s + c) / mt


@njit
def monitor_row(x, v, m, G, n_active, eps2, which, row):
    """Fill one monitor row (layout :data:`MONITOR_COLUMNS`) for the bits in ``which``;
    the work column is left as it is."""
    if which & ENERGY:
        row[0] = energy(x, v, m, G, n_active, eps2)
    if which & ANGULAR_MOMENTUM:
        angular_momentum(x, v, m, row[1:4])
    if which & MOMENTUM:
        momentum(v, m, row[4:7])
    if which & CENTER_OF_MASS:
        center_of_mass(x, m, row[7:10])


@njit(inline="always")
def holds_state(row, m):
    """Whether an output row is wide enough to hold the bodies' positions and
    velocities after the monitors (``6 N`` columns more, N = ``len(m)``)."""
    return row.shape[0] >= MONITOR_WIDTH + 6 * m.shape[0]


# Rows that hold the state (outputs recorded in a loop) get their energy and
# angular momentum, the default monitors, after the loop, by fill_monitors,
# a block of rows at a time: the energy's square roots and divisions, and
# the angular momentum's products, then go through the vector lanes a row a
# lane, where monitor_row, a row at a time, makes them one by one.  The sums
# are monitor_row's, term by term in the same order, so the values are the
# same to the bit (tests/kernels/test_invariants.py).  The momentum and the
# centre of mass stay with monitor_row in the loop: in the pass they would
# add a fifth to its compile time (benchmarks/RESULTS.md, bench_outputs) for
# monitors a run asks for by name only.

#: the monitors :func:`fill_monitors` makes after the loop
FILLED = ENERGY | ANGULAR_MOMENTUM

#: rows a block of :func:`fill_monitors` (its scratch: ``6 N`` of these);
#: LLVM makes vector loops of 12 or 16 iterations and more, so 8 stays scalar
FILL_BLOCK = 16


@njit(inline="always")
def _lane_add(s, c, lane, term):
    # _add on lane ``lane`` of the sums s and compensations c
    a = s[lane]
    t = a + term
    big = (a - t) + term
    small = (term - t) + a
    c[lane] = c[lane] + (big if abs(a) >= abs(term) else small)
    s[lane] = t


@njit
def fill_monitors(rows, m, G, n_active, eps2, which):
    """The energy and angular momentum (:data:`FILLED`, as far as ``which``
    asks for them) of output rows that hold the state (:func:`holds_state`),
    filled in from each row's positions and velocities: the values
    :func:`monitor_row` gives for them, to the bit, the energy plus what
    column 0 held (the force terms' energy; 0 without terms).  The other
    columns are left as they are."""
    w = MONITOR_WIDTH
    n = m.shape[0]
    B = FILL_BLOCK
    X = np.zeros((6 * n, B))
    s = np.empty((3, B))
    c = np.empty((3, B))
    for r0 in range(0, rows.shape[0], B):
        k = min(B, rows.shape[0] - r0)
        for lane in range(k):
            row = rows[r0 + lane]
            for q in range(6 * n):
                X[q, lane] = row[w + q]
        if which & ENERGY:
            s[0, :] = 0.0
            c[0, :] = 0.0
            s0 = s[0]
            c0 = c[0]
            for i in range(n):
                vx = X[3 * (n + i)]
                vy = X[3 * (n + i) + 1]
                vz = X[3 * (n + i) + 2]
                for lane in range(B):
                    _lane_add(s0, c0, lane, 0.5 * m[i] * (vx[lane] * vx[lane] + vy[lane] * vy[lane]
                                                          + vz[lane] * vz[lane]))
            for i in range(n_active):
                for j in range(i):
                    gm = -G * m[i] * m[j]
                    for lane in range(B):
                        dx = X[3 * i, lane] - X[3 * j, lane]
                        dy = X[3 * i + 1, lane] - X[3 * j + 1, lane]
                        dz = X[3 * i + 2, lane] - X[3 * j + 2, lane]
                        _lane_add(s0, c0, lane,
                                  gm / math.sqrt(dx * dx + dy * dy + dz * dz + eps2))
            for lane in range(k):
                rows[r0 + lane, 0] = (s0[lane] + c0[lane]) + rows[r0 + lane, 0]
        if which & ANGULAR_MOMENTUM:
            s[:, :] = 0.0
            c[:, :] = 0.0
            for i in range(n):
                x0 = X[3 * i]
                x1 = X[3 * i + 1]
                x2 = X[3 * i + 2]
                v0 = X[3 * (n + i)]
                v1 = X[3 * (n + i) + 1]
                v2 = X[3 * (n + i) + 2]
                for lane in range(B):
                    _lane_add(s[0], c[0], lane, m[i] * (x1[lane] * v2[lane] - x2[lane] * v1[lane]))
                    _lane_add(s[1], c[1], lane, m[i] * (x2[lane] * v0[lane] - x0[lane] * v2[lane]))
                    _lane_add(s[2], c[2], lane, m[i] * (x0[lane] * v1[lane] - x1[lane] * v0[lane]))
            for d in range(3):
                for lane in range(k):
                    rows[r0 + lane, 1 + d] = s[d, lane] + c[d, lane]


# The relative errors of a run's monitor rows, one pass over the rows each.
# The rows are wide (the monitors, then every body's position and
# velocity), so every numpy operation on one of their columns reads a cache
# line a row, and the energy's error takes five such operations and the
# angular momentum's six: one compiled pass is several times quicker
# (benchmarks/RESULTS.md).  Each is the expression of
# orbits.monitors.relative_error and vector_relative_error, in the same
# order, so the floats are the same.

@njit
def relative_errors(values, work, reference, denom, out):
    """``out = |(values + work) - reference| / denom``, element by element
    (1-d arrays of any stride)."""
    for i in range(values.shape[0]):
        out[i] = abs((values[i] + work[i]) - reference) / denom


@njit
def vector_errors(values, reference, denom, out):
    """``out = |values - reference| / denom`` for the rows of ``values``
    (shape (n, 3), any strides), the norm summed x, y, z."""
    for i in range(values.shape[0]):
        dx = values[i, 0] - reference[0]
        dy = values[i, 1] - reference[1]
        dz = values[i, 2] - reference[2]
        out[i] = math.sqrt(dx * dx + dy * dy + dz * dz) / denom


_ERROR_SIGNATURES = (
    (relative_errors, "void(float64[:], float64[:], float64, float64, float64[:])"),
    (vector_errors, "void(float64[:, :], float64[:], float64, float64[:])"))

_FILL_SIGNATURE = "void(float64[:, :], float64[:], float64, int64, float64, int64)"


def fill_kernel():
    """:func:`fill_monitors`, compiled (or loaded from the disk cache) once for
    rows of any layout and then closed to new compilations, as
    :func:`error_kernels`: a run that records its outputs in the loop loads
    it before the loop, whether or not the loop gets to an output."""
    if not fill_monitors.signatures:
        fill_monitors.compile(_FILL_SIGNATURE)
        fill_monitors.disable_compile()
    return fill_monitors


def error_kernels():
    """:func:`relative_errors` and :func:`vector_errors`, each compiled (or
    loaded from the disk cache) once for arrays of any layout and then
    closed to new compilations, so that a contiguous array (a run's single
    row, a file's monitor rows) converts to that one compilation instead of
    making another: an ensemble's worker loads its kernels in its first
    task only."""
    for kernel, signature in _ERROR_SIGNATURES:
        if not kernel.signatures:
            kernel.compile(signature)
            kernel.disable_compile()
    return relative_errors, vector_errors
