"""The docs name only what exists: every repository path and every isaflow module (or a name in one) that
README.md, config/README.md, docs/*.md, workflow/report/*.rst and the docstrings of src/isaflow name is in
the tree; and every path rooted in a top-level folder and every ``isaflow.*`` module the configuration files
(config/**/*.yaml: comments, sources, a registry row's ``where``) name.

What counts as a name (read from the text, no import of the package):

- a path: a token with a '/' that starts with one of the repository's top-level folders (``config/``,
  ``src/``, ...), and any token inside a code span (markdown backticks, docstring ``...``) or a markdown link
  target with a '/' whose first part is a folder of the tree, or with a file extension; in docstrings also a
  bare file name (``tank.schema.json``).  ``<name>``, ``{case}`` and ``*`` are wildcards (at least one file
  must match), ``{a,b}`` lists alternatives (each must exist).  A path that starts with a top-level folder
  is looked up from the repository root (``figures/style.py`` also under ``src/isaflow/``); any other under
  the usual bases (``src/isaflow/``, the docstring's own package and its parent, ``workflow/``,
  ``config/``) or as the end of a tracked path (``common.smk``, ``methods/isa/plan.py``).
- an output of the workflow (``results/...``, ``logs/...``): a path some rule or package function writes, a
  string of the rule files or the sources (``results/isa/study/{name}.csv``); other outputs (``docs/timing.md``,
  ``figures/error_vs_runtime.png``) are the files git ignores.  Source files of other repositories (the peer
  codes' ``.cpp``) and files outside the repository (``../shared/``) are not looked up.
- a module: ``isaflow.a.b`` anywhere, and inside a code span a dotted name whose first part is a top-level
  module or package of isaflow (``core.neighbours``, ``runfile.start_problem``) or, in a docstring, a module
  beside it (``settings.checked_values`` in ``methods/solid/``).  The longest prefix that is a module must
  exist and the next part must be defined in it (a def, class, assignment or import at its top level, or a
  submodule); settings keys that share a module's name (``settings.cfl`` of SPH, ``figures.*`` of the ISA
  workflow file) are not module names.  A package docstring's ``Modules:`` paragraph names only modules of
  the package.
"""

import ast
import re
import subprocess
from functools import lru_cache
from itertools import product
from pathlib import Path

import pytest
from conftest import ROOT

SRC = ROOT / "src" / "isaflow"
EXTENSIONS = "py|yaml|yml|smk|jsonl|json|md|rst|csv|tsv|toml|sh|txt|cfg|lock|nc|png|pdf|html|log|zip"
SEGMENT = r"(?:[\w*-]|<[^<>`/]*>|\{[^{}`/]*\})+"  # a path segment: word characters, wildcards, <...>, {...}
PATH = re.compile(rf"(?<![\w./<>{{}}*!-])((?:\.?{SEGMENT}/)+(?:{SEGMENT}|\.(?={SEGMENT}))*)")
FILE = re.compile(rf"(?<![\w./<>{{}}*!-])({SEGMENT}(?:\.{SEGMENT})*\.(?:{EXTENSIONS}))(?![\w])")
DOTTED = re.compile(r"(?<![\w./-])((?:isaflow\.)?[a-z_][a-z0-9_]*(?:\.[A-Za-z_][A-Za-z0-9_]*)+)(?![\w])")
FOREIGN = (".cpp", ".c", ".h", ".hpp", ".f90", ".cu")  # source files of the peer codes (other repositories)
OUTPUTS = ("results/", "logs/")
TOOLS = (".snakemake/", ".numba-cache/", ".venv/")  # the local tools' own folders (git ignores them)  # written by the workflow: looked up among the paths rules and sources name
# first parts of dotted names that are settings keys or file fields, not modules, though a module has the name
NOT_MODULES = {"settings", "figures", "report", "tank", "run", "rest"}


@lru_cache(maxsize=None)
def tracked():
    """(files, folders) of the repository (git ls-files, as in the work tree)."""
    out = subprocess.run(["git", "ls-files", "--cached", "--others", "--exclude-standard"], cwd=ROOT,
                         capture_output=True, text=True, check=True).stdout
    files = {f for f in out.split("\n") if f and (ROOT / f).exists()}
    dirs = set()
    for f in files:
        parts = f.split("/")[:-1]
        dirs.update("/".join(parts[:k]) for k in range(1, len(parts) + 1))
    return frozenset(files), frozenset(dirs)


