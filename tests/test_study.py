"""Error measures, the study's run plan and tables, and the CI-sized study workflow."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import xarray as xr
import yaml

from isaflow import settings as S, theory
from isaflow.methods.isa import metrics, scene, tables
from isaflow.methods.isa import plan as plans
from isaflow.methods.isa.solver import DETECTED_BY
from isaflow.methods.isa.settings import VALUES, fire_dt_max, settings

from conftest import ISA_SETTINGS, ROOT

STUDY = S.plain(yaml.safe_load((ROOT / "config" / "methods" / "isa_study.yaml").read_text()))["study"]
SPEC = S.read(ISA_SETTINGS, VALUES)
CI_CONFIG = ROOT / "tests" / "data" / "study_ci.yaml"


# -- error measures -----------------------------------------------------------


def hydrostatic_run(h=60.0, a=10.0, width=100.0, w=50.0):
    """A run Dataset whose wall contacts carry exactly the hydrostatic loads of a liquid
    of level h [cm] (theory.contact_theory), with the free surface (the one surface: top centres + half the layer
    pitch a) exactly at h."""
    walls = np.array([[0, 100, 0, 0], [0, 0, width, 0], [width, 0, width, 100]], float)
    xs = np.arange(a / 2, width, a)
    pos = np.array([[x, y] for x in xs for y in np.arange(h - a / 2, 0, -a)])  # top of every strip at h - a/2
    W = w * len(pos)
    gamma = theory.specific_weight(W, width, h)
    ys = np.arange(a / 4, 100, a / 2)
    cw = np.concatenate([np.zeros(len(ys), int), np.ones(len(xs), int), np.full(len(ys), 2)])
    cp = np.concatenate([np.column_stack([np.zeros_like(ys), ys]), np.column_stack([xs, np.zeros_like(xs)]),
                         np.column_stack([np.full_like(ys, width), ys])])
    mag = theory.contact_theory(walls, cw, cp, gamma, h)
    normal = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0]])[cw]
    keep = mag > 0
    # each contact belongs to the particle nearest its point (only used to assign contacts to the vessel)
    owner = np.argmin(np.hypot(*(cp[keep, None, :] - pos[None, :, :]).transpose(2, 0, 1)), axis=1)
    ds = xr.Dataset(
        {"pos": (("particle", "xy"), pos), "weight": (("particle",), np.full(len(pos), w)),
         "wall_segment": (("wall", "end"), walls), "contact_wall": (("contact",), cw[keep]),
         "contact_particle": (("contact",), owner),
         "contact_point": (("contact", "xy"), cp[keep]),
         "contact_force": (("contact", "xy"), normal[keep] * mag[keep, None]), "residual": ((), 0.05)},
        coords={"wall": ["left", "floor", "right"], "xy": ["x", "y"]})
    ds.attrs.update(spacing=a, **{"forces.wall.l_u": 5.0, "forces.wall.r_u": 10000.0, "forces.pair.l_u": a / np.sqrt(2), "forces.pair.r_u": 500 * a / np.sqrt(2)})
    return ds


def test_hydrostatic_loads_have_zero_error():
    ds = hydrostatic_run(h=60.0)
    e = metrics.hydrostatic_errors(ds, paper_level=62.5)
    assert e["level_cm"] == pytest.approx(60.0)
    assert e["level_err_paper_cm"] == pytest.approx(-2.5)
    # every wall total and every contact equals hydrostatics; the side loads imply the measured level
    for key in ("wall_err_left", "wall_err_floor", "wall_err_right", "wall_err_max", "side_err", "floor_err",
                "contact_rms", "contact_max", "level_err_hydro_cm"):
        assert e[key] == pytest.approx(0.0, abs=1e-9), key
    assert e["residual"] == 0.05
    # side contacts a/2 apart: the resultant of the tributary loads sits within a/4 of h/3
    assert abs(e["side_height_err_cm"]) < 10.0 / 4


def test_halved_side_loads_show_in_every_side_measure():
    ds = hydrostatic_run(h=60.0)
    side = np.isin(ds["contact_wall"].values, [0, 2])
    ds["contact_force"].values[side] *= 0.5
    e = metrics.hydrostatic_errors(ds)
    assert e["side_err"] == pytest.approx(-0.5) and e["wall_err_max"] == pytest.approx(0.5)
    assert e["floor_err"] == pytest.approx(0.0, abs=1e-12)
    # F_side = gamma h^2 / 4 implies a level of h / 2
    assert e["level_err_hydro_cm"] == pytest.approx(30.0)
    assert np.isnan(e["level_err_paper_cm"])


def test_law_usage_by_hand():
    ds = hydrostatic_run(h=60.0)
    pos = ds["pos"].values.copy()
    l_pu = ds.attrs["forces.pair.l_u"]
    pos[1] = pos[0] + [0.5 * l_pu, 0.0]  # one pair at half the pair law's range
    ds["pos"].values[:] = pos
    u = metrics.law_usage(ds)
    assert u["pair_use"] == pytest.approx(0.5) and u["min_pair_cm"] == pytest.approx(0.5 * l_pu)
    biggest = np.hypot(*ds["contact_force"].values.T).max()
    assert u["wall_use"] == pytest.approx(biggest / 10000.0)


# -- plan ----------------------------------------------------------------------


@pytest.fixture(scope="module")
def plan():
    return {k: {**v["meta"], **v} for k, v in plans.plan(STUDY, SPEC).items()}


def planned_scene(m, sets=True):
    return scene.of_run(m["tank"], m["resolution"], m["variant"], m["set"] if sets else (), ISA_SETTINGS)


def test_plan_covers_the_issue(plan):
    er = {k: v for k, v in plan.items() if v["group"] == "error_runtime"}
    assert {v["lattice"] for v in er.values()} >= {"coarse", "refined", "fine", "finer"}
    assert {v["variant"] for v in er.values()} == {"paper", "capped", "fire"}
    factors = {v["du_factor"] for v in er.values()}
    assert min(factors) <= 0.1 and max(factors) >= 10
    spacings = [scene.of_run("single", STUDY["lattices"][k]["resolution"], "paper").spacing
                for k in ("coarse", "refined", "fine", "finer")]
    assert spacings == sorted(spacings, reverse=True) and spacings[-1] < 5.0 / 2 + 1e-12  # two finer than the paper's
    cases = {v["case"] for v in plan.values() if v["group"] == "cases"}
    assert cases >= {"stiff", "du_large", "du_small", "overlap", "coincident", "on_wall", "narrow_opening", "shallow",
                     "tall", "lattice_100k", "float_limit"}
    big = scene.of_run("single", STUDY["cases"]["list"]["lattice_100k"]["resolution"], "fire")
    assert len(scene.initial_positions(big)) >= 100_000
    # the map reaches k du far above w and du far above and below the paper's
    sm = [v for v in plan.values() if v["group"] == "stability_map"]
    assert max(v["k_factor"] * v["du_factor"] for v in sm) * 0.4 >= 1e4  # paper: k_b du / w = 0.4
    assert min(v["du_factor"] for v in sm) <= 0.1 and max(v["du_factor"] for v in sm) >= 100


def test_every_planned_run_is_a_valid_scene_with_its_du(plan):
    for sid, m in plan.items():
        sc = planned_scene(m)  # raises InputError naming the field otherwise
        s = settings(sc)
        assert s["variant"] == m["variant"] and s["history"] == {} and set(m["accept"]) == set(DETECTED_BY), sid
        if m["group"] != "cases":
            base = settings(planned_scene(m, sets=False))["du"]
            assert s["du"] == pytest.approx(m["du_factor"] * base, rel=1e-7), sid
        if m["variant"] == "fire":
            k = 2 * sc.stiffness("wall") + 12 * sc.stiffness("pair")
            assert s["dt_max"] == pytest.approx(m.get("dt_factor", STUDY["fire_dt_factor"]) / np.sqrt(k), rel=1e-7)


def test_the_float_limit_case_is_refused_at_input_for_the_overdamped_update():
    """Why isa_study.yaml runs float_limit without overdamped: its derived step is 0 s there."""
    from isaflow.inputs import InputError
    case = STUDY["cases"]["list"]["float_limit"]
    assert "overdamped" not in case["variants"]
    with pytest.raises(InputError, match="forces.wall.r_u"):
        settings(scene.of_run("single", case["resolution"], "overdamped", case["set"], ISA_SETTINGS))


def test_fire_dt_max_of_the_paper_stiffness():
    # 2 / sqrt(2 x 2000 + 12 x 500) = 2 / 100 s
    assert fire_dt_max(2000.0, 500.0, 2.0) == pytest.approx(0.02)


@pytest.mark.parametrize("x", [1e-5, 0.01, 3535.5339, 1e8, 1e308, 2.5e-300])
def test_planned_numbers_keep_eight_digits(x):
    y = plans._num(x)
    assert isinstance(y, float) and y == pytest.approx(x, rel=1e-7) and y == float(f"{x:.8g}")


def test_outcome_detail_separates_the_two_escapes():
    assert tables.outcome_detail("escaped", "particle 3 at (1, 2) cm would cross wall 'floor' at step 0; step refused, "
                                           "run stopped") == "crossed a wall (step refused)"
    assert tables.outcome_detail("escaped", "2 particle(s) left the walls' bounding box by step 1000") == \
        "left the walls' bounding box"
    assert tables.outcome_detail("step_limit", "") == "step limit"


def test_recommend_takes_the_cheapest_converged_run_of_a_robust_family():
    """Cost = particle-steps (steps x particles), never wall-clock time."""
    rows = [("a", "coarse", "paper", "cycle", 0.001, 10), ("b", "coarse", "fire", "converged", -0.04, 100),
            ("c", "coarse", "capped", "converged", 0.03, 500), ("d", "refined", "fire", "converged", -0.2, 13),
            ("e", "refined", "capped", "converged", 0.02, 5), ("f", "refined", "capped", "converged", 0.3, 10)]
    tab = pd.DataFrame([dict(run=r, lattice=la, variant=v, du_cm=0.01, status=s, side_err=e, steps=n,
                             particles=180 if la == "coarse" else 684, wall_time_s=0.0)
                        for r, la, v, s, e, n in rows])
    rec = tables.recommend(tab, {"side_err": [0.5, 0.05, 0.035, 0.01]}).set_index("target")
    # every family stays within 0.5: the cheapest converged run of all ('a' never converged;
    # 'e' costs 5 x 684 = 3,420 particle-steps against b's 18,000)
    assert rec.loc[0.5, "run"] == "e"
    # refined/capped misses 0.05 at one du ('f'), so its fast 'e' meets it by chance only
    assert rec.loc[0.05, "run"] == "b" and rec.loc[0.05, "family_worst"] == pytest.approx(0.04)
    assert rec.loc[0.05, "robust_families"] == "coarse/capped, coarse/fire" and rec.loc[0.05, "by_chance"] == "e"
    assert rec.loc[0.035, "run"] == "c" and rec.loc[0.035, "by_chance"] == "e"
    assert rec.loc[0.01, "run"] == "none" and rec.loc[0.01, "by_chance"] == "none"


# -- CI-sized workflow ---------------------------------------------------------


def test_reduced_study_builds_both_figures_and_the_report_fragment(tmp_path):
    """The study's rules on a few coarse points (tests/data/study_ci.yaml) in a scratch copy."""
    for item in ("Snakefile", "workflow", "config"):
        src = ROOT / item
        (shutil.copytree if src.is_dir() else shutil.copy)(src, tmp_path / item)
    (tmp_path / "src").symlink_to(ROOT / "src")  # rules depend on the package sources
    shutil.copy(CI_CONFIG, tmp_path / "config" / "methods" / "isa_study.yaml")
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}"}
    targets = ["figures/error_vs_runtime.png", "figures/stability_map.png", "results/report/30_study.md",
               "results/report/figures/error_vs_runtime.png", "results/report/figures/stability_map.png"]
    proc = subprocess.run([sys.executable, "-m", "snakemake", "-c2", *targets], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=400)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    for t in targets:
        assert (tmp_path / t).stat().st_size > 0
    err = pd.read_csv(tmp_path / "results" / "isa" / "study" / "error_vs_runtime.csv").set_index("run")
    assert len(err) == 6
    # physics: the capped update reaches f_tol at the paper's level (tolerance a/4 = 2.5 cm);
    # the literal update ends in its period-2 cycle
    cap = err.loc["er_coarse_capped_du1"]
    # the level is the one surface, half a layer pitch (a/4 = 2.5 cm) above the top centres that k_p was calibrated
    # to put at the paper's 72.5 cm (to a/4)
    assert cap["status"] == "converged" and cap["residual"] < 0.1 and abs(cap["level_err_paper_cm"] - 2.5) <= 2.5
    assert err.loc["er_coarse_paper_du1", "status"] == "cycle" and err.loc["er_coarse_paper_du1", "paper_config"]
    cases = pd.read_csv(tmp_path / "results" / "isa" / "study" / "stability_cases.csv").set_index("run")
    big = cases.loc["sc_du_large_paper"]
    assert big["status"] == "escaped" and "would cross wall 'floor' at step 0" in big["message"]
    assert (cases.loc[["sc_on_wall_paper", "sc_on_wall_fire"], "positions_finite"]).all()
    smap = pd.read_csv(tmp_path / "results" / "isa" / "study" / "stability_map.csv")
    assert len(smap) == 8 and set(smap["status"]) <= set(DETECTED_BY)
    # FIRE needs fewer force evaluations than the capped update and than the paper's reported 2000 steps
    ratio = pd.read_csv(tmp_path / "results" / "isa" / "study" / "fire_ratio.csv").iloc[0]
    assert ratio["ratio_vs_capped"] > 1 and ratio["ratio_vs_paper_reported"] > 1
    # the Snakemake report of those targets holds both figures with their captions
    rep = subprocess.run([sys.executable, "-m", "snakemake", "--report", "report.html", *targets[3:]], cwd=tmp_path,
                         env=env, capture_output=True, text=True, timeout=300)
    assert rep.returncode == 0, rep.stdout[-2000:] + rep.stderr[-2000:]
    html = (tmp_path / "report.html").read_text()
    assert "error_vs_runtime.png" in html and "stability_map.png" in html and "Studies" in html
    assert "ISA stability" in html and "Outcome of each ISA update rule" in html  # its own subcategory and caption
    text = (tmp_path / "results" / "report" / "30_study.md").read_text()
    assert "## Error against work, and numerical stability" in text and "Which configuration to pick" in text
    assert " s)" not in text and "wall_time" not in text  # no timing in the report text
