"""README.md tells the truth: its layout names paths that exist, its one-run examples run, its one-figure
example plans exactly that figure's run, and its workflow commands plan."""

import os
import re
import shlex
import subprocess
import sys

from conftest import ROOT

README = (ROOT / "README.md").read_text()


def _block(heading):
    section = README.split(f"## {heading}")[1]
    return re.search(r"```bash\n(.*?)```", section, re.S).group(1).strip().splitlines()


def test_the_layout_names_only_paths_that_exist():
    table = README.split("## Layout")[1].split("\n## ")[0]
    missing = []
    for cell in re.findall(r"^\| ([^|]+) \|", table, re.M):
        for path in re.findall(r"`([^`]+)`", cell):
            if path == "path":
                continue
            first = path.split(",")[0].strip()
            if "*" in first:
                ok = any(ROOT.glob(first))
            elif "/" not in first and not first.endswith((".yaml", ".md")):
                ok = any(ROOT.glob(f"**/{first}"))  # a module named in a row of its folder
            else:
                ok = (ROOT / first).exists()
            if not ok:
                missing.append(path)
    assert not missing


def test_the_one_run_examples_run(tmp_path):
    for line in _block("Running one run"):
        argv = shlex.split(line)
        assert argv[:2] == ["isaflow", "run"]
        out = argv.index("-o") + 1
        argv[out] = str(tmp_path / f"{len(list(tmp_path.iterdir()))}.nc")
        proc = subprocess.run([sys.executable, "-m", "isaflow.cli", *argv[1:]], cwd=ROOT, capture_output=True,
                              text=True, timeout=600)
        assert proc.returncode == 0, line + "\n" + proc.stderr[-2000:]
        assert (tmp_path / argv[out]).exists()


def test_the_one_figure_example_plans_that_figure_and_its_run_only():
    line = next(s for s in re.findall(r"`(snakemake -c1 figures/[^`]+)`", README))
    proc = subprocess.run([sys.executable, "-m", *shlex.split(line), "-n", "--forceall", "--workflow-profile", "none"],
                          cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    table = proc.stdout.split("Job stats:")[1].split("total")[0]
    assert {r.split()[0] for r in table.splitlines()[3:] if r.strip()} == {"compile", "run", "isa_fig_single"}


def test_the_python_example_plots_a_run(tmp_path):
    """The README's xarray example draws its figure from the run file the first one-run example writes (made here
    by that command, its output path moved into the test's folder)."""
    code = re.search(r"## Open a run in Python.*?```python\n(.*?)```", README, re.S).group(1)
    assert len(code.strip().splitlines()) <= 14
    first = shlex.split(_block("Running one run")[0])
    path = first[first.index("-o") + 1]
    assert f'"{path}"' in code and 'fig.savefig("run.png")' in code
    first[first.index("-o") + 1] = str(tmp_path / "run.nc")
    proc = subprocess.run([sys.executable, "-m", "isaflow.cli", *first[1:]], cwd=ROOT, capture_output=True, text=True,
                          timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    proc = subprocess.run([sys.executable, "-c", code.replace(f'"{path}"', repr(str(tmp_path / "run.nc")))],
                          cwd=tmp_path, capture_output=True, text=True, timeout=300, env={**os.environ, "MPLBACKEND": "Agg"})
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert (tmp_path / "run.png").stat().st_size > 10_000