@lru_cache(maxsize=None)
def folder_names():
    """Folders a path in a code span may start with: the top-level ones, and those of src/isaflow, workflow/ and
    config/ (``methods/``, ``rules/``, ``tanks/``...)."""
    dirs = tracked()[1]
    return frozenset({d for d in dirs if "/" not in d} | {d.split("/")[-1] for d in dirs
                                                         if d.count("/") == 1 and d.split("/")[0] in ("workflow", "config")
                                                         or d.count("/") == 2 and d.startswith("src/isaflow/")})


def top_folders():
    return {d for d in tracked()[1] if "/" not in d}


def _regex(pattern):
    """A path pattern as a regular expression: *, <...> and {...} match within one path segment."""
    return re.compile("^" + re.sub(r"(?:\\\*|<[^>]*>|\\\{[^}]*\\\})+", "[^/]*", re.escape(pattern)) + "/?$")


def _matches(pattern, names):
    if not re.search(r"[*<>{}]", pattern):
        return pattern in names
    rx = _regex(pattern)
    return any(rx.match(n) for n in names)


def alternatives(path):
    """A path with {a,b} alternatives as the list of its paths ({name} without a comma stays a wildcard)."""
    parts = re.split(r"(\{[^{}]*,[^{}]*\})", path)
    choices = [[c.strip() for c in p[1:-1].split(",")] if p.startswith("{") and "," in p else [p] for p in parts]
    return ["".join(c) for c in product(*choices)]


@lru_cache(maxsize=None)
def output_patterns():
    """Every path a rule file or a source of the package names in a string (f-string fields and {wildcards} as
    wildcards), and the PNG and PDF of every figure("name") of the rule files: what the workflow writes."""
    found = set()
    for p in [ROOT / "Snakefile", *sorted((ROOT / "workflow").rglob("*.smk")), *sorted((ROOT / "workflow").rglob("*.py")),
              *sorted(SRC.rglob("*.py"))]:
        text = p.read_text()
        if p.suffix != ".py":
            found.update(f"figures/{name}.{ext}" for name in re.findall(r"figure\(\"([\w|{}]+)\"\)", text)
                         for ext in ("png", "pdf"))
        tree = ast.parse(_python_of(p))
        docs = {id(n.value) for n in ast.walk(tree) if isinstance(n, ast.Expr)}  # docstrings: text, not paths
        for node in ast.walk(tree):
            if id(node) in docs:
                continue
            if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Div) and _joined(node):  # Path("a") / "b"
                text = _joined(node)
            elif isinstance(node, ast.JoinedStr):
                text = "".join(v.value if isinstance(v, ast.Constant) else "{}" for v in node.values)
            elif isinstance(node, ast.Constant) and isinstance(node.value, str):
                text = node.value
            else:
                continue
            found.update(m.group(0) for m in re.finditer(r"[\w.{}*-]+(?:/[\w.{}*-]*)+|[\w{}-]+\.(?:%s)\b" % EXTENSIONS,
                                                         text))
    return frozenset(found)


def _joined(node):
    """The path of Path("logs") / "timing" / "jobs.jsonl" (constants and Path(...) of one constant), or None."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return node.value
    if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "Path" and len(node.args) == 1:
        return _joined(node.args[0])
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Div):
        left, right = _joined(node.left), _joined(node.right)
        return f"{left}/{right}" if left and right else None
    return None


def _python_of(path):
    """Python source of a file; of a rule file, its quoted strings (one list)."""
    text = path.read_text()
    if path.suffix == ".py":
        return text
    text = re.sub(r'"""(?:.|\n)*?"""', "", text)  # docstrings of the rule files' functions
    strings = re.findall(r"""(f?"(?:[^"\\\n]|\\.)*"|f?'(?:[^'\\\n]|\\.)*')""", text)
    return "[\n" + ",\n".join(strings) + "]"  # one list: no string of it is a statement (a docstring)


