"""The architecture the issue asks for, checked on the source: no module outside methods/ names a method
or a variant, imports only point down the layers, no import cycle, and every rule's code inputs hold
every module its output depends on."""

import ast
import re
import subprocess
import sys
from pathlib import Path

import pytest

from isaflow import deps, methods

from conftest import ROOT

SRC = ROOT / "src" / "isaflow"
# 'paper' is a variant name and also the claims tables' column naming a claim's paper, so it is left out
NAMES = ({m for m in methods.PACKAGES} | {v for m in methods.registry().values() for v in m.variants}) - {"paper"}
LAYERS = [  # a module may import its own layer and the ones above it in this list, never one below
    ("core",),
    # what reads and checks inputs, the registry ('methods': methods/__init__.py only), the contract, the driver
    # and its at-rest numbers, the tank's theory, and helpers importing no other module here (deps, html, timing)
    ("inputs", "settings", "tank", "contract", "rest", "at_rest", "deps", "theory", "methods", "plausible", "budget", "preflight",
     "claims_registry", "driver", "html", "timing"),
    # what writes, reads and judges run files: the run file, the run, the command line, measures, tables, figures,
    # the report, the claims (judge, quantities, derived numbers), the ParaView export and the comparison on any tank
    ("metrics", "runfile", "tables", "run", "cli", "figures", "report", "claims", "judge", "quantities", "derived", "export", "compare"),
    ("methods.",),  # a method package
]
ARCHITECTURE = ROOT / "docs" / "architecture.md"


def _layer(module):
    rel = module.removeprefix("isaflow.").removeprefix("isaflow")
    for k in range(len(LAYERS) - 1, -1, -1):
        for prefix in LAYERS[k]:
            if prefix.endswith(".") and rel.startswith(prefix) or rel == prefix or rel.startswith(prefix + "."):
                return k
    return 0 if rel in ("", "__init__") else None


def test_every_module_is_in_a_layer_and_every_layer_name_a_module():
    """Every module of the package (deps.graph) belongs to a layer; every name of LAYERS is a module or package."""
    modules = sorted(deps.graph())
    assert len(modules) > 100
    assert [m for m in modules if _layer(m) is None] == []
    assert [n for layer in LAYERS for n in layer if not n.endswith(".") and deps.module_file(f"isaflow.{n}") is None] == []
    top = {p.stem for p in SRC.glob("*.py")} | {p.name for p in SRC.iterdir() if (p / "__init__.py").is_file()}
    named = {n for layer in LAYERS for n in layer if not n.endswith(".")}
    assert top - {"__init__"} == named


def test_the_architecture_doc_states_the_layers_of_this_test():
    """docs/architecture.md's layer sentence ('The layers (checked by tests/test_architecture.py): `a, b` <- ...')
    lists exactly LAYERS, in order."""
    text = " ".join(ARCHITECTURE.read_text().split())
    start = text.index("The layers (checked by `tests/test_architecture.py`): ") + 54
    inside, end = False, start
    while inside or text[end] != ".":  # the sentence ends at the first full stop outside a code span
        inside ^= text[end] == "`"
        end += 1
    groups = [re.search(r"`([^`]+)`", part).group(1) for part in text[start:end].split("<-")]
    stated = [tuple(n.strip() for n in g.split(",")) for g in groups]
    assert stated == [tuple("methods.<name>" if n == "methods." else n for n in layer) for layer in LAYERS]


def shared_sources():
    """Python sources outside methods/ and the workflow's shared rule files and scripts."""
    py = [p for p in SRC.rglob("*.py") if "methods" not in p.relative_to(SRC).parts[:1]]
    smk = [ROOT / "Snakefile", *sorted((ROOT / "workflow" / "rules").glob("*.smk"))]
    return py, smk + sorted((ROOT / "workflow" / "scripts").glob("*.py"))


