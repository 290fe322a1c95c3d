"""The dissipative force terms: Migration, TidesConstantTimeLag, RadiationPressure.

Layers: (e) each kernel against a readable numpy version of its formula, and
its analytic Jacobian against central differences; (f) oracles: parity with
REBOUND + REBOUNDx (``modify_orbits_forces``, ``tides_constant_time_lag``,
``radiation_forces``) on the same floats, G and c with ias15 on both sides over
1000 orbits, and the orbit-averaged rates of the papers (exponential migration
and damping, Hut's 1981 tidal de/dt, the Poynting-Robertson in-spiral of Wyatt
& Whipple 1950); bad input gets named errors; terms survive their dictionaries;
the Wisdom-Holman family refuses them.
"""

import json
import math

import astropy.constants as const
import astropy.units as u
import numpy as np
import pytest

import orbits
from orbits import forces
from orbits._kernels import terms as kt
from orbits.errors import (BodyUnitsError, ForceTermError, IntegratorOptionError,
                           UnknownBodyError)

C_AU_DAY = const.c.to_value(u.au / u.day)
YEAR = 365.25  # days
G = orbits.UnitSystem().G  # au^3 / (Msun day^2)
#: the issue's parity bound on final positions, as a fraction of the orbit's size
PARITY = 1e-8


# -- kernels against readable formulas ---------------------------------------------------

def random_state(n, seed=0):
    rng = np.random.default_rng(seed)
    x = rng.normal(size=(n, 3))
    v = rng.normal(size=(n, 3)) * 0.3
    m = rng.uniform(0.1, 1.0, n)
    m[0] = 50.0
    m[-1] = 0.0          # a test particle
    return x, v, m


def _accel(kernel, x, v, args):
    a = np.zeros_like(x)
    kernel(x, v, 0.0, args, a)
    return a


def migration_numpy(x, v, m, b, p, ta, te, ti):
    r = x[b] - x[p]
    w = v[b] - v[p]
    rel = -w / (2 * ta) - 2 * (r @ w) * r / ((r @ r) * te) - 2 * w[2] * np.eye(3)[2] / ti
    a = np.zeros_like(x)
    a[b] = m[p] / (m[p] + m[b]) * rel
    a[p] = -m[b] / (m[p] + m[b]) * rel
    return a


def tides_numpy(x, v, gm, b, k2, R, tau, spin):
    # Hut (1981) and Eggleton, Kiseleva & Hut (1998) in vector form, as the force on
    # each perturber j; the distorted body b takes the reaction
    a = np.zeros_like(x)
    for j in range(len(gm)):
        if j == b:
            continue
        r = x[j] - x[b]
        w = v[j] - v[b]
        r2 = r @ r
        F_over_G_mj = -3 * k2 * gm[j] * R ** 5 / r2 ** 4 * (
            r + tau * (2 * (r @ w) * r / r2 + w + np.cross(r, spin)))
        a[j] += F_over_G_mj
        a[b] -= gm[j] / gm[b] * F_over_G_mj
    return a


def radiation_numpy(x, v, gm_s, s, beta, c):
    # Burns, Lamy & Soter (1979): beta G M / r^2 [(1 - rdot / c) r_hat - v / c]
    a = np.zeros_like(x)
    for i in range(len(beta)):
        r = x[i] - x[s]
        w = v[i] - v[s]
        d = np.linalg.norm(r)
        if beta[i]:
            a[i] = beta[i] * gm_s / d ** 2 * ((1 - (r @ w) / (d * c)) * r / d - w / c)
    return a


def _cases():
    x, v, m = random_state(5, seed=3)
    gm = 0.3 * m
    spin = np.array([0.2, -0.5, 0.9])
    beta = np.array([0.0, 0.1, 0.0, 0.4, 0.8])
    return {
        "migration": (x, v, kt.migration_accel, kt.migration_jacobian,
                      (2, 0, gm[0] / (gm[0] + gm[2]), gm[2] / (gm[0] + gm[2]),
                       1 / 7.0, -1 / 3.0, 1 / 5.0),
                      migration_numpy(x, v, m, 2, 0, 7.0, -3.0, 5.0)),
        # the tide on a light body, distorted by the others (the test particle raises none)
        "tides": (x, v, kt.tides_accel, kt.tides_jacobian,
                  (1, gm, 3 * 0.4 * 0.3 ** 5, 0.7, spin),
                  tides_numpy(x, v, gm, 1, 0.4, 0.3, 0.7, spin)),
        "radiation": (x, v, kt.radiation_accel, kt.radiation_jacobian,
                      (0, gm[0], beta, 1 / 4.0),
                      radiation_numpy(x, v, gm[0], 0, beta, 4.0)),
    }


