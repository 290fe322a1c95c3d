"""Three stepping loops with nothing but the method, compiled by numba alone:
what numba takes on this host to compile the least loop of each kind.

``python benchmarks/_bare_numba.py leapfrog|wh|ias15`` compiles one of them in
this process (an empty cache: nothing here is cached) and prints, as JSON,
the CPU seconds of importing numba and of the loop's first call (its
compiling, numba's own first-use set-up included, no steps taken).
``... ias15 --check`` (or ``wh --check``) instead integrates a circular orbit for
ten periods and prints the radius's largest departure from 1.

- ``leapfrog``: kick-drift-kick with the pairwise pull, written component by
  component (numba compiles loops of scalars quicker than array
  expressions).
- ``wh``: a Wisdom-Holman step in democratic heliocentric coordinates
  (Duncan, Levison & Lee 1998): each planet's Kepler drift by the universal
  variable with Stumpff's functions and Newton's iteration, the planets'
  mutual pulls, the star's jump.
- ``ias15``: the Gauss-Radau predictor-corrector of IAS15 (Rein & Spiegel
  2015) over seven substeps, iterated to
  convergence, and the global step control.  No compensated sums, outputs,
  landing on times, monitors, stopping conditions or checks of the state:
  what every run of the package's loops has besides.

Run by ``benchmarks/bench_first_compile.py`` beside the package's first runs.
"""

import json
import math
import sys
import time

_cpu = time.process_time()
import numpy as np  # noqa: E402 - the import is what is timed
from numba import njit  # noqa: E402
_IMPORTED = time.process_time() - _cpu


@njit
def pulls(x, m, a):
    n = x.shape[0]
    for i in range(n):
        for d in range(3):
            a[i, d] = 0.0
    for i in range(n):
        for j in range(i + 1, n):
            dx = x[j, 0] - x[i, 0]
            dy = x[j, 1] - x[i, 1]
            dz = x[j, 2] - x[i, 2]
            r2 = dx * dx + dy * dy + dz * dz
            f = 1.0 / (r2 * math.sqrt(r2))
            a[i, 0] += m[j] * f * dx
            a[i, 1] += m[j] * f * dy
            a[i, 2] += m[j] * f * dz
            a[j, 0] -= m[i] * f * dx
            a[j, 1] -= m[i] * f * dy
            a[j, 2] -= m[i] * f * dz


@njit
def leapfrog(x, v, m, dt, steps, a):
    pulls(x, m, a)
    for _ in range(steps):
        for i in range(x.shape[0]):
            for d in range(3):
                v[i, d] += 0.5 * dt * a[i, d]
                x[i, d] += dt * v[i, d]
        pulls(x, m, a)
        for i in range(x.shape[0]):
            for d in range(3):
                v[i, d] += 0.5 * dt * a[i, d]


@njit
def ias15(x, v, m, t, t_end, dt, eps, H, R, C):
    n = x.shape[0]
    a0 = np.zeros((n, 3))
    a = np.zeros((n, 3))
    xs = np.zeros((n, 3))
    b = np.zeros((7, n, 3))
    g = np.zeros((7, n, 3))
    while t < t_end:
        dt = min(dt, t_end - t)
        pulls(x, m, a0)
        b[...] = 0.0
        g[...] = 0.0
        for _ in range(12):
            db6 = 0.0
            for s in range(1, 8):
                h = H[s - 1]
                for i in range(n):
                    for d in range(3):
                        p = 0.0
                        for k in range(6, -1, -1):
                            p = (p + b[k, i, d] / ((k + 2) * (k + 3))) * h
                        xs[i, d] = x[i, d] + h * dt * (v[i, d] + h * dt * (
                            0.5 * a0[i, d] + p))
                pulls(xs, m, a)
                for i in range(n):
                    for d in range(3):
                        r = (a[i, d] - a0[i, d]) * R[s, 0]
                        for j in range(1, s):
                            r = (r - g[j - 1, i, d]) * R[s, j]
                        dg = r - g[s - 1, i, d]
                        g[s - 1, i, d] = r
                        for k in range(s):
                            b[k, i, d] += C[k, s - 1] * dg
                        if s == 7:
                            db6 = max(db6, abs(dg))
            amax = 0.0
            for i in range(n):
                for d in range(3):
                    amax = max(amax, abs(a[i, d]))
            if db6 <= 1e-16 * amax:
                break
        b6 = 0.0
        for i in range(n):
            for d in range(3):
                b6 = max(b6, abs(b[6, i, d]))
                sx = 0.5 * a0[i, d]
                sv = a0[i, d]
                for k in range(7):
                    sx += b[k, i, d] / ((k + 2) * (k + 3))
                    sv += b[k, i, d] / (k + 2)
                x[i, d] += dt * (v[i, d] + dt * sx)
                v[i, d] += dt * sv
        t += dt
        if b6 > 0.0 and amax > 0.0:
            dt = min(dt * (eps / (b6 / amax)) ** (1.0 / 7.0), dt / 0.25)
    return t


@njit
def _stumpff(z):
    # c0..c3 of Stumpff by their series (|z| small) or closed forms
    if abs(z) < 1e-2:
        c3 = (1.0 - z / 20.0 * (1.0 - z / 42.0 * (1.0 - z / 72.0))) / 6.0
        c2 = (1.0 - z / 12.0 * (1.0 - z / 30.0 * (1.0 - z / 56.0))) / 2.0
    elif z > 0.0:
        q = math.sqrt(z)
        c2 = (1.0 - math.cos(q)) / z
        c3 = (q - math.sin(q)) / (z * q)
    else:
        q = math.sqrt(-z)
        c2 = (math.cosh(q) - 1.0) / -z
        c3 = (math.sinh(q) - q) / (-z * q)
    return 1.0 - z * c2, 1.0 - z * c3, c2, c3


