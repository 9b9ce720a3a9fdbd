"""MPS as a tank method: what isaflow.run calls (check, solve, warm_up, REFERENCES).

A run is a tank, the MPS settings of one source term (the variant) and spacing (the resolution), and
optionally a start file (an MPS run whose final state, clock and step count this run continues).  The
time limit is ``time.single_time`` in a single vessel and ``time.flow_time`` in a tank of vessels; a run
stops earlier once at rest (isaflow.rest).  Units: cm, N, s.
"""

from pathlib import Path

import numpy as np

from ... import runfile
from ...inputs import InputError
from . import boundary, model, solver

REFERENCES = ("Koshizuka & Oka (1996), Nucl. Sci. Eng. 123, 421; MPS-Basic (github.com/MPS-Basic/MPS-Basic); "
              "Hattori, Seta, Shibata & Koshizuka, 'A new derivation of pressure Poisson equation in MPS'; "
              "Tanaka & Masunaga (2010), J. Comput. Phys. 229, 4279")


def _flow(tank):
    return len(tank.spec.get("vessels", [])) > 1


def check(tank, settings, start=None):
    """Every check that can refuse the run before any work beyond checks.plausible's: a start file that is an MPS
    run of the run's spacing."""
    l0 = settings["resolution.spacing"]
    if start is not None:
        with runfile.open_run(start) as ds:
            problem = runfile.start_problem(ds, start, "mps", ("pos", "velocity", "steps", "sim_time", "spacing",
                                                                    "initial_depth"))
            if problem:
                raise InputError(f"--start: {problem}")
            if not np.isclose(float(ds.attrs["spacing"]), l0, rtol=1e-9):
                raise InputError(f"--start: '{start}' has spacing {ds.attrs.get('spacing')} cm, this run asks for "
                                 f"{l0:.6g} cm")


def start_state(path):
    """solver.solve's start dict of a run file: final positions and velocities, step count, time, the chain's
    initial depth."""
    ds = runfile.read(path)
    return dict(pos=ds["pos"].values, vel=ds["velocity"].values, steps=int(ds["steps"]), sim_time=float(ds["sim_time"]),
                initial_depth=float(ds.attrs["initial_depth"]),
                origin=f"final state of {Path(path).name} ({ds.attrs['status']}, t = {float(ds['sim_time']):.3f} s)")


def on_wall_start(tank, l0, point):
    """The liquid block at rest with the particle nearest ``point`` (x, y cm) moved onto it."""
    xr, floor = tank.first_vessel
    fluid = boundary.liquid_block(xr, floor, tank.depth, l0, tank.vessel_polygon(0), tank.walls)
    k = int(np.argmin(np.hypot(*(fluid - np.asarray(point) - [0, l0 / 2]).T)))
    fluid[k] = point
    return dict(pos=fluid, vel=np.zeros_like(fluid), steps=0, sim_time=0.0)


def warm_up(threads=None):
    """Compile (or load from numba's cache) every kernel a run times: a few steps of a small block."""
    from ...tank import Tank
    from . import settings as S

    tank = Tank("warm-up", {"name": "box", "walls": [{"name": "l", "from": [0, 20], "to": [0, 0]},
                                                      {"name": "f", "from": [0, 0], "to": [20, 0]},
                                                      {"name": "r", "from": [20, 0], "to": [20, 20]}],
                            "liquid": {"weight": 10.0, "depth": 10.0}}, "")
    for variant in ("standard", "hattori", "mixed"):
        cfg = S.resolved(variant=variant, resolution=None, overrides={"resolution.spacing": 2.0})
        solver.solve(tank, cfg, variant, 2.0, 3e-3, np.array([[10.0, 5.0]]), log=lambda msg: None, threads=threads)
    # what the claims' derived numbers (methods.mps.derived) and measures call beside a run's kernels (a run's step
    # fuses the stage kernels, model.step_cg): the plain pair distances, number density, velocity Laplacian and
    # gradient the step check recomputes its operators with, the one-particle source term of the dilation and the
    # relaxation factors hat-eq4-rho-star reports
    pos = np.array([[0.0, 0.0], [1.0, 0.0]])
    kind = np.zeros(2, np.int64)
    start, nbr = model.neighbour_list(pos, kind, np.array([-1.0, -1.0, 2.0, 1.0]), 1.5, np.full(2, -1, np.int64),
                                      np.ones(2, np.int64), np.zeros((0, 4)))
    dist = model.distances(pos, start, nbr)
    model.number_density(start, nbr, dist, 1.5)
    model.laplacian(np.zeros_like(pos), kind, start, nbr, dist, 1.5, 1.0, 1.0)
    model.gradient(pos, np.zeros(2), kind, start, nbr, dist, 1.5, 1.0, model.GRADIENTS["variational"])
    model.source_term(1.0, 1.0, 1.0, 1.0, 1.0, model.SOURCES["hattori"], 0.5, 1.0)
    model.relaxation_factors(model.SOURCES["hattori"], model.RELAX_SCOPES["density"], 0.2)


def solve(tank, settings, variant, resolution, start=None, log=None, threads=None):
    """Run MPS on the tank (from start's final state if given) -> contract.Result."""
    l0 = float(settings["resolution.spacing"])
    flow = _flow(tank)
    t_end = settings["time.flow_time"] if flow else settings["time.single_time"]
    probes = settings["probes.flow"] if flow else settings["probes.single"]
    st = start_state(start) if start is not None else None
    if st is None and settings["start.on_wall_point"] is not None:
        st = on_wall_start(tank, l0, settings["start.on_wall_point"])
    log = log or (lambda msg: None)
    res = solver.solve(tank, settings, variant, l0, t_end, probes, start=st, log=log, threads=threads)
    res.spacing = l0
    return res
