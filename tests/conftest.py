"""Shared fixtures: repository paths and single-vessel runs solved once per session."""

from pathlib import Path

import numpy as np
import pytest

from isaflow import cli, runfile, scene
from isaflow.methods.isa import solver

ROOT = Path(__file__).resolve().parents[1]
SCENES = ROOT / "config" / "scenes"

# the coarse lattice's force laws (config/scenes/single_coarse.yaml): cm, N
L_B, R_B = 5.0, 10000.0  # wall: l_bu, R_bu (k_b = 2000 N/cm)
L_P, R_P = 7.0710678, 3535.5339  # pair: l_pu = a / sqrt(2), R_pu (k_p = 500 N/cm)
OUTCOMES = ["converged", "cycle", "step_limit", "escaped", "nonfinite"]  # the ISA solver's outcomes
BOX = [{"name": "left", "from": [0, 20], "to": [0, 0]}, {"name": "floor", "from": [0, 0], "to": [20, 0]},
       {"name": "right", "from": [20, 0], "to": [20, 20]}]
# four particles of the coarse lattice in a 20 cm box (w = 50 N, k_b = 2000, k_p = 500 N/cm)
TINY = {
    "name": "tiny",
    "walls": BOX,
    "particles": {"weight": 50.0, "lattice": {"a": 10.0, "rows": 3, "row_lengths": [1, 2], "center_x": 10.0,
                                              "bottom_y": 5.0}},
    "forces": {"wall": {"law": "linear", "l_u": L_B, "r_u": R_B}, "pair": {"law": "linear", "l_u": L_P, "r_u": R_P}},
    "solver": {"variant": "capped", "du": 0.01, "f_tol": 0.1, "max_steps": 20000},
}


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
