"""Adding a method takes what docs/architecture.md says and nothing more: a toy dynamic tank method (a damped
lattice of masses and springs released in the first vessel, tests/data/toy/) added to a copy of the project as new
files only -- one package, one settings file, its paper's registry file with one claim -- runs through the one run
driver (isaflow.driver) until at rest by the shared rest monitor (isaflow.rest, config/rest.yaml), and appears in
the methods' comparison table, the report's comparison section and the claims (its own paper's row, judged from
its run, and the elastic floor under every tank method's liquid, row prj-floor-beam) without a line of any shared
file changing.

The copy's workflow is planned (snakemake --dag) and the toy's run is made through `isaflow run`; its row of the
comparison table, of the report section and its claim's verdict come from the shared functions of those rules."""

import filecmp
import re
import shutil
import subprocess
import sys

import pandas as pd
import xarray as xr

from conftest import ROOT

TOY = ROOT / "tests" / "data" / "toy"  # src/ and config/ as in the project; papers/ as ../shared/papers
SHARED = ("Snakefile", "workflow", "config", "src", "requirements")
IGNORE = shutil.ignore_patterns("__pycache__", "*.egg-info")


def _files(top):
    """Paths relative to top of every file under it (no caches, no egg-info)."""
    return {p.relative_to(top) for p in top.rglob("*")
            if p.is_file() and not any(q == "__pycache__" or q.endswith(".egg-info") for q in p.parts)}


def _project(tmp_path):
    """A copy of the project (tmp_path/project) with the toy's files added, each a new file; its paper's text in
    tmp_path/shared/papers, where a checkout's ../shared/papers is."""
    proj = tmp_path / "project"
    proj.mkdir()
    for item in SHARED:
        src = ROOT / item
        if src.is_dir():
            shutil.copytree(src, proj / item, ignore=IGNORE)
        else:
            shutil.copy(src, proj / item)
    for rel in {p for p in _files(TOY) if p.parts[0] != "papers"}:
        assert not (proj / rel).exists(), f"{rel}: the toy would edit a shared file"
        (proj / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(TOY / rel, proj / rel)
    shutil.copytree(TOY / "papers", tmp_path / "shared" / "papers")
    return proj


def _unchanged(proj):
    """Every shared file of the copy is the project's own, byte for byte, and its shared folders hold no file but
    those and the toy's (checked after the copy planned the workflow and made the toy's run and claims)."""
    for item in SHARED:
        if (ROOT / item).is_file():
            assert filecmp.cmp(ROOT / item, proj / item, shallow=False), f"{item}: a shared file changed"
            continue
        ours = _files(ROOT / item)
        for rel in ours:
            assert filecmp.cmp(ROOT / item / rel, proj / item / rel, shallow=False), f"{item}/{rel}: a shared file changed"
        added = {item / p for p in _files(proj / item) - ours}
        assert added == {p for p in _files(TOY) if p.parts[0] == item}, added


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


def test_a_toy_dynamic_method_runs_through_the_driver_and_joins_the_comparison_the_report_and_the_claims(tmp_path):
    proj = _project(tmp_path)
    assert _python(proj, "from isaflow import methods; print(','.join(methods.registry()), ','.join(methods.papers()))"
                   ).split() == ["isa,sph,mps,sph1d,solid,toy", "papadopoulos2016,marko2017,hattori,merino_alonso2020,"
                                                               "toy_lattice"]

    labels, edges = _dag(proj, "results/compare/runs.csv", "results/report/70_methods.md",
                         "results/claims/registry/counts.csv")
    toy = [k for k, v in labels.items() if "single_toy" in v]
    assert len(toy) == 1, labels
    after = {b for a, b in edges if a == toy[0]}
    assert {labels[b].split("\\n")[0] for b in after} >= {"compare_table", "solid_floors_oneway"}
    reach, todo = set(), [toy[0]]  # the claims jobs: the toy's own paper, and the floor under its liquid (marko2017)
    while todo:
        k = todo.pop()
        for a, b in edges:
            if a == k and b not in reach:
                reach.add(b)
                todo.append(b)
    claims_jobs = {labels[b].split("\\n")[-1] for b in reach if labels[b].startswith("claims\\n")}
    assert {"paper: toy_lattice", "paper: marko2017"} <= claims_jobs, claims_jobs

    out = proj / "toy.nc"
    _python(proj, f"import sys; from isaflow import cli; sys.argv = ['isaflow', 'run', '--method', 'toy', '--run', "
                  f"'single_toy', '-o', r'{out}']; sys.exit(cli.main())")
    with xr.open_dataset(out) as ds:  # driven: at rest by the shared monitor, with the driver's numbers
        a = ds.attrs
        assert (a["status"], a["rest_energy_ratio"], a["rest_window"]) == ("converged", 1e-5, 1.2)  # config/rest.yaml
        assert a["status_message"].startswith("at rest: e = KE / (W h) < 1e-05 for 1.2 s")
        assert a["final_energy_ratio"] < 1e-5 and a["start_time"] == 0.0
        rest = float(ds["time_to_rest"])
        assert 0 < rest and rest + 1.2 <= float(ds["sim_time"]) < a["t_max_s"]  # at rest before its time limit
        snaps = ds["snap_time"].values
        assert len(snaps) >= 3 and snaps[0] == 0.0 and snaps[-1] == float(ds["sim_time"])
        assert ds["snap_pos"].shape == (len(snaps), ds.sizes["particle"], 2) and int(ds["wall_crossings"]) == 0
        walls = [str(w) for w in ds["wall"].values]
        share = float(ds["wall_load_mean"].values[walls.index("floor")]) / float(ds["weight"].values.sum())

    table, md, csv = proj / "runs.csv", proj / "70_methods.md", proj / "methods_compare.csv"
    _python(proj, f"from isaflow import tables; from isaflow.report import methods as r; "
                  f"tables.compare_table([r'{out}'], [r'{table}'], compare=[r'{out}']); "
                  f"r.methods_section(r'{table}', [r'{md}', r'{csv}'], tanks=['single'])")
    row = pd.read_csv(table).iloc[0]
    assert (row["method"], row["variant"], row["status"]) == ("toy", "damped", "converged")
    assert abs(row["held_weight_N"] - row["tank_weight_N"]) < 1e-9 * row["tank_weight_N"]
    assert abs(row["time_to_rest_s"] - rest) < 1e-5 * rest  # the driver's number (the table prints 6 digits)
    assert "toy" in md.read_text()

    judged = proj / "claims"  # the claims rule's function on the toy's paper, from its run
    _python(proj, f"from isaflow import claims; claims.write_paper([r'{judged}.csv', r'{judged}.html'], 'config/claims', "
                  f"'toy_lattice', runs={{'toy:single_toy': r'{out}'}})")
    claim = pd.read_csv(f"{judged}.csv").set_index("id").loc["toy-2-floor-carries-the-weight"]
    assert abs(share - 1) <= 0.01 and claim["verdict"] == "reproduced", claim["measured"]  # the run's floor share
    assert f"single_toy {share:.5f}" in claim["measured"], claim["measured"]
    assert "single_toy converged" in claim["measured"] and str(out) in claim["evidence"]
    assert _python(proj, f"from isaflow import claims_registry as reg; t = open(r'{tmp_path}/shared/papers/' + "
                         f"reg.load_files()['toy_lattice']['text']).read(); "
                         f"print(reg.quote_found(next(c['quote'] for c in reg.load() if c['paper'] == 'toy_lattice'), t))"
                   ).strip() == "True"  # its quote is the paper's text (as tests/test_claims_registry.py checks)
    _unchanged(proj)
