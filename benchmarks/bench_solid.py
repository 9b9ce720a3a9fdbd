"""Cost per particle-step of the solid step loop (marko2017), 2D plates and 3D blocks of growing size.

Writes benchmarks/results/solid_step_cost.csv (n particles, dim, variant, steps, s, ns per particle-step).
Run: python benchmarks/bench_solid.py   (about 2 min on one core)
"""

import csv
import time
from pathlib import Path

import numpy as np

from isaflow.core.units import KG, PA
from isaflow.methods.solid import lattice, solve

OUT = Path(__file__).parent / "results" / "solid_step_cost.csv"
MAT = solve.Material(207e9 * PA, 0.3, 7800 * KG / 1e6)
STEPS = 2000


def cost(shape, variant, push):
    b = lattice.block(*shape, 0.0159)
    st = solve.State(b, MAT, variant, np.ones((b.n, 3)), push=push)
    mask = np.zeros((b.n, 3), bool)
    mask[b.index[:, 1] == 0] = True
    if b.dim == 2:
        mask[:, 2] = True
    disp = np.zeros((b.n, 3))
    disp[b.index[:, 1] == shape[1] - 1, 1] = 1e-6
    solve.prescribe(st, mask, disp)
    solve.relax(st, 0.0, 2)  # compile / load cache
    t = time.perf_counter()
    solve.relax(st, 0.0, STEPS, min_steps=STEPS)  # tol 0: never converges, runs all steps
    return b.n, time.perf_counter() - t


def main():
    rows = []
    for shape, push in [((51, 10, 1), 1), ((100, 100, 1), 1), ((300, 300, 1), 1), ((11, 11, 11), 0), ((30, 30, 30), 0)]:
        for variant in ("paper", "hooke"):
            n, s = cost(shape, variant, push)
            rows.append({"n": n, "dim": 2 if shape[2] == 1 else 3, "variant": variant, "steps": STEPS,
                         "seconds": round(s, 4), "ns_per_particle_step": round(s / (n * STEPS) * 1e9, 2)})
            print(rows[-1], flush=True)
    OUT.parent.mkdir(parents=True, exist_ok=True)
    with open(OUT, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


if __name__ == "__main__":
    main()
