"""ISA as a tank method: what isaflow.run calls (check, solve, warm_up, REFERENCES).

A run is a tank, the ISA settings of one resolution (config/methods/isa.yaml),
an update rule (the variant) and optionally a start file (a previous ISA run
whose final state this run continues).  Units: cm, N.
"""

import numpy as np

from . import scene as scenes
from . import solver
from .settings import RULES

REFERENCES = ("Papadopoulos, Koutitas & Lazaridis (2016), Open J. Civil Eng. 6, 397-409, "
              "doi:10.4236/ojce.2016.63034")


def _scene(tank, settings, variant, start):
    if variant not in RULES:
        raise scenes.SceneError(f"{settings.path}: variant '{variant}': no update rule of that name "
                                f"(choose from {', '.join(RULES)})")
    return scenes.build(tank, settings, variant, start)


def check(tank, settings, start=None):
    """Every check that can refuse the run (scene geometry, memory, start file); InputError naming the field."""
    scene = _scene(tank, settings, settings.variant, start)
    if start is not None:
        scenes.start_file(scene)


def warm_up(threads=None):
    """Compile (or load from numba's cache) every kernel a run times, and the replay's (a derived job's)."""
    from . import replay  # imports xarray: only where a run warms up

    solver.warm_up(solver.thread_count(threads))
    replay.warm_up()


def tank_difference(tank, pos0, weight, pitch, floor_y):
    """(held_weight N, initial_depth cm, one line) of an initial ISA state against the tank's liquid."""
    held = float(np.sum(weight))
    depth = float(pos0[:, 1].max() + pitch / 2 - floor_y) if len(pos0) and np.isfinite(pitch) else float("nan")
    notes = []
    if not np.isclose(held, tank.weight, rtol=1e-9):
        notes.append(f"weight held {held:.6g} N (tank {tank.weight:.6g} N)")
    if np.isfinite(depth):
        notes.append(f"initial lattice {depth:.4g} cm deep; ISA's depth is the equilibrium's (tank {tank.depth:.4g} cm)")
    return held, depth, "; ".join(notes) or "none"


def solve(tank, settings, variant, resolution, start=None, log=None, threads=None):
    """Relax the scene of tank, settings and variant (from start's final state if given) -> contract.Result."""
    scene = _scene(tank, settings, variant, start)
    extra = {}
    if start is None:
        pos0, weight, start_step, spacing = scenes.initial_state(scene)
        state = None
        lattice = scene.spec["particles"].get("lattice")
        pitch = scenes.layer_pitch(lattice) if lattice else float("nan")
        held, depth, diff = tank_difference(tank, pos0, weight, pitch, tank.floor_y(0))
    else:
        st = scenes.start_file(scene)
        pos0, weight, start_step, spacing, state = st["pos"], st["weight"], st["steps"], st["spacing"], st["state"]
        pitch, held, depth, diff = st["chain"]
        extra = dict(restart=st["restart"], start_sha256=st["sha256"], start_step=st["steps"])
    result = solver.solve(scene, pos0, weight, start_step=start_step, log=log,
                          state=state, rest_depth=tank.depth, threads=threads)
    result.spacing = spacing
    result.params.update(layer_pitch=pitch, held_weight=held, initial_depth=depth, tank_difference=diff, **extra)
    return result
