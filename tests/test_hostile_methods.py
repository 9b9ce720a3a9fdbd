"""Hostile inputs of every method, refused before any work: tanks tried with every tank method, each
method's settings (SPH, MPS, ISA through ``isaflow run``; solid and 1D SPH through their loaders), the
command line, and the workflow's configuration while it is parsed.

The promise (as tests/test_hostile_input.py for ISA scenes): exit status 2, one line naming the file and
the setting, no traceback, nothing written, and fast (no allocation, no loop: a refusal takes < 5 s).
Declared stability cases may go outside the literature ranges (isaflow.plausible) but never past the
cost budget (isaflow.budget).
"""

import copy
import re
import shutil
import subprocess
import sys
import time

import pytest
import yaml
from conftest import ROOT, vessel

from isaflow import budget, cli, preflight, settings, tank as tanks
from isaflow.inputs import InputError

SINGLE = ROOT / "config" / "tanks" / "single.yaml"
FLOW = ROOT / "config" / "tanks" / "flow_step50.yaml"
DEFAULT = {"isa": ("coarse", "paper"), "sph": ("n180", "wcsph"), "mps": ("dx5.56", "standard")}


def cli_refuses(capsys, tmp_path, argv, field):
    """Run the CLI in process: exit 2, one 'error:' line naming field, no output, < 5 s."""
    out = tmp_path / "out" / "run.nc"
    t0 = time.perf_counter()
    code = cli.main(["run", *argv, "-o", str(out)])
    elapsed = time.perf_counter() - t0
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2, err
    assert len(err) == 1 and err[0].startswith("error: "), err
    assert field in err[0], (field, err[0])
    assert not out.exists() and not list(tmp_path.glob("out/.*"))
    assert elapsed < 5.0
    return err[0]


def method_argv(method, *sets, tank=SINGLE, extra=()):
    resolution, variant = DEFAULT[method]
    return ["--method", method, "--tank", str(tank), "--variant", variant, "--resolution", resolution,
            *[a for s in sets for a in ("--set", s)], *extra]


# ---- tanks: every tank method refuses the same bad tank ------------------------------------------------
def _tank(base=SINGLE, **change):
    spec = yaml.safe_load(base.read_text())
    for key, value in change.items():
        spec[key] = value
    return spec


W = vessel(100, 100)
TANK_CASES = {
    "depth_above_walls": (_tank(liquid={"weight": 9000.0, "depth": 150.0}), "'liquid.depth'"),
    "depth_zero": (_tank(liquid={"weight": 9000.0, "depth": 0.0}), "'liquid.depth"),
    "depth_huge": (_tank(liquid={"weight": 9000.0, "depth": 1e308}), "'liquid.depth'"),
    "weight_negative": (_tank(liquid={"weight": -1.0, "depth": 50.0}), "'liquid.weight"),
    "weight_nan": (_tank(liquid={"weight": float("nan"), "depth": 50.0}), "'liquid.weight"),
    "reversed_walls": (_tank(walls=[{"name": w["name"], "from": w["to"], "to": w["from"]} for w in reversed(W)]),
                       "'walls'"),
    "self_intersecting": (_tank(walls=[W[0], W[1], {"name": "right", "from": [100, 0], "to": [-20, 60]}]),
                          "'walls'"),
    # a floorless or sloping-floored vessel is a tank of one's own since issue 40 (tests/test_compare.py)
    "walls_not_joined": (_tank(walls=[W[0], {"name": "floor", "from": [5, 0], "to": [100, 0]}, W[2]]), "'walls'"),
    "vessel_outside": (_tank(vessels=[{"name": "v", "x": [200.0, 300.0]}]), "'vessels' (v)"),
    "vessels_overlap": (_tank(vessels=[{"name": "a", "x": [0.0, 60.0]}, {"name": "b", "x": [40.0, 100.0]}]),
                        "'vessels' (b)"),
    "coordinate_huge": (_tank(walls=[W[0], {"name": "floor", "from": [0, 0], "to": [1e300, 0]}, W[2]]), "'walls'"),
    "unknown_key": (_tank(colour="blue"), "(top level)"),
    "no_liquid": ({k: v for k, v in _tank().items() if k != "liquid"}, "'liquid'"),
    "one_wall": (_tank(walls=[W[1]]), "'walls'"),
    # the depth from the first vessel's own floor (y = 0), not from the second vessel's 50 cm lower
    "depth_above_own_vessel": (_tank(FLOW, liquid={"weight": 9000.0, "depth": 140.0}), "'liquid.depth'"),
    # the first vessel's right wall 60 cm high: a 72.5 cm liquid stands over it (the outline's walls are 100 cm)
    "depth_above_own_side_wall": (_tank(FLOW, walls=[{**w, "to": [100, 60]} if w["name"] == "right1" else w
                                                     for w in _tank(FLOW)["walls"]]), "'liquid.depth'"),
}


@pytest.mark.parametrize("method", sorted(DEFAULT))
@pytest.mark.parametrize("case", sorted(TANK_CASES))
def test_bad_tanks_are_refused_by_every_method(tmp_path, capsys, method, case):
    spec, field = TANK_CASES[case]
    path = tmp_path / "tank.yaml"
    path.write_text(yaml.safe_dump(spec, allow_unicode=True))
    line = cli_refuses(capsys, tmp_path, method_argv(method, tank=path), field)
    assert str(path) in line


