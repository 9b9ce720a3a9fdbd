"""Hostile input: every bad tank, settings file, override, start file and output path is refused
before any work with exit code 2, one line naming the file and the field, and nothing written.

Cases run in process through ``cli.main`` (argument parsing, checks, exit code) with stderr captured;
two run through a real subprocess to show that no traceback reaches the user.  The corpus of small
malformed files is tests/data/hostile/ (each file is tried as a tank and as a settings file); large
files and field-level cases are built here from a valid scene (conftest.TINY written as a tank and an
ISA settings file).  Accepted on purpose (documented in docs/hostile_input.md): hostile but
well-formed physics (coincident particles, particles on walls, R_u = 1e308) - those are outcomes, not
bad input.
"""

import copy
import os
import re
import stat
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import yaml
from conftest import ROOT, TINY, scene_of, settings_spec, vessel, write_spec

from isaflow import cli, methods, runfile

CORPUS = Path(__file__).parent / "data" / "hostile"


def files(tmp_path, spec=TINY):
    """(tank, settings) files of a scene mapping."""
    return write_spec(tmp_path, spec)


def argv_of(tank, settings, out, *args, variant="capped"):
    return ["run", "--method", "isa", "--tank", str(tank), "--settings", str(settings), "--variant", variant,
            "--resolution", "r", "-o", str(out), *args]


def refused(tmp_path, capsys, argv, out, field=None):
    """Run the CLI; assert exit 2, one 'error:' line naming the field, and no output."""
    existed = os.path.lexists(out)
    t0 = time.perf_counter()
    code = cli.main(argv)
    elapsed = time.perf_counter() - t0
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert code == 2, err
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    assert "Traceback" not in err
    if field is not None:
        assert field in lines[0], (field, lines[0])
    assert existed or not os.path.lexists(out), f"{out} was written"
    parent = Path(out).parent
    if parent.is_dir():
        assert not [p for p in parent.glob(".*partial*")], "a temporary file was left"
    return lines[0], elapsed


def refused_spec(tmp_path, capsys, spec, *args, out=None, field=None):
    """Refusal of a scene mapping written as tank + settings files."""
    tank, settings = files(tmp_path, spec)
    out = tmp_path / "out" / "run.nc" if out is None else out
    return refused(tmp_path, capsys, argv_of(tank, settings, out, *args, variant=spec["solver"]["variant"]), out, field)


def mutate(path_value_pairs):
    spec = copy.deepcopy(TINY)
    for dotted, value in path_value_pairs:
        node = spec
        keys = dotted.split(".")
        for k in keys[:-1]:
            node = node[int(k)] if isinstance(node, list) else node[k]
        if value is DELETE:
            del node[keys[-1]]
        elif isinstance(node, list):
            node[int(keys[-1])] = value
        else:
            node[keys[-1]] = value
    return spec


DELETE = object()

# ---- files that are not a small plain YAML mapping --------------------------------------------
FILE_CASES = {
    "empty.yaml": "(top level)", "comment_only.yaml": "(top level)", "latin1.yaml": "not UTF-8",
    "binary.yaml": "not UTF-8", "utf16_bom.yaml": "not UTF-8", "top_list.yaml": "(top level)",
    "top_scalar.yaml": "(top level)", "two_documents.yaml": "more than one YAML document",
    "alias_bomb.yaml": "anchors and aliases", "anchor_alias.yaml": "anchors and aliases",
    "python_tag.yaml": "explicit YAML tags", "str_tag.yaml": "explicit YAML tags",
    "custom_tag.yaml": "explicit YAML tags", "duplicate_top.yaml": "duplicate key 'name'",
    "duplicate_nested.yaml": "duplicate key 'du'", "complex_key.yaml": "mapping key",
    "int_key.yaml": "mapping key", "merge_key.yaml": "line 3", "unclosed_bracket.yaml": "line",
    "tab_indent.yaml": "line 3", "deep_block.yaml": "nesting deeper than 32", "nul_char.yaml": "line 1",
}


