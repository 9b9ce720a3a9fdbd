"""Workflow: the real config builds a complete DAG; one figure needs only its own run."""

import subprocess
import sys
from pathlib import Path

from conftest import ROOT

SNAKEMAKE = [sys.executable, "-m", "snakemake"]


def dry_run(*targets):
    """Dry run listing every job; without the default profile, whose `quiet: [rules, host]` hides job blocks."""
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
    assert counts == {"isa_fig_single": 1, "run": 1}


def test_every_rule_has_a_log_and_solver_rules_a_benchmark():
    files = sorted((ROOT / "workflow" / "rules").rglob("*.smk"))
    blocks = [b for p in files for b in ("\n" + p.read_text()).split("\nrule ")[1:]]
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


def test_lint_passes():
    """snakemake --lint: every rule has a log, a conda environment, no mixed functions in rule files."""
    proc = subprocess.run([*SNAKEMAKE, "--lint"], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]


def test_report_holds_every_committed_figure_with_its_caption(tmp_path):
    """snakemake --report over the committed figures (a clean clone has them): every caption file resolves,
    whichever rule file (rules/ or rules/methods/) marks the figure."""
    import shutil

    for item in ("Snakefile", "workflow", "config", "figures"):
        src = ROOT / item
        (shutil.copytree if src.is_dir() else shutil.copy)(src, tmp_path / item)
    (tmp_path / "src").symlink_to(ROOT / "src")
    pngs = sorted(p.relative_to(tmp_path).as_posix() for p in (tmp_path / "figures").glob("*.png"))
    assert len(pngs) >= 25
    proc = subprocess.run([*SNAKEMAKE, "--workflow-profile", "none", "--report", "report.html", *pngs], cwd=tmp_path,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    added = {line.split()[1] for line in proc.stderr.splitlines() if line.startswith("Adding ")}
    assert added == {Path(p).name for p in pngs}
    html = (tmp_path / "report.html").read_text()
    for category in ("Paper figures", "Studies", "Methods compared"):
        assert category in html
