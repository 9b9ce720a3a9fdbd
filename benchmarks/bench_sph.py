"""Cost per particle-step of the SPH step loop against N, on 1 and 2 threads side by side.

The single vessel filled to its depth with N liquid particles (hydrostatic start, the
variant's settings); after one untimed chunk (compilation, first list), chunks of
``steps`` steps are timed, 1-thread and 2-thread chunks interleaved, ``reps`` of each;
the median is kept.  ns per particle-step counts liquid particles (the wall particles are
the boundary's overhead; their count is in the table).  The two thread counts give
bit-identical states (kernels docstring), so both advance one state.  Parallel efficiency
= t(1 thread) / (2 t(2 threads)).  Each OpenMP wait policy runs in its own process (the policy
is read once, when numba starts its pool): PASSIVE (solver.set_threads' default: robust on a
loaded machine) and ACTIVE (spinning: faster when both cores are free, much slower when they are
not).  Writes benchmarks/results/sph_step_cost.csv with the machine's load average at the start
and end of each (the machine is shared: read the figures with it).

Floor (wcsph, PASSIVE process, 1 thread): :func:`floor_advance`, the same steps as one compiled loop over the
same pair list, against the project's loop; ``reps`` rounds of a chunk by each from the same state, each timed
by the thread's CPU time, medians, its ns per liquid particle-step, the ratio project / floor and the largest
difference of the floor's state from the project's (floor_* columns; 0 is the same bits).

    python benchmarks/bench_sph.py            # N = 5,000, 20,000, 50,000, wcsph; about a minute
    python benchmarks/bench_sph.py --quick    # N <= 5,000 (results/quick)
"""

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

os.environ.setdefault("NUMBA_NUM_THREADS", "2")
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")  # as solver.set_threads; the parent sets it per child

from isaflow.core.geometry import bounding_box  # noqa: E402
from isaflow.core.jit import njit  # noqa: E402
from isaflow.methods.sph import kernels as K  # noqa: E402
from isaflow.methods.sph import settings as S  # noqa: E402
from isaflow.methods.sph import solver  # noqa: E402
from isaflow.methods.sph.pairs import build  # noqa: E402
from isaflow.methods.sph.repulsion import wall_repulsion  # noqa: E402
from isaflow.tank import load as load_tank  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
FLOOR_VARIANT = "wcsph"
STATE = ("x", "v", "rho", "p", "acc", "wall_force", "force_sum", "panel_sum")  # compared floor against project


@njit(cache=True, nogil=True)
def floor_advance(x, v, rho, p, nf, walls, box, grid_box, par, n_steps, xref, lst, wk, fk, acc, wall_force,
                  force_sum, panel_sum, panel0, npanel):
    """n_steps of kernels.advance (continuity density, one thread) as one compiled loop calling each of its
    range kernels once a pass over the whole data; arrays and returns as advance (no diagnostics).

    Per step: kernels._move_range over all liquid particles (the kicks, the drift, the crossing test of the
    particles that could reach a wall, the |v|^2 sum, the box and finite checks); pairs.build at the same steps
    (a particle moved skin / 2); kernels.kernel_range over each cell column (even columns, then odd: advance's
    order) for W, (dW/dr)/r and the continuity rate; kernels.liquid_range (density update, Tait pressure,
    P / rho^2, gravity) and kernels.wall_range (Adami wall pressures); kernels.force_range over each column
    (eq. 9, the same viscosity); repulsion.wall_repulsion; force_sum += wall_force.  What it leaves out is
    advance's dispatch: the chunks of the per-particle passes, the colour passes' calls, the thread tests.
    The same sums in the same order: the same bits."""
    lim2 = (0.5 * par[K.SKIN]) ** 2
    rc = 2.0 * par[K.H] + par[K.SKIN]
    half = 0.5 * par[K.DT]
    n = x.shape[0]
    rate = np.zeros(nf)
    p_rho2 = np.empty(n)
    for step in range(n_steps + 1):
        if step == n_steps:  # the last step's second kick
            return (K.OK if np.isfinite(K._kick_range(0, nf, v, acc, half)) else K.NONFINITE), n_steps, lst, wk, fk
        v2, moved2, cross, bad = K._move_range(0, nf, x, v, acc, xref, half, par[K.DT], box, walls, lst[7],
                                               0.5 * par[K.SKIN], step > 0)
        if not np.isfinite(v2) or cross >= 0 or bad >= 0:
            return K.NONFINITE if not np.isfinite(v2) else K.CROSSED if cross >= 0 else K.LEFT_BOX, step, lst, wk, fk
        if moved2 > lim2:
            lst = build(x, nf, grid_box, rc, walls, lst[0], lst[1], K.reach_of(par))
            if wk.shape[0] < lst[2]:
                wk = np.empty(lst[0].shape[0])
                fk = np.empty(lst[0].shape[0])
            xref[:nf] = x[:nf]
        pi, pj, m, col, wrow, wpair, close, dwall = lst
        rate[:] = 0.0
        for colour in range(2):
            for c in range(colour, col.shape[0] - 1, 2):
                K.kernel_range(col[c], col[c + 1], x, v, rho, nf, pi, pj, par, wk, fk, rate)
        K.liquid_range(0, nf, rho, rate, p, p_rho2, acc, par, True)
        K.wall_range(0, n - nf, x, rho, p, p_rho2, nf, pi, wrow, wpair, wk, par, wall_force)
        for colour in range(2):
            for c in range(colour, col.shape[0] - 1, 2):
                K.force_range(col[c], col[c + 1], x, v, rho, p_rho2, nf, pi, pj, par, fk, acc, wall_force)
        wall_repulsion(x, close, walls, panel0, npanel, par[K.LJ_D], par[K.LJ_R0], par[K.MASS], acc, panel_sum)
        force_sum += wall_force
    return K.OK, n_steps, lst, wk, fk


