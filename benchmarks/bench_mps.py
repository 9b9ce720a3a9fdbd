"""MPS cost per step against N: predict (numba: neighbour lists, explicit step, collision, number density,
free surface, source term, CSR assembly), pressure solve and correct (numba: gradient, update, wall check, the
wall loads of both readings summed every step),
each timed separately, for the pressure solvers (cg_jacobi: compiled, bit-identical for any thread count;
scipy_cg, amg, direct) and for 1 and 2 numba threads (cg_jacobi).

A liquid block at rest in the single tank with a spacing giving about N liquid particles (a whole number of
columns, so the lattice is square and starts at n = n0); 30 warm-up steps (the lattice starts to disorder,
the CG is warm-started from the previous step's pressures as in the runs), then the median of 20 steps.
Writes benchmarks/results/mps_step_cost.csv.  Run: python benchmarks/bench_mps.py [--quick]

BLAS and OpenMP get one thread unless the environment says otherwise (scipy_cg's dot products; a threaded
OpenBLAS was slower on the shared 2-core machine and changes round-off); numba's threads are set per row.
"""

import os
import sys
from pathlib import Path

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numba  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402


ROOT = Path(__file__).resolve().parents[1]
SIZES = (180, 720, 2000, 5000, 20000)
RUNS = (("cg_jacobi", 1), ("cg_jacobi", 2), ("scipy_cg", 1), ("amg", 1), ("direct", 1))


def step_cost(root, n, method="cg_jacobi", warm=30, steps=20):
    """The step cost of the liquid block of about n particles at rest in the single tank of the checkout at ``root``
    (its settings' defaults, pressure solver ``method``, standard source, numba's current threads), with whichever
    isaflow is imported (mps_step_ratio.py imports another commit's): ``warm`` steps, then over ``steps`` steps the
    median of each stage.  Returns dict: liquid and all particles, predict / solve / correct / step ms (the step: the
    stages' medians summed), median solve iterations."""
    from isaflow.methods.mps import boundary, settings, solver
    from isaflow.tank import load as load_tank

    tank = load_tank(Path(root) / "config/tanks/single.yaml")
    l0 = 100.0 / round(np.sqrt(n * 100.0 / 72.5))  # whole columns: the lattice is square (dx = l0)
    cfg = settings.resolved(Path(root) / "config/methods/mps.yaml").with_overrides(**{"pressure.solver": method})
    xr, floor = tank.first_vessel
    fluid = boundary.liquid_block(xr, floor, tank.depth, l0)
    s = solver.State(tank, cfg, l0, fluid, np.zeros_like(fluid))
    dt = solver.time_step(tank, l0, cfg["time.courant"])
    for _ in range(warm):
        solver.step(s, dt, "standard", cfg)
    per, its = [], []
    for _ in range(steps):
        t = np.zeros(3)
        _, _, it = solver.step(s, dt, "standard", cfg, t)
        per.append(t)
        its.append(it)
    per = np.median(np.array(per), axis=0) * 1e3
    return dict(liquid_particles=s.nf, all_particles=len(s.pos), predict_ms=per[0], solve_ms=per[1], correct_ms=per[2],
                step_ms=per.sum(), solve_iterations=float(np.median(its)))


def main(quick=False):
    rows = []
    for n in SIZES[:3] if quick else SIZES:
        for method, threads in RUNS:
            if method == "direct" and n > 5000:
                continue
            if threads > numba.config.NUMBA_NUM_THREADS:
                continue
            numba.set_num_threads(threads)
            r = step_cost(ROOT, n, method)
            rows.append(dict(liquid_particles=r.pop("liquid_particles"), all_particles=r.pop("all_particles"),
                             solver=method, threads=threads, **r))
            print(rows[-1], flush=True)
    out = ROOT / "benchmarks/results" / ("mps_step_cost_quick.csv" if quick else "mps_step_cost.csv")
    out.parent.mkdir(parents=True, exist_ok=True)
    pd.DataFrame(rows).to_csv(out, index=False, float_format="%.4g")


if __name__ == "__main__":
    main("--quick" in sys.argv)
