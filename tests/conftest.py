"""Shared fixtures: repository paths and single-vessel runs solved once per session."""

from pathlib import Path

import numpy as np
import pytest

from isaflow import run, runfile
from isaflow.core import jit
from isaflow.preflight import UNSTABLE
from isaflow.methods.isa import scene, solver


ROOT = Path(__file__).resolve().parents[1]
TANKS = ROOT / "config" / "tanks"
ISA_SETTINGS = ROOT / "config" / "methods" / "isa.yaml"


def pytest_configure(config):
    """Kernels, before any test: with pytest-xdist the controller (which runs no test) first compiles and seals
    every tank method's generation, its processes in parallel, exactly as a run does (run.compile_method), so
    the workers, and the runs and workflow jobs the tests start, load them instead of each compiling them
    again.  A process that runs tests binds a generation of its own (``tests``, or ``tests-<worker>``: its
    core, solid and 1D kernels, sealed at exit), so workflow jobs the tests start never meet a test session
    that writes theirs, and reads the tank methods' sealed generations beside it (core.jit.read_also)."""
    import os
    import subprocess
    import sys

    from isaflow import methods

    names = list(methods.tank_methods())
    worker = os.environ.get("PYTEST_XDIST_WORKER")
    if worker is None and (getattr(config.option, "numprocesses", 0) or 0) > 0:
        procs = [subprocess.Popen([sys.executable, "-c", f"from isaflow import run; run.compile_method({m!r})"],
                                  cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
                 for m in names]
        for m, p in zip(names, procs):
            _, err = p.communicate()
            if p.returncode:  # the tests then compile these kernels themselves
                print(f"conftest: compiling {m}'s kernels failed:\n{err[-2000:]}", file=sys.stderr)
        return
    jit.use("tests" if worker is None else f"tests-{worker}")
    jit.read_also(*names)

# the coarse lattice's force laws (config/methods/isa.yaml, resolution coarse): cm, N
L_B, R_B = 5.0, 10000.0  # wall: l_bu, R_bu (k_b = 2000 N/cm)
L_P, R_P = 7.0710678, 3535.5339  # pair: l_pu = a / sqrt(2), R_pu (k_p = 500 N/cm)
OUTCOMES = ["converged", "cycle", "step_limit", "escaped", "nonfinite"]  # the ISA solver's outcomes
LAWS = {"wall": {"law": "linear", "l_u": L_B, "r_u": R_B}, "pair": {"law": "linear", "l_u": L_P, "r_u": R_P}}


def vessel(width, height):
    """Walls mapping [cm] of an open vessel from the origin: left wall, floor, right wall."""
    return [{"name": "left", "from": [0, height], "to": [0, 0]}, {"name": "floor", "from": [0, 0], "to": [width, 0]},
            {"name": "right", "from": [width, 0], "to": [width, height]}]


def coarse_lattice(rows, row_lengths, center_x):
    """Particles mapping of the coarse lattice (a = 10 cm, w = 50 N), rows of row_lengths alternating, centred
    at center_x [cm], the bottom row at y = 5 cm."""
    return {"weight": 50.0, "lattice": {"a": 10.0, "rows": rows, "row_lengths": row_lengths, "center_x": center_x,
                                        "bottom_y": 5.0}}


BOX = vessel(20, 20)
# four particles of the coarse lattice in a 20 cm box (w = 50 N, k_b = 2000, k_p = 500 N/cm)
TINY = {"name": "tiny", "walls": BOX, "particles": coarse_lattice(3, [1, 2], 10.0), "forces": LAWS,
        "solver": {"variant": "capped", "du": 0.01, "f_tol": 0.1, "max_steps": 20000}}
TINY_TANK = {"name": "tiny", "walls": BOX, "liquid": {"weight": 200.0, "depth": 10.0}}


def solve_scene(tank, resolution, variant="paper", overrides=()):
    """Solve an ISA scene (tank name, resolution of config/methods/isa.yaml, update rule) in memory;
    returns (Scene, Result)."""
    sc = scene.of_run(tank, resolution, variant, overrides, ISA_SETTINGS)
    pos0, weight, start, _ = scene.initial_state(sc)
    return sc, solver.solve(sc, pos0, weight, start_step=start)


def run_isa(out, tank="single", resolution="coarse", variant="paper", overrides=(), start=None,
            accept=("converged", "cycle", "step_limit")):
    """Run ISA through isaflow.run (the command line's path) into ``out``; returns the exit code."""
    return run.run("isa", str(TANKS / f"{tank}.yaml"), variant, resolution, str(out), str(ISA_SETTINGS),
                   list(overrides), None if start is None else str(start), accept, log=lambda m: None)


def run_declared(out, run_id, start=None, overrides=(), variant=None):
    """Run a run declared in config/methods/isa.yaml (its tank, rule, resolution, overrides) into ``out``,
    continuing ``start``; extra overrides ('key=value') after the declaration's; variant: another update
    rule than the declaration's (None: its own); returns the exit code."""
    from isaflow import settings as S
    from isaflow.methods.isa.settings import VALUES

    decl = S.read(ISA_SETTINGS, VALUES)["runs"][run_id]
    sets = {**decl.get("set", {}), **dict(S._parse(o, "test", "override") for o in overrides)}
    return run.run("isa", str(TANKS / f"{decl['tank']}.yaml"), variant or decl["variant"], decl["resolution"],
                   str(out), str(ISA_SETTINGS), sets, None if start is None else str(start),
                   ("converged", "cycle", "step_limit"), log=lambda m: None)


@pytest.fixture(scope="session")
def single_runs(tmp_path_factory):
    """Run files of both paper lattices (resolutions coarse and refined) with both update rules,
    keyed by their old scene names."""
    out = {}
    tmp = tmp_path_factory.mktemp("runs")
    for res in ("coarse", "refined"):
        for variant in ("paper", "capped"):
            path = tmp / f"single_{res}_{variant}.nc"
            assert run_isa(path, "single", res, variant) == 0
            out[f"single_{res}", variant] = runfile.read(path)
    return out


def box_walls(width=100.0, height=100.0):
    """(3, 4) left, floor, right walls of an open-top box [cm]."""
    return np.array([[0, height, 0, 0], [0, 0, width, 0], [width, 0, width, height]], float)


def settings_spec(spec):
    """An ISA settings mapping (config/methods/isa.yaml's dialect, one resolution 'r') of a scene mapping
    (name, walls, vessels, particles, forces, solver with its variant, as methods.isa.scene.spec_of builds
    it): lets a test run any scene through isaflow.run, the path every run takes."""
    src = "inferred: test scene"
    leaf = lambda v: {"value": v, "source": src}  # noqa: E731
    part, sol = spec["particles"], spec["solver"]
    lat = {"kind": "rhombic", "jitter": 0.0, "seed": 0,
           **part.get("lattice", {"a": 10.0, "rows": 1, "row_lengths": [1], "center_x": 0.0, "bottom_y": 0.0})}
    return {
        "particles": {"weight": leaf(part["weight"]), "points": leaf(part.get("points")),
                      "lattice": {k: leaf(v) for k, v in lat.items()}},
        "forces": {w: {k: leaf(v) for k, v in spec["forces"][w].items()} for w in ("wall", "pair")},
        "solver": {k: leaf(sol.get(k, d)) for k, d in (("du", None), ("f_tol", None), ("max_steps", None),
                                                       ("f_ref", None), ("dt_max", None), ("skin", None),
                                                       ("chunk", 1000), ("stop_on_cycle", True), ("history", {}),
                                                       ("zeta", 1.0), ("lambda_max", 3176.4), ("dt", None),
                                                       ("snapshot_every_single", 5000), ("snapshot_every_flow", 2000),
                                                       ("snapshot_megabytes", 8.0))},
        "resolutions": {"r": {"source": src, "set": {}}},
        "variants": {"paper": {"set": {}}, "capped": {"set": {}}, "fire": {"set": {}}, "overdamped": {"set": {}},
                     "newton_lm": {"set": {}}},
    }


def tank_spec(spec):
    """The tank mapping of a scene mapping (its walls and vessels; a liquid 10 cm deep)."""
    n = len(spec["particles"].get("points", [])) or 1
    tank = {"name": "test_tank", "walls": spec["walls"], "liquid": {"weight": spec["particles"]["weight"] * n,
                                                                     "depth": 10.0}}
    if spec.get("vessels"):
        tank["vessels"] = spec["vessels"]
    return tank


def scene_of(spec):
    """A Scene of a scene mapping built in memory the way every run builds it: its settings validated and read
    by the one settings loader (settings_spec), then methods.isa.scene.build."""
    from isaflow import inputs, settings as S, tank as T
    from isaflow.methods.isa.settings import VALUES

    mapping = settings_spec(spec)
    inputs.validate(mapping, S.file_schema(VALUES), "<test settings>")
    s = S.load("<test settings>", VALUES, spec["solver"]["variant"], "r", spec=mapping)
    return scene.build(T.Tank("<test tank>", tank_spec(spec), ""), s, spec["solver"]["variant"])


def write_spec(tmp_path, spec, name="scene"):
    """(tank path, settings path) of a scene mapping written as a tank and an ISA settings file."""
    import yaml

    tank = tank_spec(spec)
    tp, sp = tmp_path / f"{name}_tank.yaml", tmp_path / f"{name}_settings.yaml"
    tp.write_text(yaml.safe_dump(tank))
    sp.write_text(yaml.safe_dump(settings_spec(spec)))
    return tp, sp


def run_spec(tmp_path, spec, out, overrides=(), start=None, accept=("converged", "cycle", "step_limit")):
    """Run a scene mapping through isaflow.run (its solver.variant is the update rule); returns the exit code."""
    tp, sp = write_spec(tmp_path, spec, f"scene_{abs(hash(str(out))) % 10**8}")
    stability = any(a in UNSTABLE for a in accept)  # the stability tests accept every outcome
    return run.run("isa", str(tp), spec["solver"]["variant"], "r", str(out), str(sp), list(overrides),
                   None if start is None else str(start), accept, log=lambda m: None, stability=stability)
