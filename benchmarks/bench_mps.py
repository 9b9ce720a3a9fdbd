"""MPS cost per step against N: predict (numba: explicit step, neighbour lists, number density, CSR assembly),
pressure solve (amg, cg_jacobi, direct) and correct (numba: gradient, update), each timed separately.

A liquid block at rest in the single tank with a spacing giving about N liquid particles (a whole number of
columns, so the lattice is square and starts at n = n0); 20 steps after 2 warm-up steps, median per step.  Writes benchmarks/results/mps_step_cost.csv.  Run: python benchmarks/bench_mps.py [--quick]

One core, as the step-cost target: BLAS (the CG's dot products), OpenMP and numba get one thread unless the
environment says otherwise (on the shared 2-core machine a threaded OpenBLAS made the CG solve at 20,000
particles slower, ~150 against ~95 ms per step in one check, and changes its round-off).
"""

import os
import sys
from pathlib import Path

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from isaflow.methods.mps import boundary, settings, solver  # noqa: E402
from isaflow.scene import load_tank  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SIZES = (180, 720, 2000, 5000, 20000)
SOLVERS = ("amg", "cg_jacobi", "direct")


def main(quick=False):
    tank = load_tank(ROOT / "config/tanks/single.yaml")
    rows = []
    for n in SIZES[:3] if quick else SIZES:
        l0 = 100.0 / round(np.sqrt(n * 100.0 / 72.5))  # whole columns: the lattice is square (dx = l0)
        for method in SOLVERS:
            if method == "direct" and n > 5000:
                continue
            cfg = settings.load(ROOT / "config/methods/mps.yaml").with_overrides(**{"pressure.solver": method})
            xr, floor = solver.first_vessel(tank)
            fluid = boundary.liquid_block(xr, floor, tank.depth, l0)
            s = solver.State(tank, cfg, l0, fluid, np.zeros_like(fluid))
            dt = solver.time_step(tank, l0, cfg["time.courant"])
            for _ in range(2):
                solver.step(s, dt, "standard", cfg)
            per = []
            for _ in range(20):
                t = np.zeros(3)
                solver.step(s, dt, "standard", cfg, t)
                per.append(t)
            per = np.median(np.array(per), axis=0) * 1e3
            rows.append(dict(liquid_particles=s.nf, all_particles=len(s.pos), solver=method, predict_ms=per[0],
                             solve_ms=per[1], correct_ms=per[2], step_ms=per.sum()))
            print(rows[-1], flush=True)
    out = ROOT / "benchmarks/results" / ("mps_step_cost_quick.csv" if quick else "mps_step_cost.csv")
    pd.DataFrame(rows).to_csv(out, index=False, float_format="%.4g")


if __name__ == "__main__":
    main("--quick" in sys.argv)