# ---- each tank method's settings, as command-line overrides ---------------------------------------------
SETTINGS_CASES = {
    # SPH: plausibility (literature ranges, with the reason), impossible numbers, cost
    "sph_h_below_spacing": ("sph", ["settings.h_factor=0.5"], "'settings.h_factor'", "Monaghan"),
    "sph_cfl_50": ("sph", ["settings.cfl=50"], "'settings.cfl'", "CFL"),
    "sph_gamma_1e308": ("sph", ["settings.gamma=1e308"], "'settings.gamma'", "Tait"),
    "sph_alpha_5": ("sph", ["settings.alpha=5"], "'settings.alpha'", "viscosity"),
    "sph_mach_1": ("sph", ["settings.sound_speed_factor=1"], "'settings.sound_speed_factor'", "Mach"),
    "sph_delta_50": ("sph", ["settings.delta=50"], "'settings.delta'", "diffusion"),
    "sph_skin_100": ("sph", ["settings.skin=100"], "'settings.skin'", "fraction"),
    "sph_max_drop_huge": ("sph", ["settings.max_drop=1e308"], "'settings.max_drop'", "longer fall"),
    "sph_particles_1e12": ("sph", ["resolution.particles=1000000000000"], "'resolution.particles'", "memory"),
    "sph_spacing_1e-9": ("sph", ["resolution.particles=null", "resolution.spacing=1e-9"], "'resolution.spacing'",
                         "memory"),
    "sph_spacing_above_tank": ("sph", ["resolution.particles=null", "resolution.spacing=1000"],
                               "'resolution.spacing'", "at least 2"),
    "sph_cfl_1e-12": ("sph", ["settings.cfl=1e-12"], "'settings.cfl'", "CPU-hours"),
    "sph_time_1e9": ("sph", ["settings.t_max_single=1e9"], "'settings.t_max_single'", "t = 1e+09 s"),
    "sph_million_particles_50_s": ("sph", ["resolution.particles=1000000", "settings.t_max_single=50"],
                                   "'resolution.particles'", "CPU-hours"),
    "sph_chunk_time_tiny": ("sph", ["settings.chunk_time=1e-300"], "'settings.chunk_time'", "memory"),
    "sph_h_negative": ("sph", ["settings.h_factor=-1"], "'settings.h_factor'", "h_factor"),
    "sph_h_nan": ("sph", ["settings.h_factor=.nan"], "'settings.h_factor'", "h_factor"),
    "sph_kernel_unknown": ("sph", ["settings.kernel=gaussian"], "'settings.kernel'", "kernel"),
    "sph_unknown_key": ("sph", ["settings.colour=1"], "'settings.colour'", "no such setting"),
    # MPS
    "mps_courant_1e-12": ("mps", ["time.courant=1e-12"], "'time.courant'", "CPU-hours"),
    "mps_time_1e9": ("mps", ["time.single_time=1e9"], "'time.single_time'", "t = 1e+09 s"),
    "mps_courant_5": ("mps", ["time.courant=5"], "'time.courant'", "courant x l0"),
    "mps_radius_below_spacing": ("mps", ["model.re_density=0.5"], "'model.re_density", "re_density"),
    "mps_radius_too_small": ("mps", ["model.re_laplacian=1.2"], "'model.re_laplacian'", "Koshizuka"),
    "mps_radius_huge_stability_case": ("mps", ["model.re_gradient=1e6"], "'model.re_gradient'", "memory",
                                       ["--stability-case"]),
    "mps_radius_large": ("mps", ["model.re_gradient=5"], "'model.re_gradient'", "Koshizuka"),
    "mps_beta_half": ("mps", ["model.beta=0.5"], "'model.beta'", "free-surface"),
    "mps_viscosity_huge": ("mps", ["model.kinematic_viscosity=1e9"], "'model.kinematic_viscosity'", "viscous"),
    "mps_spacing_1e-4": ("mps", ["resolution.spacing=1e-4"], "'resolution.spacing'", "memory"),
    "mps_spacing_1e-9": ("mps", ["resolution.spacing=1e-9"], "'resolution.spacing'", "viscous"),
    "mps_spacing_above_tank": ("mps", ["resolution.spacing=1000"], "'resolution.spacing'", "at least 2"),
    "mps_sampling_tiny": ("mps", ["time.sample_interval=1e-300"], "'time.sample_interval'", "memory"),
    "mps_window_too_long": ("mps", ["time.average_window=100"], "'time.average_window'", "longer than the run"),
    "mps_solver_unknown": ("mps", ["pressure.solver=magic"], "'pressure.solver'", "solver"),
    # ISA (its scene checks are tests/test_hostile_input.py)
    "isa_steps_1e15": ("isa", ["solver.max_steps=1000000000000000", "solver.history={}"], "'solver.max_steps'",
                       "CPU-hours"),
    "isa_history_of_1e15_steps": ("isa", ["solver.max_steps=1000000000000000"], "'solver.history.every'", "memory"),
    "isa_du_beyond_pair_range": ("isa", ["solver.du=10"], "'solver.du'", "l_pu"),
    # a derived size refused only by its allocation (MPS: a 22-78 GB dense load map; SPH: its panel records)
    "mps_panels_of_4e-5_cm": ("mps", ["walls.panel_length=4e-5"], "'walls.panel_length'", "memory"),
    "mps_panels_of_1e-320_cm": ("mps", ["walls.panel_length=1e-320"], "'walls.panel_length'", "not a finite"),
    "sph_panels_of_5e-5_cm": ("sph", ["settings.panel_length=5e-5"], "'settings.panel_length'", "memory"),
    "sph_30000_snapshots_of_1e6_particles": ("sph", ["resolution.particles=1000000", "settings.t_max_single=0.5",
                                                     "settings.snapshot_megabytes=1300000.0"],
                                             "'settings.snapshot_megabytes'", "memory", ["--max-hours", "1000"]),
    # a spacing whose particle count overflows (an internal error, exit 70, before)
    "mps_spacing_1e-320": ("mps", ["resolution.spacing=1e-320"], "'resolution.spacing'", "particle count"),
    "sph_spacing_1e-320": ("sph", ["resolution.particles=null", "resolution.spacing=1e-320"], "'resolution.spacing'",
                           "particle count"),
    # a periodic block it cannot run (an internal error, exit 70, after the warm-up before)
    "sph_block_summation": ("sph", ["settings.domain=periodic_block", "settings.density=summation"],
                            "'settings.density'", "periodic block"),
    "sph_block_h_wide": ("sph", ["settings.domain=periodic_block", "settings.h_factor=5"], "'settings.h_factor'",
                         "minimum image", ["--stability-case"]),
    # points and probes far outside the tank's walls (ran, and wrote a run with a probe that never saw liquid)
    "isa_points_far_outside": ("isa", ["particles.points=[[1e6, 1e6]]"], "'particles.points'", "bounding box"),
    "isa_lattice_far_outside": ("isa", ["particles.lattice.center_x=1e6"], "'particles.lattice'", "bounding box"),
    "mps_probe_far_outside": ("mps", ["probes.single=[[50.0, 10.0], [1e6, 1e6]]"], "'probes.single'", "bounding box"),
    "mps_on_wall_point_far_outside": ("mps", ["start.on_wall_point=[1e6, 1e6]"], "'start.on_wall_point'",
                                      "bounding box"),
}


