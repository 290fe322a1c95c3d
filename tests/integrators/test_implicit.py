"""Implicit Euler and the implicit midpoint rule (orbits.integrators.implicit).

Their measured orders on a Kepler orbit (1 and 2, through Simulation) are
checked by the registry-wide test_convergence.py; bit-exact restart from a
file of implicit-midpoint by test_hdf5.py, of implicit-euler here.
"""

import math

import numba
import numpy as np
import pytest

import orbits
from orbits import integrators
from orbits._kernels import gravity, jacobians, stepping
from orbits.integrators.implicit import ImplicitOneLeg

from helpers import kepler_bodies

IMPLICIT = ["implicit-euler", "implicit-midpoint"]
K = 1.0e4  # stiff spring: w = 100, so w dt = 10 at dt = 0.1


@numba.njit
def stiff(x, v, t):
    return -K * x


def spring_energy(tr):
    return 0.5 * tr.v ** 2 + 0.5 * K * tr.x ** 2


def test_stiff_spring_implicit_midpoint_keeps_energy():
    # the midpoint rule maps z = w x + i v by the Cayley transform
    # (1 + i w h/2) / (1 - i w h/2), of modulus exactly 1, whatever w h: the
    # energy is kept up to Newton's tolerance and rounding.  Measured 2.3e-13
    # after 1000 steps (a random walk of ~1e-14 per step: positions are sums
    # of terms ~100 times larger than x); 1e-11 leaves room, while any
    # damping or growth of the method would show as O(1).
    tr = orbits.integrate(stiff, 1.0, 0.0, dt=0.1, steps=1000, method="implicit-midpoint")
    E = spring_energy(tr)
    assert np.all(np.isfinite(E))
    assert np.max(np.abs(E / E[0] - 1)) < 1e-11
    # and it does oscillate (not frozen): x takes both signs
    assert tr.x.min() < -0.5 and tr.x.max() > 0.5


def test_stiff_spring_implicit_euler_damps():
    # implicit Euler maps z -> z / (1 - i w h): the energy shrinks by exactly
    # 1 / (1 + (w h)^2) = 1/101 every step (to rounding: measured 1.6e-11
    # relative, the positions being sums of terms ~100 times larger; rtol
    # 1e-9), so it is
    # bounded and decreasing, and after 1000 steps underflows to zero
    tr = orbits.integrate(stiff, 1.0, 0.0, dt=0.1, steps=1000, method="implicit-euler")
    E = spring_energy(tr)
    assert np.all(np.isfinite(E))
    np.testing.assert_allclose(E[1:20] / E[:19], 1 / 101, rtol=1e-9)
    assert np.all(np.diff(E) <= 0)
    assert E[-1] == 0.0


EXPLICIT_FIXED = [i.name for i in integrators.available()
                  if not i.adaptive and not isinstance(integrators.get(i.name), ImplicitOneLeg)]


@pytest.mark.parametrize("name", EXPLICIT_FIXED)
def test_stiff_spring_every_explicit_method_fails_loudly(name):
    # w dt = 10 is outside every explicit method's stability interval (at
    # most 2 for the Verlet family, 2.8 for rk4, smaller for the Yoshida
    # compositions): the state overflows, and that must end in NonFiniteState
    # with the last good step kept, never in inf or NaN values returned
    try:
        with pytest.raises(orbits.NonFiniteState) as exc:
            orbits.integrate(stiff, 1.0, 0.0, dt=0.1, steps=1000, method=name)
    except orbits.IntegratorOptionError as refusal:
        # the Kepler-splitting methods (wh, saba*) integrate gravity only and
        # must refuse a user's force with this clear error instead
        assert integrators.get(name).needs_central_body, refusal
        assert "cannot integrate another force" in str(refusal)
        return
    tr = exc.value.result
    assert np.all(np.isfinite(tr.x)) and np.all(np.isfinite(tr.v))
    assert tr.steps < 1000


def test_newton_iterations_per_step_on_kepler():
    # with the previous step's accelerations as predictor, Newton needs about
    # two iterations a step on a smooth orbit (measured 2.0 to 2.7 at 400 to
    # 8000 steps an orbit); more than 4 would mean a poor predictor or Jacobian
    for name in IMPLICIT:
        sim = orbits.Simulation(kepler_bodies(e=0.5), integrator=name, dt=2 * math.pi / 800,
                                monitors=())
        sim.run(until=2 * math.pi, outputs=2, progress=False)
        assert sim._ws["newton_iterations"][0] / sim.steps <= 4.0


def _two_body():
    b = kepler_bodies(e=0.6, m_orbiter=0.3)
    x = np.ascontiguousarray(b.positions.value)
    v = np.ascontiguousarray(b.velocities.value)
    gm = np.array([1.0, 0.3])
    return x, v, gravity.gravity_args(1.0, gm, 2, 0.0)


