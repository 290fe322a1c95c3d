"""The Wisdom-Holman map across systems (orbits._kernels.wh_batch): every lane
against the scalar kernels, bit for bit, and the Kepler drift against 50-digit
arithmetic."""

import importlib.util
import math
import pathlib

import astropy.units as u
import numpy as np
import pytest

import orbits
from orbits._kernels import kepler as K
from orbits._kernels import wh_batch as W
from orbits._kernels.anomalies import true_from_mean
from orbits._kernels.elements import elements_to_state
from orbits._kernels.invariants import MONITOR_WIDTH
from orbits._kernels.status import Status
from orbits._kernels.stumpff import _stumpff_short, stumpff_medium_lane

# the 50-digit drift of the scalar Kepler tests (bisection on the universal
# Kepler equation in mpmath)
_spec = importlib.util.spec_from_file_location(
    "_kepler_drift_tests", pathlib.Path(__file__).with_name("test_kepler_drift.py"))
_mod = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_mod)
mp_drift = _mod.mp_drift

#: eccentricities: those of the validation problems (the giant planets below
#: 0.06, Mercury 0.21, the Kepler problems 0.5 and 0.9), then beyond them,
#: near-parabolic and hyperbolic orbits, which the lanes leave to the scalar
#: drift where its short-step path does not apply
ECCENTRICITIES = (0.0, 0.05, 0.21, 0.5, 0.9, 0.99, 0.999, 1.5, 5.0)
#: steps as fractions of the period (of 2 pi / n for a hyperbola): the
#: validation problems' (kepler-e0.9 P/1000, the outer solar system's 10 days
#: P_Jupiter/433, kepler-e0.5 P/200, the Sun and eight planets' 1 day
#: P_Mercury/88), then longer ones
STEP_RATIOS = (1 / 1000, 1 / 433, 1 / 200, 1 / 88, 1 / 20, 1 / 5)
VALIDATION_E = 0.9
VALIDATION_RATIO = 1 / 88

LANES = 12


def orbit_lanes(e, ratio, lanes=LANES):
    """Jacobi arrays (2, 3, lanes) of a body on an orbit of eccentricity e about
    mu = 1 (row 0 the centre of mass at rest), spread over the orbit, and the
    step ratio * period."""
    a = 1.0 if e < 1 else -1.0
    xj, vj = np.zeros((2, 3, lanes)), np.zeros((2, 3, lanes))
    for b in range(lanes):
        M = -math.pi + 2 * math.pi * (b + 0.5) / lanes
        if e < 1:
            f = true_from_mean(M, e)
        else:
            f = true_from_mean(M * 2.0, e)    # both branches of the hyperbola
        x, v = np.zeros(3), np.zeros(3)
        assert elements_to_state(1.0, a, e, 0.3, 1.1, 2.3, f, x, v) == 0
        xj[1, :, b], vj[1, :, b] = x, v
    return xj, vj, ratio * 2 * math.pi


def drift_lanes(xj, vj, h):
    """kepler_drift_lanes on the (N, 3, B) arrays, in place; the lanes of row 1
    that took the scalar drift."""
    n, _, nb = xj.shape
    X = np.ascontiguousarray(xj.transpose(1, 0, 2).reshape(3, n * nb))
    V = np.ascontiguousarray(vj.transpose(1, 0, 2).reshape(3, n * nb))
    fl = np.zeros((3, n * nb))
    W.kepler_drift_lanes(X, V, np.ones(n * nb), h, np.ones(n * nb), nb,
                         np.zeros((W.SCRATCH_ROWS, n * nb)), fl, np.zeros((1, 3)),
                         np.zeros((1, 3)))
    xj[...] = X.reshape(3, n, nb).transpose(1, 0, 2)
    vj[...] = V.reshape(3, n, nb).transpose(1, 0, 2)
    return fl[2, nb:2 * nb].copy()


@pytest.mark.parametrize("e", ECCENTRICITIES)
def test_drift_lanes_are_the_scalar_drift_bit_for_bit(e):
    # each lane does kepler_drift's operations in its order (the module notes),
    # and a lane outside the lanes' domain is kepler_drift itself
    for ratio in STEP_RATIOS:
        for sign in (1, -1):
            xj, vj, h = orbit_lanes(e, ratio)
            x0, v0 = xj.copy(), vj.copy()
            drift_lanes(xj, vj, sign * h)
            for b in range(LANES):
                xs = np.ascontiguousarray(x0[1:, :, b])
                vs = np.ascontiguousarray(v0[1:, :, b])
                K.kepler_drift(1.0, xs, vs, 0, sign * h)
                assert np.array_equal(xj[1, :, b], xs[0]), (e, ratio, sign, b)
                assert np.array_equal(vj[1, :, b], vs[0]), (e, ratio, sign, b)