@pytest.mark.parametrize("case", sorted(SETTINGS_CASES))
def test_bad_method_settings_are_refused_with_their_reason(tmp_path, capsys, case):
    method, sets, field, reason, *extra = SETTINGS_CASES[case]
    line = cli_refuses(capsys, tmp_path, method_argv(method, *sets, extra=extra[0] if extra else ()),
                       field.rstrip("'"))
    assert reason in line, line
    assert f"config/methods/{method}.yaml" in line


# ---- a derived number names the input it follows: the tank's field when the tank's liquid or walls are its cause
BIG = vessel(7e5, 7e5)
TALL = vessel(100, 2e6)
BLAME_CASES = {
    # a 1e-9 cm liquid was reported as the method's resolution.particles / resolution.spacing
    "depth_1e-9_sph": ("sph", _tank(liquid={"weight": 9000.0, "depth": 1e-9}), "'liquid.depth'"),
    "depth_1e-9_mps": ("mps", _tank(liquid={"weight": 9000.0, "depth": 1e-9}), "'liquid.depth'"),
    # a 1e6 cm deep liquid 100 cm wide: 2.4e7 particles at dx = 2.5 cm (was blamed on resolution.spacing)
    "depth_1e6_sph": ("sph", _tank(walls=TALL, liquid={"weight": 9000.0, "depth": 1e6}), "'liquid.depth'",
                      ["resolution.particles=null", "resolution.spacing=2.5"]),
    # 700 km walls round a 100 cm vessel: wall particles, cell lists and the MPS load map (was a MemoryError)
    "walls_7e5_sph": ("sph", _tank(walls=BIG, vessels=[{"name": "first", "x": [0.0, 100.0]}]), "'walls'"),
    "walls_7e5_mps": ("mps", _tank(walls=BIG, vessels=[{"name": "first", "x": [0.0, 100.0]}]), "'walls'"),
    "walls_7e5_isa": ("isa", _tank(walls=BIG, vessels=[{"name": "first", "x": [0.0, 100.0]}]), "'walls'"),
}


@pytest.mark.parametrize("case", sorted(BLAME_CASES))
def test_a_derived_number_names_the_tank_field_it_follows(tmp_path, capsys, case):
    method, spec, field, *sets = BLAME_CASES[case]
    path = tmp_path / "tank.yaml"
    path.write_text(yaml.safe_dump(spec))
    line = cli_refuses(capsys, tmp_path, method_argv(method, *(sets[0] if sets else ()), tank=path), field)
    assert line.startswith(f"error: {path}: field {field}"), line


