"""orbits.integrate: a user's force law, compiled or plain Python."""

import numba
import numpy as np
import pytest

import orbits
from orbits.errors import ForceTermError, NonFiniteState, UnknownIntegratorError


@numba.njit
def spring(x, v, t):
    return -100.0 * x


def spring_py(x, v, t):
    return -100.0 * x


METHODS = ["euler", "symplectic-euler", "verlet", "leapfrog", "rk2", "rk4"]


@pytest.mark.parametrize("method", METHODS)
def test_jitted_and_python_forces_give_identical_numbers(method):
    a = orbits.integrate(spring, 1.0, 0.0, dt=0.01, steps=200, method=method)
    b = orbits.integrate(spring_py, 1.0, 0.0, dt=0.01, steps=200, method=method)
    assert a.x.shape == (201,) and a.t.shape == (201,)
    np.testing.assert_array_equal(a.x, b.x)
    np.testing.assert_array_equal(a.v, b.v)


def test_verlet_matches_exact_oscillator_to_second_order():
    # x(t) = cos(10 t); Verlet's phase error after time T is ~ T w^3 dt^2 / 24
    # = 10 * 1000 * 1e-4 / 24 = 0.04 rad, so |x - cos| <= 0.05
    tr = orbits.integrate(spring, 1.0, 0.0, dt=0.01, steps=1000, method="verlet")
    assert np.max(np.abs(tr.x - np.cos(10 * tr.t))) < 0.05
    assert tr.t[-1] == pytest.approx(10.0, rel=1e-14)


def test_spring_energy_of_each_method():
    # energy E = v^2/2 + 50 x^2 starts at 50.  In z = w x + i v explicit Euler
    # is z -> (1 - i w dt) z, so E is multiplied by exactly |1 - i w dt|^2 =
    # 1 + (w dt)^2 = 1.01 every step: after 100 steps by 1.01^100 (+170 %).
    tr = orbits.integrate(spring, 1.0, 0.0, dt=0.01, steps=1000, method="euler")
    E = 0.5 * tr.v ** 2 + 50 * tr.x ** 2
    np.testing.assert_allclose(E[100] / E[0], 1.01 ** 100, rtol=1e-12)
    tr = orbits.integrate(spring, 1.0, 0.0, dt=0.01, steps=1000, method="symplectic-euler")
    E = 0.5 * tr.v ** 2 + 50 * tr.x ** 2
    # symplectic Euler conserves E - (dt/2) w^2 x v... its energy oscillates with
    # amplitude ~ w dt / 2 = 5 % and does not grow
    assert np.max(np.abs(E / E[0] - 1)) < 0.06
    assert np.max(np.abs(E[500:] / E[0] - 1)) < 1.01 * np.max(np.abs(E[:500] / E[0] - 1))


def test_array_state_and_every():
    @numba.njit
    def pair(x, v, t):
        return -x - 0.1 * v

    x0 = np.array([[1.0, 0.0], [0.0, 2.0]])
    tr = orbits.integrate(pair, x0, np.zeros((2, 2)), dt=0.01, steps=100, every=10,
                          method="rk4", velocity_dependent=True)
    assert tr.x.shape == (11, 2, 2) and tr.t[-1] == pytest.approx(1.0)
    # damped oscillator x'' = -x - 0.1 x': rk4 at dt = 0.01 agrees with the
    # exact solution to ~1e-10
    g = 0.05
    w = np.sqrt(1 - g * g)
    exact = np.exp(-g * 1.0) * (np.cos(w) + g / w * np.sin(w))
    assert tr.x[-1, 0, 0] == pytest.approx(exact, abs=1e-9)
    assert tr.x[-1, 1, 1] == pytest.approx(2 * exact, abs=1e-9)


def test_non_finite_keeps_last_good_step():
    @numba.njit
    def stiff(x, v, t):
        return -1.0e4 * x

    # explicit Euler at dt = 0.1 on w = 100 grows by sqrt(1 + 100) a step and
    # overflows after ~300 steps: it must stop, not return inf
    with pytest.raises(NonFiniteState) as exc:
        orbits.integrate(stiff, 1.0, 0.0, dt=0.1, steps=1000, method="euler")
    tr = exc.value.result
    assert 200 < exc.value.step < 400 and tr.steps == exc.value.step
    assert np.all(np.isfinite(tr.x)) and np.all(np.isfinite(tr.v))
    assert tr.t[-1] == pytest.approx(0.1 * exc.value.step)