@pytest.mark.parametrize("role", ["tank", "settings"])
@pytest.mark.parametrize("name", sorted(FILE_CASES))
def test_malformed_files_are_refused(tmp_path, capsys, name, role):
    tank, settings = files(tmp_path)
    bad = CORPUS / name
    out = tmp_path / "out" / "run.nc"
    argv = argv_of(bad if role == "tank" else tank, bad if role == "settings" else settings, out)
    line, elapsed = refused(tmp_path, capsys, argv, out, field=FILE_CASES[name])
    assert name in line
    # the alias bomb expands to 9^9 strings; it is refused at its first anchor (it took > 30 s before)
    assert elapsed < 5.0


@pytest.mark.parametrize("case", ["missing", "directory", "fifo", "deep_flow", "too_large", "unreadable"])
def test_unusable_tank_files_are_refused(tmp_path, capsys, case):
    path = tmp_path / "t" / "tank.yaml"
    path.parent.mkdir()
    expect = {"missing": "no such file", "directory": "a directory", "fifo": "not a regular file",
              "deep_flow": "nesting deeper than 32", "too_large": "larger than", "unreadable": "tank"}[case]
    if case == "directory":
        path.mkdir()
    elif case == "fifo":
        os.mkfifo(path)
    elif case == "deep_flow":  # 50,000-deep nesting raised RecursionError before
        path.write_text("name: " + "[" * 50_000 + "]" * 50_000 + "\n")
    elif case == "too_large":
        path.write_text("description: '" + "x" * 1_100_000 + "'\n")
    elif case == "unreadable":
        path = Path("/proc/self/mem")  # a "regular" file that cannot be read
        expect = "cannot read tank"
    _, settings = files(tmp_path)
    out = tmp_path / "out" / "run.nc"
    line, elapsed = refused(tmp_path, capsys, argv_of(path, settings, out), out, field=expect)
    assert str(path) in line and elapsed < 5.0


