"""Scene validation, CLI exit codes, run-file contents and provenance."""

import subprocess
import sys

import numpy as np
import pytest
import yaml

from isaflow import cli, runfile, scene

from conftest import ROOT, SCENES, TINY

TINY = {**TINY, "solver": {**TINY["solver"], "history": {"every": 10}}}


def write_scene(tmp_path, spec, name="scene.yaml"):
    path = tmp_path / name
    path.write_text(yaml.safe_dump(spec))
    return path


def test_paper_scenes_load_with_the_paper_particle_counts():
    assert len(scene.initial_positions(scene.load(SCENES / "single_coarse.yaml"))) == 180
    assert len(scene.initial_positions(scene.load(SCENES / "single_refined.yaml"))) == 684


def test_unknown_key_is_rejected_naming_file_and_field(tmp_path):
    spec = {**TINY, "solver": {**TINY["solver"], "stepsize": 1}}
    path = write_scene(tmp_path, spec)
    with pytest.raises(scene.SceneError, match=r"scene\.yaml: field 'solver'.*'stepsize'"):
        scene.load(path)


def test_wrong_type_names_the_field(tmp_path):
    spec = {**TINY, "forces": {**TINY["forces"], "wall": {**TINY["forces"]["wall"], "l_u": -1}}}
    with pytest.raises(scene.SceneError, match=r"field 'forces\.wall\.l_u'"):
        scene.load(write_scene(tmp_path, spec))


def test_particles_outside_the_walls_are_an_impossible_geometry(tmp_path):
    spec = {**TINY, "particles": {**TINY["particles"], "lattice": {**TINY["particles"]["lattice"], "center_x": 50.0}}}
    with pytest.raises(scene.SceneError, match="outside the walls' bounding box"):
        scene.load(write_scene(tmp_path, spec))


def test_zero_length_wall_and_nan_points_are_rejected(tmp_path):
    spec = {**TINY, "walls": TINY["walls"] + [{"name": "dot", "from": [5, 5], "to": [5, 5]}]}
    with pytest.raises(scene.SceneError, match=r"field 'walls' \(dot\): segment has zero length"):
        scene.load(write_scene(tmp_path, spec))
    spec = {**TINY, "particles": {"weight": 1.0, "points": [[1.0, float("nan")]]}}
    with pytest.raises(scene.SceneError, match="must be finite"):
        scene.load(write_scene(tmp_path, spec))


def test_override_of_a_missing_field_is_an_error(tmp_path):
    with pytest.raises(scene.SceneError, match="override 'solver.bogus.x': no field 'bogus'"):
        scene.load(write_scene(tmp_path, TINY), ["solver.bogus.x=1"])


def test_bad_scene_exits_2_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "run.nc"
    code = cli.run(str(write_scene(tmp_path, {**TINY, "extra": 1})), str(out), quiet=True)
    assert code == 2 and not out.exists()
    assert "scene.yaml" in capsys.readouterr().err


def test_unaccepted_outcome_exits_1_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "run.nc"
    spec = {**TINY, "solver": {**TINY["solver"], "max_steps": 50}}
    code = cli.run(str(write_scene(tmp_path, spec)), str(out), quiet=True)
    assert code == 1 and not out.exists() and not list(tmp_path.glob(".*tmp*"))
    assert "outcome 'step_limit' is not accepted" in capsys.readouterr().err


def test_tiny_scene_end_to_end_through_the_command_line(tmp_path):
    out = tmp_path / "run.nc"
    proc = subprocess.run([sys.executable, "-m", "isaflow.cli", "run", str(write_scene(tmp_path, TINY)), "-o",
                           str(out), "-q"], capture_output=True, text=True, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    ds = runfile.read(out)
    # physics: converged, and the walls carry the weight of the 4 particles
    assert ds.attrs["status"] == "converged" and float(ds["residual"]) < 0.1
    assert ds["wall_resultant"].sel(xy="y").sum() == pytest.approx(200.0, abs=4 * 0.1)
    # every variable has units; provenance is complete
    assert all("units" in ds[v].attrs for v in ds.variables if v not in ds.coords)
    for key in ("git_commit", "git_dirty", "scene_sha256", "config_sha256", "package_versions", "command",
                "time_coverage_start", "time_coverage_end", "Conventions", "variant_label"):
        assert ds.attrs[key] not in ("", None), key
    assert "ACDD" in ds.attrs["Conventions"] and "numba==" in ds.attrs["package_versions"]
    assert yaml.safe_load(ds.attrs["scene_yaml"])["name"] == "tiny"
    assert not list(tmp_path.glob(".*tmp*"))


def test_equilibrium_balances_the_weight(single_runs):
    """At a converged state the wall reactions balance the weight within N f_tol."""
    for name in ("single_coarse", "single_refined"):
        ds = single_runs[name, "capped"]
        n, W = ds.sizes["particle"], float(ds["weight"].sum())
        R = ds["wall_resultant"].values.sum(0)
        assert ds.attrs["status"] == "converged"
        assert abs(R[1] - W) <= n * 0.1
        assert abs(R[0]) <= n * 0.1
        # per-particle residuals are all below f_tol, so the sum is bounded as well
        assert np.abs(ds["force"].values).max() < 0.1
