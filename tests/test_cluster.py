"""Workflow profiles and the SLURM path.

Fast checks run everywhere: every profile key is an option Snakemake (and the
SLURM plugin) knows, the SLURM profile leaves per-rule resources to the rules,
a dry run through it plans the jobs, and the output comparison used by
tests/cluster/slurm_local.sh tells equal from different outputs.  The real
one-node cluster (installs SLURM, needs root) runs only with ISAFLOW_SLURM=1.
"""

import importlib.util
import os
import subprocess
import sys

import numpy as np
import pytest
import xarray as xr
import yaml

from conftest import ROOT

PROFILES = {name: ROOT / path / "config.yaml" for name, path in [
    ("default", "workflow/profiles/default"), ("slurm", "workflow/profiles/slurm"), ("test", "tests/cluster/profile"),
    ("integration", ".tests/integration")]}
HAS_SLURM_PLUGIN = importlib.util.find_spec("snakemake_executor_plugin_slurm") is not None
needs_plugin = pytest.mark.skipif(not HAS_SLURM_PLUGIN, reason="snakemake-executor-plugin-slurm not installed "
                                  "(pip install -r requirements/lock-py311.txt)")


def snakemake_options():
    from snakemake.cli import get_argument_parser

    return {s.removeprefix("--") for a in get_argument_parser()._actions for s in a.option_strings}


@pytest.mark.parametrize("name", PROFILES)
def test_profile_keys_are_snakemake_options(name):
    keys = set(yaml.safe_load(PROFILES[name].read_text()))
    if not HAS_SLURM_PLUGIN:
        keys = {k for k in keys if not k.startswith("slurm-")}
    assert keys - snakemake_options() == set()


def test_slurm_profile_takes_resources_from_the_rules():
    profile = yaml.safe_load(PROFILES["slurm"].read_text())
    assert profile["executor"] == "slurm"
    assert not {"set-resources", "set-threads", "resources"} & set(profile), "per-rule resources belong in the rules"
    # cpus_per_task must not be a default: the plugin would ask for it instead of the rule's threads
    assert set(profile["default-resources"]) == {"runtime", "mem_mb", "disk_mb"}
    # the site profile of the test cluster must not shadow what the workflow profile sets
    assert not set(yaml.safe_load(PROFILES["test"].read_text())) & set(profile)


@needs_plugin
def test_dry_run_through_the_slurm_profiles():
    proc = subprocess.run(
        [sys.executable, "-m", "snakemake", "-n", "--forceall", "--profile", "tests/cluster/profile",
         "--workflow-profile", "workflow/profiles/slurm", "figures/fig06_single_coarse.png"],
        cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    out = proc.stdout + proc.stderr
    assert "workflow specific profile workflow/profiles/slurm" in out
    assert "fig_single" in out and "total" in out


# --- the comparison behind "outputs equal a local run's" ----------------------

def write_run(path, pos, wall_time):
    xr.Dataset({"pos": (("particle", "xy"), pos, {"units": "cm"}),
                "wall_time": ((), wall_time, {"units": "s", "long_name": "solver wall-clock time of this run"})},
               attrs={"method": "isa", "date_created": str(wall_time)}).to_netcdf(path)


def run_tree(root, pos, wall_time, table="level_cm,wall_time_s\n1.5,2.0\n"):
    (root / "results" / "runs").mkdir(parents=True)
    (root / "figures").mkdir()
    write_run(root / "results" / "runs" / "r.nc", pos, wall_time)
    (root / "figures" / "t.csv").write_text(table)
    return root


def compare(a, b):
    proc = subprocess.run([sys.executable, str(ROOT / "tests" / "cluster" / "compare_outputs.py"), str(a), str(b)],
                          capture_output=True, text=True, timeout=60)
    return proc.returncode, proc.stdout


def test_outputs_equal_apart_from_timing(tmp_path):
    pos = np.arange(6.0).reshape(3, 2)
    code, out = compare(run_tree(tmp_path / "a", pos, 1.0),
                        run_tree(tmp_path / "b", pos, 2.5, table="level_cm,wall_time_s\n1.5,7.0\n"))
    assert code == 0 and "2 of 2 outputs equal" in out


@pytest.mark.parametrize("change", ["position", "table", "missing"])
def test_outputs_that_differ_are_caught(tmp_path, change):
    pos = np.arange(6.0).reshape(3, 2)
    a = run_tree(tmp_path / "a", pos, 1.0)
    b = run_tree(tmp_path / "b", pos + (np.nextafter(pos, np.inf) - pos) * (change == "position"), 1.0,
                 table="level_cm,wall_time_s\n1.6,2.0\n" if change == "table" else "level_cm,wall_time_s\n1.5,2.0\n")
    if change == "missing":
        (b / "figures" / "t.csv").unlink()
    code, out = compare(a, b)
    assert code == 1 and "1 of 2 outputs equal" in out, out


# --- the real cluster ---------------------------------------------------------

@pytest.mark.skipif(os.environ.get("ISAFLOW_SLURM") != "1",
                    reason="local SLURM cluster test is opt-in: ISAFLOW_SLURM=1 (root, Debian; installs and starts "
                           "SLURM, runs the paper target locally and through SLURM, several minutes)")
def test_paper_target_through_local_slurm_equals_local_run():
    proc = subprocess.run(["bash", str(ROOT / "tests" / "cluster" / "slurm_local.sh")], cwd=ROOT,
                          capture_output=True, text=True, timeout=3600)
    print(proc.stdout)  # sacct lines, timing and the comparison: shown with pytest -rP
    if proc.returncode == 77:
        pytest.skip(proc.stderr.strip().splitlines()[-1])
    assert proc.returncode == 0, proc.stdout[-4000:] + proc.stderr[-4000:]
    assert "PASSED" in proc.stdout