# ---- fields: types, integers, non-finite and out-of-range numbers, names ----------------------
# (changes of the scene mapping, text the refusal names, the file it names: tank or settings)
NAN, INF = float("nan"), float("inf")
FIELD_CASES = {
    "name_trailing_newline": ([("name", "tiny\n")], "'name'", "tank"),
    "name_uppercase": ([("name", "Tiny")], "'name'", "tank"),
    "unknown_top_key": ([("forces.extra", {"value": 1})], "'forces'", "settings"),
    "unknown_solver_key": ([("solver.stepsize", 1)], "'solver'", "settings"),
    "rows_integral_float": ([("particles.lattice.rows", 3.0)], "'particles.lattice.rows.value'", "settings"),
    "every_integral_float": ([("solver.history", {"every": 5.0})], "'solver.history.value.every'", "settings"),
    "max_steps_float": ([("solver.max_steps", 1e20)], "'solver.max_steps.value'", "settings"),
    "max_steps_beyond_int64": ([("solver.max_steps", 10**20)], "'solver.max_steps.value'", "settings"),
    "max_steps_beyond_limit": ([("solver.max_steps", 10**16)], "'solver.max_steps.value'", "settings"),
    "weight_nan": ([("particles.weight", NAN)], "'particles.weight.value'", "settings"),
    "weight_inf": ([("particles.weight", INF)], "'particles.weight.value'", "settings"),
    "weight_minus_inf": ([("particles.weight", -INF)], "'particles.weight.value'", "settings"),
    "weight_zero": ([("particles.weight", 0.0)], "'particles.weight.value'", "settings"),
    "weight_huge_int": ([("particles.weight", 10**400)], "'particles.weight.value'", "settings"),
    "weight_bool": ([("particles.weight", True)], "'particles.weight.value'", "settings"),
    "weight_string": ([("particles.weight", "50")], "'particles.weight.value'", "settings"),
    "wall_l_u_nan": ([("forces.wall.l_u", NAN)], "'forces.wall.l_u.value'", "settings"),
    "wall_r_u_inf": ([("forces.wall.r_u", INF)], "'forces.wall.r_u.value'", "settings"),
    "pair_l_u_nan": ([("forces.pair.l_u", NAN)], "'forces.pair.l_u.value'", "settings"),
    "pair_r_u_negative": ([("forces.pair.r_u", -1.0)], "'forces.pair.r_u.value'", "settings"),
    "law_not_linear": ([("forces.pair.law", "cubic")], "'forces.pair.law.value'", "settings"),
    "du_nan": ([("solver.du", NAN)], "'solver.du.value'", "settings"),
    "du_inf": ([("solver.du", INF)], "'solver.du.value'", "settings"),
    "f_tol_nan": ([("solver.f_tol", NAN)], "'solver.f_tol.value'", "settings"),
    "f_tol_inf": ([("solver.f_tol", INF)], "'solver.f_tol.value'", "settings"),
    "dt_max_nan": ([("solver.dt_max", NAN)], "'solver.dt_max.value'", "settings"),
    "f_ref_inf": ([("solver.f_ref", INF)], "'solver.f_ref.value'", "settings"),
    "skin_nan": ([("solver.skin", NAN)], "'solver.skin.value'", "settings"),
    "chunk_too_small": ([("solver.chunk", 50)], "'solver.chunk.value'", "settings"),
    "lattice_a_nan": ([("particles.lattice.a", NAN)], "'particles.lattice.a.value'", "settings"),
    "center_x_inf": ([("particles.lattice.center_x", INF)], "'particles.lattice.center_x.value'", "settings"),
    "row_lengths_zero": ([("particles.lattice.row_lengths", [0, 2])], "'particles.lattice.row_lengths.value.0'",
                         "settings"),
    "points_nan": ([("particles", {"weight": 50.0, "points": [[1.0, NAN]]})], "'particles.points.value.0.1'",
                   "settings"),
    "wall_coordinate_nan": ([("walls.0.from", [0.0, NAN])], "'walls.0.from.1'", "tank"),
    "wall_coordinate_huge": ([("walls.0.from", [0.0, 1e300])], "'walls'", "tank"),
    "wall_zero_length": ([("walls.1.to", [0, 0])], "'walls' (floor)", "tank"),
    "wall_names_duplicate": ([("walls.1.name", "left")], "'walls'", "tank"),
    "wall_name_control_char": ([("walls.1.name", "flo\x00or")], "'walls.1.name'", "tank"),
    "description_lone_surrogate": ([("description", "a\ud800b")], "'description'", "tank"),
    "vessel_x_nan": ([("vessels", [{"name": "v", "x": [0.0, NAN]}])], "'vessels.0.x.1'", "tank"),
    "vessel_x_reversed": ([("vessels", [{"name": "v", "x": [20.0, 0.0]}])], "'vessels' (v)", "tank"),
    "outside_the_walls": ([("particles.lattice.center_x", 50.0)], "outside the walls' bounding box", "settings"),
    "stiffness_overflows": ([("forces.wall.l_u", 1e-300), ("forces.wall.r_u", 1e301)], "'forces.wall.r_u'", "settings"),
    "stiffness_underflows": ([("forces.pair.l_u", 1e300), ("forces.pair.r_u", 1e-300)], "'forces.pair.r_u'", "settings"),
    "stiffness_underflows_by_its_range": ([("forces.pair.l_u", 1e300), ("forces.pair.r_u", 1e-30)],
                                          "'forces.pair.l_u'", "settings"),
    "du_below_round_off": ([("solver.du", 1e-320)], "'solver.du'", "settings"),
}


def write_case(tmp_path, spec):
    """(tank, settings) of a mutated scene: settings keys outside the dialect go in raw (unknown-key cases)."""
    raw = {k: spec["solver"].pop(k) for k in list(spec["solver"]) if k not in
           ("variant", "du", "f_tol", "max_steps", "f_ref", "dt_max", "skin", "chunk", "stop_on_cycle", "history")}
    extra_forces = spec["forces"].pop("extra", None)
    tank_spec = {"name": spec.get("name", "tiny"), "walls": spec["walls"], "liquid": {"weight": 200.0, "depth": 10.0}}
    for k in ("vessels", "description"):
        if k in spec:
            tank_spec[k] = spec[k]
    sp = settings_spec(spec)
    for k, v in raw.items():
        sp["solver"][k] = {"value": v, "source": "inferred: test"}
    if extra_forces is not None:
        sp["forces"]["extra"] = extra_forces
    tank, settings = tmp_path / "tank.yaml", tmp_path / "settings.yaml"
    # PyYAML writes NaN/inf as .nan/.inf and huge ints as digits, as a user would type them
    tank.write_text(yaml.dump(tank_spec, allow_unicode=False))
    settings.write_text(yaml.dump(sp, allow_unicode=False))
    return tank, settings