# ---- the command line ------------------------------------------------------------------------------------
CLI_CASES = {
    "accept_escaped_without_stability": (method_argv("sph", extra=["--accept", "converged,escaped"]), "--accept"),
    "max_hours_nan": (method_argv("sph", extra=["--max-hours", "nan"]), "--max-hours"),
    "max_hours_negative": (method_argv("sph", extra=["--max-hours", "-1"]), "--max-hours"),
    "max_hours_too_small": (method_argv("mps", extra=["--max-hours", "1e-9"]), "CPU-hours"),
    "unknown_method": (["--method", "lbm", "--tank", str(SINGLE), "--variant", "a", "--resolution", "b"], "--method"),
    "non_tank_method": (["--method", "solid", "--tank", str(SINGLE), "--variant", "a", "--resolution", "b"],
                        "does not run on tanks"),
    "unknown_variant": (["--method", "sph", "--tank", str(SINGLE), "--variant", "eq7", "--resolution", "n180"],
                        "--variant"),
    "unknown_resolution": (["--method", "mps", "--tank", str(SINGLE), "--variant", "standard", "--resolution", "x"],
                           "'resolutions'"),
    "unknown_run": (["--method", "sph", "--run", "nope"], "'runs'"),
    "set_without_equals": (method_argv("mps", "time.courant"), "key=value"),
    "set_shell_metachars": (method_argv("mps", "time.courant=$(touch pwned)"), "'time.courant"),
    "set_backticks": (method_argv("sph", "settings.kernel=`id`"), "settings.kernel"),
    "set_quote_comment": (method_argv("sph", "settings.cfl=0.25' # ; rm -rf ~"), "'settings.cfl"),
    "set_newline": (method_argv("sph", "settings.cfl=0.25\nsettings.alpha=9"), "settings.cfl"),
    "set_comment": (method_argv("mps", "time.courant=0.1 # smaller"), "a comment ('# smaller')"),
    "set_twice": (method_argv("sph", "settings.cfl=0.25", "settings.cfl=0.2"), "'settings.cfl' is given twice"),
    # --run with --tank / --variant / --resolution: they were ignored without a word
    "run_with_tank": (["--method", "isa", "--run", "single_coarse", "--tank", str(FLOW)], "--tank: not with --run"),
    "run_with_variant": (["--method", "sph", "--run", "single_wcsph_n180", "--variant", "wcsph_eq6"],
                         "--variant: not with --run"),
    # an empty --accept was the default (converged) without a word
    "accept_empty": (method_argv("sph", extra=["--accept", ""]), "unknown outcome ''"),
    "tank_is_a_directory": (["--method", "sph", "--tank", str(ROOT / "config"), "--variant", "wcsph",
                             "--resolution", "n180"], "a directory"),
    "threads_zero": (method_argv("isa", extra=["--threads", "0"]), "--threads"),
    "threads_negative": (method_argv("sph", extra=["--threads", "-1"]), "--threads"),
    "threads_beyond_the_machine": (method_argv("mps", extra=["--threads", str(budget.machine_cores() + 1)]),
                                   "--threads"),
}


@pytest.mark.parametrize("case", sorted(CLI_CASES))
def test_bad_command_lines_are_refused(tmp_path, capsys, case):
    argv, field = CLI_CASES[case]
    cli_refuses(capsys, tmp_path, argv, field)
    assert not (tmp_path / "pwned").exists()


@pytest.mark.parametrize("argv, field", [
    (method_argv("isa", extra=["--threads", "1.5"]), "argument --threads: invalid int value: '1.5'"),
    (method_argv("isa", extra=["--config", "x.yaml"]), "unrecognized arguments: --config x.yaml"),  # gone option
    (method_argv("sph", extra=["--max-hours", "many"]), "argument --max-hours: invalid float value"),
    (["--tank", str(SINGLE)], "the following arguments are required: --method"),
])
def test_argument_parser_refusals_are_one_line(tmp_path, capsys, argv, field):
    """argparse's refusals were a usage block of several lines and its message: now one line, exit 2."""
    with pytest.raises(SystemExit) as exc:
        cli.main(["run", *argv, "-o", str(tmp_path / "run.nc")])
    err = capsys.readouterr().err.strip().splitlines()
    assert exc.value.code == 2 and len(err) == 1 and err[0].startswith("error: ") and field in err[0], err


@pytest.mark.parametrize("value", ["0", "-3", "abc", str(budget.machine_cores() + 1)])
def test_a_thread_count_numba_cannot_use_is_refused_from_the_environment(tmp_path, capsys, monkeypatch, value):
    monkeypatch.setenv("NUMBA_NUM_THREADS", value)
    cli_refuses(capsys, tmp_path, method_argv("isa"), "environment variable NUMBA_NUM_THREADS")


def test_a_stability_case_may_leave_the_literature_ranges_but_not_the_budget():
    """cfl 50 and Mach 1 are refused for a run, allowed for a declared stability case; the budget holds for
    both."""
    m = preflight.methods.get("sph")
    tank = tanks.load(SINGLE)
    s = settings.load(m.settings, m.values_schema(), "wcsph", "n180", ["settings.cfl=50"])
    with pytest.raises(InputError, match="'settings.cfl'"):
        preflight.check("sph", tank, s)
    preflight.check("sph", tank, s, ("converged", "escaped"), stability=True)
    long = s.with_overrides(["settings.cfl=1e-9"])
    with pytest.raises(InputError, match="CPU-hours"):
        preflight.check("sph", tank, long, stability=True)
    preflight.check("sph", tank, long, max_hours=1e12)  # a deliberate long run


