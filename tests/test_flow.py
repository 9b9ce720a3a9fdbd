"""Flow applications 3-4: mass conservation, walls never crossed, restart
equivalence, and the CI tolerance check at the end of the complete flow."""

import numpy as np
import pytest

from isaflow import metrics, runfile

from conftest import run_declared

PAPER = {"particles_left": 14, "level_second": 32.0}
A = 10.0  # coarse lattice diagonal, cm


def run(tmp, name, run_id, start=None):
    out = tmp / f"{name}.nc"
    assert run_declared(out, run_id, start) == 0
    return out


@pytest.fixture(scope="module")
def chain(tmp_path_factory):
    """Application 1 -> 3 -> 4 (paper's update) and 4 with the capped variant (config/methods/isa.yaml runs)."""
    tmp = tmp_path_factory.mktemp("flow")
    app1 = run(tmp, "app1", "single_coarse")
    app3 = run(tmp, "app3", "flow_incomplete", app1)
    app4 = run(tmp, "app4", "flow_complete", app3)
    app4c = run(tmp, "app4c", "flow_complete_capped", app3)
    return {k: runfile.read(v) for k, v in dict(app1=app1, app3=app3, app4=app4, app4c=app4c).items()}


def test_every_particle_is_in_one_vessel_at_every_recorded_step(chain):
    for key in ("app3", "app4", "app4c"):
        ds = chain[key]
        counts = ds["sample_vessel_count"].values
        assert counts.shape[0] >= 10
        assert (counts.sum(1) == 180).all()
        assert metrics.flow_measures(ds)["mass_conserved"]


def test_particles_stay_inside_the_walls(chain):
    for key in ("app3", "app4", "app4c"):
        ds = chain[key]
        assert ds.attrs["status"] != "escaped"
        x, y = ds["pos"].values.T
        first, second = x < 100, x >= 100
        assert (x > 0).all() and (x < 300).all()
        assert (y[first] > 0).all() and (y[second] > -50).all()
        snaps = ds["snap_pos"].values if "snap_pos" in ds else []  # runs ending early keep fewer
        for snap in snaps:
            assert np.isfinite(snap).all() and (snap[:, 0] > 0).all() and (snap[:, 0] < 300).all()


def test_steps_chain_from_the_start_of_application_1(chain):
    assert int(chain["app3"]["start_step"]) == int(chain["app1"]["steps"])
    assert int(chain["app3"]["steps"]) == 100000
    assert int(chain["app4"]["start_step"]) == 100000
    # application 3 is not in equilibrium: large forces and sum F_x >> N f_tol, to the right
    fm = metrics.flow_measures(chain["app3"])
    assert fm["sum_fx_N"] > 5 * 180 * 0.1 and float(chain["app3"]["residual"]) > 1.0
    assert fm["particles_second"] > 90  # "more than half"


def test_restart_from_a_state_file_repeats_an_uninterrupted_run(tmp_path, chain):
    app1 = tmp_path / "app1.nc"
    runfile.write(chain["app1"], app1)
    start = int(chain["app1"]["steps"])
    def leg(name, start_file, max_steps):
        out = tmp_path / f"{name}.nc"
        assert run_declared(out, "flow_incomplete", start_file, [f"solver.max_steps={max_steps}"]) == 0
        return out

    whole = leg("whole", app1, start + 7000)
    leg1 = leg("leg1", app1, start + 3000)
    leg2 = leg("leg2", leg1, start + 7000)
    a, b = runfile.read(whole), runfile.read(leg2)
    assert int(a["steps"]) == int(b["steps"]) == start + 7000
    np.testing.assert_array_equal(a["pos"].values, b["pos"].values)
    np.testing.assert_array_equal(a["force"].values, b["force"].values)


def test_second_vessel_level_matches_the_paper(chain):
    for key in ("app4", "app4c"):
        e = metrics.load_errors(chain[key], "second", "level")
        assert abs(e["depth"] - PAPER["level_second"]) <= A / 4


