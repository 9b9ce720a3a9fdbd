"""Registry of methods and their variants: the one list of them, in one place.

Each method lives in its own sub-package ``isaflow.methods.<name>`` whose
``__init__`` defines ``METHOD`` (a :class:`Method`) and imports nothing heavy,
so the workflow reads the registry while it is parsed.  A package declares only
what is its own (label, paper, marker, variants, its place `order`); its modules
``<package>.method``, ``.checks``, ``.settings:VALUES``, its settings file
``config/methods/<name>.yaml`` follow from its name (:class:`Method`).  The registry finds the packages itself
(:data:`PACKAGES`: every sub-package defining ``METHOD``, by ``order``), so
adding a method edits no file of the registry; nothing outside ``methods/``
names a method or a variant: labels, colours, markers, papers, settings files,
claims modules and report fragments all come from here.

A *tank method* (``tank=True``) runs on the shared tanks: its ``entry``
module provides ``check(tank, settings, start)``,
``solve(tank, settings, variant, resolution, start=None, log=None,
threads=None) -> contract.Result`` (log(text): its progress lines, from
driver.drive), ``warm_up(threads)`` and ``REFERENCES``; its ``values`` (``module:attribute``) is the schema of its
settings file (isaflow.settings).  Every method's ``checks`` module (pure
Python, read while the workflow is parsed) has ``plausible(tank, settings,
stability)`` and ``cost(tank, settings, particles) -> [isaflow.budget.Cost]``
(isaflow.preflight; tank is None for the methods without tanks).
"""

import importlib
import pkgutil
from dataclasses import dataclass, field


@dataclass(frozen=True)
class Variant:
    name: str
    label: str  # says what it is and whether the paper states it
    colour: str
    marker: str = "o"
    paper: bool = False  # True only for the paper's method as the paper states it


@dataclass(frozen=True)
class Method:
    """A method as its package declares it: its own name, labels, paper, marker, variants and place (order);
    the modules and files every method has in the same places follow from the name (:meth:`__post_init__`)."""

    name: str
    label: str
    paper: str  # id of the paper the method replicates or completes (claims name it; ../shared/papers/<id>_*.txt)
    paper_label: str = ""  # citation and role, e.g. "Papadopoulos, Koutitas & Lazaridis (2016), the paper replicated"
    marker: str = "o"  # where methods share a figure
    variants: dict = field(default_factory=dict)  # name -> Variant (given as Variants, keyed by their names)
    tank: bool = False  # runs on the shared tanks through isaflow.run
    order: int = 0  # its place in the registry (and the number of its report fragments, results/report/NN_*.md)
    entry: str = ""  # module with check / solve / warm_up / REFERENCES (tank methods): <package>.method
    checks: str = ""  # pure-Python checks, plausible(tank, settings, stability) and cost(...): <package>.checks
    values: str = ""  # "module:attribute" of the settings values schema: <package>.settings:VALUES
    settings: str = ""  # default settings file, relative to the project root: config/methods/<name>.yaml

    def __post_init__(self):
        """Variants keyed by their names; every module or file not given, at its place for the package's name."""
        variants = self.variants.values() if isinstance(self.variants, dict) else self.variants
        object.__setattr__(self, "variants", {v.name: v for v in variants})
        package = f"{__name__}.{self.name}"
        places = dict(entry=f"{package}.method" if self.tank else "", checks=f"{package}.checks",
                      values=f"{package}.settings:VALUES", settings=f"config/methods/{self.name}.yaml")
        for key, place in places.items():
            if not getattr(self, key):
                object.__setattr__(self, key, place)

    def entry_module(self):
        return importlib.import_module(self.entry)

    def checks_module(self):
        return importlib.import_module(self.checks)

    def values_schema(self):
        module, attr = self.values.split(":")
        return getattr(importlib.import_module(module), attr)


def get(method):
    """The Method of one registered package (KeyError naming the choices)."""
    if method not in PACKAGES:
        raise KeyError(f"unknown method '{method}' (choose from {', '.join(PACKAGES)})")
    return importlib.import_module(f"isaflow.methods.{method}").METHOD


def registry():
    """{method name: Method} of every registered sub-package."""
    return {pkg: get(pkg) for pkg in PACKAGES}


def papers():
    """{paper id: label} of every method's paper, the paper replicated first (registry order)."""
    out = {}
    for m in registry().values():
        out.setdefault(m.paper, m.paper_label)
    return out


def tank_methods():
    """{name: Method} of the methods that run on the shared tanks."""
    return {k: m for k, m in registry().items() if m.tank}


def variant(method, name):
    """The registry's Variant of method/name (KeyError naming the choices)."""
    m = get(method)
    if name not in m.variants:
        raise KeyError(f"method '{method}' has no variant '{name}' (choose from {', '.join(m.variants)})")
    return m.variants[name]


def label(method, name):
    """Label of a method's variant, e.g. 'paper: x += du F / max|F| (section 3.3, literal)'."""
    return variant(method, name).label


def _discover():
    """Names of the method packages here: every sub-package whose ``__init__`` defines ``METHOD`` (named after
    its package), ordered by ``Method.order`` (the place of its report fragment), then name."""
    found = []
    for info in pkgutil.iter_modules(__path__):
        module = importlib.import_module(f"{__name__}.{info.name}") if info.ispkg else None
        if module is not None and hasattr(module, "METHOD"):
            if module.METHOD.name != info.name:
                raise ValueError(f"{module.__file__}: METHOD.name '{module.METHOD.name}' is not its package's name")
            found.append(module.METHOD)
    return tuple(m.name for m in sorted(found, key=lambda m: (m.order, m.name)))


PACKAGES = _discover()  # the registry's one list: isa, sph, mps, sph1d, solid (and any package added beside them)