@pytest.mark.parametrize("which", ["migration", "tides", "radiation"])
def test_kernels_match_readable_formulas(which):
    x, v, accel, _, args, expected = _cases()[which]
    got = _accel(accel, x, v, args)
    np.testing.assert_allclose(got, expected, rtol=1e-13, atol=1e-15 * np.abs(expected).max())
    assert np.abs(expected).max() > 0


@pytest.mark.parametrize("which", ["migration", "tides"])
def test_pair_terms_conserve_momentum(which):
    x, v, accel, _, args, _ = _cases()[which]
    m = random_state(5, seed=3)[2]
    a = _accel(accel, x, v, args)
    assert np.abs(m @ a).max() < 1e-14 * np.abs(m[:, None] * a).max()


def test_radiation_source_takes_no_reaction():
    x, v, accel, _, args, _ = _cases()["radiation"]
    a = _accel(accel, x, v, args)
    assert np.all(a[0] == 0) and np.all(a[2] == 0) and np.abs(a[1]).max() > 0


def _table_of(which, args):
    # the term of _cases() as the one row of a table of terms
    m = random_state(5, seed=3)[2]
    if which == "migration":
        row = kt.TermRow(kt.MIGRATION, args[:2], args[2:])
        return kt.table([row], 0.3 * m, m)
    if which == "tides":
        row = kt.TermRow(kt.TIDES, (args[0],), (args[2], args[3]) + tuple(args[4]))
        return kt.table([row], args[1], m)
    row = kt.TermRow(kt.RADIATION, (args[0],), (args[1], args[3]), args[2])
    return kt.table([row], 0.3 * m, m)


def test_a_table_row_is_its_terms_kernel():
    # the table's dispatch hands each term the arguments its kernel takes
    for which, (x, v, accel, _, args, _) in _cases().items():
        a = np.zeros_like(x)
        kt.table_accel(x, v, 0.0, _table_of(which, args), a)
        np.testing.assert_array_equal(a, _accel(accel, x, v, args))


@pytest.mark.parametrize("which", ["migration", "tides", "radiation"])
def test_analytic_jacobians_match_differences(which):
    # the package's own central differences (relative step 6e-6, orbits._kernels.terms
    # FD_STEP): truncation ~ step^2 and rounding ~ 1e-16 / step give ~1e-10 of the
    # largest entry on these O(1) states; measured at most 4.4e-10, so 1e-7 leaves
    # a factor 200 and still sees a wrong sign or factor in any entry above it
    x, v, accel, jac, args, _ = _cases()[which]
    n = 3 * x.shape[0]
    jx, jv = np.zeros((n, n)), np.zeros((n, n))
    jac(x, v, 0.0, args, jx, jv)
    fx, fv = np.zeros((n, n)), np.zeros((n, n))
    kt.row_difference_jacobian(x, v, 0.0, _table_of(which, args).rows, 0, True, fx, fv)
    scale = max(np.abs(fx).max(), np.abs(fv).max())
    np.testing.assert_allclose(jx, fx, rtol=0, atol=1e-7 * scale)
    np.testing.assert_allclose(jv, fv, rtol=0, atol=1e-7 * scale)
    assert np.abs(jv).max() > 1e-3 * scale    # the velocity part is really there


def test_energy_kernel_is_zero():
    x, v, _, _, args, _ = _cases()["tides"]
    assert kt.dissipative_energy(x, v, args) == 0.0


# -- parity with REBOUNDx ------------------------------------------------------------------

# rebound and reboundx are test dependencies (the test extra): a missing one is
# an import error, not a skipped parity check
import reboundx  # noqa: E402


def rebound_run(bodies, until, setup):
    """REBOUND + REBOUNDx, ias15, from the same floats; setup(sim, rebx) loads the effect."""
    sim = bodies.to_rebound()
    sim.integrator = "ias15"
    rebx = reboundx.Extras(sim)     # kept alive while sim integrates
    if setup is not None:
        setup(sim, rebx)
    sim.integrate(until)
    return np.array([p.xyz for p in sim.particles])


def ours(bodies, until, terms):
    sim = orbits.Simulation(bodies, "ias15", forces=terms, monitors=())
    res = sim.run(until=until * u.day, outputs=1, progress=False)
    return res.positions[-1].to_value(u.au)


def star_planet(a, e, inc, mass=1 * u.Mjup):
    b = orbits.BodySet()
    b.add("Star", mass=1 * u.Msun)
    b.add("Planet", mass=mass, primary="Star", a=a * u.au, e=e, inc=inc * u.rad,
          Omega=0.3 * u.rad, omega=1.0 * u.rad, f=0.5 * u.rad)
    b.move_to_com()
    return b


