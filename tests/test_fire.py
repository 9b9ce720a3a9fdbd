"""FIRE (methods.isa.relax, variant FIRE) on the paper's coarse single vessel: it reaches
the same equilibrium criterion as the capped update in far fewer force evaluations.
Units cm, N."""

import numpy as np

import pytest

from isaflow import metrics, runfile

from conftest import run_isa


def run(tmp_path, name, variant, *sets):
    out = tmp_path / f"{name}.nc"
    assert run_isa(out, "single", "coarse", variant, sets) == 0
    return runfile.read(out)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("fire")
    return (run(tmp, "capped", "capped"), run(tmp, "fire", "fire", "solver.du=1.0", "solver.dt_max=0.02"))


def test_fire_reaches_the_capped_equilibrium_in_far_fewer_steps(runs):
    capped, fire = runs
    for ds in (capped, fire):
        assert ds.attrs["status"] == "converged"
        assert np.abs(ds["force"].values).max() < 0.1  # f_tol
    # same free-surface level to a / 4 = 2.5 cm (the single-vessel tolerance)
    level = metrics.load_errors(fire, None, "level")["level"]
    assert abs(level - metrics.load_errors(capped, None, "level")["level"]) < 2.5
    # every step is one force evaluation.  Bound: 1/20 of the capped update's steps
    # (9,964 -> 498), a margin below the 50x that FIRE does not reach here
    # (298 steps, 33x; FIRE 2.0 was tried: 278 coarse but 805 refined, so not kept);
    # the paper's update never converges.
    assert int(fire["steps"]) < int(capped["steps"]) / 20


@pytest.mark.xfail(strict=True, reason="FIRE needs 298 steps against the capped update's 9,964 (33x), short of "
                   "the 50x target (benchmarks: error-vs-run-time study, fire_ratio.csv)")
def test_fire_needs_50_times_fewer_force_evaluations(runs):
    capped, fire = runs
    assert int(fire["steps"]) * 50 <= int(capped["steps"])