def test_every_declared_run_passes_its_checks_and_stability_cases_say_so():
    """The declared runs of every tank method pass isaflow.preflight; every run accepting an unstable outcome
    is a declared stability case."""
    d = preflight.Declarations()
    for method in DEFAULT:
        runs = d.spec(method).get("runs", {})
        d.check(method, runs)
        for run_id, decl in runs.items():
            if set(decl.get("accept", [])) & set(preflight.UNSTABLE):
                assert decl.get("stability"), run_id


# ---- the solid and 1D SPH settings (no tanks): their loaders check the same way -------------------------
def _mutated(tmp_path, src, dotted, value):
    spec = yaml.safe_load((ROOT / src).read_text())
    node = spec
    for k in dotted.split("."):
        node = node[k]
    node["value"] = value
    path = tmp_path / (src.split("/")[-1])
    path.write_text(yaml.safe_dump(spec, allow_unicode=True, sort_keys=False))
    return path


OTHER_CASES = {
    "solid_E_1e308": ("solid", "material.E_GPa", 1e308, "'material.E_GPa'"),
    "solid_rho_tiny": ("solid", "material.rho_kg_m3", 1e-300, "'material.rho_kg_m3'"),
    "solid_nu_half": ("solid", "material.nu", 0.5, "'material.nu"),
    "solid_tol_1e-300": ("solid", "solver.tol", 1e-300, "'solver.tol'"),
    "solid_steps_1e15": ("solid", "solver.max_steps", 10**15, "'solver.max_steps'"),
    "solid_bar_1e5_cubed": ("solid", "bar.particles", [100000, 100000, 100000], "'bar.particles'"),
    "solid_hertz_through_plate": ("solid", "hertz.depths_um", [26.0, 2000.0], "'hertz.depths_um'"),
    "solid_vessel_dt_above_rule": ("solid", "vessel.dt_ns", 1e6, "'vessel.dt_ns'"),
    "solid_water_h_tiny": ("solid", "vessel.water_h_over_dx", 0.1, "'vessel.water_h_over_dx'"),
    "solid_history_1e12_us": ("solid", "vessel.history_us", 1e12, "'vessel.history_us'"),
    "solid_floor_dx_1e-9": ("solid", "floor.dx_cm", 1e-9, "'floor.dx_cm'"),
    # a case that is no solid under load was written as converged with zero stress
    "solid_bar_one_particle": ("solid", "bar.particles", [1, 1, 1], "'bar.particles'"),
    "solid_bar_two_layers": ("solid", "bar.particles", [5, 2, 5], "'bar.particles'"),
    "solid_shear_no_grip": ("solid", "shear.grip_layers", 0, "'shear.grip_layers'"),
    "solid_hertz_plate_one_row": ("solid", "hertz.plate", [51, 1], "'hertz.plate'"),
    "solid_floor_one_column": ("solid", "floor.dx_cm", 200.0, "'floor.dx_cm'"),
    "solid_long_bar_1e15_steps": ("solid", "bar_long.steps", 10**15, "'bar_long.steps'"),
    "sph1d_n_1e12": ("sph1d", "n", [32, 64, 128, 1000000000000], "'n'"),
    "sph1d_ratio_1e9": ("sph1d", "ratio", {"start": 0.51, "stop": 1e9, "step": 0.01}, "'ratio'"),
    "sph1d_step_tiny": ("sph1d", "ratio", {"start": 0.51, "stop": 3.0, "step": 1e-12}, "'ratio'"),
    # counts that overflow an integer (OverflowError tracebacks while the workflow was parsed before)
    "sph1d_step_1e-320": ("sph1d", "ratio", {"start": 0.51, "stop": 3.0, "step": 1e-320}, "'ratio'"),
    "solid_floor_dx_1e-320": ("solid", "floor.dx_cm", 1e-320, "'floor.dx_cm'"),
    "sph1d_column_overflow": ("sph1d", "column.height", 1e308, "'column.height'"),
    "sph1d_n_below_8": ("sph1d", "n", [2, 4, 8, 16], "'n"),
    # step counts costed under another field's name (solver.max_steps, vessel.history_us) or not at all
    "solid_hertz_dt_check_steps_1e15": ("solid", "hertz.dt_check_steps", 10**15, "'hertz.dt_check_steps'"),
    "solid_vessel_steps_1e15": ("solid", "vessel.steps", 10**15, "'vessel.steps'"),
    "solid_mechanism_steps_1e15": ("solid", "solver.max_steps_mechanism", 10**15, "'solver.max_steps_mechanism'"),
    "solid_vessel_record_every_1e15": ("solid", "vessel.record_every", 10**15, "'vessel.record_every'"),
}