@pytest.mark.parametrize("case", sorted(FIELD_CASES))
def test_bad_fields_are_refused_naming_the_file_and_field(tmp_path, capsys, case):
    changes, field, role = FIELD_CASES[case]
    tank, settings = write_case(tmp_path, mutate(changes))
    out = tmp_path / "out" / "run.nc"
    line, _ = refused(tmp_path, capsys, argv_of(tank, settings, out), out, field=field)
    assert f"{role}.yaml" in line


def test_unknown_variant_resolution_and_outcome_are_refused(tmp_path, capsys):
    tank, settings = files(tmp_path)
    out = tmp_path / "out" / "run.nc"
    refused(tmp_path, capsys, argv_of(tank, settings, out, variant="bogus"), out, field="no variant 'bogus'")
    argv = argv_of(tank, settings, out)
    argv[argv.index("--resolution") + 1] = "bogus"
    refused(tmp_path, capsys, argv, out, field="no resolution 'bogus'")
    refused(tmp_path, capsys, argv_of(tank, settings, out, "--accept", "converged,done"), out,
            field="unknown outcome 'done'")


# ---- resources: refused with the estimate, before anything is allocated ------------------------
RESOURCE_CASES = {
    "1e10_particles": ([("particles.lattice.rows", 100_000), ("particles.lattice.row_lengths", [100_000]),
                        ("particles.lattice.a", 0.5), ("particles.lattice.center_x", 2.75e4),
                        ("walls", vessel(5.5e4, 3e4))], "'particles.lattice'"),
    "chunk_1e12": ([("solver.chunk", 10**12), ("solver.max_steps", 10**12)], "'solver.chunk'"),
    "records_every_step": ([("solver.max_steps", 10**15), ("solver.history", {"every": 1})],
                           "'solver.history.every'"),
    "snapshots_of_1e6_particles": ([("particles.lattice.rows", 1000), ("particles.lattice.row_lengths", [1000]),
                                    ("walls", vessel(11000, 6000)),
                                    ("particles.lattice.center_x", 5500.0), ("solver.max_steps", 10**15),
                                    ("solver.snapshot_megabytes", 1e9)], "'solver.snapshot_megabytes'"),
    "grid_of_1e15_cells": ([("forces.pair.l_u", 1e-6), ("forces.pair.r_u", 1e-3), ("solver.du", 1e-7)],
                           "'forces.pair.l_u'"),
}


@pytest.mark.parametrize("case", sorted(RESOURCE_CASES))
def test_runs_that_cannot_fit_in_memory_are_refused_with_the_estimate(tmp_path, capsys, case, monkeypatch):
    monkeypatch.setenv("ISAFLOW_MEMORY_LIMIT_MB", "4096")  # a 4 GB machine: the refusals hold anywhere
    changes, field = RESOURCE_CASES[case]
    tank, settings = write_case(tmp_path, mutate(changes))
    out = tmp_path / "out" / "run.nc"
    line, elapsed = refused(tmp_path, capsys, argv_of(tank, settings, out), out, field=field)
    assert ("the run needs about" in line and "GB available" in line) or "cells" in line
    assert elapsed < 5.0  # nothing was allocated (a 10^10-particle lattice would take minutes and 160 GB)