def test_migration_matches_reboundx_modify_orbits_forces():
    # 1000 orbits of a Jupiter at 1 au migrating on 5000 yr and damping e and inc;
    # the innermost body about the star, where REBOUNDx's default Jacobi
    # coordinates and the pair split here are the same force
    b = star_planet(1.0, 0.1, 0.1)
    taus = {"tau_a": 5000 * YEAR, "tau_e": 2000 * YEAR, "tau_inc": 3000 * YEAR}
    until = 1000 * YEAR

    def setup(sim, rebx):
        f = rebx.load_force("modify_orbits_forces")
        rebx.add_force(f)
        for k, tau in taus.items():
            sim.particles[1].params[k] = -tau     # REBOUNDx: negative damps
    theirs = rebound_run(b, until, setup)
    plain = rebound_run(b, until, None)
    mine = ours(b, until, [forces.Migration("Planet", **{k: t * u.day
                                                          for k, t in taus.items()})])
    # measured 3.3e-11 au; the term moves the planet by 0.23 au, so the check can fail
    assert np.abs(theirs - plain).max() > 0.1
    assert np.abs(mine - theirs).max() < PARITY * 1.0


@pytest.mark.parametrize("on", ["planet", "star"])
def test_tides_match_reboundx_tides_constant_time_lag(on):
    # 1000 orbits of a hot Jupiter at 0.05 au (4 d): the tide raised on the planet by
    # the star (spin along z, as REBOUNDx's OmegaMag), or on the star by two planets
    # (REBOUNDx's primary feels every body, as here)
    b = star_planet(0.05, 0.1, 0.02)
    if on == "star":
        b.add("Outer", mass=0.5 * u.Mjup, primary="Star", a=0.12 * u.au, e=0.05,
              inc=0.01 * u.rad, f=2.0 * u.rad)
        b.move_to_com()
        body, k2, R, tau, spin = "Star", 0.03, 1 * u.Rsun, 0.2, 2 * math.pi / 25.0
    else:
        body, k2, R, tau, spin = "Planet", 0.5, 1 * u.Rjup, 0.01, 2 * math.pi / 0.4
    i = b.names.index(body)
    until = 1000 * 0.05 ** 1.5 * YEAR

    def setup(lag):
        def load(sim, rebx):
            f = rebx.load_force("tides_constant_time_lag")
            rebx.add_force(f)
            p = sim.particles[i]
            p.r = R.to_value(u.au)
            p.params["tctl_k2"] = k2
            p.params["tctl_tau"] = lag
            p.params["OmegaMag"] = spin
        return load
    theirs = rebound_run(b, until, setup(tau))
    no_lag = rebound_run(b, until, setup(0.0))
    term = forces.TidesConstantTimeLag(body, k2=k2, time_lag=tau * u.day, radius=R,
                                       spin=[0, 0, spin] * u.rad / u.day)
    mine = ours(b, until, [term])
    # the lag alone moves the planets by 0.04 au (planet) and 5e-4 au (star), 8 and 6
    # orders above the bound, so the check can fail
    assert np.abs(theirs - no_lag).max() > 1e4 * PARITY * 0.05
    # measured 1.1e-12 au (planet) and 2.7e-12 au (star)
    assert np.abs(mine - theirs).max() < PARITY * 0.05


def test_radiation_matches_reboundx_radiation_forces():
    # two dust grains (test particles) with beta 0.05 and 0.2 over 1000 orbits of the
    # inner one, Jupiter at 5.2 au feeling no radiation
    b = orbits.BodySet()
    b.add("Sun", mass=1 * u.Msun)
    b.add("Jupiter", mass=1 * u.Mjup, primary="Sun", a=5.2 * u.au, e=0.05)
    b.add("dust1", mass=0 * u.kg, primary="Sun", a=1.0 * u.au, e=0.1, inc=0.1 * u.rad)
    b.add("dust2", mass=0 * u.kg, primary="Sun", a=1.5 * u.au, e=0.2, f=1 * u.rad)
    b.move_to_com()
    betas = {"dust1": 0.05, "dust2": 0.2}
    until = 1000 * YEAR

    def setup(sim, rebx):
        f = rebx.load_force("radiation_forces")
        rebx.add_force(f)
        f.params["c"] = C_AU_DAY
        sim.particles[0].params["radiation_source"] = 1
        for name, beta in betas.items():
            sim.particles[b.names.index(name)].params["beta"] = beta
    theirs = rebound_run(b, until, setup)
    plain = rebound_run(b, until, None)
    mine = ours(b, until, [forces.RadiationPressure("Sun", beta=betas)])
    # measured 3.2e-11 au; the radiation moves the grains by 2.5 au, so the check can fail
    assert np.abs(theirs - plain).max() > 0.1
    assert np.abs(mine - theirs).max() < PARITY * 1.0


# -- analytic rates ------------------------------------------------------------------------

def _relative(res, body, primary=0):
    x = (res.positions[:, body] - res.positions[:, primary]).to_value(u.au)
    v = (res.velocities[:, body] - res.velocities[:, primary]).to_value(u.au / u.day)
    mu = G * (res.masses[body] + res.masses[primary]).to_value(u.Msun)
    return x, v, mu


