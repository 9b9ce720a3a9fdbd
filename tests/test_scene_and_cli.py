"""Tanks, the one settings loader, ISA scenes built from them, `isaflow run` exit codes, run-file
contents and provenance."""

import subprocess
import sys

import numpy as np
import pytest
import yaml

from isaflow import cli, runfile, settings as S, tank as T
from isaflow.inputs import InputError
from isaflow.methods.isa import scene
from isaflow.methods.isa import settings as isa_settings
from isaflow.methods.isa.settings import VALUES

from conftest import ISA_SETTINGS, ROOT, TANKS, TINY, run_spec, write_spec

TINY = {**TINY, "solver": {**TINY["solver"], "history": {"every": 10}}}


def test_paper_resolutions_build_the_paper_particle_counts():
    assert len(scene.initial_positions(scene.of_run("single", "coarse", "paper"))) == 180
    assert len(scene.initial_positions(scene.of_run("single", "refined", "paper"))) == 684


def test_every_tank_loads_and_states_its_theory():
    for path in sorted(TANKS.glob("*.yaml")):
        t = T.load(path)
        assert t.rho_g > 0 and t.depth > 0 and len(t.walls) >= 3
    t = T.load(TANKS / "single.yaml")
    assert t.rho_g == pytest.approx(9000 / 7250) and t.rho_g * t.depth**2 / 2 == pytest.approx(3262.5)


def test_unknown_settings_key_is_rejected_naming_file_and_field(tmp_path):
    tp, sp = write_spec(tmp_path, TINY)
    spec = yaml.safe_load(sp.read_text())
    spec["solver"]["stepsize"] = {"value": 1, "source": "inferred: test"}
    sp.write_text(yaml.safe_dump(spec))
    with pytest.raises(InputError, match=r"settings\.yaml: field 'solver'.*'stepsize'"):
        S.load(sp, VALUES, "paper", "r")


def test_wrong_type_names_the_field(tmp_path):
    spec = {**TINY, "forces": {**TINY["forces"], "wall": {**TINY["forces"]["wall"], "l_u": -1}}}
    tp, sp = write_spec(tmp_path, spec)
    with pytest.raises(InputError, match=r"field 'forces\.wall\.l_u\.value'"):
        S.load(sp, VALUES, "paper", "r")


def test_particles_outside_the_walls_are_an_impossible_geometry(tmp_path):
    spec = {**TINY, "particles": {**TINY["particles"], "lattice": {**TINY["particles"]["lattice"], "center_x": 50.0}}}
    tp, sp = write_spec(tmp_path, spec)
    with pytest.raises(InputError, match="outside the walls' bounding box"):
        scene.build(T.load(tp), S.load(sp, VALUES, "capped", "r"), "capped")


def test_zero_length_wall_and_nan_points_are_rejected(tmp_path):
    spec = {**TINY, "walls": TINY["walls"] + [{"name": "dot", "from": [5, 5], "to": [5, 5]}]}
    tp, _ = write_spec(tmp_path, spec)
    with pytest.raises(InputError, match=r"field 'walls' \(dot\): segment has zero length"):
        T.load(tp)
    spec = {**TINY, "particles": {"weight": 1.0, "points": [[1.0, float("nan")]]}}
    tp, sp = write_spec(tmp_path, spec)
    with pytest.raises(InputError, match="must be finite"):
        S.load(sp, VALUES, "paper", "r")


def test_override_of_a_missing_setting_is_an_error():
    with pytest.raises(InputError, match=r"override field 'solver\.bogus': no such setting"):
        S.load(ISA_SETTINGS, VALUES, "paper", "coarse", ["solver.bogus=1"])


def test_resolution_and_variant_must_exist():
    with pytest.raises(InputError, match="no resolution 'nope'"):
        S.load(ISA_SETTINGS, VALUES, "paper", "nope")
    with pytest.raises(InputError, match="no variant 'nope'"):
        S.load(ISA_SETTINGS, VALUES, "nope", "coarse")


