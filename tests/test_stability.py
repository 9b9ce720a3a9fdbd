"""Stability classes: each outcome is produced by a small scene, recorded in the run
file's status with its message, and never hides NaN positions or a wall crossing."""

import copy

import numpy as np
import pytest

from isaflow import runfile
from isaflow.methods.isa import tables

from conftest import BOX, OUTCOMES as ALL, TINY, run_spec, scene_of, vessel
from isaflow.core import geometry as GEO
from isaflow.methods.isa import relax as R




def scene(**changes):
    """TINY with top-level sections replaced or solver fields updated (solver=...)."""
    spec = copy.deepcopy(TINY)
    solver = changes.pop("solver", {})
    spec.update(changes)
    spec["solver"].update(solver)
    return spec


def run(tmp_path, spec):
    """Run a scene through isaflow.run (the command line's path), every outcome accepted; the run file."""
    out = tmp_path / "run.nc"
    assert run_spec(tmp_path, spec, out, accept=ALL) == 0
    return runfile.read(out)


def check_honest(ds):
    """Outcome invariants: finite positions unless nonfinite, and inside the walls unless escaped."""
    pos = ds["pos"].values
    status = ds.attrs["status"]
    if status != "nonfinite":
        assert np.isfinite(pos).all()
    if status not in ("escaped", "nonfinite"):
        w = ds["wall_segment"].values.reshape(-1, 2)
        assert ((pos >= w.min(0) - 1e-9) & (pos <= w.max(0) + 1e-9)).all()


def test_converged(tmp_path):
    ds = run(tmp_path, scene())
    assert ds.attrs["status"] == "converged"
    assert ds.attrs["status_message"].startswith("max|F| = ") and "< f_tol = 0.1 N after" in ds.attrs["status_message"]
    # equilibrium: every residual below f_tol and the walls carry the 4 x 50 N
    assert np.abs(ds["force"].values).max() < 0.1
    assert float(ds["wall_resultant"].sel(xy="y").sum()) == pytest.approx(200.0, abs=4 * 0.1)
    check_honest(ds)


def test_cycle_of_the_paper_update(tmp_path):
    """The literal update x += du F / max|F| cannot go below ~lambda_max du / 2: a period-2 cycle."""
    ds = run(tmp_path, scene(solver={"variant": "paper"}))
    assert ds.attrs["status"] == "cycle" and int(ds.attrs["cycle_period"]) == 2
    assert "max|F| repeats with period 2 steps between" in ds.attrs["status_message"]
    assert float(ds["residual"]) > 0.1  # never reaches f_tol
    check_honest(ds)


def test_step_limit(tmp_path):
    ds = run(tmp_path, scene(solver={"max_steps": 50}))
    assert ds.attrs["status"] == "step_limit" and int(ds["steps"]) == 50
    assert ds.attrs["status_message"] == f"max|F| = {float(ds['residual']):.4g} N >= f_tol = 0.1 N after 50 steps"
    assert float(ds["residual"]) > 0.1  # not yet settled
    check_honest(ds)


def test_escaped_across_a_wall_is_refused_and_reported(tmp_path):
    # a particle 5.5 cm above the floor (out of the wall's 5 cm reach) and a 6 cm step straight down
    spec = scene(particles={"weight": 50.0, "points": [[10.0, 5.5]]}, solver={"variant": "paper", "du": 6.0})
    ds = run(tmp_path, spec)
    assert ds.attrs["status"] == "escaped"
    assert ds.attrs["status_message"] == ("particle 0 at (10, 5.5) cm would cross wall 'floor' at step 0; "
                                          "step refused, run stopped")
    np.testing.assert_array_equal(ds["pos"].values, ds["pos0"].values)  # the step was not taken
    assert tables.outcome_detail("escaped", ds.attrs["status_message"]) == "crossed a wall (step refused)"


def test_escaped_through_a_gap_leaves_the_bounding_box():
    """A 4 cm gap in the floor (a tank the tank check refuses, so the solver runs it in memory): a particle
    heavier than both gap ends can push (2 R_bu) falls through and the solver says so."""
    from isaflow.methods.isa import scene as scenes, solver

    walls = [BOX[0], {"name": "floor_a", "from": [0, 0], "to": [8, 0]},
             {"name": "floor_b", "from": [12, 0], "to": [20, 0]}, BOX[2]]
    spec = scene(walls=walls, particles={"weight": 1.0e5, "points": [[10.0, 5.0]]}, solver={"du": 0.1})
    sc = scene_of(spec)
    pos0, weight, start, _ = scenes.initial_state(sc)
    res = solver.solve(sc, pos0, weight, start_step=start)
    assert res.status == "escaped"
    assert res.message.startswith("1 particle(s) left the walls' bounding box by step ")
    assert res.pos[0, 1] < 0.0  # below the floor, not silently inside
    assert tables.outcome_detail("escaped", res.message) == "left the walls' bounding box"