@njit
def kepler_drift(x, v, mu, dt):
    # one body's two-body drift by dt about a centre of G mass mu, in place
    r0 = math.sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2])
    eta = x[0] * v[0] + x[1] * v[1] + x[2] * v[2]
    beta = 2.0 * mu / r0 - (v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    s = dt / r0
    for _ in range(50):
        c0, c1, c2, c3 = _stumpff(beta * s * s)
        g1 = s * c1
        g2 = s * s * c2
        g3 = s * s * s * c3
        r = r0 * c0 + eta * g1 + mu * g2
        ds = (r0 * g1 + eta * g2 + mu * g3 - dt) / r
        s -= ds
        if abs(ds) <= 1e-15 * abs(s):
            break
    c0, c1, c2, c3 = _stumpff(beta * s * s)
    g1 = s * c1
    g2 = s * s * c2
    g3 = s * s * s * c3
    r = r0 * c0 + eta * g1 + mu * g2
    f = 1.0 - mu * g2 / r0
    g = dt - mu * g3
    fd = -mu * g1 / (r0 * r)
    gd = 1.0 - mu * g2 / r
    for d in range(3):
        xd = x[d]
        x[d] = f * xd + g * v[d]
        v[d] = fd * xd + gd * v[d]


@njit
def _jump(x, v, m, h):
    # the star's part: every planet moved by h times the planets' momentum
    # over the star's mass
    p0 = 0.0
    p1 = 0.0
    p2 = 0.0
    for i in range(1, x.shape[0]):
        p0 += m[i] * v[i, 0]
        p1 += m[i] * v[i, 1]
        p2 += m[i] * v[i, 2]
    for i in range(1, x.shape[0]):
        x[i, 0] += h * p0 / m[0]
        x[i, 1] += h * p1 / m[0]
        x[i, 2] += h * p2 / m[0]


@njit
def _kick(x, v, m, h, a):
    # the planets' mutual pulls
    pulls(x[1:], m[1:], a[1:])
    for i in range(1, x.shape[0]):
        for d in range(3):
            v[i, d] += h * a[i, d]


@njit
def wh(x, v, m, dt, steps, a):
    # democratic heliocentric: x the planets' heliocentric positions, v their
    # barycentric velocities (rows 1..), m G times the masses, the star's
    # first; a step is kick, jump, drift, jump, kick
    for _ in range(steps):
        _kick(x, v, m, 0.5 * dt, a)
        _jump(x, v, m, 0.5 * dt)
        for i in range(1, x.shape[0]):
            kepler_drift(x[i], v[i], m[0], dt)
        _jump(x, v, m, 0.5 * dt)
        _kick(x, v, m, 0.5 * dt, a)

def _tables():
    # the Gauss-Radau spacings of IAS15's substeps; R[i, j] = 1 / (h_i - h_j)
    # over the nodes with h_0 = 0; C, the matrix of b = C g (Everhart 1985),
    # by its recursion (the same numbers as orbits._kernels.ias15's tables
    # to 4.4e-16; nothing of the package imported, so that numba's first-use
    # set-up stays in the timing)
    H = np.array([0.0562625605369221464656521910318, 0.180240691736892364987579942780,
                  0.352624717113169637373907769648, 0.547153626330555383001448554766,
                  0.734210177215410531523210605558, 0.885320946839095768090359771030,
                  0.977520613561287501891174488626])
    nodes = np.concatenate(([0.0], H))
    R = np.zeros((8, 8))
    for i in range(8):
        for j in range(i):
            R[i, j] = 1.0 / (nodes[i] - nodes[j])
    C = np.eye(7)
    for k in range(1, 7):
        C[0, k] = -H[k - 1] * C[0, k - 1]
        for j in range(1, k):
            C[j, k] = C[j - 1, k - 1] - H[k - 1] * C[j, k - 1]
    return H, R, C


def _orbit(which, x, v, m, t):
    # one period (2 pi) of the circular orbit of a massless body at 1 about
    # a unit mass at rest, by the loop named, from time t; the time reached
    if which == "wh":
        wh(x, v, m, 2 * math.pi / 20, 20, np.zeros((2, 3)))
        return t + 2 * math.pi
    return ias15(x, v, m, t, t + 2 * math.pi, 0.1, 1e-9, *_tables())


def main(argv):
    which = argv[0]
    if "--check" in argv:
        x = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
        v = np.array([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
        m = np.array([1.0, 0.0])
        worst = 0.0
        t = 0.0
        for _ in range(10):
            t = _orbit(which, x, v, m, t)
            worst = max(worst, abs(math.hypot(*(x[1] - x[0])) - 1.0))
        print(json.dumps({"radius_error": worst}))
        return
    x = np.arange(18.0).reshape(6, 3)
    v = np.ones((6, 3))
    m = np.ones(6)
    tables = _tables()
    cpu = time.process_time()
    if which == "leapfrog":
        leapfrog(x, v, m, 0.01, 0, np.zeros((6, 3)))
    elif which == "wh":
        wh(x, v, m, 0.01, 0, np.zeros((6, 3)))
    else:
        ias15(x, v, m, 0.0, 0.0, 0.01, 1e-9, *tables)
    print(json.dumps({"import": _IMPORTED, "compile": time.process_time() - cpu}))

if __name__ == "__main__":
    main(sys.argv[1:])
