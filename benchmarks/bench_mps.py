"""MPS cost per step against N, and the step's operators against their floor.

Step cost: predict (neighbour lists, explicit step, collision, free surface, source term, CSR assembly), pressure
solve and correct (gradient, update, wall check, the wall loads of both readings summed every step), each timed
separately, for the pressure solvers (cg_jacobi: compiled, bit-identical for any thread count; scipy_cg, amg, direct)
and for 1 and 2 numba threads (cg_jacobi).

Floor (cg_jacobi, 1 thread): the step's operators (the step without its pressure solve) against one fused pass over
the same data, :func:`floor_pass`: over the step's own neighbour lists at its predicted positions, every list entry's
distance (sqrt) and, within r_e, its weight and every pair sum a step takes (number density, velocity divergence,
Laplacian of the velocity, the variational pressure gradient, the free surface's offsets), writing each unknown's row
of the step's own pressure matrix.  The step cannot be one pass (each stage needs its neighbours' results of the one
before: the velocity Laplacian at the old positions, the surface at the predicted ones, the matrix after every
particle's surface flag, the gradient after the solve); the ratio says how close it comes.  Floor calls and steps
are interleaved, each timed by the thread's CPU time (the machine is shared: wall time would count other processes'
time slices); the step's operators are its CPU time times the share of its cycles outside the solve (solver.step's
stage timers).  ns per particle-step count every particle (liquid, wall and dummy: the lists' rows), the
whole step's also per liquid particle against the peer MPS-Basic (../shared/peers.md: 46 ms per step on one thread at
l0 = 1.25 cm, 4,640 liquid particles).

A liquid block at rest in the single tank with a spacing giving about N liquid particles (a whole number of columns,
so the lattice is square and starts at n = n0: 234, 609 and 4,640 are the runs' dx5.56, dx3.45 and dx1.25); 30
warm-up steps (the lattice starts to disorder, the CG is warm-started from the previous step's pressures as in the
runs), then the median of 20 steps (the floor: of 20 to 200 interleaved rounds).
Writes benchmarks/results/mps_step_cost.csv (with the machine's load average).  Run:
python benchmarks/bench_mps.py [--quick]

BLAS and OpenMP get one thread unless the environment says otherwise (scipy_cg's dot products; a threaded
OpenBLAS was slower on the shared 2-core machine and changes round-off); numba's threads are set per row.
"""

import os
import sys
import time
from pathlib import Path

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numba  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
from numba import prange, uint64  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SIZES = (234, 609, 2000, 4640, 20000)
RUNS = (("cg_jacobi", 1), ("cg_jacobi", 2), ("scipy_cg", 1), ("amg", 1), ("direct", 1))
PEER = dict(code="MPS-Basic", ms_per_step=46.0, liquid_particles=4640)  # ../shared/peers.md, one thread


def block(root, n, method="cg_jacobi"):
    """(State, settings, dt) of the liquid block of about n particles at rest in the single tank of the checkout at
    ``root`` (its settings' defaults, pressure solver ``method``), with whichever isaflow is imported
    (mps_step_ratio.py imports another commit's)."""
    from isaflow.methods.mps import boundary, settings, solver
    from isaflow.tank import load as load_tank

    tank = load_tank(Path(root) / "config/tanks/single.yaml")
    l0 = 100.0 / round(np.sqrt(n * 100.0 / 72.5))  # whole columns: the lattice is square (dx = l0)
    cfg = settings.resolved(Path(root) / "config/methods/mps.yaml").with_overrides(**{"pressure.solver": method})
    xr, floor = tank.first_vessel
    fluid = boundary.liquid_block(xr, floor, tank.depth, l0)
    s = solver.State(tank, cfg, l0, fluid, np.zeros_like(fluid))
    return s, cfg, solver.time_step(tank, l0, cfg["time.courant"])


def step_cost(root, n, method="cg_jacobi", warm=30, steps=20):
    """The step cost of block(root, n, method) (standard source, numba's current threads): ``warm`` steps, then over
    ``steps`` steps the median of each stage.  Returns dict: liquid and all particles, predict / solve / correct /
    step ms (the step: the stages' medians summed), median solve iterations."""
    from isaflow.methods.mps import solver

    s, cfg, dt = block(root, n, method)
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