# ---- --set overrides ---------------------------------------------------------------------------
SET_CASES = {
    "no_equals": ("solver.du", "key=value"),
    "malformed_yaml": ("solver.du=[1,", "not valid YAML"),
    "python_tag": ("solver.du=!!python/object/apply:os.system [ls]", "explicit YAML tags"),
    "alias": ("solver.history=&a [*a]", "anchors and aliases"),
    "into_a_scalar": ("solver.du.x=1", "no such setting"),
    "into_a_list": ("walls.0.from=[1, 2]", "no such setting"),
    "missing_field": ("solver.bogus.x=1", "no such setting"),
    "empty_key": ("=1", "no such setting"),
    "empty_segment": ("solver..du=1", "no such setting"),
    "deep_value": ("solver.du=" + "[" * 100 + "]" * 100, "nesting deeper than 32"),
    "control_char": ("solver.du=0.\x0701", "control characters"),
    "nan_value": ("solver.du=.nan", "'solver.du"),
    "inf_value": ("solver.f_tol=.inf", "'solver.f_tol"),
    "replace_a_block_with_a_scalar": ("solver=5", "no such setting"),
    "two_documents": ("solver.du=1\n---\n2", "more than one YAML document"),
    # a comment after the value was dropped silently (the run used 0.02 and recorded no reason)
    "trailing_comment": ("solver.du=0.02 # half the step", "a comment ('# half the step') is not part of a value"),
    "quote_and_comment": ("forces.pair.law='linear' # kept", "a comment ('# kept')"),
    "only_a_comment": ("solver.f_ref=# the default", "a comment"),
    # YAML 1.1 reads these as other values than YAML 1.2 (and the user): 010 = 8, 1:30 = 90, yes = true
    "octal_looking": ("solver.max_steps=010", "the octal number 8"),
    "base_60": ("solver.max_steps=1:30", "base-60"),
    "yes_for_true": ("solver.stop_on_cycle=yes", "a boolean in YAML 1.1"),
}


@pytest.mark.parametrize("case", sorted(SET_CASES))
def test_bad_overrides_are_refused(tmp_path, capsys, case):
    item, expect = SET_CASES[case]
    line, _ = refused_spec(tmp_path, capsys, TINY, "--set", item, field=expect)
    assert "settings.yaml" in line


# ---- start files (--start) --------------------------------------------------------------------
@pytest.fixture(scope="module")
def tiny_run(tmp_path_factory):
    """A valid run file of TINY stopped at step 300 (so a continuation has steps left)."""
    tmp = tmp_path_factory.mktemp("start")
    tank, settings = files(tmp)
    out = tmp / "tiny.nc"
    assert cli.main(argv_of(tank, settings, out, "--set", "solver.max_steps=300", "--accept",
                            "converged,step_limit")) == 0
    return out


def start_case(tmp_path, tiny_run, case):
    """(path of the start file, extra overrides, expected text) of one bad start file."""
    p = tmp_path / "start.nc"
    extra = []
    ds = runfile.read(tiny_run)
    if case == "missing":
        return tmp_path / "nope.nc", extra, "no such file"
    if case == "directory":
        p.mkdir()
        return p, extra, "a directory"
    if case == "fifo":
        os.mkfifo(p)
        return p, extra, "not a regular file"
    if case == "text_file":
        p.write_text("pos: [1, 2]\n")
        return p, extra, "not a netCDF file"
    if case == "truncated":
        p.write_bytes(Path(tiny_run).read_bytes()[:600])
        return p, extra, "cannot be opened as netCDF"
    if case == "partial_name":
        p = tmp_path / f".tiny.nc{runfile.PARTIAL}12345"
        p.write_bytes(Path(tiny_run).read_bytes())
        return p, extra, "temporary file of an unfinished write"
    if case == "incomplete":
        ds.attrs["isaflow_complete"] = "no"
    elif case == "no_pos":
        ds = ds.drop_vars("pos")
    elif case == "pos_1d":
        ds["pos"] = ("particle", ds["pos"].values[:, 0])
    elif case == "other_method":
        ds.attrs["method"] = "sph"
    elif case == "nan_pos":
        ds["pos"].values[1, 0] = np.nan
    elif case == "escaped":
        ds.attrs["status"] = "escaped"
    elif case == "outside_walls":
        ds["pos"].values[0] = [30.0, 5.0]
    elif case == "other_weight":
        ds["weight"].values[:] = 10.0
    elif case == "past_max_steps":
        extra = ["solver.max_steps=300"]
    elif case == "nan_state":
        ds["state_vel"].values[0, 0] = np.nan
    elif case == "steps_float":
        ds["steps"] = ((), 300.5)
    ds.to_netcdf(p)
    expect = {"incomplete": "incomplete write", "no_pos": "no variable 'pos'", "pos_1d": "no variable 'pos'",
              "other_method": "method 'sph'", "nan_pos": "must be finite", "escaped": "no valid state",
              "outside_walls": "outside the walls", "other_weight": "'particles.weight'",
              "past_max_steps": "'solver.max_steps'", "nan_state": "state_vel",
              "steps_float": "no valid step count"}[case]
    return p, extra, expect