def test_lanes_take_every_validation_step_and_leave_long_or_extreme_ones_to_the_scalar_drift():
    for e in ECCENTRICITIES:
        for ratio in STEP_RATIOS:
            xj, vj, h = orbit_lanes(e, ratio)
            alone = drift_lanes(xj, vj, h)
            if e <= VALIDATION_E and ratio <= VALIDATION_RATIO:
                assert not alone.any(), (e, ratio)
    # a fifth of an orbit is no short step but near apocentre (measured: 10 of
    # the 12 lanes go to the scalar drift), and neither is the hyperbola's
    # passage of its pericentre in such a step
    xj, vj, h = orbit_lanes(0.5, 1 / 5)
    assert drift_lanes(xj, vj, h).sum() >= LANES // 2
    for e in (0.99, 1.5):
        xj, vj, h = orbit_lanes(e, 1 / 5)
        assert drift_lanes(xj, vj, h).any(), e


def test_a_few_declined_elements_go_to_the_scalar_drift_and_many_to_the_masked_path():
    # the drift's one pass declines the eccentric orbit's lanes near
    # pericentre (two of twelve need a second iteration at P / 200); beside
    # twenty near-circular lanes they are few (at most one in W.FEW) and go
    # to the scalar drift, alone they are many and the masked short-step path
    # takes them; either way every lane is kepler_drift bit for bit
    xe, ve, h = orbit_lanes(0.9, 1 / 200)
    xc, vc, _ = orbit_lanes(0.05, 1 / 200, lanes=20)
    for xj, vj, n_scalar in ((np.concatenate([xe, xc], axis=2),
                              np.concatenate([ve, vc], axis=2), 2), (xe, ve, 0)):
        x0, v0 = xj.copy(), vj.copy()
        alone = drift_lanes(xj, vj, h)
        assert alone.sum() == n_scalar
        for b in range(xj.shape[2]):
            xs = np.ascontiguousarray(x0[1:, :, b])
            vs = np.ascontiguousarray(v0[1:, :, b])
            K.kepler_drift(1.0, xs, vs, 0, h)
            assert np.array_equal(xj[1, :, b], xs[0]), b
            assert np.array_equal(vj[1, :, b], vs[0]), b


@pytest.mark.parametrize("e", [x for x in ECCENTRICITIES if x <= VALIDATION_E])
def test_drift_lanes_reach_round_off_on_the_validation_orbits(e):
    worst = 0.0
    for ratio in [r for r in STEP_RATIOS if r <= VALIDATION_RATIO]:
        xj, vj, h = orbit_lanes(e, ratio, lanes=4)
        x0, v0 = xj.copy(), vj.copy()
        drift_lanes(xj, vj, h)
        for b in range(4):
            xr, vr = mp_drift(1.0, x0[1, :, b], v0[1, :, b], h)
            err = max(np.linalg.norm(xj[1, :, b] - xr) / np.linalg.norm(xr),
                      np.linalg.norm(vj[1, :, b] - vr) / np.linalg.norm(vr))
            worst = max(worst, err)
    # one short step is a handful of roundings: measured at most 1.3e-16 here;
    # the bound is that of the scalar drift's test against mpmath (1e-13),
    # far below any integration error and far above a wrong root
    assert worst < 1e-13


ZS = [0.0, 1e-7, 1e-4, 2e-3, np.nextafter(2e-3, 1), 0.05, 0.1, np.nextafter(0.1, 1), 0.3,
      0.4, np.nextafter(0.4, 1), 1.0, 1.6, np.nextafter(1.6, 2), 3.9, 4.0]


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_stumpff_lanes_are_the_scalar_stumpff_functions_bit_for_bit(sign):
    # every branch of stumpff._stumpff_short and its boundaries (the series, the
    # quartered argument 1, 2 and 3 times), taken without a branch
    for z in ZS:
        z = sign * z
        *c, inside = W._stumpff_lane(z, True)
        assert inside
        assert c == list(_stumpff_short(z)), z
        if abs(z) <= 2e-3:
            *c, _ = W._stumpff_lane(z, False)
            assert c == list(_stumpff_short(z)), z
    for z in (np.nextafter(4.0, 5), 10.0, -10.0):
        assert not W._stumpff_lane(z, True)[-1]     # beyond 4: the scalar drift


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_the_medium_lanes_stumpff_functions_are_the_scalar_ones_bit_for_bit(sign):
    # the four-term and the nine-term series of stumpff._stumpff_short and
    # the boundaries between them, taken without a branch (the planets'
    # medium passes, orbits._kernels.wh_lanes)
    for z in ZS + [0.7, np.nextafter(1.0, 0)]:
        z = sign * z
        if abs(z) > 1.0:
            assert not stumpff_medium_lane(z)[-1], z       # beyond: the scalar drift
            continue
        *c, inside = stumpff_medium_lane(z)
        assert inside
        assert c == list(_stumpff_short(z)), z
    assert not stumpff_medium_lane(sign * np.nextafter(1.0, 2))[-1]
    assert not stumpff_medium_lane(np.nan)[-1]