def _elements(res, body, primary=0):
    x, v, mu = _relative(res, body, primary)
    r = np.linalg.norm(x, axis=1)
    a = 1 / (2 / r - np.sum(v * v, axis=1) / mu)
    h = np.cross(x, v)
    e = np.linalg.norm(np.cross(v, h) / mu - x / r[:, None], axis=1)
    inc = np.arccos(h[:, 2] / np.linalg.norm(h, axis=1))
    return res.times.to_value(u.day), a, e, inc


def _rate(t, y):
    # least-squares slope of ln y; over whole orbits with ~20 samples an orbit the
    # short-period terms of the osculating elements average out
    return np.polyfit(t, np.log(y), 1)[0]


@pytest.mark.parametrize("tau_yr", [100.0, -100.0])
def test_migration_recovers_the_semi_major_axis_time_scale(tau_yr):
    # a circular orbit under -u / (2 tau_a): the drag is along the velocity and
    # da/dt = 2 a^2 (u . a_drag) / mu = -a / tau_a exactly while e stays ~0
    # (Papaloizou & Larwood 2000); the forced e is O(1 / (n tau)) ~ 2e-3, so the
    # issue's 1 % bound holds with room (measured 4e-6 and 1.6e-5 relative)
    b = star_planet(1.0, 0.0, 0.0, mass=1 * u.Mearth)
    term = forces.Migration("Planet", tau_a=tau_yr * u.yr)
    res = orbits.Simulation(b, "ias15", forces=[term], monitors=()).run(
        until=50 * u.yr, outputs=1001, progress=False)
    t, a, _, _ = _elements(res, 1)
    measured = -1 / _rate(t, a) / YEAR
    assert abs(measured / tau_yr - 1) < 0.01
    assert abs(a[-1] / a[0] - math.exp(-50 / tau_yr)) < 0.01 * abs(a[-1] / a[0] - 1)


def test_migration_recovers_the_eccentricity_and_inclination_time_scales():
    # -2 (r . u) r / (r^2 tau_e) is radial: de/dt = -2 e sin^2 f / tau_e, whose orbit
    # average is -e (1 - 3 e^2 / 4) / tau_e, 0.2 % from -e / tau_e at e = 0.05;
    # -2 u_z z / tau_inc gives di/dt = -2 sin i cos^2 u / tau_inc, averaging to
    # -sin i / tau_inc, 0.04 % from -i / tau_inc at i = 0.05 (measured 0.07 % and 0.09 %)
    b = star_planet(1.0, 0.05, 0.05, mass=1 * u.Mearth)
    term = forces.Migration("Planet", tau_e=40 * u.yr, tau_inc=60 * u.yr)
    res = orbits.Simulation(b, "ias15", forces=[term], monitors=()).run(
        until=40 * u.yr, outputs=801, progress=False)
    t, _, e, inc = _elements(res, 1)
    assert abs(-1 / _rate(t, e) / YEAR / 40 - 1) < 0.01
    assert abs(-1 / _rate(t, inc) / YEAR / 60 - 1) < 0.01


def hut_de_dt(e, n, a, k2, tau, R, m_body, m_other, spin):
    """Hut (1981) eq. 10, with T = R^3 / (G m_body tau) and q = m_other / m_body::

        de/dt = -27 (k / T) q (1 + q) (R / a)^8 e / (1 - e^2)^(13/2)
                [ f3(e^2) - (11/18) (1 - e^2)^(3/2) f4(e^2) Omega / n ]
              = -27 k2 tau n^2 q (R / a)^5 e / (1 - e^2)^(13/2) [ ... ]

    f3 = 1 + 15/4 e^2 + 15/8 e^4 + 5/64 e^6, f4 = 1 + 3/2 e^2 + 1/8 e^4.  Hut's
    force is the term's with his k in the place of k2: the same k.
    At Omega = n it is the familiar -(21/2) k2 tau n^2 q (R / a)^5 e.
    """
    e2 = e * e
    f3 = 1 + 3.75 * e2 + 1.875 * e2 ** 2 + 5 / 64 * e2 ** 3
    f4 = 1 + 1.5 * e2 + 0.125 * e2 ** 2
    return (-27 * k2 * tau * n ** 2 * (m_other / m_body) * (R / a) ** 5 * e
            / (1 - e2) ** 6.5 * (f3 - 11 / 18 * (1 - e2) ** 1.5 * f4 * spin / n))