START_CASES = ["missing", "directory", "fifo", "text_file", "truncated", "partial_name", "incomplete", "no_pos",
               "pos_1d", "other_method", "nan_pos", "escaped", "outside_walls", "other_weight", "past_max_steps",
               "nan_state", "steps_float"]


@pytest.mark.parametrize("case", START_CASES)
def test_bad_start_files_are_refused(tmp_path, capsys, tiny_run, case):
    start, extra, expect = start_case(tmp_path, tiny_run, case)
    sets = [a for e in extra for a in ("--set", e)]
    line, _ = refused_spec(tmp_path, capsys, TINY, "--start", str(start), *sets, field=expect)
    assert "start" in line


@pytest.mark.parametrize("case, variable", [("nan_pos", "pos"), ("outside_walls", "pos"), ("nan_state", "state_vel"),
                                            ("steps_float", "steps")])
def test_a_bad_variable_of_a_start_file_names_the_start_file_and_the_variable(tmp_path, capsys, tiny_run, case,
                                                                               variable):
    """NaN positions or positions outside the walls are the start file's, not the settings file's: the line was
    '<settings>: field 'start': positions must be finite' (no settings file has a field 'start')."""
    start, extra, expect = start_case(tmp_path, tiny_run, case)
    line, _ = refused_spec(tmp_path, capsys, TINY, "--start", str(start), field=expect)
    assert line.startswith(f"error: {start}: field '{variable}': "), line
    assert "settings.yaml" not in line


def test_a_good_start_file_continues(tmp_path, capsys, tiny_run):
    tank, settings = files(tmp_path)
    out = tmp_path / "cont.nc"
    assert cli.main(argv_of(tank, settings, out, "--start", str(tiny_run))) == 0
    ds = runfile.read(out)
    assert int(ds["start_step"]) == 300 and ds.attrs["start_sha256"] == runfile.sha256(tiny_run)


# ---- output paths: checked before the solve ---------------------------------------------------
def out_case(tmp_path, case):
    if case == "directory":
        (tmp_path / "o").mkdir()
        return tmp_path / "o", "a directory"
    if case == "device":
        return Path("/dev/null"), "a device"
    if case == "full_device":
        return Path("/dev/full"), "a device"
    if case == "fifo":
        os.mkfifo(tmp_path / "f.nc")
        return tmp_path / "f.nc", "a device, FIFO or socket"
    if case == "symlink":
        (tmp_path / "real.nc").write_text("x")
        (tmp_path / "link.nc").symlink_to(tmp_path / "real.nc")
        return tmp_path / "link.nc", "a symbolic link"
    if case == "parent_is_a_file":
        (tmp_path / "file").write_text("x")
        return tmp_path / "file" / "sub" / "run.nc", "is not a directory"
    if case == "unwritable_directory":
        if os.geteuid() == 0:  # root writes anywhere permissions allow nothing; /proc refuses new files
            return Path("/proc/isaflow_test_run.nc"), "cannot write the output"
        d = tmp_path / "ro"
        d.mkdir()
        d.chmod(stat.S_IRUSR | stat.S_IXUSR)
        return d / "run.nc", "cannot write the output"
    if case == "empty_name":
        return Path("."), "names no file"


OUT_CASES = ["directory", "device", "full_device", "fifo", "symlink", "parent_is_a_file", "unwritable_directory",
             "empty_name"]


