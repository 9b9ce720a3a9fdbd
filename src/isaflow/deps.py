"""Which source files a module's results depend on: the closure of its imports inside the package.

The workflow gives every rule the files of :func:`closure` of the module it
calls as inputs, so editing any module an output depends on (directly or
through another module) reruns the rule.  Imports are read from the source
(ast), anywhere in a module (also inside functions); the sub-packages a
registry finds itself (an ``__init__`` calling ``pkgutil.iter_modules(__path__)``)
and literal ``import_module("isaflow...")`` calls count as imports.  A method's entry module is what the run rule adds itself.
The JSON schemas beside a module count as its source.  Pure Python.
"""

import ast
import re
from functools import lru_cache
from pathlib import Path

ROOT = Path(__file__).resolve().parent  # src/isaflow
PACKAGE = ROOT.name


def module_file(name):
    """Path of module ``isaflow.x.y`` (a module file or a package's __init__), or None."""
    parts = name.split(".")
    if parts[0] != PACKAGE:
        return None
    base = ROOT.joinpath(*parts[1:])
    for p in (base.with_suffix(".py"), base / "__init__.py"):
        if p.is_file():
            return p
    return None


def _name_of(path):
    rel = path.relative_to(ROOT.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


@lru_cache(maxsize=None)
def imports(path, by_name=True):
    """Package modules imported by the file at ``path`` (absolute and relative imports, at any depth);
    by_name: also the modules it imports by name (a registry entry ``entry="..."``, import_module("..."))."""
    path = Path(path)
    tree = ast.parse(path.read_text(), str(path))
    here = _name_of(path).split(".")
    if path.name != "__init__.py":
        here = here[:-1]  # the package the module lives in
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = (node.module or "").split(".") if node.level == 0 else \
                here[: len(here) - node.level + 1] + ([*node.module.split(".")] if node.module else [])
            mod = ".".join(p for p in base if p)
            found.add(mod)
            found.update(f"{mod}.{a.name}" for a in node.names)  # 'from . import x' imports module x
    if by_name:
        text = path.read_text()
        if path.name == "__init__.py" and "pkgutil.iter_modules(__path__)" in text:  # a registry that imports
            # every sub-package beside it (isaflow.methods): it imports isaflow.methods.a, ...
            found.update(f"{'.'.join(here)}.{p.parent.name}" for p in sorted(path.parent.glob("*/__init__.py")))
        found.update(re.findall(r"""import_module\(\s*["'](isaflow\.[\w.]+)["']""", text))
    return frozenset(m for m in found if m.split(".")[0] == PACKAGE and module_file(m))


def closure(*modules):
    """Sorted source files (``src/isaflow/...``, relative to the project) of modules and everything they import,
    with the package __init__ files on their way and the JSON schemas beside them that they name (a module
    reading ``tank.schema.json`` depends on it; editing the claims schema reruns no solver run)."""
    todo = [m if m.startswith(PACKAGE + ".") or m == PACKAGE else f"{PACKAGE}.{m}" for m in modules]
    files = set()
    seen = set()
    while todo:
        name = todo.pop()
        if name in seen:
            continue
        seen.add(name)
        parts = name.split(".")
        todo.extend(".".join(parts[:k]) for k in range(1, len(parts)))  # parent packages run first
        path = module_file(name)
        if path is None:
            continue
        files.add(path)
        text = path.read_text()
        files.update(p for p in path.parent.glob("*.json") if p.name in text)  # the schemas it reads by name
        todo.extend(imports(path))
    return sorted(str(p.relative_to(ROOT.parents[1])) for p in files)


def graph():
    """{module: modules it imports statically} of every module of the package (imports by name left out)."""
    out = {}
    for path in sorted(ROOT.rglob("*.py")):
        name = _name_of(path)
        out[name] = sorted(m for m in imports(path, by_name=False) if m != name)
    return out


def cycles(g=None):
    """Import cycles of the package graph: a list of module lists (empty if acyclic).  An edge to a package
    whose __init__ only re-exports (e.g. 'from . import x') counts as an edge to that package."""
    g = graph() if g is None else g
    colour, stack, found = {}, [], []

    def visit(u):
        colour[u] = 1
        stack.append(u)
        for v in g.get(u, ()):
            if colour.get(v) == 1:
                found.append(stack[stack.index(v):] + [v])
            elif v in g and not colour.get(v):
                visit(v)
        stack.pop()
        colour[u] = 2

    for u in sorted(g):
        if not colour.get(u):
            visit(u)
    return found
