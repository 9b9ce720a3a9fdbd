"""Registry of methods and their variants: name -> solver, label, colour, in one place.

Each method lives in its own sub-package ``isaflow.methods.<name>`` that
defines ``METHOD`` (a :class:`Method`).  Add a new method's package name to
``PACKAGES``; nothing else branches on method names.
"""

import importlib
from dataclasses import dataclass, field

PACKAGES = ("isa", "sph", "mps", "sph1d", "solid")


@dataclass(frozen=True)
class Variant:
    name: str
    label: str  # says what it is and whether the paper states it
    colour: str
    marker: str = "o"


@dataclass(frozen=True)
class Method:
    name: str
    label: str
    paper: str  # the paper in ../shared/papers the method replicates or completes
    variants: dict = field(default_factory=dict)  # name -> Variant
    solver: str = ""  # "module:function" of its solve()


def get(method):
    """The Method of one registered package (KeyError naming the choices)."""
    if method not in PACKAGES:
        raise KeyError(f"unknown method '{method}' (choose from {', '.join(PACKAGES)})")
    return importlib.import_module(f"isaflow.methods.{method}").METHOD


def registry():
    """{method name: Method} of every registered sub-package that exists."""
    out = {}
    for pkg in PACKAGES:
        try:
            out[pkg] = get(pkg)
        except ModuleNotFoundError as err:
            if err.name != f"isaflow.methods.{pkg}":
                raise
    return out


def variant(method, name):
    """The registry's Variant of method/name (KeyError naming the choices)."""
    m = get(method)
    if name not in m.variants:
        raise KeyError(f"method '{method}' has no variant '{name}' (choose from {', '.join(m.variants)})")
    return m.variants[name]


def label(method, name):
    """Label of a method's variant, e.g. 'paper: x += du F / max|F| (section 3.3, literal)'."""
    return variant(method, name).label
