"""The layout rules of the package that a test can check."""

import ast
import pathlib

import orbits

PACKAGE = pathlib.Path(orbits.__file__).parent


def imported_modules(path):
    tree = ast.parse(path.read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            yield from (a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            yield node.module


def test_kernels_do_not_import_astropy():
    # units stay at the boundary: the compiled kernels see plain floats only
    files = sorted((PACKAGE / "_kernels").glob("*.py"))
    assert len(files) >= 5
    for path in files:
        for mod in imported_modules(path):
            assert not mod.startswith("astropy"), f"{path.name} imports {mod}"


def test_every_module_declares_all():
    for path in PACKAGE.rglob("*.py"):
        if path.name in ("__main__.py",):
            continue
        tree = ast.parse(path.read_text())
        names = {t.id for node in tree.body if isinstance(node, ast.Assign)
                 for t in node.targets if isinstance(t, ast.Name)}
        if path.name == "__init__.py" and path.parent.name == "_kernels":
            continue
        assert "__all__" in names, f"{path.relative_to(PACKAGE)} has no __all__"


def test_no_dispatch_on_integrator_names_outside_registry():
    # one registry: no `if name == "verlet"` chains elsewhere
    for path in PACKAGE.rglob("*.py"):
        text = path.read_text()
        for name in ("'verlet'", '"verlet"', '"rk4"', "'rk4'"):
            if f"== {name}" in text:
                raise AssertionError(f"{path.name} dispatches on {name}")


def test_files_read_no_private_attribute_of_a_simulation():
    # the HDF5 layer goes through Simulation.description(), .state, .snapshot(),
    # .time_value and .output_path; a `sim._name` in it is a regression
    files = sorted((PACKAGE / "io").rglob("*.py"))
    assert len(files) >= 5
    for path in files:
        tree = ast.parse(path.read_text())
        private = sorted({node.attr for node in ast.walk(tree)
                          if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name)
                          and node.value.id == "sim" and node.attr.startswith("_")})
        assert private == [], path.name
