"""CI tolerance check: single-vessel free-surface levels and wall loads.

Tolerances come from isaflow.metrics.tolerances (derived from the lattice,
not from the results; see docs/replication.md).  Known, explained differences
from hydrostatic theory are strict xfails: they fail loudly if they vanish.
"""

import numpy as np
import pytest

from isaflow import theory
from isaflow.methods.isa import metrics
from isaflow.methods.isa import theory as isa_theory

PAPER_LEVEL = {"single_coarse": 72.5, "single_refined": 75.0}
A = {"single_coarse": 10.0, "single_refined": 5.0}
CASES = [(s, v) for s in PAPER_LEVEL for v in ("paper", "capped")]


@pytest.fixture(scope="module")
def rows(single_runs):
    """metrics.run_row of every case, computed once for the module."""
    return {c: metrics.run_row(single_runs[c]) for c in CASES}


@pytest.fixture
def row_and_tol(rows):
    def get(_, name, variant):
        row = rows[name, variant]
        return row, metrics.tolerances(row, A[name], row["particles"], 0.1)
    return get


COARSE_SURFACE = pytest.mark.xfail(
    strict=True,
    reason="k_p was calibrated on the top particle centres (72.63 cm); the one surface, half a layer pitch above them, "
           "reads 75.13 cm, 0.13 cm beyond a/4 of 72.5 cm (claims row pap-6.1-level-coarse, fragile in level_definition)")


@pytest.mark.parametrize("name,variant", [pytest.param(*c, marks=COARSE_SURFACE) if c[0] == "single_coarse" else c
                                          for c in CASES])
def test_free_surface_level_matches_the_paper(single_runs, row_and_tol, name, variant):
    """The level on the one surface (top centres + half the layer pitch) against the paper's, to a/4."""
    row, tol = row_and_tol(single_runs, name, variant)
    assert abs(row["level"] - PAPER_LEVEL[name]) <= tol["level"][0]


@pytest.mark.parametrize("name,variant", CASES)
def test_top_centres_sit_at_the_papers_level(single_runs, name, variant):
    """The calibration's reading: k_p = 500 N/cm puts the top particle centres at the paper's levels, to a/4."""
    level = metrics.level_of(single_runs[name, variant])
    assert abs(level - PAPER_LEVEL[name]) <= A[name] / 4


@pytest.mark.parametrize("name,variant", CASES)
def test_floor_carries_the_weight(single_runs, row_and_tol, name, variant):
    row, tol = row_and_tol(single_runs, name, variant)
    assert abs(row["floor_err"]) <= tol["floor"][0]


SIDE_DEFICIT = pytest.mark.xfail(
    strict=True,
    reason="the relaxed lattice is not a fluid: its horizontal/vertical stress ratio is about 0.88, so the side "
           "walls carry less than the hydrostatic gamma h^2/2 (docs/replication.md, claims pap-6.1-satisfactory-coarse)",
)


@pytest.mark.parametrize("name,variant", [pytest.param(*c, marks=SIDE_DEFICIT) for c in CASES])
def test_side_wall_totals_match_hydrostatics(single_runs, row_and_tol, name, variant):
    row, tol = row_and_tol(single_runs, name, variant)
    assert abs(row["side_err"]) <= tol["side"][0]


@pytest.mark.parametrize("name,variant", CASES)
def test_side_wall_deficit_is_bounded(single_runs, row_and_tol, name, variant):
    """The documented deficit itself: side walls carry 75-100 % of hydrostatics, never more."""
    row, _ = row_and_tol(single_runs, name, variant)
    assert -0.25 <= row["side_err"] <= 0.0
    assert 0.8 <= row["stress_ratio"] <= 0.95


REFINED_HEIGHT = pytest.mark.xfail(strict=True, reason="refined side resultant sits 1.7-1.9 cm above h/3 "
                                   "(tolerance a/4 = 1.25 cm): the side deficit is largest near the floor")


