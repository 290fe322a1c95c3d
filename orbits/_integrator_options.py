"""An integrator's options, each declared once: :class:`Option` (name, type,
default, help, unit, the values it takes), the check of a value against it,
and the declarations read from the integrators' source.

An integrator class lists its options as ``option_specs = (Option(...), ...)``
in its body (:mod:`orbits.integrators.base`, point 2 of the contract).  The
classes check given values against those declarations, and the command line
makes its flags from them (``orbits run --epsilon``, ``--min-dt``, ...).
The command line builds its parser and ``--help`` without importing numba or
astropy, which every integrator module imports; so :func:`declared` reads the
declarations from the source of :mod:`orbits.integrators` (:mod:`ast`, no
import), and ``tests/test_integrator_options.py`` checks that it reads what the
registered classes hold.  For that, an ``Option``'s arguments are literals or
names of module-level constants (literals, or ``tuple(NAME)`` of a dict whose
keys are literals), and its class is named by a name.

This module imports nothing of the package: the command line and the
integrators' base class both import it.
"""

import ast
import functools
import math
import numbers
import pathlib
from typing import NamedTuple

__all__ = ["Option", "declared", "taken_by", "INTEGRATORS"]

#: the package whose modules :func:`declared` reads
INTEGRATORS = pathlib.Path(__file__).resolve().parent / "integrators"

#: the types an option may have, by the name its declaration gives
_KINDS = {"float": float, "int": int, "str": str}

#: what ``sign`` asks of a number, as the error message says it
_SIGNS = {"positive": (lambda x: x > 0), "non-negative": (lambda x: x >= 0)}


class Option(NamedTuple):
    """One option of an integrator, as its class declares it.

    Parameters
    ----------
    name : str
        The keyword (``get("ias15", epsilon=1e-10)``); the command line's flag
        is the name with hyphens (``--min-dt``).
    kind : {float, int, str}
        The type of a value; a given value is converted to it.
    default
        The value when none is given.
    help : str
        What it is and does, in a phrase (the command line's help lists it
        with the integrators that take the option and their defaults).
    unit : str
        The physical type of a value given in the simulation's units
        (``"time"``: the integrator receives the number in its internal
        unit, the command line reads ``1d`` or a number in the scene's
        units); ``""`` for a pure number.
    choices : tuple
        The values it takes, where they are a few; ``()`` for any of its kind.
    sign : {"", "positive", "non-negative"}
        For a number: finite, and ``> 0`` or ``>= 0``; ``""`` for no bound.

    Examples
    --------
    >>> from orbits.integrators import Option
    >>> epsilon = Option("epsilon", float, 1e-9, "precision", sign="positive")
    >>> epsilon.checked(1e-10)
    1e-10
    >>> epsilon.problem(0.0)
    "option 'epsilon' must be a positive finite number, got 0.0"
    >>> Option("mode", str, "a", "mode", choices=("a", "b")).problem("c")
    "unknown mode 'c'; valid values: 'a', 'b'"
    """

    name: str
    kind: type
    default: object
    help: str
    unit: str = ""
    choices: tuple = ()
    sign: str = ""

    @property
    def flag(self):
        """The command line's flag: ``--`` and the name with hyphens."""
        return "--" + self.name.replace("_", "-")

    def problem(self, value):
        """What is wrong with ``value`` for this option, or None.

        Returns
        -------
        str or None
            A sentence that names the option and the value, for
            :class:`~orbits.errors.IntegratorOptionError`.
        """
        if self.choices:
            if isinstance(value, bool) or value not in self.choices:
                return (f"unknown {self.name} {value!r}; valid values: "
                        f"{', '.join(map(repr, self.choices))}")
            return None
        if self.kind is str:
            return None if isinstance(value, str) else (
                f"option {self.name!r} must be a string, got {value!r}")
        whole = self.kind is int
        number = numbers.Integral if whole else numbers.Real
        ok = (isinstance(value, number) and not isinstance(value, bool)
              and math.isfinite(float(value)))
        if ok and self.sign:
            ok = _SIGNS[self.sign](float(value))
        if ok:
            return None
        kind = "whole number" if whole else "finite number"
        what = f"a {self.sign} {kind}" if self.sign else f"a {kind}"
        return (f"option {self.name!r} must be {what}, got {value!r}"
                + (" (a string)" if isinstance(value, str) else ""))

    def checked(self, value):
        """``value`` converted to the option's type; ValueError with
        :meth:`problem`'s sentence where it does not fit."""
        problem = self.problem(value)
        if problem is not None:
            raise ValueError(problem)
        if self.choices:
            return self.choices[self.choices.index(value)]
        return self.kind(value)


def taken_by(specs):
    """Option name -> ``(Option, integrator names)`` for each declaration, from
    :func:`declared`'s mapping (or one like it), in the order first declared.

    Examples
    --------
    >>> from orbits._integrator_options import declared, taken_by
    >>> [(spec.default, names) for spec, names in taken_by(declared())["rtol"]]
    [(1e-09, ('dopri5', 'dop853', 'rk4-doubling', 'radau', 'lsoda')), (1e-12, ('trace',))]
    """
    out = {}
    for integrator, options in specs.items():
        for spec in options:
            same = out.setdefault(spec.name, {})
            same.setdefault(spec, []).append(integrator)
    return {name: [(spec, tuple(names)) for spec, names in same.items()]
            for name, same in out.items()}


