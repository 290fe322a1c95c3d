"""What a person sees of a BodySet, Simulation and Result at a prompt or in Jupyter."""

import astropy.units as u
import pytest

import orbits
from orbits import forces


@pytest.fixture
def bodies():
    b = orbits.BodySet()
    b.add("Sun", mass=1 * u.Msun)
    b.add("Jupiter", mass=1 * u.Mjup, primary="Sun", a=5.2 * u.au, e=0.048, inc=1.3 * u.deg)
    b.add("comet <x>", mass=0 * u.kg, primary="Sun", a=-3 * u.au, e=1.5)  # unbound
    return b


def test_bodyset_repr_is_a_table_of_masses_and_elements(bodies):
    lines = repr(bodies).splitlines()
    assert lines[0].startswith("BodySet of 3 bodies (au-Msun-day")
    assert lines[1].split() == ["name", "mass", "[solMass]", "a", "[AU]", "e", "inc", "[deg]"]
    sun, jupiter, comet = (line.split() for line in lines[2:])
    assert sun == ["Sun", "1"]                                  # the first has no primary
    assert jupiter[0] == "Jupiter"
    assert float(jupiter[1]) == pytest.approx((1 * u.Mjup).to_value(u.Msun), rel=1e-5)
    assert [float(x) for x in jupiter[2:]] == pytest.approx([5.2, 0.048, 1.3], rel=1e-4)
    assert comet == ["comet", "<x>", "0"]                        # unbound: no a, e, inc


def test_bodyset_repr_shows_radii_only_where_a_body_has_one(bodies):
    assert "radius" not in repr(bodies) and "radius" not in bodies._repr_html_()
    bodies.add("moon", mass=0 * u.kg, position=[9, 0, 0] * u.au, radius=0.5 * u.au)
    lines = repr(bodies).splitlines()
    assert lines[1].split()[:5] == ["name", "mass", "[solMass]", "radius", "[AU]"]
    assert lines[2].split() == ["Sun", "1", "0"]
    assert lines[-1].split()[:3] == ["moon", "0", "0.5"]
    assert "<th>radius [AU]</th>" in bodies._repr_html_()


def test_bodyset_repr_of_a_large_set_shows_its_ends():
    plummer = orbits.scenes.plummer(n=1000, seed=1)
    lines = repr(plummer).splitlines()
    assert len(lines) == 2 + 5 + 1 + 5
    assert lines[2].split()[0] == "0" and lines[-1].split()[0] == "999"
    assert "... 990 more ..." in lines[7]
    html = plummer._repr_html_()
    assert html.count("<tr>") == 1 + 10 + 1 and "990 more" in html


def test_bodyset_html_escapes_names(bodies):
    html = bodies._repr_html_()
    assert "<table>" in html and "<th>a [AU]</th>" in html
    assert "comet &lt;x&gt;" in html and "comet <x>" not in html
    assert "<td>5.2</td>" in html


def test_simulation_repr_says_integrator_step_time_bodies_forces():
    sim = orbits.Simulation(orbits.scenes.outer_solar_system(), "wh", dt=100 * u.day,
                            forces=[forces.GRPotential("Sun")])
    text = repr(sim)
    for part in ("6 bodies", "t = 0 d", "wh(coordinates='jacobi', corrector=0, lanes='auto')",
                 "dt = 100 d", "GRPotential(source='Sun')"):
        assert part in text, text
    sim = orbits.Simulation(orbits.scenes.kepler(), "ias15",
                            escape_distance=100 * u.au)
    text = repr(sim)
    assert "chosen by the integrator" in text and "escape_distance = 100 AU" in text
    html = sim._repr_html_()
    assert "<th style='text-align:left'>integrator</th>" in html and "ias15" in html


def test_result_html_has_outputs_span_status_and_errors():
    sim = orbits.Simulation(orbits.scenes.outer_solar_system(), "leapfrog", dt=100 * u.day)
    result = sim.run(until=1000 * u.yr, outputs=11, progress=False)
    html = result._repr_html_()
    for part in ("<td>11</td>", "0 d to 365250 d (1000 yr)", "<td>completed</td>",
                 "largest energy error", f"{result.max_energy_error():.3e}"):
        assert part in html, html