@pytest.mark.parametrize("case", sorted(OTHER_CASES))
def test_bad_solid_and_sph1d_settings_are_refused(tmp_path, case):
    method, dotted, value, field = OTHER_CASES[case]
    if dotted == "column.height":  # and rho_g with it: the floor pressure overflows
        path = _mutated(tmp_path, f"config/methods/{method}.yaml", dotted, value)
        text = re.sub(r"(rho_g:\n\s+value: )[0-9.e-]+", r"\g<1>1.0e+308", path.read_text())
        path.write_text(text)
    else:
        path = _mutated(tmp_path, f"config/methods/{method}.yaml", dotted, value)
    t0 = time.perf_counter()
    with pytest.raises(InputError) as err:
        preflight.check_file(method, path)
    assert time.perf_counter() - t0 < 5.0
    msg = str(err.value)
    assert msg.startswith(f"{path}: ") and "\n" not in msg and field in msg, msg


# ---- the workflow, while it is parsed ----------------------------------------------------------------------
def _project(tmp_path):
    for item in ("Snakefile", "workflow", "config"):
        src = ROOT / item
        (shutil.copytree if src.is_dir() else shutil.copy)(src, tmp_path / item)
    (tmp_path / "src").symlink_to(ROOT / "src")
    return tmp_path


def _edit(path, old, new, count=1):
    text = path.read_text()
    assert old in text, (path, old)
    path.write_text(text.replace(old, new, count))


PARSE_CASES = {
    # a tank named by the comparison that does not exist / escapes the tank directory
    "config_unknown_tank": ("config/config.yaml", "tanks: [single,", "tanks: [nosuch,", "'compare.tanks'"),
    "config_alias_bomb": ("config/config.yaml", "compare:", "a: &a [x, x]\nb: [*a, *a]\ncompare:", "aliases"),
    # a run override whose value carries shell syntax (a quote, a comment, a command)
    "run_override_shell": ("config/methods/mps.yaml", "time.courant: {value: 0.1,",
                           "time.courant: {value: \"0.1' ; touch pwned #\",", "(run 'dt_standard_c0.1')"),
    "run_unstable_without_stability": ("config/methods/sph.yaml", "    stability: true\n", "", "stability case"),
    "run_cfl_50": ("config/methods/sph.yaml", "resolution: n180, compare: true}",
                   "resolution: n180, compare: true, set: {settings.cfl: {value: 50.0, source: 'inferred: x'}}}",
                   "(run 'single_wcsph_n180')"),
    "run_unknown_variant": ("config/methods/mps.yaml", "single_standard_dx5.56: {tank: single, variant: standard,",
                            "single_standard_dx5.56: {tank: single, variant: eq99,", "'runs.single_standard_dx5.56"),
    "run_unknown_tank": ("config/methods/mps.yaml", "single_standard_dx5.56: {tank: single,",
                         "single_standard_dx5.56: {tank: nosuch,", "'runs.single_standard_dx5.56.tank'"),
    "study_nan": ("config/methods/isa_study.yaml", "fire_dt_factor:", "fire_dt_factor: .nan\n  x_fire_dt_factor:",
                  "isa_study.yaml"),
    "tank_depth_above_walls": ("config/tanks/single.yaml", "depth: 72.5", "depth: 150.0", "'liquid.depth'"),
    "solid_tol": ("config/methods/solid.yaml", "tol: {value: 1.0e-6,", "tol: {value: 1.0e-300,", "'solver.tol'"),
    # a one-particle bar was written as converged with zero stress
    "solid_one_particle": ("config/methods/solid.yaml", "particles: {value: [5, 11, 5],", "particles: {value: [1, 1, 1],",
                           "'bar.particles'"),
    # the default flow probes lie below the same-floor tank's floor: the run declares its own
    "probes_below_the_floor": ("config/methods/mps.yaml", "[200.0, 5.0], [250.0, 10.0]]", "[200.0, -45.0], [250.0, -40.0]]",
                               "'probes.flow'"),
    "sph1d_huge_n": ("config/methods/sph1d.yaml", "[32, 64, 128, 256, 512, 1024, 2048]",
                     "[32, 64, 128, 256, 512, 1024, 1000000000000]", "memory"),
    # a claims' derived number computed from a run nobody makes (was a KeyError while the DAG was built)
    "derived_from_no_run": ("config/claims/hattori.yaml", 'from: "mps:single_standard_dx3.45"', 'from: "mps:no_such_run"',
                            "config/claims/hattori.yaml: field 'derived.1.from'"),
    "derived_unread": ("config/claims/hattori.yaml", '- id: "mps:dilation_single_hattori_dx3.45"\n',
                       '- id: "mps:dilation_nobody"\n', "derived.2 ('mps:dilation_nobody'): no row or input"),
    # a study case's overrides were 'key=value' strings whose comments were dropped and whose sources were comments;
    # they are sourced mappings now: a plain value, a bad source and an unknown key are refused naming the field
    "study_override_unsourced": ("config/methods/isa_study.yaml",
                                 'solver.du: {value: 10.0, source: "study plan: du = a = 2 l_bu (1000 x the paper\'s)"}',
                                 "solver.du: 10.0",
                                 "config/methods/isa_study.yaml: field 'study.cases.value.list.du_large.set.solver.du': "
                                 "an override is a {value, source} mapping"),
    "study_override_bad_source": ("config/methods/isa_study.yaml", 'source: "study plan: du = a = 2 l_bu',
                                  'source: "because: du = a = 2 l_bu', "list.du_large.set.solver.du': field "
                                  "'solver.du.source'"),
    "study_override_unknown": ("config/methods/isa_study.yaml", "solver.du: {value: 10.0,", "solver.dx: {value: 10.0,",
                               "config/methods/isa_study.yaml: field 'study.cases.value.list.du_large.set.solver.dx': "
                               "override field 'solver.dx': no such setting"),
    # YAML 1.1 reads 010 as 8: a file value the user typed as ten
    "octal_in_a_settings_file": ("config/methods/mps.yaml", "time.courant: {value: 0.1,", "time.courant: {value: 010,",
                                 "the octal number 8"),
    # the study's names of nothing: a KeyError ("config/methods/isa_study.yaml: 'nosuch'"), or the line named
    # config/methods/isa.yaml's field or a generated run's; a repeated value was a ValueError traceback (exit 1)
    "study_lattice_unknown": ("config/methods/isa_study.yaml", "- {lattices: [coarse, refined], variants",
                              "- {lattices: [coarse, nosuch], variants",
                              "isa_study.yaml: field 'study.error_runtime.value.blocks.0.lattices': no lattice 'nosuch'"),
    "study_resolution_unknown": ("config/methods/isa_study.yaml", "coarse: {resolution: coarse,",
                                 "coarse: {resolution: nosuch,",
                                 "isa_study.yaml: field 'study.lattices.value.coarse.resolution'"),
    "study_case_tank_unknown": ("config/methods/isa_study.yaml", "tank: study_on_wall", "tank: nosuch",
                                "isa_study.yaml: field 'study.cases.value.list.on_wall.tank': no tank 'nosuch'"),
    "study_value_twice": ("config/methods/isa_study.yaml", "du_factors: [0.1, 0.3, 1, 3, 10, 100]}", "du_factors: [1, 1]}",
                          "isa_study.yaml: field 'study.error_runtime': run 'er_coarse_paper_du1' is planned twice"),
    # a claim id twice or of another paper's prefix passed until the claims job
    "claim_id_twice": ("config/claims/marko2017.yaml", "  - id: mar-1-spam-tensile", "  - id: mar-abs-stable",
                       "claim id 'mar-abs-stable' occurs 2 times"),
    "claim_id_of_another_paper": ("config/claims/marko2017.yaml", "  - id: mar-1-spam-tensile",
                                  "  - id: hat-1-spam-tensile", "id must start with 'mar-'"),
    # a run that continues itself was planned without its start; the job failed on the missing start file
    "run_starts_from_itself": ("config/methods/sph.yaml", "single_wcsph_n180: {tank: single, variant: wcsph, "
                               "resolution: n180, compare: true}", "single_wcsph_n180: {tank: single, variant: wcsph, "
                               "resolution: n180, compare: true, start: flow_wcsph_n180}",
                               "single_wcsph_n180 -> flow_wcsph_n180 -> single_wcsph_n180"),
    # the run files record the tank's name and the comparison reads it: single.yaml named 'other' left the figures
    "tank_named_otherwise": ("config/tanks/single.yaml", "name: single", "name: other",
                             "config/tanks/single.yaml: field 'name': 'other', but the file is tank 'single'"),
}