def systems(b, scale=1e-7, monitors=(), dt=10 * u.day):
    """b perturbed outer solar systems with masses scaled differently, as
    simulations (wh, 10 days unless said) and as lanes."""
    sims = []
    for k in range(b):
        bodies = orbits.scenes.outer_solar_system()
        rng = np.random.default_rng(k)
        bodies._x = bodies._x * (1 + scale * rng.standard_normal(bodies._x.shape))
        bodies._m = bodies._m * (1 + 0.1 * k * np.r_[0, np.ones(len(bodies) - 1)])
        sims.append(orbits.Simulation(bodies, "wh", dt=dt, monitors=monitors))
    return sims


def masses(sim):
    return sim.description().masses[sim.state.order]


def lanes_of(sims):
    x = np.stack([s.state.x for s in sims], 2)
    v = np.stack([s.state.v for s in sims], 2)
    gm = np.ascontiguousarray(np.stack([s.units.G * masses(s) for s in sims], 1))
    xj, vj, eta = W.to_lanes(x, v, gm)
    return xj, vj, gm, eta


def advance(xj, vj, gm, eta, n_active, dt, steps, owed=None, unrolled=False, ws=None):
    # unrolled: the loop of advance_loop, whose kick is written out for the
    # systems' size (the same steps bit for bit), else advance_lanes
    n, _, nb = xj.shape
    ws = W.lanes_workspace(n, nb) if ws is None else ws
    owed = np.zeros(nb) if owed is None else owed
    live = np.ones(nb)
    status, good = np.zeros(nb, dtype=np.int64), np.zeros(nb, dtype=np.int64)
    loop = W.advance_loop(n, n_active, nb) if unrolled else W.advance_lanes
    failed = loop(W.Lanes(xj, vj, gm, eta, owed, live, status, good), n_active, dt, steps, ws)
    return failed, owed, live, status, good


def test_the_unrolled_kick_is_the_loops_kick_bit_for_bit():
    # interaction_kick_lanes and the kick written out for one size, on
    # systems spread over many orders of magnitude, some lanes frozen, with
    # test particles: the same velocities, signs of zeros included
    rng = np.random.default_rng(5)
    for n, n_active, nb in [(3, 3, 4), (6, 6, 16), (7, 5, 9), (10, 10, 8)]:
        m = n * nb
        X = rng.standard_normal((3, m)) * 10 ** rng.uniform(-1, 1.5, m)
        V = rng.standard_normal((3, m))
        GM = 10 ** rng.uniform(-9, -3, m)
        GM[:nb] = 1.0
        GM[n_active * nb:] = 0.0
        MU = np.cumsum(GM.reshape(n, nb), axis=0).reshape(-1)
        LF = (rng.random(m) < 0.8).astype(float)
        LF = np.tile(LF[:nb], n)
        d = np.zeros((10, m))
        d[6] = GM / MU
        want, got = V.copy(), V.copy()
        W.interaction_kick_lanes(X, want, np.zeros((3, m)), np.zeros((3, m)), GM, MU, d[6],
                                 n_active, 0.7, LF, nb, np.zeros((3, nb)), np.zeros((3, nb)),
                                 np.zeros((4, nb)))
        K = d.copy()
        K[0:3] = X
        K[3], K[8], K[9] = LF, GM, MU
        W.unrolled_kick(n, n_active, nb)(K.reshape(-1), got.reshape(-1), 0.7, nb)
        assert np.array_equal(got, want) and np.array_equal(np.signbit(got), np.signbit(want))
        assert not np.array_equal(got[:, nb:], V[:, nb:])