@pytest.mark.parametrize("case", OUT_CASES)
def test_unusable_output_paths_are_refused_before_the_solve(tmp_path, capsys, case, monkeypatch):
    out, expect = out_case(tmp_path, case)
    before = os.lstat(out) if os.path.lexists(out) else None
    solved = []
    monkeypatch.setattr("isaflow.methods.isa.solver.solve", lambda *a, **k: solved.append(1))
    line, _ = refused_spec(tmp_path, capsys, TINY, out=out, field=expect)
    assert not solved and str(out) in line
    if before is not None:  # the device, FIFO, link or directory is untouched
        after = os.lstat(out)
        assert (after.st_mode, after.st_ino, after.st_rdev) == (before.st_mode, before.st_ino, before.st_rdev)


def test_output_onto_an_input_is_refused(tmp_path, capsys, tiny_run):
    tank, settings = files(tmp_path)
    refused(tmp_path, capsys, argv_of(tank, settings, tank), tank, field="would overwrite the tank")
    refused(tmp_path, capsys, argv_of(tank, settings, settings), settings, field="would overwrite the settings")
    start = tmp_path / "start.nc"
    start.write_bytes(Path(tiny_run).read_bytes())
    refused(tmp_path, capsys, argv_of(tank, settings, start, "--start", str(start)), start,
            field="would overwrite the start file")
    assert runfile.read(start)["steps"] == 300  # untouched


def test_settings_file_must_exist(tmp_path, capsys):
    tank, _ = files(tmp_path)
    out = tmp_path / "out" / "r.nc"
    line, _ = refused(tmp_path, capsys, argv_of(tank, tmp_path / "none.yaml", out), out, field="no such file")
    assert line.startswith(f"error: argument --settings: '{tmp_path / 'none.yaml'}': ")  # the option was not named
    line, _ = refused(tmp_path, capsys, argv_of(tmp_path / "none.yaml", _, out), out, field="no such file")
    assert line.startswith("error: argument --tank: ")


# ---- the real command line: no traceback, exit 2 ---------------------------------------------
@pytest.mark.parametrize("args", [["--tank", str(CORPUS / "binary.yaml")],
                                  ["--tank", str(CORPUS / "alias_bomb.yaml"), "--set", "solver.du=.nan"]])
def test_command_line_refuses_without_a_traceback(tmp_path, args):
    out = tmp_path / "run.nc"
    proc = subprocess.run([sys.executable, "-m", "isaflow.cli", "run", "--method", "isa", "--variant", "paper",
                           "--resolution", "coarse", "-o", str(out), *args], capture_output=True, text=True,
                          cwd=ROOT, timeout=120)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1 and not out.exists()


def test_argument_errors_exit_2(capsys):
    for argv in ([], ["run"], ["run", "x.yaml"], ["bogus"], ["run", "--method", "isa"]):
        with pytest.raises(SystemExit) as exc:
            cli.main(argv)
        assert exc.value.code == 2
    assert "Traceback" not in capsys.readouterr().err
    assert cli.main(["run", "--method", "isa", "-o", "x.nc"]) == 2
    assert "--tank, --variant, --resolution required" in capsys.readouterr().err


def test_undecodable_command_line_arguments_are_refused(tmp_path, capsys):
    bad = os.fsdecode(b"tank\xff.yaml")  # how Python hands over non-UTF-8 argv bytes
    assert cli.main(["run", "--method", "isa", "--tank", bad, "--variant", "paper", "--resolution", "coarse", "-o",
                     str(tmp_path / "r.nc")]) == 2
    assert "not valid Unicode" in capsys.readouterr().err


def test_accepted_hostile_physics_is_an_outcome_not_an_input_error(tmp_path, capsys):
    """R_u = 1e308 N overflows the force (the study's float_limit case): a valid input whose run ends as
    'nonfinite' - reported against the accepted outcomes (exit 1), never written as a NaN file."""
    spec = mutate([("forces.wall.r_u", 1e308), ("particles", {"weight": 50.0, "points": [[10.0, 0.1]]})])
    tank, settings = files(tmp_path, spec)
    out = tmp_path / "run.nc"
    assert cli.main(argv_of(tank, settings, out)) == 1
    assert "outcome 'nonfinite' is not accepted" in capsys.readouterr().err and not out.exists()