@pytest.mark.parametrize("synchronous", [False, True])
def test_tidal_eccentricity_damping_follows_hut(synchronous):
    # an inflated hot Jupiter (2 R_J at 0.03 au, k2 = 0.5, lag 0.05 d) at e = 0.02,
    # not spinning or spinning at the mean motion; over 200 orbits e falls by 10 % and
    # 4 %.  Hut's rate is first order in the tidal force (5e-5 of the star's pull
    # here), so it holds to ~1e-4, and the osculating a and n carry the conservative
    # tide's O(5e-5) offset.  The comparison uses the run's mean a: without spin a
    # falls by d = 2.4 % over the run and the rate goes as a^-8, so the mean rate is
    # the rate at the mean a to 3 d^2 ~ 2e-3.  Measured 0.12 % (spin 0) and 0.04 %
    # (synchronous)
    b = star_planet(0.03, 0.02, 0.0)
    m, M = b.masses[1].to_value(u.Msun), b.masses[0].to_value(u.Msun)
    n0 = math.sqrt(G * (M + m) / 0.03 ** 3)
    spin = n0 if synchronous else 0.0
    R = (2 * u.Rjup).to_value(u.au)
    term = forces.TidesConstantTimeLag("Planet", k2=0.5, time_lag=0.05 * u.day,
                                       radius=R * u.au, spin=[0, 0, spin] / u.day)
    period = 2 * math.pi / n0
    res = orbits.Simulation(b, "ias15", forces=[term], monitors=()).run(
        until=200 * period * u.day, outputs=4001, progress=False)
    t, a, e, _ = _elements(res, 1)
    measured = _rate(t, e)
    a_mean = a.mean()
    n = math.sqrt(G * (M + m) / a_mean ** 3)
    # Hut's de/dt over e is the rate of ln e; its e^2 terms (~1e-3 at e = 0.02) are
    # kept by evaluating it at the run's mean e
    e_mean = e.mean()
    expected = hut_de_dt(e_mean, n, a_mean, 0.5, 0.05, R, m, M, spin) / e_mean
    assert abs(measured / expected - 1) < 0.01


def test_poynting_robertson_in_spiral_time_follows_wyatt_whipple():
    # Wyatt & Whipple (1950); Burns, Lamy & Soter (1979): on a circular orbit the drag
    # -beta G M (rdot r_hat + u) / (c r^2) removes angular momentum at
    # dh/dt = -beta G M h / (c r^2); with h = sqrt((1 - beta) G M r),
    # dr/dt = -2 beta G M / (c r), so r^2 = r0^2 - 4 beta G M t / c and the grain
    # reaches the source after t = c r0^2 / (4 beta G M), whatever (1 - beta).
    # Corrections are O(beta v^2 / c^2) ~ 1e-9 and the forced e O(beta v / c) ~ 2e-5;
    # measured 8e-6 relative
    beta, r0 = 0.2, 1.0
    mu = G * 1.0
    b = orbits.BodySet()
    b.add("Sun", mass=1 * u.Msun)
    # circular for the Sun's gravity less the radiation pressure
    b.add("dust", mass=0 * u.kg, position=[r0, 0, 0] * u.au,
          velocity=[0, math.sqrt((1 - beta) * mu / r0), 0] * u.au / u.day)
    term = forces.RadiationPressure("Sun", beta={"dust": beta})
    res = orbits.Simulation(b, "ias15", forces=[term], monitors=()).run(
        until=200 * u.yr, outputs=2001, progress=False)
    x, _, _ = _relative(res, 1)
    t = res.times.to_value(u.day)
    slope = np.polyfit(t, np.sum(x * x, axis=1), 1)[0]     # d(r^2)/dt
    measured = r0 ** 2 / -slope
    expected = C_AU_DAY * r0 ** 2 / (4 * beta * mu)
    assert abs(measured / expected - 1) < 0.01
    # the grain really spirals in over the run (r^2 falls by ~10 %)
    assert 0.05 < 1 - np.sum(x[-1] ** 2) / r0 ** 2 < 0.2


# -- bad input -----------------------------------------------------------------------------

def _dusty():
    b = star_planet(1.0, 0.1, 0.0)
    b.add("dust", mass=0 * u.kg, primary="Star", a=2 * u.au, e=0.1)
    # a grain leaving on a hyperbola: beta >= 1 is fine for it
    b.add("stream", mass=0 * u.kg, position=[0.5, 0, 0] * u.au,
          velocity=[0, 0.2, 0] * u.au / u.day)
    return b


def _raises(error, call, body, field):
    with pytest.raises(error) as info:
        call()
    assert info.value.field == field
    if body is not None:
        assert info.value.body == body
        assert repr(body) in str(info.value)
    assert repr(field) in str(info.value) or field in str(info.value)
    return info.value


@pytest.mark.parametrize("k2", [-0.1, math.nan, "soft"])
def test_bad_love_number(k2):
    _raises(ForceTermError, lambda: forces.TidesConstantTimeLag(
        "Planet", k2=k2, time_lag=1 * u.s, radius=1 * u.km), "Planet", "k2")