@numba.njit(parallel=True, nogil=True)
def floor_pass(pos, vel, p, kind, start, nbr, row, indptr, re, sums, indices, data):
    """One fused pass over the lists (start, nbr) of particles pos (N, 2) [cm], velocities vel (N, 2) and pressures p:
    per row (fluid and wall particles) every entry's distance, and within re its weight w = re / r - 1 and the pair
    sums (number density, divergence, Laplacian of the velocity, variational gradient, offsets) into sums (N, 8); an
    unknown's (row >= 0) pairs with unknowns written into its row of the CSR matrix (indptr, indices, data) after
    the diagonal, as far as the row reaches.  The step's own arithmetic, once per entry, with the step's unsigned
    indices (operators.row_span).  numba's njit, not the package's: mps_step_ratio.py imports this file beside commits
    that predate isaflow.core.jit."""
    re2 = re * re
    for i in prange(pos.shape[0]):
        if kind[i] == 2:  # DUMMY: empty rows
            continue
        nd = dv = lx = ly = gx = gy = sx = sy = 0.0
        q = indptr[row[i]] + 1 if row[i] >= 0 else 0
        last = indptr[row[i] + 1] if row[i] >= 0 else 0
        for k in range(uint64(start[i]), uint64(start[i + 1])):
            j = uint64(nbr[k])
            dx = pos[j, 0] - pos[i, 0]
            dy = pos[j, 1] - pos[i, 1]
            r2 = dx * dx + dy * dy
            if r2 >= re2:
                continue
            r = np.sqrt(r2)
            w = re / r - 1.0
            nd += w
            ux = vel[j, 0] - vel[i, 0]
            uy = vel[j, 1] - vel[i, 1]
            dv += (ux * dx + uy * dy) / r2 * w
            lx += ux * w
            ly += uy * w
            cg = (p[i] + p[j]) * re / (r2 * r)
            gx += cg * dx
            gy += cg * dy
            sx += dx
            sy += dy
            if row[j] >= 0 and q < last:
                indices[q] = row[j]
                data[q] = -w
                q += 1
        sums[i, 0], sums[i, 1], sums[i, 2], sums[i, 3] = nd, dv, lx, ly
        sums[i, 4], sums[i, 5], sums[i, 6], sums[i, 7] = gx, gy, sx, sy


def floor_cost(n, warm=30, rounds=None):
    """The step's operators against floor_pass (block(ROOT, n), cg_jacobi, one numba thread): ``rounds`` interleaved
    (floor pass, step) pairs after ``warm`` steps, each timed by the thread's CPU time.  Returns dict: the medians of the
    floor pass and of the step without its solve [ms], their ratio, and the solve's median [ms]."""
    from isaflow.methods.mps import model, solver

    s, cfg, dt = block(ROOT, n)
    for _ in range(warm):
        solver.step(s, dt, "standard", cfg)
    rounds = rounds or int(np.clip(2e5 / len(s.pos), 20, 200))
    c = s.constants(cfg)
    out = model.predict(s.pos, s.vel, s.p, s.kind, s.tw, s.tside, s.thin, s.walls, s.grid_box, s.start, s.nbr,
                        s.list_pos, s.n_prev, s.counts.copy(), c, dt, *s.gravity, 0, 0.0)
    ps, row, indptr, indices, data = out[4], out[10], out[11], out[12].copy(), out[13].copy()
    sums = np.zeros((len(ps), 8))
    args = (ps, s.vel, s.p, s.kind, out[0], out[1], row, indptr, s.re_n, sums, indices, data)
    floor_pass(*args)
    floor, ops, solve = [], [], []
    for _ in range(rounds):
        t0 = time.thread_time()
        floor_pass(*args)
        floor.append(time.thread_time() - t0)
        stage = np.zeros(3)
        t0 = time.thread_time()
        solver.step(s, dt, "standard", cfg, stage)
        cpu = time.thread_time() - t0
        ops.append(cpu * (stage[0] + stage[2]) / stage.sum())
        solve.append(cpu * stage[1] / stage.sum())
    f, o = np.median(floor) * 1e3, np.median(ops) * 1e3
    return dict(floor_ms=f, ops_ms=o, floor_ratio=o / f, ops_solve_ms=np.median(solve) * 1e3, floor_rounds=rounds)


def main(quick=False):
    rows = []
    for n in SIZES[:3] if quick else SIZES:
        for method, threads in RUNS:
            if method == "direct" and n > 5000:
                continue
            if threads > numba.config.NUMBA_NUM_THREADS:
                continue
            numba.set_num_threads(threads)
            load = os.getloadavg()[0]
            r = step_cost(ROOT, n, method)
            row = dict(liquid_particles=r.pop("liquid_particles"), all_particles=r.pop("all_particles"), solver=method,
                       threads=threads, **r)
            if method == "cg_jacobi" and threads == 1:
                row.update(floor_cost(n))
                row["ops_ns_per_particle_step"] = row["ops_ms"] * 1e6 / row["all_particles"]
                row["floor_ns_per_particle_step"] = row["floor_ms"] * 1e6 / row["all_particles"]
            row["ns_per_liquid_particle_step"] = row["step_ms"] * 1e6 / row["liquid_particles"]
            row["load_average"] = 0.5 * (load + os.getloadavg()[0])
            rows.append(row)
            print(rows[-1], flush=True)
    out = ROOT / "benchmarks/results" / ("mps_step_cost_quick.csv" if quick else "mps_step_cost.csv")
    out.parent.mkdir(parents=True, exist_ok=True)
    df = pd.DataFrame(rows)
    df["peer_ns_per_liquid_particle_step"] = PEER["ms_per_step"] * 1e6 / PEER["liquid_particles"]
    df.to_csv(out, index=False, float_format="%.4g")


if __name__ == "__main__":
    main("--quick" in sys.argv)