@pytest.mark.parametrize("name,variant", [
    ("single_coarse", "paper"), ("single_coarse", "capped"),
    pytest.param("single_refined", "paper", marks=REFINED_HEIGHT),
    pytest.param("single_refined", "capped", marks=REFINED_HEIGHT),
])
def test_side_resultant_acts_at_a_third_of_the_depth(single_runs, row_and_tol, name, variant):
    row, tol = row_and_tol(single_runs, name, variant)
    assert abs(row["side_height_err"]) <= tol["side_height"][0]


@pytest.mark.parametrize("name", PAPER_LEVEL)
def test_literal_update_settles_in_a_cycle_at_the_stability_floor(single_runs, name):
    """The paper's x += du F/max|F| cannot reach 0.1 N: once max|F| < lambda_max du / 2
    the gain du / max|F| exceeds 2 / lambda_max, and it oscillates around that floor."""
    ds = single_runs[name, "paper"]
    a = ds.attrs
    assert a["status"] == "cycle" and a["cycle_period"] == 2
    lam, floor = isa_theory.step_floor(ds["pos"].values, ds["wall_segment"].values, a["forces.wall.l_u"], a["forces.wall.r_u"],
                                   a["forces.pair.l_u"], a["forces.pair.r_u"], a["solver.du"])
    tail = ds["hist_fmax"].values[-20:]
    lo, hi = ds["hist_fmax_lo"].values[-20:].min(), ds["hist_fmax_hi"].values[-20:].max()
    assert lo > 10 * a["solver.f_tol"]
    assert lo < floor < hi
    assert 0.5 * (lo + hi) == pytest.approx(floor, rel=0.05)
    assert np.all(tail > a["solver.f_tol"])


@pytest.mark.parametrize("name", PAPER_LEVEL)
def test_capped_variant_converges_to_the_same_state(single_runs, rows, name):
    c = single_runs[name, "capped"]
    assert c.attrs["status"] == "converged" and float(c["residual"]) < 0.1
    rp, rc = rows[name, "paper"], rows[name, "capped"]
    assert rc["level"] == pytest.approx(rp["level"], abs=0.5)


# -- the paper's incompressibility claim (section 5) ----------------------------
# Documented values (docs/replication.md): interior rhombs lose 22.0 % (coarse) and 21.3 % (refined) of their
# area.  Tolerance: the level's relative uncertainty (a/4)/h, the same rule as the side walls.
RHOMB_LOSS = {"single_coarse": 0.220, "single_refined": 0.213}


@pytest.mark.parametrize("name,variant", CASES)
def test_rhomb_area_loss_is_the_documented_one(single_runs, row_and_tol, name, variant):
    row, tol = row_and_tol(single_runs, name, variant)
    assert abs(row["rhomb_loss_mean"] - RHOMB_LOSS[name]) <= tol["side"][0]


@pytest.mark.xfail(strict=True, reason="the activated rhomb diagonal is a linear spring, not a rigid bar: interior "
                   "rhombs lose ~22 % of their area, not at most 8.6 % (docs/replication.md, claims)")
@pytest.mark.parametrize("name,variant", CASES)
def test_rhombs_lose_at_most_the_paper_bound(single_runs, row_and_tol, name, variant):
    row, _ = row_and_tol(single_runs, name, variant)
    assert row["rhomb_loss_mean"] <= 1 - 0.9141


def test_mechanism_limit_is_the_papers_geometry():
    """Section 5: the vertical diagonal a - u enters the pair range a / sqrt(2) at u = 0.293 a, A/A_0 = 0.9141."""
    u = 1 - 1 / np.sqrt(2)
    assert u == pytest.approx(0.293, abs=5e-4) and 1 - u**2 == pytest.approx(0.9141, abs=2e-4)
    rhomb = np.array([[0.0, 0.0], [5.0, 5.0], [0.0, 10.0], [-5.0, 5.0]])  # a = 10 cm
    assert isa_theory.polygon_area(rhomb, np.array([[0, 1, 2, 3]]))[0] == pytest.approx(50.0)