@pytest.mark.parametrize("radius", [-1 * u.km, 0 * u.km, np.nan * u.km, np.inf * u.km])
def test_bad_tidal_radius(radius):
    exc = _raises(ForceTermError, lambda: forces.TidesConstantTimeLag(
        "Planet", k2=0.3, time_lag=1 * u.s, radius=radius), "Planet", "radius")
    assert "positive finite radius" in str(exc)


@pytest.mark.parametrize("lag", [-1 * u.s, np.nan * u.s, np.inf * u.s])
def test_bad_time_lag(lag):
    exc = _raises(ForceTermError, lambda: forces.TidesConstantTimeLag(
        "Planet", k2=0.3, time_lag=lag, radius=1 * u.km), "Planet", "time_lag")
    assert "time lag >= 0" in str(exc)


def test_bad_spin_and_units_at_bind():
    with pytest.raises(ForceTermError, match="spin"):
        forces.TidesConstantTimeLag("Planet", k2=0.3, time_lag=1 * u.s, radius=1 * u.km,
                                    spin=[0, 1] / u.s)
    term = forces.TidesConstantTimeLag("Planet", k2=0.3, time_lag=1 * u.km, radius=1 * u.km)
    with pytest.raises(BodyUnitsError, match="time_lag"):
        orbits.Simulation(star_planet(1.0, 0.0, 0.0), "ias15", forces=[term])
    term = forces.TidesConstantTimeLag("Planet", k2=0.3, time_lag=1 * u.s, radius=1 * u.km,
                                       spin=[0, 0, 1] * u.km)
    with pytest.raises(BodyUnitsError, match="spin"):
        orbits.Simulation(star_planet(1.0, 0.0, 0.0), "ias15", forces=[term])


def test_tide_on_a_massless_body():
    term = forces.TidesConstantTimeLag("dust", k2=0.3, time_lag=1 * u.s, radius=1 * u.km)
    _raises(ForceTermError, lambda: orbits.Simulation(_dusty(), "ias15", forces=[term]),
            "dust", "body")


@pytest.mark.parametrize("beta, body", [(-0.1, None), ({"dust": -0.1}, "dust"),
                                        ({"dust": math.inf}, "dust"), ([0, 0, -1, 0], 2)])
def test_negative_or_non_finite_beta(beta, body):
    _raises(ForceTermError, lambda: forces.RadiationPressure("Star", beta=beta), body, "beta")


@pytest.mark.parametrize("beta", [{"dust": 1.0}, 1.5, [0, 0, 1.2, 0.0]])
def test_beta_of_one_or_more_on_a_bound_orbit(beta):
    # the planet and the grain are bound to the star: a uniform beta >= 1 names the
    # first of them in the internal order (the planet)
    term = forces.RadiationPressure("Star", beta=beta)
    name = "Planet" if beta == 1.5 else "dust"
    exc = _raises(ForceTermError, lambda: orbits.Simulation(_dusty(), "ias15", forces=[term]),
                  name, "beta")
    assert "bound orbit" in str(exc) and "expected beta < 1" in str(exc)


def test_beta_of_one_or_more_on_an_unbound_orbit_is_allowed():
    term = forces.RadiationPressure("Star", beta={"stream": 1.5})
    sim = orbits.Simulation(_dusty(), "ias15", forces=[term])
    assert sim.forces == (term,)


def test_beta_for_the_source_or_of_the_wrong_length():
    _raises(ForceTermError, lambda: orbits.Simulation(
        _dusty(), "ias15", forces=[forces.RadiationPressure("Star", beta={"Star": 0.1})]),
        "Star", "beta")
    _raises(ForceTermError, lambda: orbits.Simulation(
        _dusty(), "ias15", forces=[forces.RadiationPressure("Star", beta=[0.1, 0, 0, 0])]),
        "Star", "beta")
    with pytest.raises(ForceTermError, match="expected 4 values of beta"):
        orbits.Simulation(_dusty(), "ias15",
                          forces=[forces.RadiationPressure("Star", beta=[0, 0.1])])


@pytest.mark.parametrize("term, field", [
    (forces.Migration("Vulcan", tau_a=1 * u.yr), "body"),
    (forces.Migration("Planet", tau_a=1 * u.yr, primary="Vulcan"), "primary"),
    (forces.TidesConstantTimeLag("Vulcan", k2=0.3, time_lag=1 * u.s, radius=1 * u.km),
     "body"),
    (forces.RadiationPressure("Vulcan", beta=0.1), "source"),
    (forces.RadiationPressure("Star", beta={"Vulcan": 0.1}), "beta"),
])
def test_unknown_body_is_named(term, field):
    exc = _raises(UnknownBodyError, lambda: orbits.Simulation(_dusty(), "ias15",
                                                              forces=[term]), "Vulcan", field)
    assert "no such body" in str(exc)


