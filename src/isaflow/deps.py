"""Which source files a module's results depend on: the closure of its imports inside the package.

The workflow gives every rule the files of :func:`closure` of the module it
calls as inputs, so editing any module an output depends on (directly or
through another module) reruns the rule.  Imports are read from the source
(ast), anywhere in a module (also inside functions); a method package's
``METHOD.entry`` is followed too (the registry imports it by name).  The JSON
schemas beside a module count as its source.  Pure Python.
"""

import ast
import re
from functools import lru_cache
from pathlib import Path

ROOT = Path(__file__).resolve().parent  # src/isaflow
PACKAGE = ROOT.name
_ENTRY = re.compile(r"""entry\s*=\s*["']([\w.]+)["']""")


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
def imports(path):
    """Package modules imported by the file at ``path`` (absolute and relative imports, at any depth)."""
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
    text = path.read_text()
    found.update(_ENTRY.findall(text))  # the registry's METHOD.entry
    for m in re.findall(r"""import_module\(\s*f?["'](isaflow\.[\w.]+)["']""", text):
        found.add(m)
    return frozenset(m for m in found if m.split(".")[0] == PACKAGE and module_file(m))


def closure(*modules):
    """Sorted source files (``src/isaflow/...``, relative to the project) of modules and everything they import,
    with the package __init__ files on their way and the JSON schemas beside them."""
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
        files.update(path.parent.glob("*.json"))
        todo.extend(imports(path))
    return sorted(str(p.relative_to(ROOT.parents[1])) for p in files)
