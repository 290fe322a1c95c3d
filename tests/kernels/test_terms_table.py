"""The table of force terms as data: its buffers, the addresses of its C
callables, and the loops that serve runs with and without terms."""

import copy
import pickle

import astropy.units as u
import numpy as np
import pytest

import orbits
from orbits._kernels import terms as T


def _state(n=4, seed=7):
    rng = np.random.default_rng(seed)
    m = np.r_[1.0, rng.uniform(1e-6, 1e-3, n - 1)]
    x = rng.normal(size=(n, 3))
    v = 0.01 * rng.normal(size=(n, 3))
    return m, x, v


def _gr_table(m, jacobian=False):
    # GR about body 0 and the GR potential, c^2 = 1e4 (large terms, so that
    # a wrong row or parameter shows)
    rows = [T.TermRow(T.GR, (0,), (1e-4,)), T.TermRow(T.GR_POTENTIAL, (0,), (2e-4,))]
    return T.table(rows, m, m, jacobian=jacobian)


def _direct_accel(x, v, m):
    acc = np.zeros_like(x)
    T.gr_accel(x, v, 0.0, (0, m, 1e-4), acc)
    T.gr_potential_accel(x, v, 0.0, (0, m, 2e-4), acc)
    return acc


def test_the_table_calls_each_rows_kernel_with_its_parameters():
    # through the callable, the same floats as the rows' kernels called one
    # after the other (the same operations in the same order)
    m, x, v = _state()
    tab = _gr_table(m)
    acc = np.zeros_like(x)
    T.table_accel(x, v, 0.0, tab, acc)
    assert np.array_equal(acc, _direct_accel(x, v, m))
    e = T.gr_energy(x, v, (0, m, 1e-4, m)) + T.gr_potential_energy(x, v, (0, m, 2e-4, m))
    assert T.table_energy(x, v, tab) == e
    assert T.table_reads_velocities(tab)            # GR reads them
    assert not T.table_reads_velocities(T.table(rows=[T.TermRow(T.GR_POTENTIAL, (0,), (1e-4,))],
                                                gm=m, m=m))


def test_an_empty_table_holds_no_address_and_adds_nothing():
    m, x, v = _state()
    tab = T.table([], m, m)
    assert T.table_rows(tab) == 0 and not tab.ibuf[3:6].any()
    acc = np.full_like(x, 0.5)
    T.table_accel(x, v, 0.0, tab, acc)
    assert np.all(acc == 0.5) and T.table_energy(x, v, tab) == 0.0


def test_a_table_travels_without_its_addresses_and_takes_this_process_ones():
    # another process has its callables elsewhere: the pickle holds no
    # address, and the table unpickled takes the addresses of the process it
    # arrives in (here the same ones); its numbers are the same, bit for bit
    m, x, v = _state()
    tab = _gr_table(m)
    ibuf = tab.__reduce__()[1][0]
    assert not ibuf[3:6].any() and np.array_equal(ibuf[6:], tab.ibuf[6:])
    for back in (pickle.loads(pickle.dumps(tab)), copy.deepcopy(tab)):
        assert np.array_equal(back.ibuf, tab.ibuf) and np.array_equal(back.rbuf, tab.rbuf)
        assert not np.shares_memory(back.rbuf, tab.rbuf)
        acc = np.zeros_like(x)
        T.table_accel(x, v, 0.0, back, acc)
        assert np.array_equal(acc, _direct_accel(x, v, m))