# ---- the solver never returns a non-finite state silently (issue 9, item 2) ------------------
def test_a_nan_position_ends_the_compiled_loop_as_nonfinite_naming_the_particle():
    """With a NaN position every distance test is false, so the force laws take their 'coincident' /
    'on the wall' branches and return finite forces: the loop must check positions, not only forces."""
    from isaflow.methods.isa import relax as R
    from conftest import box_walls

    pos = np.array([[30.0, 5.0], [40.0, 5.0], [np.nan, 5.0], [50.0, 5.0]])
    walls = box_walls()
    force, hist = np.zeros_like(pos), np.zeros(10)
    done, status, which = R.relax(pos, np.zeros_like(pos), np.full(4, 50.0), walls, np.array([0, 0, 100, 100.0]),
                                  5.0, 1e4, 7.07, 3535.5, R.PAPER, 0.01, 50.0, 0.1, 0.1, 10, 2.0, force, hist)
    assert (done, status, which) == (0, R.NONFINITE, 2)


def test_a_run_started_at_its_step_limit_computes_its_forces_once(tmp_path):
    """Called directly (the command line refuses such a start file), the solver evaluates the forces
    of the start state instead of returning zeros, and takes no step."""
    from isaflow.methods.isa import scene as scenes
    from isaflow.methods.isa import solver

    sc = scene_of(TINY)
    pos0, weight, _, _ = scenes.initial_state(sc)
    res = solver.solve(sc, pos0, weight, start_step=TINY["solver"]["max_steps"])
    assert res.steps == TINY["solver"]["max_steps"] and res.force_evals == 1
    np.testing.assert_array_equal(res.pos, pos0)
    # the lattice start is out of balance: max|F| is the weight-scale residual, not 0
    assert res.status == "step_limit" and res.residual == np.abs(res.fields["force"][1]).max() > 1.0


# Method settings files (config/methods/*.yaml, the registry's) go through the same reader and checks as scenes.
SETTINGS_MUTATIONS = {
    "alias": lambda t: "base: &a {value: 1}\n" + t,
    # the first top-level key again at the end
    "duplicate_key": lambda t: t + "\n" + re.search(r"^([a-z_0-9]+):", t, re.M).group(1) + ": {}\n",
    # the first numeric value becomes NaN
    "nan_value": lambda t: re.sub(r"value: -?[0-9][0-9.eE+-]*", "value: .nan", t, count=1),
    "python_tag": lambda t: "x: !!python/object/apply:os.system ['true']\n" + t,
}


@pytest.mark.parametrize("mutation", sorted(SETTINGS_MUTATIONS))
@pytest.mark.parametrize("method", sorted(methods.PACKAGES))
def test_bad_method_settings_are_refused_naming_the_file(tmp_path, method, mutation):
    """Every method's settings file by the one reader (isaflow.settings.read) against its values schema."""
    from isaflow import settings

    m = methods.get(method)
    bad = tmp_path / f"{method}_{mutation}.yaml"
    bad.write_text(SETTINGS_MUTATIONS[mutation]((ROOT / m.settings).read_text()))
    with pytest.raises(ValueError, match=f"^{bad}: ") as err:
        settings.read(bad, m.values_schema())
    assert "\n" not in str(err.value)


def test_libyaml_and_the_pure_python_reader_read_every_tracked_yaml_file_alike():
    """The fast reader (libyaml) reads what the reference reader reads: every YAML file of config/, workflow/ and
    the toy method's (tests/data/toy) gives the same value, key order included, from both (1 s).  The hostile files
    of tests/data/hostile are not read raw here (an alias bomb or deep nesting costs the raw readers minutes): the
    tests above refuse each through inputs.read_yaml, whose first reader is libyaml."""
    from isaflow import inputs

    if inputs._FastLoader is None:
        pytest.skip("PyYAML without libyaml: only the reference reader runs")
    import yaml

    files = sorted(p for d in ("config", "workflow", "tests/data/toy") for p in (ROOT / d).rglob("*.yaml"))
    assert len(files) > 30
    for path in files:
        text = path.read_text()
        ref, fast = yaml.load(text, Loader=inputs._StrictLoader), yaml.load(text, Loader=inputs._FastLoader)
        assert ref == fast and repr(ref) == repr(fast), path