def is_output(path):
    """A path some rule or source writes or reads (either side's wildcards match anything; a folder of one; a
    bare file name, the end of one)."""
    literal = re.sub(r"\*|<[^>]*>|\{[^}]*\}", "X", path).rstrip("/")
    for pattern in output_patterns():
        plain = re.sub(r"\{[^}]*\}", "X", pattern)
        if _regex(pattern).match(literal) or _regex(path).match(plain) or plain.startswith(literal + "/"):
            return True
        if "/" not in path and (_regex(path).match(plain.rsplit("/", 1)[-1]) or
                                _regex(pattern.rsplit("/", 1)[-1]).match(literal)):
            return True
    return False


@lru_cache(maxsize=None)
def ignored(path):
    """A path git ignores (an output of the workflow or of local tools, never tracked)."""
    literal = re.sub(r"\*|<[^>]*>|\{[^}]*\}", "x", path)
    proc = subprocess.run(["git", "check-ignore", "-q", "--no-index", literal], cwd=ROOT)
    return proc.returncode == 0


def path_exists(path, bases):
    """Whether path names a file or folder of the tree, or an output (module docstring)."""
    return all(_one_path_exists(p, bases) for p in alternatives(path))


def _one_path_exists(path, bases):
    if path.startswith(TOOLS):
        return ignored(path)
    folder = path.endswith("/")
    path = path.rstrip("/") or path
    if path.startswith("../") or path.endswith(FOREIGN):
        return True
    if path.startswith(OUTPUTS):
        return is_output(path)
    first = path.split("/")[0]
    if "/" in path and (ROOT / first).is_symlink():  # profiles -> workflow/profiles
        path = str((ROOT / first).readlink()) + path[len(first):]
    files, dirs = tracked()
    names = files | dirs
    rooted = path.split("/")[0] in top_folders()
    for base in (["", "src/isaflow"] if rooted else bases):
        if _matches(f"{base}/{path}" if base else path, names):
            return True
    if not rooted and ("/" in path and _matches("*/" + path, names) or
                       "/" not in path and any(_matches(path, {n.rsplit("/", 1)[-1]}) for n in files)):
        return True
    return ("/" not in path or ignored(path + "/" * folder)) and is_output(path)


def code_spans(text, markdown):
    """The code spans of a text: `...` (markdown) or ``...`` (docstrings, reStructuredText)."""
    rx = r"(?<!`)`([^`\n]+)`(?!`)" if markdown else r"``([^`]+)``|(?<![`\w]):?`([^`\n]+)`"
    return [next(g for g in m.groups() if g is not None) for m in re.finditer(rx, text)]


def _path_like(token):
    """A token of a code span that names a path: its first part a folder of the tree, or a file extension."""
    first = token.lstrip("./").split("/")[0]
    return (first in folder_names() or token.startswith(OUTPUTS) or token.startswith("../")
            or re.search(rf"\.(?:{EXTENSIONS})$", token) is not None) and not re.fullmatch(r"[\d./]+", token)


def candidates(text, markdown):
    """(paths, dotted names) a text names (module docstring above)."""
    spans = code_spans(text, markdown)
    links = [t for t in re.findall(r"\]\(([^)\s]+)\)", text)] if markdown else []
    paths = set()
    for m in PATH.finditer(text):  # bare paths: only those rooted in a top-level folder or outputs
        p = m.group(1)
        if p.split("/")[0] in top_folders() or p.startswith(OUTPUTS):
            paths.add(p)
    for span in spans:
        paths.update(m.group(1) for m in PATH.finditer(span) if _path_like(m.group(1)))
        paths.update(m.group(1) for m in FILE.finditer(span))
    for link in links:
        if "://" not in link and not link.startswith("#"):
            paths.add(link.split("#")[0])
    if not markdown:
        paths.update(m.group(1) for m in FILE.finditer(text))
    paths = {p.rstrip(".,;:") for p in paths if "://" not in p and p.rstrip(".,;:")}
    dotted = {m.group(1) for m in DOTTED.finditer(text) if m.group(1).startswith("isaflow.")}
    for span in spans:
        dotted.update(m.group(1) for m in DOTTED.finditer(span))
    dotted = {d.rstrip(".") for d in dotted
              if not re.search(rf"\.(?:{EXTENSIONS})$", d) and not any(len(x) == 1 for x in d.split(".")[1:])}
    return paths, dotted


