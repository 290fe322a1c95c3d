"""Integrators chosen where the simulation is made: options beside the name,
aliases, suggestions for unknown names, and the default that needs no step."""

import astropy.units as u
import pytest

import orbits
from orbits import integrators
from orbits.errors import IntegratorOptionError, UnknownIntegratorError


def bodies():
    return orbits.scenes.kepler(e=0.1)


@pytest.mark.parametrize("name", [i.name for i in integrators.available()])
def test_every_integrators_options_are_taken_beside_its_name(name):
    plain = integrators.get(name)
    # each option set to its default's value given explicitly, one that is not
    # the default where the type allows, so that a dropped option shows
    changed = {
        "epsilon": 1e-10, "min_dt": 1e-9, "adaptive_mode": "prs24", "rtol": 1e-10,
        "atol": 1e-13, "tol": 1e-14, "order": 12, "coordinates": "democratic-heliocentric",
        "corrector": 17, "hill": 4.0, "speed": 2.0, "pericentre": 3.0, "lanes": "off",
    }
    options = {k: changed[k] for k in plain.options}
    if name.startswith("saba"):
        options["corrector"] = 0    # the correctors belong to wh's map alone
    dt = None if plain.adaptive else 0.01 * u.yr
    sim = orbits.Simulation(bodies(), name, dt=dt, **options)
    assert sim.integrator.config == integrators.get(name, **options).config
    assert all(sim.integrator.config[k] == v for k, v in options.items())


def test_the_issues_examples():
    sim = orbits.Simulation(bodies(), "ias15", epsilon=1e-10)
    assert sim.integrator.config["epsilon"] == 1e-10
    sim = orbits.Simulation(bodies(), "wh", dt=1 * u.day, corrector=17,
                            coordinates="democratic-heliocentric")
    assert sim.integrator.config == {"coordinates": "democratic-heliocentric",
                                     "corrector": 17, "lanes": "auto"}
    assert sim.config.integrator_options == sim.integrator.config


def test_an_option_the_integrator_lacks_lists_those_it_has():
    with pytest.raises(IntegratorOptionError,
                       match=r"'ias15' has no option 'epsilom' \(did you mean 'epsilon'\?\).*"
                             r"options of 'ias15': adaptive_mode, epsilon, min_dt"):
        orbits.Simulation(bodies(), "ias15", epsilom=1e-10)
    # a misspelt keyword of the simulation's own is suggested too
    with pytest.raises(IntegratorOptionError, match=r"did you mean 'monitors'\?"):
        orbits.Simulation(bodies(), "ias15", monitor=["energy"])
    with pytest.raises(IntegratorOptionError, match="options of 'verlet': none"):
        orbits.Simulation(bodies(), "verlet", dt=1 * u.day, rtol=1e-9)
    # bad values are still the integrator's own check
    with pytest.raises(IntegratorOptionError, match="corrector"):
        orbits.Simulation(bodies(), "wh", dt=1 * u.day, corrector=4)


def test_options_beside_an_instance_are_refused():
    with pytest.raises(IntegratorOptionError,
                       match=r"beside an integrator instance.*Simulation\(bodies, 'wh', "
                             r"corrector=17\)"):
        orbits.Simulation(bodies(), integrators.get("wh"), dt=1 * u.day, corrector=17)
    # an instance alone is taken as it is
    integ = integrators.get("ias15", epsilon=1e-11)
    assert orbits.Simulation(bodies(), integ).integrator is integ


def test_aliases():
    assert integrators.aliases() == {"whfast": "wh"}
    sim = orbits.Simulation(bodies(), "whfast", dt=1 * u.day, corrector=11)
    assert sim.integrator.name == "wh" and sim.config.integrator == "wh"
    assert integrators.get("WHFast").name == "wh"      # REBOUND lower-cases names too
    assert integrators.get("IAS15").name == "ias15"
    info = {i.name: i for i in integrators.available()}
    assert info["wh"].aliases == ("whfast",) and info["ias15"].aliases == ()


@pytest.mark.parametrize("name, nearest", [
    ("whfst", "wh"), ("rk45", "rk4"), ("verlett", "verlet"), ("ias16", "ias15"),
    ("mercurius", "trace"), ("saba", "saba2"), ("whfast512", "wh"),
])
def test_an_unknown_name_suggests_the_nearest(name, nearest):
    with pytest.raises(UnknownIntegratorError,
                       match=rf"unknown integrator '{name}'.*did you mean '{nearest}'\?.*"
                             r"valid names: euler, .*; aliases: whfast -> wh"):
        orbits.Simulation(bodies(), name, dt=1 * u.day)


def test_rebounds_methods_that_are_not_here_say_why():
    with pytest.raises(UnknownIntegratorError, match="smooth changeover function"):
        integrators.get("mercurius")
    with pytest.raises(UnknownIntegratorError, match=r"SABA\(10,6,4\)"):
        integrators.get("saba")
    # nothing near: no suggestion, only the list
    with pytest.raises(UnknownIntegratorError) as exc:
        integrators.get("qqqqqq")
    assert "did you mean" not in str(exc.value) and "valid names" in str(exc.value)
    with pytest.raises(UnknownIntegratorError, match="a name is a string"):
        integrators.get(15)


def test_the_default_is_ias15_and_needs_no_step():
    sim = orbits.Simulation(bodies())
    assert sim.integrator.name == "ias15" == integrators.DEFAULT
    result = sim.run(until=1 * u.yr, outputs=3, progress=False)
    # ias15 at its default epsilon keeps a Kepler orbit's energy to round-off
    # (a few hundred ulps over a year)
    assert result.max_energy_error() < 1e-13


@pytest.mark.parametrize("name", [i.name for i in integrators.available() if not i.adaptive])
def test_a_fixed_step_method_without_dt_names_the_adaptive_ones(name):
    with pytest.raises(IntegratorOptionError) as exc:
        orbits.Simulation(bodies(), name)
    text = str(exc.value)
    assert f"integrator {name!r} takes fixed steps and needs dt" in text
    assert "need none: " + ", ".join(integrators.adaptive_names()) in text
    assert set(integrators.adaptive_names()) == {
        i.name for i in integrators.available() if i.adaptive}