@pytest.mark.parametrize("unrolled", [False, True])
@pytest.mark.parametrize("nb", [1, 4, 5])     # one lane, a power of two, an odd width
def test_advance_lanes_is_wh_bit_for_bit(nb, unrolled):
    sims = systems(nb)
    xj, vj, gm, eta = lanes_of(sims)
    n = xj.shape[0]
    failed, owed, live, status, good = advance(xj, vj, gm, eta, n, 10.0, 500,
                                               unrolled=unrolled)
    assert failed == 0 and live.all() and (good == 500).all()
    for b, sim in enumerate(sims):
        sim.run(until=5000 * u.day, outputs=2, progress=False)
        ws = sim.state.workspace
        assert np.array_equal(ws["xj"], xj[:, :, b])
        assert np.array_equal(ws["vj"], vj[:, :, b])
        assert ws["owed"][0] == owed[b]
        x, v = W.lane_inertial(xj, vj, gm, eta, owed, n, b)
        assert np.array_equal(x, sim.state.x) and np.array_equal(v, sim.state.v)


@pytest.mark.parametrize("unrolled", [False, True])
def test_the_step_people_use_goes_to_the_medium_passes_bit_for_bit(unrolled):
    # at a twentieth of Jupiter's period the short passes decline every
    # planet (their four-term Stumpff series does not reach); the medium
    # passes take them, and the next RETRY drifts go straight to those,
    # then the short passes are tried again: over 200 steps both ways are
    # taken several times, and every system is wh's bit for bit
    dt = 216.6
    sims = systems(4, dt=dt * u.day)
    xj, vj, gm, eta = lanes_of(sims)
    n = xj.shape[0]
    ws = W.lanes_workspace(n, 4)
    failed, owed, live, status, good = advance(xj, vj, gm, eta, n, dt, 200, unrolled=unrolled,
                                               ws=ws)
    assert failed == 0 and live.all() and (good == 200).all()
    # (a drift a step: 200 drifts, the last RETRY-long run of medium ones
    # still going)
    assert 0 < ws.d[W._MEMO, 0] < W.RETRY
    for b, sim in enumerate(sims):
        sim.run(until=200 * dt * u.day, outputs=2, progress=False)
        ws_b = sim.state.workspace
        assert np.array_equal(ws_b["xj"], xj[:, :, b])
        assert np.array_equal(ws_b["vj"], vj[:, :, b])


def test_one_declined_element_in_eight_goes_to_the_medium_passes_bit_for_bit():
    # the Sun and eight planets at a day: the short passes decline Mercury
    # alone (its Stumpff argument beyond the four-term series), one element
    # in W.FEW, in every system; the medium passes take it with the others
    sims = [orbits.Simulation(orbits.scenes.solar_system(moon=False), "wh", dt=1 * u.day,
                              monitors=()) for _ in range(2)]
    xj, vj, gm, eta = lanes_of(sims)
    n = xj.shape[0]
    ws = W.lanes_workspace(n, 2)
    failed, *_ = advance(xj, vj, gm, eta, n, 1.0, 100, ws=ws)
    assert failed == 0
    assert 0 < ws.d[W._MEMO, 0] < W.RETRY
    for b, sim in enumerate(sims):
        sim.run(until=100 * u.day, outputs=2, progress=False)
        assert np.array_equal(sim.state.workspace["xj"], xj[:, :, b])
        assert np.array_equal(sim.state.workspace["vj"], vj[:, :, b])


@pytest.mark.parametrize("unrolled", [False, True])
def test_test_particles_and_a_short_last_step_bit_for_bit(unrolled):
    sims = []
    for k in range(3):
        bodies = orbits.scenes.outer_solar_system()
        bodies.add("tp", mass=0 * u.Msun, primary="Sun", a=(30 + k) * u.au, e=0.1,
                   f=1 * u.rad)
        sims.append(orbits.Simulation(bodies, "wh", dt=10 * u.day, monitors=()))
    xj, vj, gm, eta = lanes_of(sims)
    n_active = len(sims[0].state.order) - 1
    _, owed, *_ = advance(xj, vj, gm, eta, n_active, 10.0, 300, unrolled=unrolled)
    advance(xj, vj, gm, eta, n_active, 3.5, 1, owed, unrolled=unrolled)
    for b, sim in enumerate(sims):
        sim.run(until=3003.5 * u.day, outputs=2, progress=False)
        ws = sim.state.workspace
        assert np.array_equal(ws["xj"], xj[:, :, b]) and np.array_equal(ws["vj"], vj[:, :, b])
        assert ws["owed"][0] == owed[b] == 1.75


