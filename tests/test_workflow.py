"""Workflow: the real config builds a complete DAG; one figure needs only its own run."""

import functools
import re
import subprocess
import sys
from pathlib import Path

from conftest import ROOT

SNAKEMAKE = [sys.executable, "-m", "snakemake"]


@functools.lru_cache(maxsize=None)
def dry_run(*targets):
    """Dry run listing every job (full job blocks: without the default profile); one per target set and test
    session (the full one is read by three tests, 6-8 s each)."""
    proc = subprocess.run([*SNAKEMAKE, "-n", "-c1", "--forceall", "--workflow-profile", "none", *targets], cwd=ROOT,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    return proc.stdout


def jobs(out):
    """{rule: count} from the dry run's job-stats table."""
    table = out.split("Job stats:")[1].split("total")[0]
    rows = [line.split() for line in table.splitlines()[3:] if line.strip()]
    return {r[0]: int(r[1]) for r in rows}


def test_full_dry_run_has_every_paper_figure_and_the_report():
    out = dry_run()
    for name in ("fig05_inputs_coarse", "fig06_single_coarse", "fig07_inputs_refined", "fig08_single_refined",
                 "calibration_free_surface", "convergence_single"):
        assert f"figures/{name}.png" in out
    assert "docs/replication.md" in out and "results/isa/metrics.csv" in out
    assert jobs(out)["run"] >= 5


def test_one_figure_builds_only_what_it_needs():
    counts = jobs(dry_run("figures/fig06_single_coarse.png"))
    assert counts == {"isa_fig_single": 1, "run": 1, "compile": 1}


def test_the_paper_target_builds_figures_5_to_10_table_1_and_the_papers_claims_from_their_own_runs_only():
    """The runs of Figures 5-10 and Table 1's chain, and the runs the paper's claims read (its rows' runs, their
    paper's version and the inputs' stand-ins: claims_registry.paper_runs), judged by one claims job; no other
    paper's runs, no calibration or study."""
    from isaflow import claims_registry

    made = summary("paper")
    runs = {f"{Path(f).parent.name}:{Path(f).stem}" for f in made if f.startswith("results/runs/")}
    figures = {f"isa:{r}" for r in {"single_coarse", "single_refined", "flow_incomplete", "flow_complete"} | table1_runs()}
    claimed = claims_registry.paper_runs()["papadopoulos2016"]
    needed = figures | claimed | _chain_starts()
    assert figures <= runs and runs <= needed | _block_mates(needed)
    assert not [r for r in runs if r.startswith(("isa:er_", "isa:cal_", "isa:sc_"))]
    assert sorted(f for f, rule in made.items() if rule == "claims") == [f"results/claims/registry/papadopoulos2016.{x}" for x in ("csv", "html")]


def _block_mates(keys):
    """The runs made by the same block jobs as keys (a block runs all its members in one process)."""
    import yaml

    out = set()
    for m in ("isa", "sph", "mps"):
        runs = yaml.safe_load((ROOT / f"config/methods/{m}.yaml").read_text())["runs"]
        blocks = {r.get("block") for k, r in runs.items() if f"{m}:{k}" in keys} - {None}
        out |= {f"{m}:{k}" for k, r in runs.items() if r.get("block") in blocks}
    return out


def _chain_starts():
    """The runs the paper's runs continue (a flow's start), which its claims need without naming them."""
    import yaml

    out = set()
    for m in ("isa", "sph", "mps"):
        runs = yaml.safe_load((ROOT / f"config/methods/{m}.yaml").read_text())["runs"]
        out |= {f"{m}:{r['start']}" for r in runs.values() if r.get("start")}
    return out


@functools.lru_cache(maxsize=None)
def summary(*targets):
    """{output file: rule} of every job the targets need (snakemake --summary), once per target set (read only)."""
    proc = subprocess.run([*SNAKEMAKE, "--summary", "-c1", "--forceall", "--workflow-profile", "none", *targets],
                          cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    rows = [line.split("\t") for line in proc.stdout.splitlines()]
    return {r[0]: r[2] for r in rows if len(r) > 2 and r[0] != "output_file"}


def table1_runs():
    from isaflow import inputs, settings

    path = ROOT / "config" / "methods" / "isa_workflow.yaml"
    table = settings.plain(inputs.read_yaml(path, "isa workflow")[1])["table1"]
    return {run for row in table for run in row["chain"]}


def test_sweeps_run_as_blocks_and_every_run_is_made_by_one_rule():
    """Every run file comes from one job: a block's (its sweep in one process) or its own; the full workflow
    plans far fewer jobs than runs."""
    made = summary()
    runs = {f: rule for f, rule in made.items() if f.startswith("results/runs/")}
    blocks = {rule for rule in runs.values() if rule.startswith("block_")}
    assert len(runs) >= 300 and len(blocks) >= 10
    counts = jobs(dry_run())
    assert all(counts[b] == 1 for b in blocks)
    assert counts["run"] + len(blocks) < len(runs) / 2


def test_every_rule_has_a_log_and_solver_rules_a_benchmark():
    blocks = rule_blocks()
    assert len(blocks) >= 20
    for block in blocks:
        name = block.splitlines()[0]
        if "\n    output:" not in block:
            continue  # a target rule (paper, all): nothing to log
        assert "\n    log:" in block, name
        assert "\n    run:" not in block, name  # run: blocks cannot redirect to their log
        if "scripts/run.py" in block:
            assert "benchmark:" in block, name
    assert Path(ROOT / "Snakefile").exists()


def rule_blocks():
    """The text of every rule of the rules files, from its name on.  A rule made by `use rule T as NAME with:`
    (workflow/rules/templates.smk) is its `with:` block and then every directive of T's block it does not
    give itself (a directive given in `with:` replaces the template's)."""
    files = sorted((ROOT / "workflow" / "rules").rglob("*.smk"))
    chunks = [c for p in files for c in re.split(r"\n(?=rule |use rule )", "\n" + p.read_text())[1:]]
    blocks = {c[len("rule "):].split(":")[0]: c[len("rule "):] for c in chunks if c.startswith("rule ")}
    out = list(blocks.values())
    for c in chunks:
        m = re.match(r"use rule (\w+) as (\w+) with:\n", c)
        if m:
            own = set(re.findall(r"^    (\w+):", c, re.M))
            inherited = [d for d in re.split(r"\n(?=    \w+:)", blocks[m.group(1)])[1:]
                         if re.match(r"    (\w+):", d).group(1) not in own]
            out.append("\n".join([f"{m.group(2)}:" + c[m.end() - 1:].rstrip("\n"), *inherited]))
    return out


def test_every_rule_declares_its_resources_and_a_message():
    """mem_mb and runtime on every rule that makes something (docs/cluster.md), and a start line naming the job."""
    for block in rule_blocks():
        name = block.splitlines()[0]
        if "\n    output:" not in block:
            continue
        assert "\n    resources:" in block, name
        resources = block.split("\n    resources:")[1].split("\n    log:")[0]
        assert ("mem_mb" in resources and "runtime" in resources) or "**" in resources, name
        assert "\n    message:" in block, name


def test_run_resources_follow_the_estimate():
    from isaflow import budget

    small = budget.job_resources(budget.Cost(180, 8000, 180 * 640, 20.0))
    large = budget.job_resources(budget.Cost(10512, 1.6e6, 2e9, 20.0))
    assert small == {"mem_mb": 900, "runtime": 5}
    est = 10512 * 1.6e6 * 20e-9  # s
    assert large["mem_mb"] > 4000
    assert large["runtime"] == -(-(budget.JOB_START_S + budget.JOB_TIME_FACTOR * est) // 60) > 10 * est / 60


def test_default_profile_dry_run_lists_every_job_with_its_wildcards():
    proc = subprocess.run([*SNAKEMAKE, "-n", "-c1", "--forceall", "figures/fig06_single_coarse.png"], cwd=ROOT,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "run isa/single_coarse: 1 thread(s), 900 MB, 5 min" in proc.stdout
    assert "isa_fig_single: figures/fig06_single_coarse.png" in proc.stdout


PARSE_WITHOUT_PROJECT = """
import os, runpy, sys, importlib.abc
ROOT, SRC = sys.argv[1], os.path.join(sys.argv[1], "src")
# no installed isaflow: drop every path entry that holds it (an editable install's too)
sys.path = [p for p in sys.path if not os.path.isdir(os.path.join(p or ".", "isaflow"))]
sys.modules.pop("isaflow", None)
class NoNumerics(importlib.abc.MetaPathFinder):
    # the workflow's own code (rules files, src/) must not import the numerical stack while it is parsed
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] not in ("numpy", "scipy", "numba", "xarray", "netCDF4", "matplotlib"):
            return None
        f = sys._getframe(1)
        while f:
            if f.f_code.co_filename.startswith(SRC) or f.f_code.co_filename.endswith((".smk", "Snakefile")):
                raise ModuleNotFoundError(f"{name} (imported while the workflow is parsed)")
            f = f.f_back
        return None
sys.meta_path.insert(0, NoNumerics())
sys.argv = ["snakemake", "-n", "-c1", "--forceall", "--workflow-profile", "none"]
runpy.run_module("snakemake", run_name="__main__")
"""


def test_workflow_parses_without_the_project_installed():
    import os

    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    proc = subprocess.run([sys.executable, "-c", PARSE_WITHOUT_PROJECT, str(ROOT)], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    assert "Job stats:" in proc.stdout


def test_lint_passes():
    """snakemake --lint: every rule has a log, a conda environment, no mixed functions in rule files."""
    proc = subprocess.run([*SNAKEMAKE, "--lint"], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]


def test_report_holds_each_figure_the_run_made_with_its_own_caption(tmp_path):
    """The report's figures are the copies a run of this checkout makes (rule report_figure_copy), each with
    its own caption, category and subcategory (workflow/report/figures.yaml), whichever rule file makes the
    figure; a committed figure the run did not make is not in the report."""
    import shutil

    import yaml

    for item in ("Snakefile", "workflow", "config", "figures"):
        src = ROOT / item
        (shutil.copytree if src.is_dir() else shutil.copy)(src, tmp_path / item)
    (tmp_path / "src").symlink_to(ROOT / "src")
    spec = yaml.safe_load((ROOT / "workflow" / "report" / "figures.yaml").read_text())
    # claims_robustness is drawn from the claims rule's tables, whose job also makes report pages this stand-in
    # run has not made: a report holding it needs the claims rule's outputs too (the full run makes both)
    names = sorted(p.stem for p in (tmp_path / "figures").glob("*.png")
                   if p.stem in spec and p.stem != "claims_robustness")
    assert len(names) >= 25
    made, left = names[:-1], names[-1]  # the last committed figure is not made by this "run"
    copies = [f"results/report/figures/{n}.png" for n in made]
    (tmp_path / "results" / "report" / "figures").mkdir(parents=True)
    for n in made:  # what the rule's job does (the committed figures stand in for the run's)
        shutil.copy(tmp_path / "figures" / f"{n}.png", tmp_path / "results" / "report" / "figures" / f"{n}.png")
    base = [*SNAKEMAKE, "--workflow-profile", "none"]
    proc = subprocess.run([*base, "--report", "report.html", *copies], cwd=tmp_path, capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    added = {line.split()[1] for line in proc.stderr.splitlines() if line.startswith("Adding ")}
    assert added == {f"{n}.png" for n in made}
    # a report asking for every figure refuses (the figure the run did not make has no copy) instead of showing
    # the committed figures/<name>.png
    proc = subprocess.run([*base, "--report", "all.html", *copies, f"results/report/figures/{left}.png"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode != 0 and "marked for report but does not exist" in proc.stdout + proc.stderr
    assert not (tmp_path / "all.html").exists()
    html = (tmp_path / "report.html").read_text()
    for n in made:
        first = " ".join(spec[n]["caption"].split())[:40]
        assert first.replace("&", "&amp;") in html or first in html, n
        assert spec[n]["subcategory"] in html
    assert "Replication of Papadopoulos, Koutitas" in html  # the About page (workflow/report/workflow.rst)
    assert "not made by this run" in html  # no claims registry in this tree: no verdict is invented


def test_every_figure_has_one_caption_naming_real_claims():
    """Every figure a rule makes has its caption entry, and every claim a caption names is in its paper's
    claims registry file (config/claims/<paper>.yaml)."""
    import yaml

    spec = yaml.safe_load((ROOT / "workflow" / "report" / "figures.yaml").read_text())
    out = dry_run()
    made = {Path(w.rstrip(",")).stem for w in out.split()
            if w.startswith("figures/") and w.rstrip(",").endswith((".png", ".gif"))}  # figures and animations
    assert made and made <= set(spec), sorted(made - set(spec))
    assert set(spec) <= made, sorted(set(spec) - made)
    for name, entry in spec.items():
        for paper, ids in entry["claims"].items():
            registry = yaml.safe_load((ROOT / "config" / "claims" / f"{paper}.yaml").read_text())
            known = {c["id"] for c in registry["claims"]}
            assert set(ids) <= known, (name, paper, sorted(set(ids) - known))