@pytest.mark.parametrize("field", ["tau_a", "tau_e", "tau_inc"])
@pytest.mark.parametrize("value", [0 * u.yr, np.nan * u.yr, np.inf * u.yr])
def test_zero_or_non_finite_time_scale(field, value):
    exc = _raises(ForceTermError, lambda: forces.Migration("Planet", **{field: value}),
                  "Planet", field)
    assert "non-zero finite time scale" in str(exc)


def test_migration_needs_a_time_scale_and_a_primary_other_than_itself():
    _raises(ForceTermError, lambda: forces.Migration("Planet"), "Planet", "tau_a")
    term = forces.Migration("Planet", tau_a=1 * u.yr, primary="Planet")
    _raises(ForceTermError, lambda: orbits.Simulation(_dusty(), "ias15", forces=[term]),
            "Planet", "primary")
    term = forces.Migration("dust", tau_a=1 * u.yr, primary="stream")
    _raises(ForceTermError, lambda: orbits.Simulation(_dusty(), "ias15", forces=[term]),
            "stream", "primary")
    term = forces.Migration("Planet", tau_a=1 * u.km)
    with pytest.raises(BodyUnitsError, match="tau_a"):
        orbits.Simulation(_dusty(), "ias15", forces=[term])


def _context(bodies):
    m = bodies.masses.value
    order = np.argsort(m == 0, kind="stable")        # massive bodies first, as Simulation
    return forces.Context([bodies.names[k] for k in order], m[order],
                          bodies.units.G * m[order], int(np.sum(m > 0)), bodies.units,
                          False, order, bodies.positions.value, bodies.velocities.value)


def test_migration_default_primary_is_the_most_massive_other_body():
    ctx = _context(_dusty())
    star, planet = ctx.names.index("Star"), ctx.names.index("Planet")
    args = forces.Migration("dust", tau_a=1 * u.yr).bind(ctx).args
    assert args[:4] == (ctx.names.index("dust"), star, 1.0, 0.0)   # a test particle
    args = forces.Migration("Star", tau_e=1 * u.yr).bind(ctx).args
    assert args[:2] == (star, planet)
    # the pair's split: the body takes m_p / (m_p + m_b) of the relative acceleration
    args = forces.Migration("Planet", tau_inc=-2 * u.day).bind(ctx).args
    mp, mb = ctx.m[star], ctx.m[planet]
    assert args[2:] == pytest.approx((mp / (mp + mb), mb / (mp + mb), 0.0, 0.0, -0.5),
                                     rel=1e-15)


# -- dictionaries, simulations, integrators ------------------------------------------------

TERMS = [
    forces.Migration("Planet", tau_a=1e4 * u.yr, tau_e=-300 * u.yr, tau_inc=2e3 * u.yr,
                     primary="Star"),
    forces.TidesConstantTimeLag("Planet", k2=0.3, time_lag=600 * u.s, radius=7e4 * u.km,
                                spin=[0, 0.1, 1.0] * u.rad / u.day),
    forces.RadiationPressure("Star", beta={"dust": 0.1, "stream": 0.3},
                             c=3e5 * u.km / u.s),
    forces.RadiationPressure("Star", beta=[0.0, 0.0, 0.1, 1.5]),
]


@pytest.mark.parametrize("term", TERMS, ids=lambda t: type(t).__name__)
def test_terms_round_trip_through_dicts(term):
    d = json.loads(json.dumps(term.to_dict()))     # as output files store it
    back = forces.from_dict(d)
    assert back == term and back.to_dict() == d
    assert type(back).conservative is False and back.wisdom_holman is False
    assert back.velocity_dependent is True


def test_simulation_runs_and_terms_rebuilt_from_dicts_run_bit_identically():
    # what a restart or an ensemble rebuilds from the dictionaries binds to the same
    # floats: the two runs agree bit for bit.  Migration with its default primary
    # (the star, the most massive other body).
    terms = [forces.Migration("Planet", tau_a=1e3 * u.yr, tau_e=-1e3 * u.yr),
             TERMS[1], TERMS[2]]
    runs = []
    for given in (terms, [forces.from_dict(t.to_dict()) for t in terms]):
        sim = orbits.Simulation(_dusty(), "ias15", forces=given)
        assert sim.forces == tuple(terms)
        res = sim.run(until=2 * u.yr, outputs=3, progress=False)
        assert res.forces == tuple(repr(t) for t in terms)
        runs.append(res)
    assert np.all(np.isfinite(runs[0].positions.value))
    assert np.array_equal(runs[0].positions.value, runs[1].positions.value)
    assert np.array_equal(runs[0].velocities.value, runs[1].velocities.value)


def _leaves(tree):
    if isinstance(tree, tuple):
        for branch in tree:
            yield from _leaves(branch)
    else:
        yield tree