@functools.lru_cache(maxsize=1)
def declared():
    """Registry name -> its options (a tuple of :class:`Option`), for every
    integrator class in :mod:`orbits.integrators` that has a name, read from
    the source without importing it; in the registry's order (classes it does
    not list last).

    Examples
    --------
    >>> from orbits._integrator_options import declared
    >>> [spec.name for spec in declared()["ias15"]]
    ['epsilon', 'min_dt', 'adaptive_mode']
    """
    modules = {path.stem: _Module(ast.parse(path.read_text(encoding="utf-8")))
               for path in sorted(INTEGRATORS.glob("*.py"))}
    listed = [_find_class(modules, stem, cls) for stem, cls in modules["__init__"].registered]
    others = [(stem, cls) for stem, module in modules.items() for cls in module.classes]
    found = {}
    for where in [*listed, *others]:
        if where is None:
            continue
        name = _class_attribute(modules[where[0]].classes[where[1]], "name")
        if isinstance(name, ast.Constant) and isinstance(name.value, str):
            found.setdefault(name.value, _specs(modules, *where))
    return found


class _Module:
    """What :func:`declared` needs of a module's syntax tree: its constants,
    what it imports from its siblings, its classes, and the ``(module,
    class)`` pairs of a ``_BUILT_IN`` table (the registry's built-in
    integrators, in its order)."""

    def __init__(self, tree):
        self.constants, self.imports, self.classes, self.registered = {}, {}, {}, []
        for node in tree.body:
            if isinstance(node, ast.Assign) and len(node.targets) == 1 \
                    and isinstance(node.targets[0], ast.Name):
                self.constants[node.targets[0].id] = node.value
                if node.targets[0].id == "_BUILT_IN" and isinstance(node.value, ast.Dict):
                    self.registered = [tuple(e.value for e in v.elts)
                                       for v in node.value.values]
            elif isinstance(node, ast.ImportFrom) and node.level == 1 and node.module:
                for alias in node.names:
                    self.imports[alias.asname or alias.name] = (node.module, alias.name)
            elif isinstance(node, ast.ClassDef):
                self.classes[node.name] = node


def _class_attribute(node, attribute):
    for item in node.body:
        if isinstance(item, ast.Assign) and any(
                isinstance(t, ast.Name) and t.id == attribute for t in item.targets):
            return item.value
    return None


def _specs(modules, stem, cls):
    """The options of class ``cls`` of module ``stem``: its own declaration, or
    that of the first base class that has one."""
    node = modules[stem].classes[cls]
    value = _class_attribute(node, "option_specs")
    if value is not None:
        return tuple(_evaluate(value, modules, stem))
    for base in node.bases:
        where = _find_class(modules, stem, base.id) if isinstance(base, ast.Name) else None
        if where is not None:
            return _specs(modules, *where)
    return ()


def _find_class(modules, stem, name):
    """``(module, class name)`` where the class ``name`` seen in ``stem`` is defined."""
    module = modules[stem]
    if name in module.classes:
        return stem, name
    if name in module.imports:
        home, original = module.imports[name]
        if home in modules:
            return _find_class(modules, home, original)
    return None


def _resolved(node, modules, stem):
    """``(node, module)``: a name followed to the constant it stands for, here or
    in the sibling it is imported from."""
    while isinstance(node, ast.Name) and node.id not in _KINDS:
        module = modules[stem]
        if node.id in module.constants:
            node = module.constants[node.id]
        else:
            stem, original = module.imports[node.id]
            node = ast.Name(original)
    return node, stem


def _evaluate(node, modules, stem):
    """The value of a declaration's expression: literals, tuples, ``Option(...)``
    calls, names of module constants (here or imported from a sibling),
    ``tuple(NAME)`` and ``+`` of tuples."""
    node, stem = _resolved(node, modules, stem)
    if isinstance(node, ast.Name):
        return _KINDS[node.id]
    if isinstance(node, (ast.Tuple, ast.List)):
        return tuple(_evaluate(e, modules, stem) for e in node.elts)
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):
        return _evaluate(node.left, modules, stem) + _evaluate(node.right, modules, stem)
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
        if node.func.id == "Option":
            args = [_evaluate(a, modules, stem) for a in node.args]
            kwargs = {k.arg: _evaluate(k.value, modules, stem) for k in node.keywords}
            return Option(*args, **kwargs)
        if node.func.id == "tuple" and len(node.args) == 1:
            inner, home = _resolved(node.args[0], modules, stem)
            if isinstance(inner, ast.Dict):
                return tuple(ast.literal_eval(k) for k in inner.keys)
            return tuple(_evaluate(inner, modules, home))
    return ast.literal_eval(node)