def _advance(name, x, v, dt, n, fargs):
    integ = integrators.get(name)
    ws = integ.workspace(x.shape[0])
    mon = (0, 0, np.zeros(x.shape[0]), 1.0, 2, 0.0)
    status, done, _ = integ.advance(ws, x, v, 0.0, dt, n, stepping.gravity_force("small"),
                                    fargs, mon, 0, np.empty(0), np.zeros((0, 11)))
    assert status == 0 and done == n
    return ws


def test_implicit_midpoint_is_time_symmetric():
    # 300 steps with h, then 300 with -h (half an orbit through pericentre)
    # retrace the orbit: the method is symmetric, so the only difference is
    # Newton's tolerance (a few ulps) and rounding, ~1e-16 a step, amplified
    # along the orbit: 1e-12 leaves room.  Implicit Euler, not symmetric,
    # misses by O(h) (the negative control; over longer runs its orbit decays
    # into the star, where its Newton iteration finally fails).
    x0, v0, fargs = _two_body()
    for name, close in (("implicit-midpoint", True), ("implicit-euler", False)):
        x, v = x0.copy(), v0.copy()
        _advance(name, x, v, 0.01, 300, fargs)
        _advance(name, x, v, -0.01, 300, fargs)
        err = max(np.abs(x - x0).max(), np.abs(v - v0).max())
        assert (err < 1e-12) == close, (name, err)


def test_implicit_midpoint_keeps_angular_momentum():
    # the midpoint rule keeps every quadratic invariant (HLW IV.2.1), the
    # angular momentum among them: over 1e4 steps only rounding remains.
    # Measured 1.7e-12, the level of verlet (which keeps it exactly, up to
    # rounding: 2.7e-12 on this run); 1e-11 leaves room.  rk4, not conserving
    # it, errs by 6e-5 on this run (the negative control).
    def run(name):
        sim = orbits.Simulation(kepler_bodies(e=0.6, m_orbiter=0.3), integrator=name,
                                dt=2 * math.pi / 200, monitors=("angular_momentum",),
                                monitor_every=100)
        return sim.run(until=2 * math.pi * 50, outputs=2, progress=False)

    r = run("implicit-midpoint")
    assert r.steps == 10_000
    assert r.max_angular_momentum_error() < 1e-11
    assert run("rk4").max_angular_momentum_error() > 1e-8


def test_gravity_jacobian_against_central_differences():
    # 3 massive bodies and 2 test particles, softened: each column of the
    # analytic Jacobian against central differences of the acceleration
    # kernel with step 1e-5 (truncation ~ step^2 |a'''| ~ 1e-9, rounding
    # ~ eps |a| / step ~ 1e-11, relative to entries ~1): agreement to 1e-7
    rng = np.random.default_rng(3)
    n, n_active, eps2 = 5, 3, 0.01
    x = rng.normal(size=(n, 3))
    gm = np.array([1.0, 0.5, 0.2, 0.0, 0.0])
    fargs = (gm, n_active, eps2, np.zeros((4, 8)))
    jx = np.zeros((3 * n, 3 * n))
    jv = np.zeros((3 * n, 3 * n))
    jacobians.gravity_jacobian(x, np.zeros_like(x), 0.0, fargs, jx, jv)
    h = 1e-5
    fd = np.zeros_like(jx)
    for q in range(3 * n):
        xp = x.copy()
        xm = x.copy()
        xp.flat[q] += h
        xm.flat[q] -= h
        fd[:, q] = ((gravity.accelerate_reference(xp, gm, eps2)
                     - gravity.accelerate_reference(xm, gm, eps2)) / (2 * h)).ravel()
    np.testing.assert_allclose(jx, fd, rtol=0, atol=1e-7 * np.abs(fd).max())
    assert np.abs(fd).max() > 0.1
    # test particles do not pull: columns of bodies 3 and 4 vanish off their own rows
    assert np.all(jx[:9, 9:] == 0.0)
    assert np.all(jv == 0.0)


def test_user_jacobian_and_finite_differences_give_the_same_solution():
    # the Jacobian only steers Newton's method: with the exact one (user) and
    # with central differences the converged steps agree to rounding
    @numba.njit
    def pendulum(x, v, t):
        return -np.sin(x) - 0.1 * v

    @numba.njit
    def jac(x, v, t):
        n = x.size
        dadx = np.zeros((n, n))
        dadv = np.zeros((n, n))
        for i in range(n):
            dadx[i, i] = -np.cos(x.ravel()[i])
            dadv[i, i] = -0.1
        return dadx, dadv

    x0 = np.array([1.0, 2.0, -0.5, 3.0])
    v0 = np.array([0.0, 0.5, 1.0, -0.2])
    for name in IMPLICIT:
        a = orbits.integrate(pendulum, x0, v0, dt=0.05, steps=400, method=name,
                             velocity_dependent=True, jacobian=jac)
        b = orbits.integrate(pendulum, x0, v0, dt=0.05, steps=400, method=name,
                             velocity_dependent=True)
        # 1e-12: both converge to a few ulps of |v| ~ 1 every step; the
        # differences random-walk over 400 steps
        np.testing.assert_allclose(a.x, b.x, rtol=0, atol=1e-12)
        np.testing.assert_allclose(a.v, b.v, rtol=0, atol=1e-12)