def test_bad_arguments():
    with pytest.raises(UnknownIntegratorError):
        orbits.integrate(spring, 1.0, 0.0, dt=0.01, steps=10, method="nope")
    with pytest.raises(ValueError, match="same shape"):
        orbits.integrate(spring, [1.0, 2.0], 0.0, dt=0.01, steps=10)
    with pytest.raises(ValueError, match="x0 must be finite"):
        orbits.integrate(spring, np.nan, 0.0, dt=0.01, steps=10)
    with pytest.raises(ValueError, match="dt"):
        orbits.integrate(spring, 1.0, 0.0, dt=0.0, steps=10)


def test_adaptive_methods_for_a_stiff_user_problem():
    # the stiff spring (k = 1e4) that defeats every explicit fixed-step method
    # at dt = 0.1: scipy's radau and lsoda, and our adaptive methods, follow
    # it to their tolerance; exact solution x = cos(100 t)
    def stiff_py(x, v, t):
        return -1.0e4 * x

    for name, tol in (("radau", 1e-5), ("lsoda", 1e-4)):
        integ = orbits.integrators.get(name, rtol=1e-8, atol=1e-10)
        tr = orbits.integrate(stiff_py, 1.0, 0.0, method=integ, until=1.0, outputs=11)
        assert tr.x.shape == (11,) and tr.t[-1] == 1.0
        # global error of a 1e-8 local tolerance over 16 periods: measured
        # 2e-7 (radau) and 1e-6 (lsoda)
        np.testing.assert_allclose(tr.x, np.cos(100 * tr.t), atol=tol)


def test_adaptive_arguments_are_checked():
    with pytest.raises(ValueError, match="adaptive: give until"):
        orbits.integrate(spring, 1.0, 0.0, method="dop853")
    with pytest.raises(orbits.IntegratorOptionError, match="give dt and steps"):
        orbits.integrate(spring, 1.0, 0.0, method="rk4", until=1.0)


@numba.njit
def _untyped(x, v, t):
    return x + t.no_such_attribute


@numba.njit
def _raising(x, v, t):
    if t == t:
        raise ValueError("no acceleration here")
    return -x


@numba.njit
def _square_jacobian(x, v, t):
    return -np.eye(x.size + 1), np.zeros((x.size + 1, x.size + 1))


def test_compiled_functions_that_fail_on_the_first_state_are_named_errors():
    # the functions are first tried through the run's own compiled pointers,
    # which cannot raise; where those fail, the functions' own calls name the cause
    x0, v0 = np.ones(3), np.zeros(3)
    with pytest.raises(TypeError, match="could not be compiled"):
        orbits.integrate(_untyped, x0, v0, dt=0.01, steps=3)
    with pytest.raises(ValueError, match="no acceleration here"):
        orbits.integrate(_raising, x0, v0, dt=0.01, steps=3)
    with pytest.raises(ValueError, match=r"da/dx of shape \(4, 4\); expected \(3, 3\)"):
        orbits.integrate(spring, x0, v0, dt=0.01, steps=3, method="implicit-midpoint",
                         jacobian=_square_jacobian)


@numba.njit
def _spring_until(x, v, t):
    if t > 0.1:
        raise ValueError("no acceleration after t = 0.1")
    return -x


@numba.njit
def _spring_jacobian_until(x, v, t):
    if t > 0.1:
        raise ValueError("no Jacobian after t = 0.1")
    return -np.eye(x.size), np.zeros((x.size, x.size))


@numba.njit
def _spring_jacobian(x, v, t):
    return -np.eye(x.size), np.zeros((x.size, x.size))


def test_compiled_functions_that_raise_during_the_run_stop_it_with_a_named_error():
    # an exception inside the compiled loop cannot leave it; it once went on
    # with the accelerations of the call before
    x0, v0 = np.ones(3), np.zeros(3)
    with pytest.raises(ForceTermError, match=r"accel\(x, v, t\) raised an exception.*"
                                             r"step 10, the last good one") as exc:
        orbits.integrate(_spring_until, x0, v0, dt=0.01, steps=30)
    assert (exc.value.term, exc.value.field) == ("accel", "exception")
    with pytest.raises(ForceTermError, match=r"jacobian\(x, v, t\) raised an exception"):
        orbits.integrate(spring, x0, v0, dt=0.01, steps=30, method="implicit-midpoint",
                         jacobian=_spring_jacobian_until)
    # the same Jacobian without the exception runs through
    orbits.integrate(spring, x0, v0, dt=0.01, steps=30, method="implicit-midpoint",
                     jacobian=_spring_jacobian)