def test_level_matches_the_liquid_moved(chain):
    """Depth in the second vessel = (moved / N) x (level of application 1) / 2 within a/4:
    the rhombic lattice keeps its density through the flow (the paper's incompressibility check)."""
    ds = chain["app4c"]
    moved = metrics.flow_measures(ds)["particles_second"]
    level1 = metrics.load_errors(chain["app1"], None, "level")["level"]
    assert metrics.load_errors(ds, "second", "level")["depth"] == pytest.approx(moved / 180 * level1 / 2, abs=A / 4)


@pytest.mark.parametrize("key", ["app4", "app4c"])
def test_all_floors_together_carry_the_weight(chain, key):
    """Vertical and horizontal equilibrium of the whole liquid to the paper's standard: |sum| <= N f_tol
    (holds even in the literal update's cycle: its residual forces nearly cancel over the liquid)."""
    R = chain[key]["wall_resultant"].values.sum(0)
    assert abs(R[1] - 9000.0) <= 180 * 0.1 and abs(R[0]) <= 180 * 0.1


@pytest.mark.xfail(strict=True, reason="the particles left at the opening lean on the second vessel's liquid: its "
                   "floor carries 0.7 % more than its own particles' weight (the bound N f_tol / W holds for the "
                   "whole liquid only)")
def test_second_vessel_floor_carries_its_liquid(chain):
    e = metrics.load_errors(chain["app4c"], "second", "level")
    assert abs(e["floor_err"]) <= (e["weight"] / 50.0) * 0.1 / e["weight"]  # N_2 f_tol / W_2


@pytest.mark.xfail(strict=True, reason="the second vessel's lattice keeps the lateral stress of the inflow "
                   "(stress ratio ~1.75): side walls carry ~30 % more than hydrostatics (docs/replication.md)")
def test_second_vessel_side_walls_match_hydrostatics(chain):
    e = metrics.load_errors(chain["app4c"], "second", "level")
    assert abs(e["side_err"]) <= (A / 4) / e["depth"]


@pytest.mark.xfail(strict=True, reason="about 30 particles (three floor layers) stay behind, for du x0.5..x2, "
                   "against the paper's 14 (docs/replication.md, Flow sensitivity)")
def test_particles_left_match_the_paper(chain):
    left = metrics.flow_measures(chain["app4c"])["particles_left"]
    assert abs(left - PAPER["particles_left"]) <= 100 / A / 2


def test_particles_left_regression(chain):
    """Regression: 30 particles stay behind, within half a floor row (5)."""
    for key in ("app4", "app4c"):
        assert abs(metrics.flow_measures(chain[key])["particles_left"] - 30) <= 100 / A / 2


# -- the second vessel's surface (a liquid at rest is flat) -----------------------
# Documented: slope -10.2 deg, range 39.8 cm (docs/replication.md).  Tolerances from the lattice: one row
# pitch a/2 at one end of the 200 cm vessel moves the slope by atan((a/2)/200 cm) = 1.4 deg; the range by a/2.
SLOPE_TOL = np.degrees(np.arctan((A / 2) / 200.0))


@pytest.mark.parametrize("key", ["app4", "app4c"])
def test_second_vessel_surface_is_the_documented_heap(chain, key):
    s = metrics.surface_measures(chain[key], "second")
    assert abs(s["slope_deg"] - (-10.2)) <= SLOPE_TOL and abs(s["surface_range_cm"] - 39.8) <= A / 2


@pytest.mark.xfail(strict=True, reason="the lattice ends as a heap (slope ~10 deg), not a flat liquid surface "
                   "(docs/replication.md, claims)")
def test_second_vessel_surface_is_flat_like_a_liquid(chain):
    assert metrics.surface_measures(chain["app4c"], "second")["surface_range_cm"] <= A / 2