def test_the_jacobians_callable_is_there_only_where_asked():
    # a table made without it adds NaN to a Jacobian (a loop that reads the
    # Jacobians and was not given them stops as for a non-finite state);
    # with it, the rows' analytic Jacobians, bit for bit
    m, x, v = _state()
    n = len(m)
    tab = _gr_table(m)
    jx, jv = np.zeros((3 * n, 3 * n)), np.zeros((3 * n, 3 * n))
    T.table_jacobian(x, v, 0.0, tab, jx, jv)
    assert np.isnan(jx[0, 0])
    T.with_jacobian(tab)
    jx, jv = np.zeros((3 * n, 3 * n)), np.zeros((3 * n, 3 * n))
    T.table_jacobian(x, v, 0.0, tab, jx, jv)
    rx, rv = np.zeros_like(jx), np.zeros_like(jv)
    T.gr_jacobian(x, v, 0.0, (0, m, 1e-4), rx, rv)
    T.gr_potential_jacobian(x, v, 0.0, (0, m, 2e-4), rx, rv)
    assert np.array_equal(jx, rx) and np.array_equal(jv, rv) and np.abs(jx).max() > 0


@pytest.mark.parametrize("name, dt", [("leapfrog", 10.0), ("yoshida4", 10.0), ("rk4", 10.0),
                                      ("dopri5", None), ("rk4-doubling", None),
                                      ("ias15", None), ("implicit-midpoint", 10.0)])
def test_runs_with_and_without_terms_take_one_loop(name, dt):
    # the integrators that take terms as data compile one loop for gravity
    # with and without terms: the force the loop is compiled for is the
    # same with no term, a conservative one and a dissipative one
    kw = {} if dt is None else {"dt": dt * u.day}
    bodies = orbits.scenes.outer_solar_system()
    keys = {orbits.Simulation(bodies, name, forces=forces, **kw)._force.key
            for forces in ([], [orbits.forces.GR("Sun")],
                           [orbits.forces.Migration("Neptune", tau_a=1e7 * u.yr)])}
    assert len(keys) == 1, keys
    assert orbits.integrators.get(name).terms_as_data


def test_wisdom_holman_takes_terms_as_data_in_its_scalar_loop():
    # wh's force keeps gravity apart from the terms (its kick is its own),
    # and the Simulation binds no table for a run without terms; its scalar
    # loop takes an empty table of its own instead: one loop for both
    bodies = orbits.scenes.outer_solar_system()
    wh = orbits.integrators.get("wh", lanes="off")
    plain = orbits.Simulation(bodies, wh, dt=30 * u.day)
    terms = orbits.Simulation(bodies, wh, dt=30 * u.day,
                              forces=[orbits.forces.GRPotential("Sun")])
    assert plain._force.key != terms._force.key and plain._eargs is None
    assert wh.terms_as_data and not wh.table_in_force
    assert wh.loop(plain) is wh.loop(terms)


def test_the_splitting_loop_compiles_the_implicit_kick_only_for_terms_that_read_velocities():
    # the splitting methods' loop takes the implicit kick as a pointer: a run
    # whose terms read no velocities hands it one of the same type that is
    # never called (nothing compiled), one with GR the kick's C callable, which
    # the run compiles before its loop and announces as itself
    from orbits._compiling import TERMS
    from orbits._kernels import stepping
    from orbits.integrators._loops import loop_for

    bodies = orbits.scenes.outer_solar_system()
    runs = [orbits.Simulation(bodies, "leapfrog", dt=20 * u.day, forces=forces)
            for forces in ([], [orbits.forces.GRPotential("Sun")], [orbits.forces.GR("Sun")])]
    x = np.zeros((len(bodies), 3))
    parts = [sim.integrator.parts_ahead(sim._force, x, sim._fargs) for sim in runs]
    assert parts[0] == () and parts[1] == ()
    (label, make), = parts[2]
    assert label == TERMS["kick"]
    kick = make()
    idle = stepping.implicit_kick(runs[0]._force, x, runs[0]._fargs, False)
    assert kick.cfunc is not None and idle.cfunc is None
    assert kick._numba_type_ == idle._numba_type_
    # and one loop, of one signature, serves the three runs
    errors = [sim.run(200 * u.day, outputs=2).max_energy_error() for sim in runs]
    assert all(np.isfinite(errors))
    loop = loop_for(stepping.splitting_loop, runs[0]._force)
    assert {loop_for(stepping.splitting_loop, sim._force) for sim in runs} == {loop}
    assert len(loop.signatures) == 1