def state(tank, s, n):
    """Arrays of a hydrostatic single vessel with about n liquid particles (as solver._run sets them up)."""
    st = solver.setup(tank, s, {"particles": n})
    nf, nw = len(st["pos"]), len(st["wpos"])
    x = np.concatenate([st["pos"], st["wpos"]])
    rho = np.concatenate([st["rho"], np.full(nw, st["rho_ref"])])
    walls = tank.walls
    box = bounding_box(walls)
    par = st["par"]
    rc = 2 * st["h"] + par[K.SKIN]
    lo, hi = np.minimum(box[:2], st["wpos"].min(0)) - rc, np.maximum(box[2:], st["wpos"].max(0)) + rc
    grid = np.array([lo[0], lo[1], hi[0], hi[1]])
    lst = K.list_pairs(x, nf, grid, rc, walls, K.reach_of(par))
    a = dict(x=x, v=st["vel"].copy(), rho=rho, p=np.zeros(nf + nw), nf=nf, walls=walls, box=box, grid=grid,
             par=par, xref=x[:nf].copy(), lst=lst, wk=np.empty(len(lst[0])), fk=np.empty(len(lst[0])),
             acc=np.zeros((nf, 2)), wall_force=np.zeros((nw, 2)), force_sum=np.zeros((nw, 2)),
             panel0=np.zeros(len(walls), np.int64), npanel=np.ones(len(walls), np.int64),
             panel_sum=np.zeros((len(walls), 2)), diag=np.zeros(4))
    K.evaluate(a["x"], a["v"], a["rho"], a["p"], nf, walls, par, lst, a["wk"], a["fk"], a["acc"], a["wall_force"],
               a["panel0"], a["npanel"], a["panel_sum"], 1)
    return a, nw


def advance(a, steps, threads):
    code, done, a["lst"], a["wk"], a["fk"] = K.advance(
        a["x"], a["v"], a["rho"], a["p"], a["nf"], a["walls"], a["box"], a["grid"], a["par"], steps, a["xref"],
        a["lst"], a["wk"], a["fk"], a["acc"], a["wall_force"], a["force_sum"], a["panel0"], a["npanel"],
        a["panel_sum"], a["diag"], threads)
    assert code == K.OK and done == steps


def copied(a):
    """A copy of the state a (its arrays and the pair list's)."""
    out = {k: (v.copy() if isinstance(v, np.ndarray) else v) for k, v in a.items()}
    out["lst"] = tuple(e.copy() if isinstance(e, np.ndarray) else e for e in a["lst"])
    return out


def advance_floor(a, steps):
    code, done, a["lst"], a["wk"], a["fk"] = floor_advance(
        a["x"], a["v"], a["rho"], a["p"], a["nf"], a["walls"], a["box"], a["grid"], a["par"], steps, a["xref"],
        a["lst"], a["wk"], a["fk"], a["acc"], a["wall_force"], a["force_sum"], a["panel_sum"], a["panel0"],
        a["npanel"])
    assert code == K.OK and done == steps


