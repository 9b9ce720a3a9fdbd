"""Adding a method takes what docs/architecture.md says and nothing more: a toy tank method (a square lattice
at rest, its floor carrying the weight) added to a copy of the project as one package and one settings file
appears in the methods' comparison table, the report's comparison section and the claims (the elastic floor
under every tank method's liquid, row prj-floor-beam) without a line of any shared file changing.

The copy's workflow is planned (snakemake --dag) and the toy's run is made through `isaflow run`; its row
of the comparison table and of the report section come from the shared functions of those rules."""

import re
import shutil
import subprocess
import sys
import textwrap

import pandas as pd

from conftest import ROOT

TOY = {
    "src/isaflow/methods/toy/__init__.py": '''
        """A toy tank method (tests/test_add_a_method.py): a square lattice at rest in the first vessel."""

        from .. import Method, Variant

        METHOD = Method(name="toy", order=90, marker="x", tank=True, label="toy lattice at rest",
                        paper="papadopoulos2016",
                        variants=(Variant("rest", "toy: a square lattice at rest, the floor carrying its weight",
                                          "tab:gray", "x"),))
    ''',
    "src/isaflow/methods/toy/settings.py": '''
        """The toy's settings values (config/methods/toy.yaml)."""

        VALUES = {"lattice.spacing": {"type": "number", "exclusiveMinimum": 0}}  # cm
    ''',
    "src/isaflow/methods/toy/checks.py": '''
        """The toy's checks: anything goes; one particle per spacing squared."""

        from ... import budget


        def plausible(tank, s, stability=False):
            return None


        def cost(tank, s, particles=None):
            (x0, x1), dx = tank.vessels[0][1], s["lattice.spacing"]
            n = particles or (x1 - x0) * tank.depth / dx**2
            return [budget.Cost(n, 1.0, 100.0 * n, 1.0)]
    ''',
    "src/isaflow/methods/toy/method.py": '''
        """The toy as a tank method: particles on a square lattice filling the first vessel to the tank's depth,
        each weighing W / N, the floor under each column carrying the column (units cm, N)."""

        import numpy as np

        from ...contract import Result

        REFERENCES = ("none: a test method",)


        def check(tank, settings, start=None):
            return None


        def warm_up(threads=None):
            return None


        def solve(tank, settings, variant, resolution, start=None, progress=None, threads=None):
            dx = settings["lattice.spacing"]
            (x0, x1), y0 = tank.vessels[0][1], tank.floor_y(0)
            xs = np.arange(x0 + dx / 2, x1, dx)
            ys = np.arange(y0 + dx / 2, y0 + tank.depth, dx)
            pos = np.array([(x, y) for y in ys for x in xs])
            weight = np.full(len(pos), tank.weight / len(pos))
            floor = next(k for k, (a, b, c, d) in enumerate(tank.walls) if b == d == y0)
            return Result(method="toy", variant=variant, pos0=pos, pos=pos.copy(), weight=weight,
                          contact_wall=np.full(len(xs), floor), contact_point=np.column_stack([xs, np.full(len(xs), y0)]),
                          contact_force=np.column_stack([np.zeros(len(xs)), np.full(len(xs), weight[0] * len(ys))]),
                          status="converged", message="at rest by construction", steps=0, start_step=0,
                          wall_time=0.0, force_evals=0, residual=0.0, residual_name="none", residual_units="N",
                          spacing=dx, params={"layer_pitch": dx, "held_weight": tank.weight, "initial_depth": tank.depth,
                                              "tank_difference": "none"})
    ''',
    "config/methods/toy.yaml": '''
        # The toy tank method of tests/test_add_a_method.py
        lattice:
          spacing: {value: 10.0, source: "inferred: a coarse test lattice"}
        variants:
          rest: {set: {}}
        resolutions:
          coarse: {source: "inferred: the default", set: {}}
        runs:
          single_toy: {tank: single, variant: rest, resolution: coarse, compare: true, label: "the toy at rest"}
    ''',
}


def _project(tmp_path):
    """A copy of the project with the toy added (nothing else changed)."""
    for item in ("Snakefile", "workflow", "config", "src", "requirements"):
        src = ROOT / item
        if src.is_dir():
            shutil.copytree(src, tmp_path / item, ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))
        else:
            shutil.copy(src, tmp_path / item)
    for rel, text in TOY.items():
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_text(textwrap.dedent(text).lstrip())
    return tmp_path


def _python(proj, code):
    env = {"PYTHONPATH": str(proj / "src"), "PATH": "/usr/bin:/bin", "NUMBA_CACHE_DIR": str(proj / ".numba-cache"),
           "HOME": str(proj)}
    proc = subprocess.run([sys.executable, "-c", code], cwd=proj, env=env, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    return proc.stdout


def _dag(proj, *targets):
    """{rule label: set of its jobs' dot ids} and the edges of the planned jobs of targets."""
    proc = subprocess.run([sys.executable, "-m", "snakemake", "--dag", "--forceall", "-c1", "--workflow-profile", "none",
                           *targets], cwd=proj, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    labels = {int(k): v for k, v in re.findall(r'^\s*(\d+)\[label = "([^"]*)"', proc.stdout, re.M)}
    edges = {(int(a), int(b)) for a, b in re.findall(r"^\s*(\d+) -> (\d+)", proc.stdout, re.M)}
    return labels, edges


def test_a_toy_method_joins_the_comparison_the_report_and_the_claims(tmp_path):
    proj = _project(tmp_path)
    assert _python(proj, "from isaflow import methods; print(','.join(methods.registry()))").split() == [
        "isa,sph,mps,sph1d,solid,toy"]

    labels, edges = _dag(proj, "results/compare/runs.csv", "results/report/70_methods.md",
                         "results/claims/registry/counts.csv")
    toy = [k for k, v in labels.items() if "single_toy" in v]
    assert len(toy) == 1, labels
    after = {b for a, b in edges if a == toy[0]}
    assert {labels[b].split("\\n")[0] for b in after} >= {"compare_table", "solid_floors_oneway"}
    reach, todo = set(), [toy[0]]  # the claims job judges the floor under its liquid (prj-floor-beam)
    while todo:
        k = todo.pop()
        for a, b in edges:
            if a == k and b not in reach:
                reach.add(b)
                todo.append(b)
    assert "claims" in {labels[b].split("\\n")[0] for b in reach}

    out = proj / "toy.nc"
    _python(proj, f"import sys; from isaflow import cli; sys.argv = ['isaflow', 'run', '--method', 'toy', '--run', "
                  f"'single_toy', '-o', r'{out}']; sys.exit(cli.main())")
    table, md, csv = proj / "runs.csv", proj / "70_methods.md", proj / "methods_compare.csv"
    _python(proj, f"from isaflow import tables; from isaflow.report import methods as r; "
                  f"tables.compare_table([r'{out}'], [r'{table}'], compare=[r'{out}']); "
                  f"r.methods_section(r'{table}', [r'{md}', r'{csv}'], tanks=['single'])")
    row = pd.read_csv(table).iloc[0]
    assert (row["method"], row["variant"], row["status"]) == ("toy", "rest", "converged")
    assert abs(row["held_weight_N"] - row["tank_weight_N"]) < 1e-9 * row["tank_weight_N"]
    assert "toy" in md.read_text()
