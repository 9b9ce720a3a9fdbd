"""Restarts (issue 9, item 4): a run split at any step and continued from its run file
repeats the uninterrupted run bit for bit, for all three update rules.

A column of 22 particles of the coarse lattice spreading over the floor of an
80 cm vessel (particles cross cells, so a neighbour list built at the split
step would sum forces in another order), with a skin of 4 cm (lists live
long between builds), chunks of 1,000 steps, and a max|F| record stride of
7 steps that does not divide the chunk.  Split steps are drawn at random (seeded) inside the run,
plus a chunk multiple and the step after it; and, for the paper's rule in a
settled vessel where it cycles, steps inside the window that detects the
cycle.
Compared exactly (np.array_equal): every data variable of the uninterrupted
run, except pos0 / start_step / force_evals / wall_time (they describe the
continued run itself); records (hist_*) from the split step on, chunk-end samples
after it, snapshots (snap_*, each run's own from its start) at the steps both runs
keep, the stop among them (the force of the continued run's first snapshot is not
evaluated yet: NaN, said so).
"""

import numpy as np
import pytest
from conftest import LAWS, coarse_lattice, run_spec, vessel

from isaflow import runfile

SCENE = {
    "name": "restart",
    "walls": vessel(80, 80),
    "particles": coarse_lattice(9, [2, 3], 15.0),
    "forces": LAWS,
    "solver": {"variant": "paper", "du": 0.01, "f_tol": 0.1, "max_steps": 8000, "chunk": 1000, "skin": 4.0,
               "accept": ["converged", "cycle", "step_limit"], "history": {"every": 7, "walls": True}},
}
RULES = {  # rule: solver overrides (FIRE as in test_fire: du is only a move cap)
    "paper": {},
    "capped": {"variant": "capped", "f_ref": 5.0},
    "fire": {"variant": "fire", "du": 1.0, "dt_max": 0.02},
}
OWN = {"pos0", "start_step", "force_evals", "wall_time"}  # properties of the continued run itself


# the same lattice settled in a 40 cm vessel: the paper's rule ends in a limit cycle
SETTLED = {**SCENE, "walls": vessel(40, 60), "particles": coarse_lattice(7, [3, 4], 20.0)}


def run(tmp_path, name, rule, *sets, base=SCENE, start=None):
    spec = {**base, "solver": {**base["solver"], **RULES[rule]}}
    spec["solver"].pop("accept", None)
    out = tmp_path / f"{name}.nc"
    assert run_spec(tmp_path, spec, out, sets, start) == 0
    return out


def assert_continues(whole, leg2, split):
    assert leg2.attrs["restart"].startswith("solver state restored")
    assert int(leg2["start_step"]) == split
    for attr in ("status", "status_message", "cycle_period"):
        assert str(whole.attrs[attr]) == str(leg2.attrs[attr]), attr
    compared = 0
    for name in whole.data_vars:
        if name in OWN:
            continue
        a, b = whole[name], leg2[name]
        if "record" in a.dims:
            a = a.isel(record=whole["hist_step"].values >= split)
        if "sample" in a.dims:
            a = a.isel(sample=whole["sample_step"].values > split)
        if "snapshot" in a.dims:  # each run keeps snapshots on its own clock, from its start: the steps both keep
            common = np.intersect1d(whole["snap_step"].values, leg2["snap_step"].values)
            assert common[-1] == int(whole["steps"]), "the stop is a snapshot of both"
            if name == "snap_force":  # the continued run's start: its force is not evaluated yet (NaN, said so)
                assert np.isnan(b.values[0]).all() and "missing" in b.attrs
                common = common[common != split]
            a = a.isel(snapshot=np.isin(whole["snap_step"].values, common))
            b = b.isel(snapshot=np.isin(leg2["snap_step"].values, common))
        assert a.shape == b.shape, (name, a.shape, b.shape)
        assert np.array_equal(a.values, b.values), f"{name} differs after a restart at step {split}"
        compared += 1
    assert compared >= 15


def split_and_compare(tmp_path, rule, splits, base=SCENE):
    whole = runfile.read(run(tmp_path, "whole", rule, base=base))
    total = int(whole["steps"])
    for split in sorted(s for s in splits(total) if 0 < s < total):
        leg1 = run(tmp_path, f"leg1_{split}", rule, f"solver.max_steps={split}", base=base)
        assert int(runfile.read(leg1)["steps"]) == split
        leg2 = run(tmp_path, f"leg2_{split}", rule, base=base, start=leg1)
        assert_continues(whole, runfile.read(leg2), split)
    return whole


@pytest.mark.parametrize("rule", list(RULES))
def test_split_runs_repeat_the_uninterrupted_run_bit_for_bit(tmp_path, rule):
    rng = np.random.default_rng(1)  # the same steps for every rule: paper and capped coincide while max|F| > f_ref
    whole = split_and_compare(tmp_path, rule, lambda total: {int(s) for s in rng.integers(1, total, 6)} | {1000, 1001})
    assert int(whole["steps"]) > 800, "the run must be long enough to split"


def test_a_split_inside_the_cycle_window_repeats_the_uninterrupted_run(tmp_path):
    """The 450 max|F| values that detect the paper rule's cycle straddle the restart (137 and 37 steps
    before the chunk end that detects it): the window is restored from the run file."""
    whole = split_and_compare(tmp_path, "paper", lambda total: {total - 137, total - 37}, base=SETTLED)
    assert whole.attrs["status"] == "cycle" and int(whole["steps"]) % 1000 == 0


def test_a_changed_scene_continues_from_positions_only(tmp_path):
    """Another update rule (or walls, laws, du, ...) is a new problem from a previous state, as in the
    paper's applications 3-4: the run file says so, and the continued run starts FIRE and the list afresh."""
    leg1 = run(tmp_path, "leg1", "paper", "solver.max_steps=150")
    leg2 = runfile.read(run(tmp_path, "leg2", "capped", "solver.max_steps=300", start=leg1))
    assert leg2.attrs["restart"].startswith("positions only") and "variant" in leg2.attrs["restart"]
    assert leg2.attrs["start_sha256"] == runfile.sha256(leg1) and leg2.attrs["start_file"] == str(leg1)


def test_chunks_replayed_inside_an_exact_cycle_change_no_output(monkeypatch):
    """With the cycle stop off, a chunk whose input arrays repeat bit for bit is replayed from memory
    (solver.ChunkMemo): the single coarse vessel's paper rule, 100,000 steps (it cycles from about
    step 50,000), gives the same arrays, to the last bit, as the run that computes every chunk."""
    from conftest import solve_scene

    from isaflow.methods.isa import solver

    sets = ["solver.stop_on_cycle=false", "solver.max_steps=100000"]
    _, memo = solve_scene("single", "coarse", overrides=sets)
    monkeypatch.setattr(solver.ChunkMemo, "get", lambda *a: None)
    _, plain = solve_scene("single", "coarse", overrides=sets)
    assert memo.params["replayed_chunks"] > 10 and plain.params["replayed_chunks"] == 0
    assert memo.status == plain.status == "step_limit" and memo.steps == plain.steps == 100000
    for name in ("pos", "contact_force", "residual"):
        assert np.array_equal(getattr(memo, name), getattr(plain, name)), name
    for group in ("history", "fields"):
        a, b = getattr(memo, group), getattr(plain, group)
        assert a.keys() == b.keys()
        for k in a:  # the first snapshot's force is not evaluated yet in either (NaN, said so)
            assert np.array_equal(a[k][1], b[k][1], equal_nan=np.asarray(a[k][1]).dtype.kind == "f"), k