def floor_cost(a, steps, reps):
    """The project's step loop (1 thread) against :func:`floor_advance` from the state a: ``reps`` rounds, each
    a chunk of ``steps`` steps by both from the same state (copies), timed by the thread's CPU time, the floor's
    state compared with the project's (max differences: 0 is the same bits), then a continues from the project's.
    Returns dict: medians in ns per liquid particle-step, ratio, the largest difference of any state array."""
    solver.set_threads(1)
    advance(copied(a), 2, 1)
    advance_floor(copied(a), 2)
    tp, tf, diff = [], [], 0.0
    for _ in range(reps):
        b = copied(a)
        t0 = time.thread_time()
        advance(a, steps, 1)
        tp.append(time.thread_time() - t0)
        t0 = time.thread_time()
        advance_floor(b, steps)
        tf.append(time.thread_time() - t0)
        diff = max([diff] + [float(np.abs(a[k] - b[k]).max()) for k in STATE])
    ns, nf = (float(np.median(t)) / steps / a["nf"] * 1e9 for t in (tp, tf))
    return dict(floor_ns_per_particle_step_1thread=nf, project_ns_per_particle_step_1thread_floor_rounds=ns,
                floor_ratio=ns / nf, floor_max_state_diff=diff)


def measure(sizes, variants, reps):
    """Rows of one process (one OpenMP wait policy)."""
    tank = load_tank(ROOT / "config" / "tanks" / "single.yaml")
    load0 = os.getloadavg()[0]
    rows = []
    for variant in variants:
        s = S.resolve(S.read_file(), variant)
        for n in sizes:
            a, nw = state(tank, s, n)
            steps = max(10, int(2.5e6 / a["nf"]))  # about 0.3 s a chunk on one thread
            for threads in (1, 2):
                solver.set_threads(threads)
                advance(a, 2, threads)  # compile / warm caches
            times = {1: [], 2: []}
            for _ in range(reps):
                for threads in (1, 2):
                    solver.set_threads(threads)
                    t0 = time.perf_counter()
                    advance(a, steps, threads)
                    times[threads].append(time.perf_counter() - t0)
            t1, t2 = (float(np.median(times[k])) / steps / a["nf"] * 1e9 for k in (1, 2))
            timed_floor = (variant, os.environ["OMP_WAIT_POLICY"]) == (FLOOR_VARIANT, "PASSIVE")
            fl = floor_cost(a, steps, reps) if timed_floor else {}
            rows.append(dict(variant=variant, omp_wait_policy=os.environ["OMP_WAIT_POLICY"], N=a["nf"],
                             wall_particles=nw, steps=steps, reps=reps, ns_per_particle_step_1thread=t1,
                             ns_per_particle_step_2threads=t2, parallel_efficiency=t1 / (2 * t2),
                             pairs_per_particle=a["lst"][2] / a["nf"], list_builds=float(a["diag"][2]), **fl))
            print(rows[-1], file=sys.stderr, flush=True)
    for r in rows:
        r.update(load_avg_1min_start=load0, load_avg_1min_end=os.getloadavg()[0])
    return rows


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()
    sizes = [5000, 20000, 50000] if not args.quick else [684, 5000]
    if args.child:
        json.dump(measure(sizes, ["wcsph", "delta_wc2"] if os.environ["OMP_WAIT_POLICY"] == "PASSIVE" else ["wcsph"],
                          args.reps), sys.stdout)
        return
    rows = []
    for policy in ("PASSIVE", "ACTIVE"):
        cmd = [sys.executable, __file__, "--child", "--reps", str(args.reps)] + (["--quick"] if args.quick else [])
        out = subprocess.run(cmd, env={**os.environ, "OMP_WAIT_POLICY": policy}, check=True, capture_output=True,
                             text=True)
        rows += json.loads(out.stdout)
    df = pd.DataFrame(rows)
    out = ROOT / "benchmarks" / "results" / ("quick" if args.quick else "")
    out.mkdir(parents=True, exist_ok=True)
    df.to_csv(out / "sph_step_cost.csv", index=False, float_format="%.4g")
    for (variant, policy), g in df.groupby(["variant", "omp_wait_policy"]):
        big = g[g.N >= 19000]  # the 20,000 requested (19,920 on the lattice) and up
        print(f"{variant}, {policy}: N >= 20,000: {big.ns_per_particle_step_1thread.min():.0f}-"
              f"{big.ns_per_particle_step_1thread.max():.0f} ns/particle-step on 1 thread, "
              f"{big.ns_per_particle_step_2threads.min():.0f}-{big.ns_per_particle_step_2threads.max():.0f} on 2 "
              f"(target 100), efficiency {big.parallel_efficiency.min():.2f}-{big.parallel_efficiency.max():.2f}; "
              f"load average {g.load_avg_1min_start.iloc[0]:.1f} -> {g.load_avg_1min_end.iloc[0]:.1f} on "
              f"{os.cpu_count()} cores")


if __name__ == "__main__":
    main()
