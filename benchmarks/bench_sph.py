"""Cost per particle-step of the SPH step loop against N (one core), beside the paper's method.

The single vessel filled to its depth with N liquid particles (hydrostatic
start, wcsph settings); after one untimed chunk (compilation, first list),
``steps`` leapfrog steps are timed (best of ``reps``).  ns per particle-step
counts liquid particles (the wall particles are the boundary's overhead; their
count is in the table).  Writes benchmarks/results/sph_step_cost.csv and prints
the fitted exponent of time per step against N and the ISA cost from
benchmarks/results/step_cost.csv.

    python benchmarks/bench_sph.py            # N = 180 ... 102,400
    python benchmarks/bench_sph.py --quick    # N <= 5,000 (results/quick)
"""

import argparse
import os
import time
from pathlib import Path

import numpy as np
import pandas as pd

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

from isaflow.core.geometry import bounding_box  # noqa: E402
from isaflow.methods.sph import kernels as K  # noqa: E402
from isaflow.methods.sph import settings as S  # noqa: E402
from isaflow.methods.sph import solver  # noqa: E402
from isaflow.scene import load_tank  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def state(tank, s, n):
    """Arrays of a hydrostatic single vessel with about n liquid particles."""
    st = solver.setup(tank, s, {"particles": n})
    nf, nw = len(st["pos"]), len(st["wpos"])
    x = np.concatenate([st["pos"], st["wpos"]])
    rho = np.concatenate([st["rho"], np.full(nw, st["rho_ref"])])
    walls = tank.walls
    box = bounding_box(walls)
    grid = np.array([x[:, 0].min() - 1, x[:, 1].min() - 1, x[:, 0].max() + 1, x[:, 1].max() + 1])
    par = st["par"]
    pi, pj, m = K.list_pairs(x, nf, grid, 2 * st["h"] + par[K.SKIN])
    arrays = dict(x=x, v=st["vel"].copy(), rho=rho, p=np.zeros(nf + nw), nf=nf, walls=walls, box=box, grid=grid,
                  par=par, xref=x[:nf].copy(), pi=pi, pj=pj, m=m, wk=np.empty(len(pi)), fk=np.empty(len(pi)),
                  acc=np.zeros((nf, 2)), wall_force=np.zeros((nw, 2)), wsum=np.zeros((nw, 3)),
                  force_sum=np.zeros((nw, 2)), panel0=np.zeros(len(walls), np.int64),
                  npanel=np.ones(len(walls), np.int64), panel_sum=np.zeros((len(walls), 2)), diag=np.zeros(4))
    a = arrays
    K.evaluate(a["x"], a["v"], a["rho"], a["p"], nf, pi, pj, m, a["wk"], a["fk"], par, a["acc"], a["wall_force"], a["wsum"])
    return a, nw


def advance(a, steps):
    code, done, a["pi"], a["pj"], a["m"], a["wk"], a["fk"] = K.advance(
        a["x"], a["v"], a["rho"], a["p"], a["nf"], a["walls"], a["box"], a["grid"], a["par"], steps, a["xref"],
        a["pi"], a["pj"], a["m"], a["wk"], a["fk"], a["acc"], a["wall_force"], a["wsum"], a["force_sum"],
        a["panel0"], a["npanel"], a["panel_sum"], a["diag"])
    assert code == K.OK and done == steps


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    tank = load_tank(ROOT / "config" / "tanks" / "single.yaml")
    sizes = [180, 684, 1600, 5000, 20000, 102400]
    if args.quick:
        sizes = [n for n in sizes if n <= 5000]
    rows = []
    for variant in ("wcsph", "delta_wc2"):
        s = S.resolve(S.load(), variant)
        for n in sizes:
            a, nw = state(tank, s, n)
            advance(a, 5)  # compile / warm caches
            steps = max(20, int(2e7 / a["nf"] / 50))
            best = np.inf
            for _ in range(3):
                t0 = time.perf_counter()
                advance(a, steps)
                best = min(best, time.perf_counter() - t0)
            rows.append(dict(variant=variant, N=a["nf"], wall_particles=nw, steps=steps,
                             ns_per_particle_step=best / steps / a["nf"] * 1e9,
                             ns_per_all_particle_step=best / steps / (a["nf"] + nw) * 1e9,
                             pairs_per_particle=a["m"] / a["nf"], list_builds=a["diag"][2]))
            print(rows[-1], flush=True)
    df = pd.DataFrame(rows)
    out = ROOT / "benchmarks" / "results" / ("quick" if args.quick else "")
    out.mkdir(parents=True, exist_ok=True)
    df.to_csv(out / "sph_step_cost.csv", index=False)
    for variant, g in df.groupby("variant"):
        k = np.polyfit(np.log(g.N), np.log(g.ns_per_particle_step * g.N), 1)[0]
        big = g[g.N >= 5000].ns_per_particle_step
        print(f"{variant}: time per step ~ N^{k:.2f}; {big.min():.0f}-{big.max():.0f} ns/particle-step at N >= 5000 "
              f"(target 250)")
    isa = ROOT / "benchmarks" / "results" / "step_cost.csv"
    if isa.exists():
        i = pd.read_csv(isa)
        i = i[i.impl == "numba"]
        print(f"ISA (paper's method): {i.ns_per_particle_step.min():.1f}-{i.ns_per_particle_step.max():.1f} ns/particle-step")


if __name__ == "__main__":
    main()