def test_terms_rebuilt_from_dicts_bind_the_same_floats():
    # the slow test above without its runs: the three kinds of term rebuilt from
    # their dictionaries (through JSON, as files and ensembles store them) give
    # the loop the same arguments, bit for bit, as the terms they were made from,
    # so a run with them is the same floats (the compiled loop being the same)
    terms = [forces.Migration("Planet", tau_a=1e3 * u.yr, tau_e=-1e3 * u.yr),
             TERMS[1], TERMS[2]]
    rebuilt = [forces.from_dict(json.loads(json.dumps(t.to_dict()))) for t in terms]
    sims = [orbits.Simulation(_dusty(), "ias15", forces=given) for given in (terms, rebuilt)]
    assert sims[1].forces == tuple(terms)
    given, back = (list(_leaves(sim._fargs)) for sim in sims)
    # the terms' own arguments are compared too, beside gravity's
    # (the table's two buffers hold every row's numbers)
    assert len(given) == len(back) and len(list(_leaves(sims[0]._fargs[1].rows))) > len(terms)
    for a, b in zip(given, back):
        assert type(a) is type(b)
        assert np.asarray(a).tobytes() == np.asarray(b).tobytes()


@pytest.mark.parametrize("integrator", ["wh", "saba2"])
@pytest.mark.parametrize("term", TERMS[:3], ids=lambda t: type(t).__name__)
def test_wisdom_holman_refuses_them(integrator, term):
    with pytest.raises(IntegratorOptionError, match="dissipative"):
        orbits.Simulation(_dusty(), integrator, dt=1 * u.day, forces=[term])


# -- restart and ensembles -------------------------------------------------------------------

def _dissipative_sim(integrator="ias15", dt=None):
    # two terms chained, both of one kind: the resonant-migration example's loop,
    # which the default run compiles anyway (the three kinds of TERMS chained
    # compiled a loop for this test alone, 48 s of a fresh clone's run; their
    # rebuilding is checked above without a run)
    terms = [forces.Migration("Planet", tau_a=1e3 * u.yr, tau_e=-1e3 * u.yr),
             forces.Migration("dust", tau_e=300 * u.yr)]
    return orbits.Simulation(_dusty(), integrator, dt=dt, forces=terms)


@pytest.mark.parametrize("integrator, dt", [
    ("ias15", None),
    ("leapfrog", 0.5 * u.day)])
def test_restart_with_dissipative_terms_is_bit_identical(tmp_path, integrator, dt):
    # a run stopped half-way and continued from its file: the same floats as one
    # run straight through, the terms rebuilt from the file and the work W
    # carried over with the state
    path = tmp_path / "run.h5"
    ref = _dissipative_sim(integrator, dt)
    r_ref = ref.run(until=400 * u.day, outputs=5, progress=False)
    first = _dissipative_sim(integrator, dt)
    first.run(until=200 * u.day, outputs=3, output=path, progress=False)
    again = orbits.Simulation.from_file(path)
    assert again.forces == first.forces
    r = again.run(until=400 * u.day, outputs=3, output=path, progress=False)
    assert np.array_equal(r.positions[-1].value, r_ref.positions[-1].value)
    assert np.array_equal(r.velocities[-1].value, r_ref.velocities[-1].value)
    assert again.work == ref.work and ref.work.value != 0.0


def _migrating(a):
    b = orbits.BodySet()
    b.add("Star", mass=1 * u.Msun)
    b.add("Planet", mass=1 * u.Mjup, primary="Star", a=a * u.au, e=0.1)
    b.move_to_com()
    return orbits.Simulation(b, "ias15", forces=[
        forces.Migration("Planet", tau_a=1e3 * u.yr, tau_e=300 * u.yr),
        forces.RadiationPressure("Star", beta=0.0)])


def test_ensemble_rows_with_dissipative_terms_serial_and_two_workers():
    # the workers rebuild the terms from the configuration: identical rows
    pytest.importorskip("distributed")
    from orbits.ensemble import Ensemble
    where = ["wall_time_s", "worker", "kernels_compiled", "kernels_loaded"]
    params = [{"a": 1.0}, {"a": 1.5}]
    one = Ensemble(_migrating, params).run(20 * u.yr, client="serial", progress=False)
    two = Ensemble(_migrating, params).run(20 * u.yr, client=None, n_workers=2,
                                           progress=False)
    assert one.drop(columns=where).equals(two.drop(columns=where))
    # and the migration acted: a falls as exp(-t / tau_a), 2 % in 20 yr, times the
    # (1 - e0^2) / (1 - e^2) of e's damping at constant angular momentum, e =
    # e0 exp(-t / tau_e); 1e-4 is ten times the rate tests' largest error above
    e = 0.1 * math.exp(-20 / 300)
    expected = math.exp(-20 / 1e3) * (1 - 0.1 ** 2) / (1 - e ** 2)
    column = next(c for c in one.columns if c.startswith("Planet_a_"))
    assert np.allclose(one[column] / one["a"], expected, rtol=1e-4), one[column]