def _parse_refuses(proj, field, *args):
    """snakemake -n in proj: exit 2, one line naming the field, no traceback, no job, nothing under results/."""
    proc = subprocess.run([sys.executable, "-m", "snakemake", "-n", "--workflow-profile", "none", *args], cwd=proj,
                          capture_output=True, text=True, timeout=120)
    errors = [line for line in proc.stderr.splitlines() if line.startswith("error: ")]
    assert proc.returncode == 2, proc.stderr[-2000:]
    assert len(errors) == 1 and field in errors[0], proc.stderr[-2000:]
    assert "Traceback" not in proc.stderr
    assert not (proj / "results").exists() and not (proj / "pwned").exists()


@pytest.mark.parametrize("case", sorted(PARSE_CASES))
def test_the_workflow_refuses_bad_inputs_while_it_is_parsed(tmp_path, case):
    """snakemake -n on a copy of the project with one bad input: exit 2, one line naming the file and field,
    no job started, nothing written under results/."""
    rel, old, new, field = PARSE_CASES[case]
    proj = _project(tmp_path)
    _edit(proj / rel, old, new)
    _parse_refuses(proj, field, "-c1")


@pytest.mark.parametrize("old, new, field", [
    ("value: 1.0e-5", "value: .nan", "rest.yaml: field 'rest.energy_ratio.value': numbers must be finite"),
    ("value: 1.2", "value: 0", "rest.yaml: field 'rest.window.value'"),
])
def test_the_rest_criterion_is_checked_while_the_workflow_is_parsed(tmp_path, old, new, field):
    """config/rest.yaml (read by the dynamic runs from the package's checkout, so the copy holds its own src/): a
    NaN or zero passed the parse and stopped every dynamic run's job."""
    proj = _project(tmp_path)
    (proj / "src").unlink()
    shutil.copytree(ROOT / "src", proj / "src", ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))
    _edit(proj / "config" / "rest.yaml", old, new)
    _parse_refuses(proj, field, "-c1")