def test_a_resolution_then_overrides_set_the_values():
    s = S.load(ISA_SETTINGS, VALUES, "paper", "refined", ["solver.du=0.005"])
    assert s["particles.weight"] == 12.5 and s["solver.du"] == 0.005 and s["particles.lattice.a"] == 5.0
    assert s.sources["particles.weight"].startswith("page text") and "command line" in s.sources["solver.du"]


def test_bad_settings_exit_2_and_write_nothing(tmp_path, capsys):
    out = tmp_path / "run.nc"
    tp, sp = write_spec(tmp_path, TINY)
    spec = yaml.safe_load(sp.read_text())
    spec["extra"] = 1
    sp.write_text(yaml.safe_dump(spec))
    code = cli.main(["run", "--method", "isa", "--tank", str(tp), "--settings", str(sp), "--variant", "capped",
                     "--resolution", "r", "-o", str(out)])
    assert code == 2 and not out.exists()
    assert "settings.yaml" in capsys.readouterr().err


def test_unaccepted_outcome_exits_1_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "run.nc"
    spec = {**TINY, "solver": {**TINY["solver"], "max_steps": 50}}
    tp, sp = write_spec(tmp_path, spec)
    code = cli.main(["run", "--method", "isa", "--tank", str(tp), "--settings", str(sp), "--variant", "capped",
                     "--resolution", "r", "-o", str(out)])
    assert code == 1 and not out.exists() and not list(tmp_path.glob(".*partial*"))
    assert "outcome 'step_limit' is not accepted" in capsys.readouterr().err


def test_a_method_that_runs_on_no_tank_is_refused(tmp_path, capsys):
    code = cli.main(["run", "--method", "sph1d", "--tank", str(TANKS / "single.yaml"), "--variant", "x",
                     "--resolution", "r", "-o", str(tmp_path / "r.nc")])
    assert code == 2 and "does not run on tanks" in capsys.readouterr().err


def test_a_declared_run_of_a_method_that_runs_on_no_tank_is_refused_naming_the_option(tmp_path, capsys):
    """The solid's settings file declares no runs: the line names --method, not an empty list of its runs."""
    out = tmp_path / "r.nc"
    assert cli.main(["run", "--method", "solid", "--run", "x", "-o", str(out)]) == 2 and not out.exists()
    err = capsys.readouterr().err
    assert err.startswith("error: --method: method 'solid' does not run on tanks (choose from isa, sph, mps)"), err