def test_nonfinite_forces_stop_the_run(tmp_path):
    # R_bu = 1e308 N: at 0.1 cm from the floor R_b / l_b = 1e308 (1/0.1 - 1/5) overflows
    spec = scene(particles={"weight": 50.0, "points": [[10.0, 0.1]]},
                 forces={**TINY["forces"], "wall": {"law": "linear", "l_u": 5.0, "r_u": 1.0e308}})
    ds = run(tmp_path, spec)
    assert ds.attrs["status"] == "nonfinite"
    assert ds.attrs["status_message"] == "non-finite forces at step 0"
    assert int(ds["steps"]) == 0 and not np.isfinite(ds["force"].values).all()
    np.testing.assert_array_equal(ds["pos"].values, ds["pos0"].values)  # no step was taken on NaN forces


@pytest.mark.parametrize("du", [0.001, 0.1, 1.0, 3.0, 10.0])
@pytest.mark.parametrize("variant", ["paper", "capped", "fire"])
def test_no_outcome_hides_nan_or_a_tunnelled_particle(tmp_path, variant, du):
    """Across step lengths up to a = 10 cm, every run either keeps all particles finite
    and inside the walls or says why not."""
    walls = vessel(20, 40)
    spec = scene(walls=walls, particles={**TINY["particles"], "lattice": {**TINY["particles"]["lattice"], "rows": 5}},
                 solver={"variant": variant, "du": du, "max_steps": 5000})
    ds = run(tmp_path, spec)
    assert str(int(ds["steps"])) in ds.attrs["status_message"]  # every outcome says where it stopped
    check_honest(ds)
    if ds.attrs["status"] == "escaped":
        assert "would cross wall" in ds.attrs["status_message"] or "bounding box" in ds.attrs["status_message"]


def test_particles_exactly_on_walls_are_pushed_into_the_liquid(tmp_path):
    """Distance zero from a wall (floor, corner, a wall's free end): pushed along the wall's
    left normal, never out; all settle inside."""
    points = [[10.0, 0.0], [0.0, 10.0], [0.0, 0.0], [20.0, 20.0]]
    ds = run(tmp_path, scene(particles={"weight": 50.0, "points": points}))
    assert ds.attrs["status"] == "converged"
    pos = ds["pos"].values
    assert (pos[:, 0] > 0).all() and (pos[:, 0] < 20).all() and (pos[:, 1] > 0).all()
    check_honest(ds)


def test_landing_exactly_on_an_interior_wall_is_reported():
    # a shelf across the box at y = 10; a particle far heavier than R_bu at y = 10.25 with du = 0.25
    # would land exactly on the shelf (10.25 - 0.25 = 10.0): refused at step 0, nothing moves
    walls = np.array([[0, 20, 0, 0], [0, 0, 20, 0], [20, 0, 20, 20], [0, 10, 20, 10]], float)
    pos = np.array([[10.0, 10.25]])
    f = np.zeros_like(pos)
    steps, status, info = R.relax(pos, np.zeros_like(pos), np.array([1.0e6]), walls, np.array([0, 0, 20, 20.0]),
                                  5.0, 1.0e4, 7.07, 3535.0, R.PAPER, 0.25, 1.0, 1.0, 0.1, 3, 1.0, f, np.zeros(3))
    assert (steps, status, info) == (0, R.CROSSED, 0 * 4 + 3)  # particle 0, wall 3 (the shelf)
    assert pos[0, 1] == 10.25


def test_leaving_a_wall_to_its_back_side_is_refused():
    floor = np.array([[0, 0, 20, 0]], float)
    assert GEO.crossed_wall(5.0, 0.0, 5.0, -0.1, floor) == 0  # on the floor, moving below it
    assert GEO.crossed_wall(5.0, 0.0, 5.0, 0.1, floor) == -1  # on the floor, moving into the liquid
    assert GEO.crossed_wall(25.0, 0.1, 25.0, 0.0, floor) == -1  # landing on the floor's line beyond its end