def test_a_tank_method_without_a_compared_single_vessel_run_is_refused(tmp_path):
    """The comparison, the integration target and the solid floor under each tank method's liquid read its first
    compared run on `single`: a method that declares none is refused in one line (it failed while the DAG was
    built)."""
    proj = _project(tmp_path)
    path = proj / "config" / "methods" / "mps.yaml"
    text = path.read_text()
    lines = [line.replace(", compare: true", "") if "{tank: single," in line else line for line in text.splitlines(True)]
    assert "".join(lines) != text
    path.write_text("".join(lines))
    _parse_refuses(proj, "config/methods/mps.yaml: field 'runs': a tank method needs a run on tank 'single'", "-c1")


PARSE_ARGS = {
    "cores_zero": (["-c0"], "'--cores'"),
    "cores_negative": (["--cores", "-1"], "'--cores'"),
    **{f"undeclared_{m}_run": (["-c1", f"results/runs/{m}/no_such_run.nc"], f"config/methods/{m}.yaml: field 'runs'")
       for m in DEFAULT},
    "run_of_another_method": (["-c1", "results/runs/mps/single_coarse.nc"], "no mps run 'single_coarse'"),
    "derived_of_another_method": (["-c1", "results/derived/sph1d/step_check_single_hattori_dx3.45.nc"],
                                  "config/claims: field 'derived': no entry 'sph1d:step_check_single_hattori_dx3.45'"),
}


@pytest.mark.parametrize("case", sorted(PARSE_ARGS))
def test_the_workflow_refuses_bad_command_lines_before_any_job(tmp_path, case):
    """A core count that is no count, or a run file no settings file declares asked for as a target: one line,
    exit 2, before any job starts (an undeclared target was a KeyError traceback while the DAG was built)."""
    args, field = PARSE_ARGS[case]
    _parse_refuses(_project(tmp_path), field, *args)


def test_no_shell_line_is_built_from_configuration():
    """Every `shell:` command of the workflow names only files and threads ({input.*}, {output}, {log},
    {threads}, the checkout's {params.src}): settings, overrides and wildcards reach the code as data (params,
    script:)."""
    commands = []
    for path in [ROOT / "Snakefile", *sorted((ROOT / "workflow").rglob("*.smk"))]:
        text = path.read_text()
        commands += re.findall(r"^\s+shell:\s*\n\s+(\"[^\n]*\"|'[^\n]*')", text, re.M)
        assert "shell(" not in text, path
    for cmd in commands:
        for field in re.findall(r"{([^}]*)}", cmd):
            # params.src: the checkout's src/ (workflow.basedir), the one param a benchmark's shell line names
            assert re.fullmatch(r"input(\.\w+)?|output(\[\d+\])?|log|threads|params\.src", field), (cmd, field)


def test_the_1d_settings_name_the_numerical_modules_choices():
    """sph1d.settings lists the kernels, gradient forms and floors in pure Python (it is read while the workflow
    is parsed); they are the numerical modules' own."""
    from isaflow.core.smoothing import NAMES
    from isaflow.methods.sph1d import settings as S, system

    assert list(S.KERNELS) == list(NAMES)
    assert list(S.GRADIENT_FORMS) == list(system.GRADIENT_FORMS) and list(S.FLOORS) == list(system.FLOORS)


def test_the_parse_time_checks_need_no_numerics():
    """The checks the workflow runs while it is parsed import neither NumPy nor numba (the workflow parses with
    only Snakemake installed)."""
    code = ("import sys; sys.modules['numpy'] = None; sys.modules['numba'] = None; sys.path.insert(0, 'src')\n"
            "from isaflow import preflight, methods\n"
            "d = preflight.Declarations()\n"
            "for m in ('isa', 'sph', 'mps'): d.check(m, d.spec(m).get('runs', {}))\n"
            "for m in ('solid', 'sph1d'): preflight.check_file(m)\n")
    proc = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]


def test_one_start_file_test_for_every_method():
    """runfile.start_problem, the start check of ISA, SPH and MPS: another method's run, a missing variable or
    attribute of the state, an outcome no run may continue (escaped, nonfinite, solver_failed) each give one line."""
    import numpy as np
    import xarray as xr

    from isaflow import runfile

    ds = xr.Dataset({"pos": (("particle", "xy"), np.zeros((2, 2)))}, attrs={"method": "mps", "status": "converged",
                                                                           "spacing": 1.0})
    assert runfile.start_problem(ds, "a.nc", "mps", ("pos", "spacing")) is None
    assert "not an SPH run" in runfile.start_problem(ds, "a.nc", "sph")
    assert "(velocity missing)" in runfile.start_problem(ds, "a.nc", "mps", ("pos", "velocity"))
    for status in runfile.UNUSABLE:
        ds.attrs["status"] = status
        assert f"status {status}" in runfile.start_problem(ds, "a.nc", "mps")