def runaway(far):
    # a test particle about a star: on a circle, or flying out from 1.3e154 at
    # 1e76 a step of 1e76, so that |x|^2 overflows in its fifth step
    b = orbits.BodySet(units=orbits.UnitSystem.nbody())
    b.add("star", mass=1.0, position=[0, 0, 0], velocity=[0, 0, 0])
    if far:
        b.add("q", mass=0.0, position=[1.3e154, 0, 0], velocity=[1e76, 0, 0])
    else:
        b.add("q", mass=0.0, position=[2.0, 0, 0], velocity=[0.0, 0.7, 0])
    return orbits.Simulation(b, "wh", dt=1e76, monitors=())


def test_a_lane_that_turns_non_finite_is_frozen_at_its_last_good_step():
    sims = [runaway(False), runaway(True), runaway(False)]
    xj, vj, gm, eta = lanes_of(sims)
    failed, owed, live, status, good = advance(xj, vj, gm, eta, 1, 1e76, 40)
    assert failed == 1
    assert list(live) == [1, 0, 1] and list(status) == [0, Status.NON_FINITE, 0]
    with pytest.raises(orbits.NonFiniteState) as info:
        sims[1].run(until=40e76, outputs=2, progress=False)
    # the step the scalar loop reports, in the middle of a block of CHECK_EVERY
    assert good[1] == info.value.step == 5
    ws = sims[1].state.workspace
    assert np.array_equal(ws["xj"], xj[:, :, 1]) and np.array_equal(ws["vj"], vj[:, :, 1])
    assert ws["owed"][0] == owed[1]
    # the others went on, as alone
    for b in (0, 2):
        sims[b].run(until=40e76, outputs=2, progress=False)
        assert good[b] == 40
        assert np.array_equal(sims[b].state.workspace["xj"], xj[:, :, b])
    # a frozen lane stays as it is
    before = xj[:, :, 1].copy()
    advance(xj, vj, gm, eta, 1, 1e76, 3, owed)
    assert np.array_equal(xj[:, :, 1], before, equal_nan=True)


def test_record_lanes_gives_the_rows_an_output_records():
    sims = systems(3, monitors=("energy", "angular_momentum"))
    xj, vj, gm, eta = lanes_of(sims)
    n = xj.shape[0]
    _, owed, live, *_ = advance(xj, vj, gm, eta, n, 10.0, 123)
    m = np.ascontiguousarray(np.stack([masses(s) for s in sims]))
    rows = np.zeros((3, MONITOR_WIDTH + 6 * n))
    W.record_lanes(xj, vj, gm, eta, owed, live, n, m, sims[0].units.G, 3,
                   np.zeros((6, n, 3)), np.zeros((2, n)), np.zeros((0, 2)), np.zeros((n, 3)),
                   np.zeros((n, 3)), rows)
    for b, sim in enumerate(sims):
        sim.run(until=1230 * u.day, outputs=2, progress=False)
        snap = sim.snapshot()
        assert np.array_equal(rows[b, :4], snap.monitors[:4])
        assert np.array_equal(rows[b, MONITOR_WIDTH:MONITOR_WIDTH + 3 * n], snap.x.ravel())
        assert np.array_equal(rows[b, MONITOR_WIDTH + 3 * n:], snap.v.ravel())


def test_the_generated_kick_goes_to_its_folder_or_the_loops_run(tmp_path, monkeypatch):
    # the kick's source lands in ORBITS_KERNEL_DIR (named for the kernels'
    # sources); where that folder cannot be made, advance_loop falls back to
    # advance_lanes instead of failing, and the steps are the same
    monkeypatch.setenv("ORBITS_KERNEL_DIR", str(tmp_path))
    W.unrolled_kick(4, 3, 3)
    files = list(tmp_path.glob("orbits-kernels-*/wh_batch_kick_4_3_3.py"))
    assert len(files) == 1 and "def kick(K, OUT, h, nb):" in files[0].read_text()
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    monkeypatch.setenv("ORBITS_KERNEL_DIR", str(blocker))
    assert W.advance_loop(4, 4, 7) is W.advance_lanes
    assert W.advance_loop(2, 2, 16) is W.advance_lanes
    assert W.advance_loop(W.UNROLLED_KICK_BODIES + 1, 3, 16) is W.advance_lanes


def test_a_loop_of_advance_loop_refuses_another_number_of_systems():
    # its kick's offsets are those of the systems it was made for
    sims = systems(3)
    xj, vj, gm, eta = lanes_of(sims)
    n = xj.shape[0]
    loop = W.advance_loop(n, n, 4)
    with pytest.raises(ValueError, match="number of systems"):
        loop(W.Lanes(xj, vj, gm, eta, np.zeros(3), np.ones(3), np.zeros(3, dtype=np.int64),
                     np.zeros(3, dtype=np.int64)), n, 10.0, 5, W.lanes_workspace(n, 3))
