"""Shared fixtures: repository paths and single-vessel runs solved once per session."""

from pathlib import Path

import numpy as np
import pytest

from isaflow import cli, runfile, scene
from isaflow.methods.isa import solver

ROOT = Path(__file__).resolve().parents[1]
SCENES = ROOT / "config" / "scenes"


def solve_scene(path, overrides=()):
    """Solve a scene file in memory; returns (Scene, Run)."""
    sc = scene.load(path, overrides)
    pos0, weight, start, _ = scene.initial_state(sc)
    return sc, solver.solve(sc, pos0, weight, start_step=start)


@pytest.fixture(scope="session")
def single_runs(tmp_path_factory):
    """Run files of both single-vessel scenes with both update rules."""
    out = {}
    tmp = tmp_path_factory.mktemp("runs")
    for name in ("single_coarse", "single_refined"):
        for variant in ("paper", "capped"):
            path = tmp / f"{name}_{variant}.nc"
            code = cli.run(str(SCENES / f"{name}.yaml"), str(path), [f"solver.variant={variant}"], quiet=True)
            assert code == 0
            out[name, variant] = runfile.read(path)
    return out


def box_walls(width=100.0, height=100.0):
    """(3, 4) left, floor, right walls of an open-top box [cm]."""
    return np.array([[0, height, 0, 0], [0, 0, width, 0], [width, 0, width, height]], float)