def test_no_module_outside_methods_names_a_method_or_variant():
    py, other = shared_sources()
    found = []
    for p in py:
        for node in ast.walk(ast.parse(p.read_text())):
            if isinstance(node, ast.Constant) and isinstance(node.value, str) and node.value in NAMES:
                found.append(f"{p.relative_to(ROOT)}:{node.lineno}: {node.value!r}")
    for p in other:
        for k, line in enumerate(p.read_text().splitlines(), 1):
            for lit in re.findall(r"""["']([A-Za-z0-9_]+)["']""", line):
                if lit in NAMES:
                    found.append(f"{p.relative_to(ROOT)}:{k}: {lit!r}")
    assert not found, "\n".join(found)


def test_imports_point_down_the_layers_and_form_no_cycle():
    g = deps.graph()
    up = [f"{a} -> {b}" for a, targets in g.items() for b in targets
          if _layer(a) is not None and _layer(b) is not None and _layer(b) > _layer(a)]
    assert not up, "\n".join(up)
    assert deps.cycles(g) == []


def test_rule_code_inputs_hold_every_module_the_function_loads():
    """For every script rule calling an isaflow function: the modules Python loads when that function's
    module is imported, and everything it imports later (the static closure), are all code inputs."""
    from snakemake.api import SnakemakeApi
    from snakemake.settings.types import ConfigSettings, ResourceSettings, WorkflowSettings  # noqa: F401

    src = ROOT / "src"
    out = subprocess.run([sys.executable, "-c", """
import json, sys
sys.path.insert(0, 'src')
from snakemake.api import SnakemakeApi
from snakemake.settings.types import ResourceSettings
with SnakemakeApi() as api:
    wf = api.workflow(resource_settings=ResourceSettings(cores=1), snakefile='Snakefile')
    rules = {}
    for r in wf._workflow.rules:
        func = getattr(r.params, 'func', None) if hasattr(r, 'params') else None
        code = r.input.get('code') if 'code' in r.input.keys() else None
        code = [str(f) for f in code] if isinstance(code, list) else None  # a function: a run rule's closure
        if isinstance(func, str) and code is not None:
            rules[r.name] = dict(func=func, code=code)
    print(json.dumps(rules))
"""], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-3000:]
    import json

    rules = json.loads(out.stdout.strip().splitlines()[-1])
    assert len(rules) >= 20
    modules = sorted({"isaflow." + r["func"].rsplit(".", 1)[0] for r in rules.values()})
    seen = _loaded_by_import(modules)
    missing = {}
    for name, r in rules.items():
        lacking = sorted(seen["isaflow." + r["func"].rsplit(".", 1)[0]] - set(r["code"]))
        if lacking:
            missing[name] = lacking
    assert not missing, missing


# imports each module in a child forked from one interpreter that holds the third-party libraries already
# (none of them imports isaflow), so each child starts with no isaflow module loaded, as a fresh interpreter
_FORKED_IMPORTS = """
import importlib, json, os, sys
import matplotlib, netCDF4, numba, numpy, pandas, scipy.sparse, xarray, yaml, jsonschema  # noqa: F401
assert not any(n.startswith('isaflow') for n in sys.modules)
out = {}
for module in sys.argv[1:]:
    r, w = os.pipe()
    if os.fork() == 0:
        os.close(r)
        importlib.import_module(module)
        files = [m.__file__ for n, m in list(sys.modules.items()) if n.startswith('isaflow') and getattr(m, '__file__', None)]
        os.write(w, json.dumps(files).encode())
        os._exit(0)
    os.close(w)
    with os.fdopen(r) as f:
        out[module] = json.loads(f.read())
    assert os.wait()[1] == 0, module
print(json.dumps(out))
"""


def _loaded_by_import(modules):
    """{module: repository paths of the isaflow modules an interpreter holds after importing it (from no
    isaflow module loaded), and the static closure of its imports}."""
    import json

    loaded = subprocess.run([sys.executable, "-c", _FORKED_IMPORTS, *modules], cwd=ROOT, capture_output=True,
                            text=True, timeout=300)
    assert loaded.returncode == 0, loaded.stderr[-3000:]
    out = {}
    for module, paths in json.loads(loaded.stdout.strip().splitlines()[-1]).items():
        files = {str(Path(f).resolve().relative_to(ROOT)) for f in paths}
        out[module] = files | set(deps.closure(module))
    return out


