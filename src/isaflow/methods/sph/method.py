"""WCSPH as a tank method: what isaflow.run calls (check, solve, warm_up, REFERENCES).

A run is a tank, the SPH settings of one variant and resolution (config/methods/sph.yaml) and
optionally a start file (an SPH run whose final state, clock and step count this run continues).
Units: cm, N, s.
"""

from ... import runfile
from ...inputs import InputError
from . import block
from . import settings as S
from . import solver

REFERENCES = ("Marko (2017), Computation 5, 33 (section 2); Monaghan (1992), Annu. Rev. Astron. Astrophys. 30, 543; "
              "Monaghan (1994), J. Comput. Phys. 110, 399; Adami, Hu & Adams (2012), J. Comput. Phys. 231, 7057; "
              "Molteni & Colagrossi (2009), Comput. Phys. Commun. 180, 861")
START_VARS = ("pos", "velocity", "density", "weight", "cell_dx")  # variables and the attribute cell_dx


def check(tank, settings, start=None):
    """Every check that can refuse the run: one resolution, and a start file that is an SPH run with its state
    (a periodic block starts from its lattice, never from a file)."""
    S.resolution(settings)
    if start is not None and settings["settings.domain"] == "periodic_block":
        raise InputError("--start: a periodic block (settings.domain) starts from its stretched lattice, not a run file")
    if start is not None:
        with runfile.open_run(start) as ds:
            problem = runfile.start_problem(ds, start, "sph", START_VARS)
        if problem:
            raise InputError(f"--start: {problem}")


def warm_up(threads=None):
    """Compile (or load from numba's cache) the kernels a run times (the tank loop and the periodic block's)."""
    solver.warm_up(threads or 1)
    block.warm_up()


def solve(tank, settings, variant, resolution, start=None, log=None, threads=None):
    """Run SPH on the tank (from start's final state if given) -> contract.Result."""
    s = S.physics(settings)
    start_ds = runfile.read(start) if start is not None else None
    log = log or (lambda msg: None)
    if s["domain"] == "periodic_block":
        res = block.run(tank, s, S.resolution(settings), log)
        res.variant = variant
        return res
    res = solver._run(tank, s, S.resolution(settings), start_ds, bool(settings["resolution.on_wall"]), None, log,
                      solver.set_threads(threads or 1))
    res.variant = variant
    res.spacing = float((res.params["cell_dx"] * res.params["cell_dy"]) ** 0.5)
    return res