def test_tiny_scene_end_to_end_through_the_command_line(tmp_path):
    out = tmp_path / "run.nc"
    tp, sp = write_spec(tmp_path, TINY)
    proc = subprocess.run([sys.executable, "-m", "isaflow.cli", "run", "--method", "isa", "--tank", str(tp),
                           "--settings", str(sp), "--variant", "capped", "--resolution", "r", "-o", str(out)],
                          capture_output=True, text=True, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    ds = runfile.read(out)
    # physics: converged, and the walls carry the weight of the 4 particles
    assert ds.attrs["status"] == "converged" and float(ds["residual"]) < 0.1
    assert ds["wall_resultant"].sel(xy="y").sum() == pytest.approx(200.0, abs=4 * 0.1)
    # every variable has units; provenance is complete
    assert all("units" in ds[v].attrs for v in ds.variables if v not in ds.coords)
    for key in ("git_commit", "git_dirty", "tank_sha256", "settings_sha256", "package_versions", "command",
                "time_coverage_start", "time_coverage_end", "Conventions", "variant_label", "settings_sources",
                "tank_weight", "tank_rho_g", "layer_pitch", "held_weight", "tank_difference", "threads"):
        assert ds.attrs[key] not in ("", None), key
    assert "ACDD" in ds.attrs["Conventions"] and "numba==" in ds.attrs["package_versions"]
    # the settings under their dotted keys (settings.attributes): as written, or derived where the file says null
    assert ds.attrs["solver.du"] == 0.01 and "solver.du: cm" in ds.attrs["settings_units"].splitlines()
    f_ref = isa_settings.f_ref_default(0.01, ds.attrs["forces.wall.r_u"] / ds.attrs["forces.wall.l_u"],
                                       ds.attrs["forces.pair.r_u"] / ds.attrs["forces.pair.l_u"])
    assert ds.attrs["solver.f_ref"] == pytest.approx(f_ref, rel=1e-15) and "solver.f_ref: derived" in \
        ds.attrs["settings_sources"]
    assert not list(tmp_path.glob(".*partial*"))


@pytest.mark.parametrize("method", ["isa", "sph", "mps"])
def test_every_real_setting_has_units_and_every_setting_one_attribute(method):
    """The run-file naming rule (settings.attributes): each dotted key once, under its own name, and the units of
    every real-valued setting (integers are counts) recorded in settings_units."""
    import importlib

    from isaflow import settings as S

    values = importlib.import_module(f"isaflow.methods.{method}.settings").VALUES

    def types(v):
        return v.get("type") if isinstance(v.get("type"), list) else [v.get("type")]

    assert [k for k, v in values.items() if "number" in types(v) and not v.get("units")] == []

    class Resolved(dict):  # a resolved Settings' interface as attributes() reads it
        path, schema = "x.yaml", values
        sources = {k: "literature: x" for k in values}

    attrs = S.attributes(Resolved({k: 1.5 if "number" in types(v) else None for k, v in values.items()}))
    assert set(attrs) == set(values) | {"settings_sources", "settings_units"}
    assert len(attrs["settings_sources"].splitlines()) == len(values)
    assert {line.split(": ")[0] for line in attrs["settings_units"].splitlines()} == \
        {k for k, v in values.items() if v.get("units")}


def test_a_declared_run_runs_by_its_id(tmp_path):
    out = tmp_path / "sc.nc"
    assert cli.main(["run", "--method", "isa", "--run", "single_coarse", "-o", str(out)]) == 0
    ds = runfile.read(out)
    assert ds.attrs["run_id"] == "single_coarse" and ds.attrs["resolution"] == "coarse"
    assert ds.attrs["status"] == "cycle" and ds.sizes["particle"] == 180


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


def test_run_spec_helper_runs_a_scene(tmp_path):
    assert run_spec(tmp_path, TINY, tmp_path / "x.nc") == 0


def test_a_silent_run_still_logs_every_heartbeat_with_its_id_and_names_itself_when_it_ends(tmp_path, monkeypatch):
    """Progress in every job's log at least every 30 s: a 'running' line when nothing else came (compiling, a
    method's own pace); the finish line and the written line carry the run id."""
    import time

    from isaflow import run

    monkeypatch.setattr(run, "HEARTBEAT", 0.3)
    tp, sp = write_spec(tmp_path, TINY)
    p = run.prepare("isa", tp, "capped", "r", tmp_path / "run.nc", settings_path=sp, run_id="tiny_run")
    warm, solve = p.entry.warm_up, p.entry.solve

    class Slow:  # the entry module, with a silent warm-up of 2.5 s (numba releases the GIL; sleep does too)
        REFERENCES = p.entry.REFERENCES

        def warm_up(self, threads):
            time.sleep(2.5)
            warm(threads)

        def solve(self, *a, **kw):
            return solve(*a, **kw)

    p.entry = Slow()
    lines = []
    result, _, _ = run.solve(p, log=lines.append)
    beats = [line for line in lines if line.startswith("tiny_run: running, ") and "warming up" in line]
    assert len(beats) >= 2, lines  # the heartbeat looks once a second
    assert all(line.startswith("tiny_run: ") for line in lines)
    lines.clear()
    assert run.run("isa", tp, "capped", "r", tmp_path / "r2.nc", settings_path=sp, run_id="tiny_run",
                   log=lines.append) == 0
    assert any(line.startswith("tiny_run: finished: converged") for line in lines), lines
    assert lines[-1] == f"tiny_run: wrote {tmp_path / 'r2.nc'}"