def test_changing_a_shared_module_reruns_every_dependent_figure(tmp_path):
    """In a scratch copy whose every output exists and is newer than every input, a dry run has nothing
    to do; after a shared module changes (figures/style.py, then metrics.py) it reruns exactly the
    jobs whose code depends on it: every figure, never a solver run."""
    import os
    import shutil

    for item in ("Snakefile", "workflow", "config", "src"):
        src = ROOT / item
        (shutil.copytree if src.is_dir() else shutil.copy)(src, tmp_path / item,
                                                          **({"ignore": shutil.ignore_patterns("__pycache__")}
                                                             if src.is_dir() else {}))
    targets = ["figures/fig06_single_coarse.png", "figures/fig10_flow_complete.png", "figures/convergence_single.png",
               "figures/methods_tanks.png"]

    def dry(*extra):
        p = subprocess.run([sys.executable, "-m", "snakemake", "-n", "--workflow-profile", "none", *extra, "--",
                            *targets], cwd=tmp_path, capture_output=True, text=True, timeout=300)
        assert p.returncode == 0, p.stderr[-2000:]
        return p.stdout + p.stderr

    def jobs(out):
        if "Nothing to be done" in out:
            return {}
        table = out.split("Job stats:")[1].split("total")[0]
        return {r.split()[0]: int(r.split()[1]) for r in table.splitlines()[3:] if r.strip()}

    outputs = set()  # every output and log of the targets' jobs (--summary: output_file, date, rule, log-file(s), ...)
    for line in dry("--forceall", "--summary").splitlines():
        cols = line.split("\t")
        if len(cols) >= 4 and cols[0] != "output_file":
            outputs.add(cols[0])
            outputs.update(f.strip() for f in cols[3].split(",") if f.strip() not in ("", "-"))
    old, new = 1.6e9, 1.7e9
    for p in tmp_path.rglob("*"):
        if p.is_file():
            os.utime(p, (old, old))
    for f in outputs:
        path = tmp_path / f
        path.parent.mkdir(parents=True, exist_ok=True)
        path.touch()
        os.utime(path, (new, new))
    assert jobs(dry()) == {}
    os.utime(tmp_path / "src" / "isaflow" / "figures" / "style.py", (new + 10, new + 10))
    figures = jobs(dry())
    assert figures and "run" not in figures
    assert {"isa_fig_single", "isa_fig_flow", "isa_fig_convergence", "compare_figure_tanks"} <= set(figures)
    os.utime(tmp_path / "src" / "isaflow" / "metrics.py", (new + 20, new + 20))
    after = jobs(dry())
    assert "run" not in after and {"compare_table", "isa_fig_single"} <= set(after)


def test_history_names_say_their_dimension_and_shared_quantities_have_one_name():
    """contract.history_problems: a hist_ / sample_ / snap_ variable whose first dimension is not record / sample /
    snapshot, or a shared quantity (contract.SHARED_HISTORY) with other dims or units, is refused when a run file is
    written; no method source still writes the names the methods used before they were unified."""
    import numpy as np

    from isaflow import contract

    ok = {"sample_time": (("sample",), np.zeros(3), "s", "t"), "hist_fmax": (("record",), np.zeros(2), "N", "f"),
          "snap_pos": (("snapshot", "particle", "xy"), np.zeros((1, 2, 2)), "cm", "x")}
    assert contract.history_problems(ok) == []
    assert contract.history_problems({"hist_time": (("sample",), np.zeros(3), "s", "t")})  # prefix vs dims
    assert contract.history_problems({"sample_time": (("sample",), np.zeros(3), "ms", "t")})  # shared units
    assert contract.history_problems({"sample_vessel_count": (("sample",), np.zeros(3), "1", "n")})  # shared dims
    old = re.compile(r"\b(hist_(time|vessel_count|wall_resultant|rms_speed|energy_ratio)|sample_vrms|"
                     r"sample_vessel_weight)\b")
    hits = [f"{p.relative_to(ROOT)}:{k + 1}" for p in SRC.rglob("*.py")
            for k, line in enumerate(p.read_text().splitlines()) if old.search(line)]
    assert hits == []