@lru_cache(maxsize=None)
def defined(module_path):
    """(names defined at the top level of a module file, {class: names in its body})."""
    tree = ast.parse(Path(module_path).read_text())
    names, classes = set(), {}

    def targets(node):
        for t in node.targets if isinstance(node, ast.Assign) else [node.target]:
            yield from (n.id for n in ast.walk(t) if isinstance(n, ast.Name))

    for node in tree.body:
        subs = list(ast.walk(node)) if isinstance(node, (ast.If, ast.Try, ast.With)) else [node]
        for sub in subs:
            if isinstance(sub, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                names.add(sub.name)
                if isinstance(sub, ast.ClassDef):
                    body = {n.name for n in sub.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
                    body |= {t for n in sub.body if isinstance(n, (ast.Assign, ast.AnnAssign)) for t in targets(n)}
                    classes[sub.name] = body
            elif isinstance(sub, (ast.Assign, ast.AnnAssign, ast.AugAssign)):
                names.update(targets(sub))
            elif isinstance(sub, (ast.Import, ast.ImportFrom)):
                names.update((a.asname or a.name).split(".")[0] for a in sub.names)
            if sub is not node and isinstance(sub, (ast.FunctionDef, ast.ClassDef)):
                break
    return names, classes


def module_file(name):
    """The file of module isaflow.a.b (a module or a package's __init__), or None."""
    base = SRC.joinpath(*name.split(".")[1:])
    for p in (base.with_suffix(".py"), base / "__init__.py"):
        if p.is_file():
            return p
    return None


def module_problem(dotted, package=None):
    """Why a dotted name is not a module or a name in one (None if it is, or is no module name at all).
    package: the 'isaflow.x.y' a docstring lives in (the modules beside it count)."""
    first = dotted.split(".")[0]
    if dotted.startswith("isaflow."):
        return _problem(dotted.split("."))
    if first in NOT_MODULES:
        return None
    beside = package and package != "isaflow" and module_file(f"{package}.{first}")
    if module_file(f"isaflow.{first}"):  # a top-level module, or the module of that name beside the docstring
        why = _problem(["isaflow", *dotted.split(".")])
        return why if why is None or not beside else _problem([*package.split("."), *dotted.split(".")]) and why
    return _problem([*package.split("."), *dotted.split(".")]) if beside else None


def _problem(parts):
    """Why the dotted name of parts ('isaflow', ...) is not a module or a name in one, or None."""
    for k in range(len(parts), 0, -1):
        path = module_file(".".join(parts[:k]))
        if path is not None:
            break
    rest = parts[k:]
    if not rest:
        return None
    names, classes = defined(path)
    if rest[0] not in names:
        return f"module '{'.'.join(parts[:k])}' has no '{rest[0]}'"
    if len(rest) > 1 and classes.get(rest[0]) and rest[1] not in classes[rest[0]] and not rest[1][0].isupper():
        return f"class '{'.'.join(parts[:k + 1])}' has no '{rest[1]}'"
    return None


def listed_modules(doc):
    """The ``names`` of a package docstring's 'Modules:' paragraph outside parentheses (each a module)."""
    m = re.search(r"Modules:(.*?)(?:\n\s*\n|\Z)", doc, re.S)
    if not m:
        return []
    text, depth, k, out = m.group(1), 0, 0, []
    while k < len(text):
        if text.startswith("``", k):
            end = text.find("``", k + 2)
            end = len(text) if end < 0 else end
            if depth == 0:
                out.append(text[k + 2:end])
            k = end + 2
            continue
        depth += {"(": 1, ")": -1}.get(text[k], 0)
        k += 1
    return [n for n in out if re.fullmatch(r"\w+", n)]


def doc_texts():
    """(where, text, markdown, path bases, package, is a package docstring) of every document and docstring."""
    docs = [ROOT / "README.md", ROOT / "config" / "README.md", *sorted((ROOT / "docs").glob("*.md")),
            *sorted((ROOT / "workflow" / "report").glob("*.rst"))]
    common = ["", "src/isaflow", "workflow", "workflow/rules", "config", "src/isaflow/methods"]
    for p in docs:
        yield str(p.relative_to(ROOT)), p.read_text(), p.suffix == ".md", common, None, False
    for p in sorted(SRC.rglob("*.py")):
        rel = p.relative_to(ROOT)
        here = str(rel.parent)
        package = ".".join(p.relative_to(SRC.parent).parent.parts)
        for node in ast.walk(ast.parse(p.read_text())):
            if isinstance(node, (ast.Module, ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                doc = ast.get_docstring(node, clean=False)
                if doc:
                    yield (f"{rel}:{getattr(node, 'lineno', 1)}", doc, False, [*common, here, str(Path(here).parent)],
                           package, isinstance(node, ast.Module) and p.name == "__init__.py")


def config_texts():
    """(where, text) of every configuration file (config/**/*.yaml): its comments, sources and notes name files
    and modules too (a registry row's ``where``)."""
    for p in sorted((ROOT / "config").rglob("*.yaml")):
        yield str(p.relative_to(ROOT)), p.read_text()


def problems():
    found = []
    for where, text in config_texts():  # only paths rooted in a top-level folder, and isaflow.* modules
        paths = {m.group(1).rstrip(".,;:") for m in PATH.finditer(text)
                 if m.group(1).split("/")[0] in top_folders() or m.group(1).startswith(OUTPUTS)}
        found += [f"{where}: path '{p}' does not exist" for p in sorted(paths) if not path_exists(p, [""])]
        found += [f"{where}: '{m.group(1)}': {module_problem(m.group(1))}" for m in DOTTED.finditer(text)
                  if m.group(1).startswith("isaflow.") and module_problem(m.group(1).rstrip("."))]
    for where, text, markdown, bases, package, package_doc in doc_texts():
        paths, dotted = candidates(text, markdown)
        for p in sorted(paths):
            if not path_exists(p, bases):
                found.append(f"{where}: path '{p}' does not exist")
        for d in sorted(dotted):
            why = module_problem(d, package)
            if why:
                found.append(f"{where}: '{d}': {why}")
        for name in listed_modules(text) if package_doc else ():
            if module_file(f"{package}.{name}") is None:
                found.append(f"{where}: 'Modules:' lists '{name}', which is no module of {package}")
    return found


def test_every_path_and_module_the_docs_name_exists():
    found = problems()
    assert not found, f"{len(found)} names of nothing:\n" + "\n".join(found)


@pytest.mark.parametrize("text, bad", [
    ("see `config/scenes/single_refined.yaml`", "config/scenes/single_refined.yaml"),
    ("bare config/scenes/single_refined.yaml too", "config/scenes/single_refined.yaml"),
    ("the builder `isaflow.core.nosuch`", "isaflow.core.nosuch"),
    ("`core.neighbours.nosuch_function`", "core.neighbours.nosuch_function"),
    ("`cli.prepare`", "cli.prepare"),
    ("`src/isaflow/methods/<name>/nosuch.py`", "src/isaflow/methods/<name>/nosuch.py"),
    ("`config/methods/{sph,nosuch}.yaml`", "config/methods/{sph,nosuch}.yaml"),
    ("written to `results/nosuch/table.csv`", "results/nosuch/table.csv"),
])
def test_the_check_finds_a_name_of_nothing(text, bad):
    """The check itself: each text names something that is not in the tree, and it is found; the names of what
    exists pass."""
    paths, dotted = candidates(text, markdown=True)
    missing = [p for p in paths if not path_exists(p, ["", "src/isaflow"])] + [d for d in dotted if module_problem(d)]
    assert bad in missing, (paths, dotted, missing)
    good = ("`src/isaflow/core/neighbours.py`, `core.neighbours`, `methods/<name>/checks.py`, "
            "`config/methods/{sph,mps}.yaml`, `results/runs/<method>/<id>.nc`, `isaflow.driver.drive`, "
            "`docs/timing.md`, `settings.cfl`")
    ok_paths, ok_dotted = candidates(good, markdown=True)
    assert len(ok_paths) == 5 and len(ok_dotted) == 3
    assert all(path_exists(p, ["", "src/isaflow"]) for p in ok_paths)
    assert not [d for d in ok_dotted if module_problem(d)]
    assert listed_modules("X.\n\nModules: ``kernels`` (the ``step`` loop), ``nosuch``.\n") == ["kernels", "nosuch"]