def test_velocity_dependent_damped_oscillator_is_second_order():
    # x'' = -x - 0.2 x' over t = 10 against the exact solution: halving dt
    # divides the midpoint rule's error by 4 (order 2, within 0.2) and implicit
    # Euler's by 2 (order 1), the da/dv part of the Jacobian being exercised
    @numba.njit
    def damped(x, v, t):
        return -x - 0.2 * v

    g = 0.1
    w = math.sqrt(1 - g * g)
    exact = math.exp(-g * 10) * (math.cos(w * 10) + g / w * math.sin(w * 10))
    for name, order in (("implicit-euler", 1), ("implicit-midpoint", 2)):
        errs = []
        for steps in (1000, 2000):
            tr = orbits.integrate(damped, 1.0, 0.0, dt=10 / steps, steps=steps, method=name,
                                  velocity_dependent=True, every=steps)
            errs.append(abs(tr.x[-1] - exact))
        assert abs(math.log2(errs[0] / errs[1]) - order) < 0.2, (name, errs)


def test_bad_jacobian_shape_is_a_clear_error():
    def jac(x, v, t):
        return np.zeros((2, 2)), np.zeros((3, 3))

    with pytest.raises(ValueError, match=r"da/dx of shape \(2, 2\); expected \(3, 3\)"):
        orbits.integrate(lambda x, v, t: -x, np.ones(3), np.zeros(3), dt=0.1, steps=1,
                         method="implicit-midpoint", jacobian=jac)


@numba.njit
def _jacobian_that_grows(x, v, t):
    # right at t0 (the check before the run), one row and column too many past t = 0.25
    n = x.size + (1 if t > 0.25 else 0)
    return -np.eye(n), np.zeros((n, n))


def test_a_compiled_jacobian_that_changes_shape_stops_the_run_with_a_named_error():
    # the Jacobian runs through its compiled pointer, which checks the shape
    # of every result: the run stops after the last step whose Jacobians were
    # right (the step ending at 0.2 or 0.3, as Newton's method evaluates it at
    # the step's start, middle or end) and says which function and what it expected
    @numba.njit
    def spring(x, v, t):
        return -x

    with pytest.raises(orbits.errors.ForceTermError,
                       match=r"jacobian\(x, v, t\) returned matrices of another shape during "
                             r"the run \(after t = 0\.[23]\); expected two \(3, 3\)") as exc:
        orbits.integrate(spring, np.ones(3), np.zeros(3), dt=0.1, steps=10,
                         method="implicit-midpoint", jacobian=_jacobian_that_grows)
    assert exc.value.term == "jacobian" and exc.value.field == "return value"


def test_newton_failure_is_a_convergence_failure():
    # x'' = x^2 from x = 1, v = 0 with h = 1: implicit Euler's equation for
    # W = v1 - v0 is W = (1 + W)^2, which has no real root, so Newton's
    # method cannot converge; the run ends in ConvergenceFailure (not a
    # non-finite state) with the initial state as the last good one
    @numba.njit
    def repel(x, v, t):
        return x * x

    with pytest.raises(orbits.ConvergenceFailure, match="did not converge in step 1") as exc:
        orbits.integrate(repel, 1.0, 0.0, dt=1.0, steps=5, method="implicit-euler")
    tr = exc.value.result
    assert tr.steps == 0 and tr.x[-1] == 1.0 and tr.status == "no convergence"


@pytest.mark.parametrize("name", IMPLICIT)
def test_restart_state_lives_in_the_workspace(name, tmp_path):
    # one run of 600 steps equals, bit for bit, a run stopped at step 250,
    # written to a file and continued from it (the predictor's accelerations
    # and their validity flag are workspace arrays, so they travel along)
    def sim():
        return orbits.Simulation(kepler_bodies(e=0.6, m_orbiter=0.3), integrator=name,
                                 dt=0.01)

    ref = sim()
    ref.run(until=6.0, outputs=2, progress=False)
    path = tmp_path / "run.h5"
    first = sim()
    first.run(until=2.5, outputs=2, output=path, progress=False)
    again = orbits.Simulation.from_file(path)
    assert again.steps == 250
    again.run(until=6.0, outputs=2, output=path, progress=False)
    assert again.steps == ref.steps == 600
    assert np.array_equal(again._x, ref._x) and np.array_equal(again._v, ref._v)
