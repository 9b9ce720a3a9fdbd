"""Cost of one step of the paper's algorithm on 1 and 2 threads, and the equilibrium solver's evaluation counts.

Run: ``python benchmarks/bench_step.py [--quick] [--finer]`` (a plain script, not a test).

Step cost: compiled ``methods.isa.relax.relax_resume``, variant PAPER, vs N, on 1
and 2 threads (``threads`` argument and ``numba.set_num_threads``; the results are
the same bits on both, tests/test_isa_parallel.py).  Scene (units cm, N): the
paper's application-1 liquid made wide.  A rhombic lattice
(``isaflow.methods.isa.scene.rhombic_lattice``, a = 10 cm) of 19 rows alternating n and n + 1
particles (N = 19 n + 9; n = 9 is the paper's 180-particle case) in a rectangular
vessel of height 100 cm and width (n + 1) a, particle weight 50 N, wall law
l_u = 5 cm / r_u = 10 kN, pair law l_u = a / sqrt(2) / r_u = 500 l_u N, du = 0.01
cm, skin 0.3 l_u (the solver's default), f_tol 1e-30 N so no run stops early.  The
depth stays that of the paper and only the width grows, so the contact structure
per particle is the same at every N.  The liquid is relaxed before timing: the
small case directly (20,000 steps), the large ones by tiling a relaxed
1,890-particle vessel: its left 450 cm, k copies of its central 100 cm strip and
its right 450 cm (particles chosen by their initial lattice x, so every tile holds
whole lattice columns), then healed.  ns per particle-step: CPU time (one thread,
``ns_per_particle_step``, as before) and wall time (both thread counts,
step_threads.csv: the 2-thread figure is a wall time; the machine is shared with
other jobs, so each figure is the median of reps calls and the load average is
recorded).

Equilibrium solver (variant ``newton_lm``, methods/isa/newton.py): force
evaluations, Hessian assemblies, CG iterations and solver time on the single vessel
(tank single) at the resolutions coarse, refined and fine of config/methods/isa.yaml
(rows single_coarse, single_refined, study_fine; study_finer, resolution finer, with
--finer: ~20 s) and the complete coarse flow (tank flow_step50 continued from
application 3 at step 100,000: runs single_coarse, flow_incomplete, then
flow_complete_capped's settings), beside the capped update's and FIRE's (the study's
best FIRE: du 100 x the resolution's, dt_max = 2 / sqrt(2 k_b + 12 k_p)), and the
differences of its final state from the capped one (metrics.load_errors against the
top-centre level; tolerances methods.isa.metrics.tolerances).  Every solve goes through
isaflow.run (prepare, solve, write: the command line's path).  The capped
runs of study_fine / study_finer (6 s / 136 s) are not rerun: their counts are
deterministic (the same bits on every run) and are taken from REFERENCE_CAPPED.

Design floor (isa_floor.floor_relax, isaflow's kernels only): the same steps as one serial compiled loop over
SoA arrays, the project's own lists; at every N, ``reps`` calls of the project's step (1 thread) and of the floor
interleaved from the same state, each timed by the thread's CPU time, medians; the floor's positions, forces and
max|F| history compared with the project's (max differences written: 0 is the same bits).

Outputs (benchmarks/results/, or results/quick/ with --quick): step_cost[_TAG].csv
(1 thread), step_threads.csv, step_floor.csv (project and floor ns per particle-step, ratio, differences,
load average), newton_evals.csv, compile[_TAG].csv, memory[_TAG].csv, summary[_TAG].txt, machine.txt,
step_cost.png.
``--kernels FILE --tag before`` times another single-file copy of the kernels (e.g. the
version before optimisation, ``git show 09b8875:src/isaflow/kernels.py``; 1 thread only).
"""

import argparse
import csv
import importlib
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))

A = 10.0  # cm, lattice diagonal
ROWS = 19
HEIGHT = 100.0  # cm, vessel height
WEIGHT = 50.0  # N
WL_U, WR_U = 5.0, 10000.0  # wall law: cm, N
PL_U = A / np.sqrt(2.0)  # pair law: cm
PR_U = 500.0 * PL_U  # N
DU = 0.01  # cm
SKIN = 0.3 * PL_U  # cm (solver default)
F_TOL = 1e-30  # N: never converges
BASE_N_ROW = 99  # base vessel for tiling: 1000 cm wide, N = 1890
DIRECT_MAX_N_ROW = 300  # up to N = 5709 the vessel is relaxed directly
RELAX_STEPS = 20000
HEAL_STEPS = 1000
TARGET_NS_2T = 10.0  # issue 20: <= 10 ns per particle-step with 2 threads at N >= 1e5

FULL_N = [1000, 10_000, 30_000, 100_000]
QUICK_N = [1000, 10_000]
THREADS = (1, 2)

# capped update's force evaluations where the benchmark does not rerun it (deterministic counts: the same
# bits on every run of the capped update; issue 20 and benchmarks/results of the landed workflow)
REFERENCE_CAPPED = {"study_fine": 138_503, "study_finer": 809_157}
SCENES = ["single_coarse", "single_refined", "study_fine"]
# row name -> (tank of config/tanks, resolution of config/methods/isa.yaml)
CASES = {"single_coarse": ("single", "coarse"), "single_refined": ("single", "refined"),
         "study_fine": ("single", "fine"), "study_finer": ("single", "finer")}
ISA_SETTINGS = ROOT / "config" / "methods" / "isa.yaml"
FLOW_START_STEPS = 100_000  # application 3 ends here (config/methods/isa.yaml, run flow_incomplete)


def load_kernels(path):
    """The kernels to time: isaflow's (relax loop, force evaluation, neighbour list as one
    namespace) or another copy of a single kernels file (an older version)."""
    if path is None:
        from types import SimpleNamespace

        from isaflow.core import neighbours
        from isaflow.methods.isa import forces, relax
        return SimpleNamespace(relax=relax.relax, relax_resume=relax.relax_resume, PAPER=relax.PAPER,
                               RUNNING=relax.RUNNING, forces=forces.forces, build_pairs=neighbours.build_pairs,
                               threaded=True)
    path = Path(path).resolve()  # imported by name so numba's cache can find it again
    sys.path.insert(0, str(path.parent))
    return importlib.import_module(path.stem)


def lattice(n_row):
    """Initial (N, 2) positions [cm], walls (3, 4) [cm] and box of the vessel with rows of n_row / n_row + 1."""
    from isaflow.methods.isa.scene import rhombic_lattice
    width = (n_row + 1) * A
    pos = rhombic_lattice(A, ROWS, [n_row, n_row + 1], width / 2, 5.0)
    walls = np.array([[0, HEIGHT, 0, 0], [0, 0, width, 0], [width, 0, width, HEIGHT]], float)
    box = np.array([0.0, 0.0, width, HEIGHT])
    return pos, walls, box


def run_relax(K, pos, walls, box, n_steps, threads=1):
    """kernels.relax, variant PAPER, in place on pos; returns (forces, fmax_hist)."""
    n = len(pos)
    f = np.zeros_like(pos)
    hist = np.zeros(max(n_steps, 1))
    args = (pos, np.zeros_like(pos), np.full(n, WEIGHT), walls, box, WL_U, WR_U, PL_U, PR_U, K.PAPER, DU, 1.0, 0.1,
            F_TOL, n_steps, SKIN, f, hist)
    steps, status, _ = K.relax(*args, threads) if getattr(K, "threaded", False) else K.relax(*args)
    assert status == K.RUNNING and steps == n_steps, (steps, status)
    return f, hist


def run_floor(pos, walls, box, n_steps):
    """isa_floor.floor_relax on the benchmark's laws, in place on pos; returns (forces, fmax_hist)."""
    from isa_floor import floor_relax
    from isaflow.methods.isa.relax import RUNNING
    f = np.zeros_like(pos)
    hist = np.zeros(max(n_steps, 1))
    status = floor_relax(pos, np.full(len(pos), WEIGHT), walls, box, WL_U, WR_U, PL_U, PR_U, DU, n_steps, SKIN, f,
                         hist)
    assert status == RUNNING, status
    return f, hist


def floor_cost(K, pos, walls, box, target, reps):
    """Project step (kernels K, 1 thread) against isa_floor.floor_relax on the state pos: ``reps`` interleaved
    (project, floor) calls of the same steps from the same state, each timed by the thread's CPU time; the
    floor's positions, forces and max|F| history compared with the project's on every call.  Returns dict: steps
    per call, median ns per particle-step of each, ratio, max differences (0: the same bits)."""
    import numba
    n = len(pos)
    n_steps = max(100, int(np.ceil(target / n)))
    numba.set_num_threads(1)
    run_floor(pos.copy(), walls, box, 2)
    tp, tf, dpos, dforce = [], [], 0.0, 0.0
    try:
        for _ in range(reps):
            p = pos.copy()
            t0 = time.thread_time()
            f, hist = run_relax(K, p, walls, box, n_steps, 1)
            tp.append(time.thread_time() - t0)
            pf = pos.copy()
            t0 = time.thread_time()
            ff, hf = run_floor(pf, walls, box, n_steps)
            tf.append(time.thread_time() - t0)
            dpos = max(dpos, float(np.abs(pf - p).max()))
            dforce = max(dforce, float(np.abs(ff - f).max()), float(np.abs(hf - hist).max()))
    finally:
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    project = float(np.median(tp)) / (n_steps * n) * 1e9
    floor = float(np.median(tf)) / (n_steps * n) * 1e9
    return dict(N=n, steps_per_call=n_steps, reps=reps, ns_per_particle_step=project, floor_ns_per_particle_step=floor,
                ratio=project / floor, max_pos_diff_cm=dpos, max_force_diff_N=dforce)


def relaxed_state(K, n_target, base_cache, relax_steps, heal_steps, threads):
    """Relaxed wide-vessel state with about n_target particles: (pos, walls, box)."""
    n_row = max(9, round((n_target - 9) / ROWS))
    if n_row <= DIRECT_MAX_N_ROW:
        pos, walls, box = lattice(n_row)
        run_relax(K, pos, walls, box, relax_steps, threads)
        return pos, walls, box
    if "base" not in base_cache:
        pos, walls, box = lattice(BASE_N_ROW)
        run_relax(K, pos, walls, box, relax_steps, threads)
        base_cache["base"] = pos
    p = base_cache["base"]
    wb = (BASE_N_ROW + 1) * A
    k = max(2, round(n_target / len(p)))
    mirror = np.column_stack([wb - p[:, 0], p[:, 1]])
    pos = np.ascontiguousarray(np.concatenate([(mirror if c % 2 else p) + [c * wb, 0.0] for c in range(k)]))
    width = k * wb
    walls = np.array([[0, HEIGHT, 0, 0], [0, 0, width, 0], [width, 0, width, HEIGHT]], float)
    box = np.array([0.0, 0.0, width, HEIGHT])
    run_relax(K, pos, walls, box, heal_steps, threads)  # close the seams where inner walls were removed
    return pos, walls, box


def time_numba(K, pos, walls, box, target, reps, threads):
    """{t: (steps per call, CPU ns per particle-step best / median, wall ns best / median)} for every
    thread count t, the calls interleaved (t1, t2, t1, t2, ...) so that the thread counts share the
    machine's load alike."""
    import numba
    n = len(pos)
    n_steps = max(100, int(np.ceil(target / n)))
    ts = {t: [] for t in threads}
    tw = {t: [] for t in threads}
    try:
        for _ in range(reps):
            for t in threads:
                if getattr(K, "threaded", False):
                    numba.set_num_threads(t)
                p = pos.copy()
                t0, w0 = time.process_time(), time.perf_counter()
                run_relax(K, p, walls, box, n_steps, t)
                ts[t].append(time.process_time() - t0)
                tw[t].append(time.perf_counter() - w0)
    finally:
        if getattr(K, "threaded", False):
            numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    out = {}
    for t in threads:
        c = np.array(ts[t]) / (n_steps * n) * 1e9
        w = np.array(tw[t]) / (n_steps * n) * 1e9
        out[t] = (n_steps, c.min(), float(np.median(c)), w.min(), float(np.median(w)))
    return out


def time_numpy(ref, pos, walls, box, target, reps):
    """Best and median ns per particle-step of the NumPy reference (initial pair-list build excluded)."""
    n = len(pos)
    st = ref.NumpyRelax(pos, np.full(n, WEIGHT), walls, box, WL_U, WR_U, PL_U, PR_U, DU, SKIN)
    t0 = time.perf_counter()
    st.build()
    t_build = time.perf_counter() - t0
    n_steps = max(3, int(np.ceil(target / n)))
    ts, tw = [], []
    for _ in range(reps):
        t0, w0 = time.process_time(), time.perf_counter()
        st.run(n_steps)
        ts.append(time.process_time() - t0)
        tw.append(time.perf_counter() - w0)
    ts = np.array(ts) / (n_steps * n) * 1e9
    return n_steps, ts.min(), float(np.median(ts)), min(tw) / (n_steps * n) * 1e9, t_build / n * 1e9


def check_numpy_equivalence(K, ref):
    """NumPy reference forces == compiled forces on a perturbed small relaxed case; also five steps."""
    pos, walls, box = lattice(9)
    rng = np.random.default_rng(0)
    pos += rng.normal(0, 0.8, pos.shape)
    pos[:3] = [[0.5, 50.0], [99.2, 3.0], [0.3, 0.4]]  # near walls and a corner
    n = len(pos)
    w = np.full(n, WEIGHT)
    pi, pj, m = K.build_pairs(pos, box, PL_U + SKIN)
    f = np.zeros_like(pos)
    K.forces(pos, w, walls, WL_U, WR_U, PL_U, PR_U, pi, pj, m, f)
    st = ref.NumpyRelax(pos, w, walls, box, WL_U, WR_U, PL_U, PR_U, DU, SKIN)
    np.testing.assert_allclose(np.column_stack([st.fx, st.fy]), f, rtol=1e-12, atol=1e-9)
    p1 = pos.copy()
    f, _ = run_relax(K, p1, walls, box, 5)
    st.run(5)
    np.testing.assert_allclose(st.pos, p1, rtol=0, atol=1e-9)
    np.testing.assert_allclose(np.column_stack([st.fx, st.fy]), f, rtol=1e-10, atol=1e-7)
    return float(np.abs(f).max())


# ---- subprocess probes ---------------------------------------------------------------------------------

def probe_compile(kernels_path):
    """First call of the step loop in this process (compile or cache load); prints JSON."""
    t0 = time.perf_counter()
    K = load_kernels(kernels_path)
    t_import = time.perf_counter() - t0
    pos, walls, box = lattice(9)
    t0 = time.perf_counter()
    run_relax(K, pos, walls, box, 10)
    t_first = time.perf_counter() - t0
    t0 = time.perf_counter()
    run_relax(K, pos, walls, box, 10)
    t_second = time.perf_counter() - t0
    st = getattr(K, "relax_resume", K.relax).stats
    print(json.dumps(dict(import_s=t_import, first_call_s=t_first, second_call_s=t_second,
                          cache_hits=sum(st.cache_hits.values()), cache_misses=sum(st.cache_misses.values()))))


def status_kb(key):
    for line in open("/proc/self/status"):
        if line.startswith(key):
            return int(line.split()[1])
    return -1


def probe_memory(kernels_path, npy):
    """Peak RSS growth during relax on the state saved in npy (1 thread); prints JSON."""
    K = load_kernels(kernels_path)
    p, walls, box = lattice(9)
    run_relax(K, p, walls, box, 2)  # compile / load before measuring
    d = np.load(npy)
    pos, walls, box = np.ascontiguousarray(d["pos"]), d["walls"], d["box"]
    n = len(pos)
    vel, f, weight, hist = np.zeros_like(pos), np.zeros_like(pos), np.full(n, WEIGHT), np.zeros(100)
    caller = pos.nbytes + vel.nbytes + f.nbytes + weight.nbytes
    pos[:] += 0.0
    vel[:] = 0.0  # touch the pages
    f[:] = 0.0
    rss0 = status_kb("VmRSS")
    with open("/proc/self/clear_refs", "w") as fh:
        fh.write("5")  # reset the peak-RSS counter VmHWM
    args = (pos, vel, weight, walls, box, WL_U, WR_U, PL_U, PR_U, K.PAPER, DU, 1.0, 0.1, F_TOL, 100, SKIN, f, hist)
    K.relax(*args, 1) if getattr(K, "threaded", False) else K.relax(*args)
    hwm = status_kb("VmHWM")
    print(json.dumps(dict(n=n, rss_before_kb=rss0, hwm_kb=hwm, kernel_bytes=(hwm - rss0) * 1024,
                          caller_bytes=caller)))


def run_probe(args, env=None):
    out = subprocess.run([sys.executable, __file__] + args, capture_output=True, text=True, env=env)
    if out.returncode:
        raise RuntimeError(f"probe {args} failed:\n{out.stderr}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def measure_compile(kernels_path):
    extra = ["--kernels", kernels_path] if kernels_path else []
    rows = []
    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "NUMBA_CACHE_DIR": cache}
        for label in ("cold cache (compile)", "warm cache (load)"):
            r = run_probe(["--probe-compile"] + extra, env)
            r["files_in_cache"] = sum(len(fs) for _, _, fs in os.walk(cache))
            r["run"] = label
            rows.append(r)
    return rows


def machine_info():
    import numba
    model = "unknown"
    for line in open("/proc/cpuinfo"):
        if line.startswith("model name"):
            model = line.split(":", 1)[1].strip()
            break
    try:
        import llvmlite.binding as ll
        host = ll.get_host_cpu_name()
    except Exception:  # pragma: no cover
        host = "?"
    try:
        layer = numba.threading_layer()
    except ValueError:
        layer = "not initialised"
    lines = [f"cpu model (/proc/cpuinfo): {model}", f"llvm host cpu: {host}",
             f"logical cores: {os.cpu_count()}", f"numba threads used: {', '.join(map(str, THREADS))} (step table); "
             f"1 (equilibrium solver, serial); NUMBA_NUM_THREADS = {numba.config.NUMBA_NUM_THREADS}",
             f"numba threading layer: {layer}",
             "the machine is shared with other jobs: timings are medians of repeated calls; see the load averages "
             "in summary.txt",
             f"python: {platform.python_version()} ({platform.python_implementation()})",
             f"numba: {numba.__version__}", f"numpy: {np.__version__}", f"platform: {platform.platform()}"]
    try:
        lscpu = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
        lines += [ln.strip() for ln in lscpu.splitlines() if "cache" in ln or "MHz" in ln or "Model name" in ln]
    except OSError:  # pragma: no cover
        pass
    return "\n".join(lines) + "\n"


def load_average():
    return " ".join(open("/proc/loadavg").read().split()[:3])


def fit_exponent(ns, cost_per_step):
    ns, c = np.asarray(ns, float), np.asarray(cost_per_step, float)
    sel = ns >= 1e4
    if sel.sum() < 2:
        return float("nan")
    return float(np.polyfit(np.log(ns[sel]), np.log(c[sel]), 1)[0])


def plot(outdir, tables, threads_rows):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    styles = {"numba": ("o-", "C0"), "numba (before)": ("s--", "C7"), "numpy": ("^-", "C3")}
    for label, rows in tables.items():
        ns = np.array([r["N"] for r in rows], float)
        ns_ps = np.array([r["ns_per_particle_step"] for r in rows], float)
        p = fit_exponent(ns, ns_ps * ns)
        mk, col = styles.get(label, ("x-", None))
        ax.loglog(ns, ns_ps, mk, color=col, label=f"{label}, 1 thread (CPU): cost/step ~ N^{p:.2f} (fit N >= 1e4)")
    if threads_rows:
        ns = np.array([r["N"] for r in threads_rows], float)
        for t, mk in zip(THREADS, ("D:", "v-")):
            ax.loglog(ns, [r[f"wall_ns_{t}t"] for r in threads_rows], mk, color="C2" if t > 1 else "C9",
                      label=f"numba, {t} thread{'s' if t > 1 else ''} (wall, median)")
    ax.axhline(TARGET_NS_2T, color="k", lw=0.8, ls=":", label=f"target {TARGET_NS_2T:g} ns (2 threads, N >= 1e5)")
    ax.set_xlabel("N, particles [-]")
    ax.set_ylabel("time per particle-step [ns]")
    ax.set_title("relax_resume (PAPER) vs vectorised NumPy; shared 2-core machine")
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(outdir / "step_cost.png", dpi=150)


def read_csv(path):
    with open(path) as fh:
        rows = list(csv.DictReader(fh))
    for r in rows:
        for k in ("N", "ns_per_particle_step"):
            r[k] = float(r[k])
    return rows


def write_csv(path, rows, keys=None):
    keys = keys or list(rows[0])
    with open(path, "w", newline="") as fh:
        wr = csv.DictWriter(fh, keys)
        wr.writeheader()
        for r in rows:
            wr.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in r.items() if k in keys})


# ---- equilibrium solver ------------------------------------------------------------------------------------

def leaf(value, why):
    return {"value": value, "source": f"inferred: benchmark, {why}"}


def declared_sets(run_id):
    """The overrides of a run declared in config/methods/isa.yaml ({key: {value, source}})."""
    from isaflow import settings as S
    from isaflow.methods.isa.settings import VALUES
    return dict(S.read(ISA_SETTINGS, VALUES)["runs"][run_id].get("set", {}))


def solve_run(tank, resolution, variant, out, sets=None, start=None, threads=1):
    """Result of one run through isaflow.run (checks, warm-up outside the solver time, solve), its
    run file written to out (the metrics read it)."""
    from isaflow import run
    p = run.prepare("isa", str(ROOT / "config" / "tanks" / f"{tank}.yaml"), variant, resolution, str(out),
                    str(ISA_SETTINGS), sets or {}, None if start is None else str(start),
                    ("converged", "cycle", "step_limit"), threads)
    result, started, finished = run.solve(p, log=lambda msg: None)
    run.write(p, result, started, finished)
    return result


def fire_sets(tank, resolution):
    """The study's best FIRE: du = 100 x the resolution's, dt_max = 2 / sqrt(2 k_b + 12 k_p)."""
    from isaflow.methods.isa import scene as S
    from isaflow.methods.isa.settings import fire_dt_max, settings
    sc = S.of_run(tank, resolution, "fire", (), str(ISA_SETTINGS))
    du = settings(sc)["du"]
    return {"solver.du": leaf(100 * du, "du 100 x the resolution's (the study's best FIRE)"),
            "solver.dt_max": leaf(fire_dt_max(sc.stiffness("wall"), sc.stiffness("pair"), 2.0),
                                  "2 / sqrt(2 k_b + 12 k_p) (the study's best FIRE)"),
            "solver.max_steps": leaf(2_000_000, "FIRE's step limit")}


def state_diff(capped_file, newton_file, vessel=None):
    """Level [cm] and side-load (relative) differences newton - capped, with the report's tolerances."""
    from isaflow import metrics, runfile
    from isaflow.methods.isa.metrics import tolerances
    a, b = runfile.read(capped_file), runfile.read(newton_file)
    ea, eb = metrics.load_errors(a, vessel, "level"), metrics.load_errors(b, vessel, "level")
    view = metrics.vessel_view(a, vessel)
    tol = tolerances(dict(depth=ea["depth"], weight=ea["weight"]), float(a.attrs["spacing"]),
                     int(view["inside"].sum()), float(a.attrs["solver.f_tol"]))
    return dict(level_diff_cm=eb["level"] - ea["level"], level_tol_cm=tol["level"][0],
                side_err_diff=eb["side_err"] - ea["side_err"], side_tol=tol["side"][0],
                floor_err_diff=eb["floor_err"] - ea["floor_err"], floor_tol=tol["floor"][0])


def newton_table(scenes, tmp):
    """Rows of newton_evals.csv: every scene with newton_lm, FIRE and (where cheap) capped."""
    rows = []
    for name in scenes:
        tank, res = CASES[name]
        row = dict(scene=name)
        files = {}
        for variant, sets in (("newton_lm", {}), ("fire", fire_sets(tank, res)), ("capped", {})):
            if variant == "capped" and name in REFERENCE_CAPPED:
                row.update(capped_evals=REFERENCE_CAPPED[name], capped_s=float("nan"),
                           capped_source="reference (deterministic count, not rerun)")
                continue
            files[variant] = tmp / f"{name}_{variant}.nc"
            r = solve_run(tank, res, variant, files[variant], sets)
            assert r.status == "converged", (name, variant, r.status, r.message)
            key = {"newton_lm": "newton", "fire": "fire", "capped": "capped"}[variant]
            row.update({f"{key}_evals": r.force_evals, f"{key}_s": r.wall_time})
            if variant == "newton_lm":
                row.update(particles=len(r.pos), newton_steps=r.steps,
                           hessian_assemblies=r.params["hessian_assemblies"],
                           cg_iterations=r.params["cg_iterations"], refused_steps=r.params["refused_steps"])
            if variant == "capped":
                row["capped_source"] = "this run"
        if "capped" in files:
            row.update(state_diff(files["capped"], files["newton_lm"]))
        rows.append(row)
    # the complete coarse flow: application 1 -> 3 (paper's update, to step 100,000) -> 4 (capped, newton_lm)
    app1, app3 = tmp / "app1.nc", tmp / "app3.nc"
    solve_run("single", "coarse", "paper", app1)
    solve_run("flow_step50", "coarse", "paper", app3, declared_sets("flow_incomplete"), start=app1)
    row = dict(scene="flow_step50 (complete, from step 100,000)")
    files = {}
    flow_sets = declared_sets("flow_complete_capped")  # to step 300,000, flow records
    for variant, sets in (("newton_lm", flow_sets), ("fire", {**flow_sets, **fire_sets("flow_step50", "coarse")}),
                          ("capped", flow_sets)):
        files[variant] = tmp / f"flow_{variant}.nc"
        r = solve_run("flow_step50", "coarse", variant, files[variant], sets, start=app3)
        key = {"newton_lm": "newton", "fire": "fire", "capped": "capped"}[variant]
        row.update({f"{key}_evals": r.force_evals, f"{key}_s": r.wall_time, f"{key}_status": r.status})
        if variant == "newton_lm":
            row.update(particles=len(r.pos), newton_steps=r.steps - FLOW_START_STEPS,
                       hessian_assemblies=r.params["hessian_assemblies"], cg_iterations=r.params["cg_iterations"],
                       refused_steps=r.params["refused_steps"])
    row["capped_source"] = "this run"
    row.update(state_diff(files["capped"], files["newton_lm"], "second"))
    rows.append(row)
    for r in rows:
        r["newton_over_capped"] = r["newton_evals"] / r["capped_evals"]
        r["newton_over_fire"] = r["newton_evals"] / r["fire_evals"]
    return rows


NEWTON_KEYS = ["scene", "particles", "newton_evals", "newton_steps", "hessian_assemblies", "cg_iterations",
               "refused_steps", "newton_s", "capped_evals", "capped_s", "capped_source", "fire_evals", "fire_s",
               "newton_over_capped", "newton_over_fire", "level_diff_cm", "level_tol_cm", "side_err_diff", "side_tol",
               "floor_err_diff", "floor_tol", "newton_status", "capped_status", "fire_status"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="reduced N list, no newton table (< 30 s)")
    ap.add_argument("--finer", action="store_true", help="also study_finer in the newton table (~20 s more)")
    ap.add_argument("--kernels", help="time this copy of kernels.py instead of isaflow.methods.isa.relax")
    ap.add_argument("--tag", default="", help="suffix of the output files, e.g. 'before'")
    ap.add_argument("--no-numpy", action="store_true", help="skip the NumPy reference")
    ap.add_argument("--out", help="output folder (default benchmarks/results, or benchmarks/results/quick "
                                   "with --quick)")
    ap.add_argument("--probe-compile", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--probe-memory", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.probe_compile:
        return probe_compile(args.kernels)
    if args.probe_memory:
        return probe_memory(args.kernels, args.probe_memory)

    t_start = time.perf_counter()
    load_start = load_average()
    out = Path(args.out or (HERE / "results" / "quick" if args.quick else HERE / "results"))
    out.mkdir(parents=True, exist_ok=True)
    sfx = f"_{args.tag}" if args.tag else ""
    kpath = str(Path(args.kernels).resolve()) if args.kernels else None

    # compile vs cache load, in fresh processes with a private cache directory
    comp = measure_compile(kpath)
    write_csv(out / f"compile{sfx}.csv", comp, ["run", "import_s", "first_call_s", "second_call_s", "cache_hits",
                                                  "cache_misses", "files_in_cache"])
    for r in comp:
        print(f"compile: {r['run']:22s} first call {r['first_call_s']:.3f} s  (import {r['import_s']:.3f} s, "
              f"cache hits {r['cache_hits']}, misses {r['cache_misses']})", flush=True)

    K = load_kernels(kpath)
    threads = THREADS if getattr(K, "threaded", False) else (1,)
    ref = None
    if not args.no_numpy:
        import numpy_reference as ref
        fm = check_numpy_equivalence(K, ref)
        print(f"numpy reference == compiled forces (max|F| {fm:.4g} N): ok", flush=True)

    n_list = QUICK_N if args.quick else FULL_N
    target = 3e6 if args.quick else 2e7  # particle-steps per timed call (200 steps at N = 1e5)
    np_target = 2e5
    reps = 5
    relax_steps = 5000 if args.quick else RELAX_STEPS
    heal_steps = 500 if args.quick else HEAL_STEPS
    base = {}
    rows, trows, frows = [], [], []
    big_state = None
    for n_target in n_list:
        t0 = time.perf_counter()
        pos, walls, box = relaxed_state(K, n_target, base, relax_steps, heal_steps, max(threads))
        n = len(pos)
        t_prep = time.perf_counter() - t0
        f, hist = run_relax(K, pos.copy(), walls, box, 1)
        pi, pj, m = K.build_pairs(pos, box, PL_U + SKIN)
        d = np.hypot(*(pos[pi[:m]] - pos[pj[:m]]).T)
        contacts = float((d < PL_U).sum()) * 2 / n
        trow = dict(N=n)
        timed = time_numba(K, pos, walls, box, target, reps, threads)
        for t in threads:
            steps, best, med, wbest, wmed = timed[t]
            trow.update({f"cpu_ns_{t}t": med, f"wall_ns_{t}t": wmed, f"wall_ns_best_{t}t": wbest,
                         "steps_per_call": steps})
            if t == 1:
                row = dict(impl="numba", threads=1, N=n, steps_per_call=steps, reps=reps, ns_per_particle_step=best,
                           ns_median=med, ns_wall_best=wbest, s_per_step=best * n * 1e-9,
                           contacts_per_particle=contacts, list_pairs_per_particle=m / n, fmax_start=hist[0],
                           prep_s=t_prep)
                rows.append(row)
        msg = f"N={n:8d} " + "  ".join(f"{t} thread(s): {trow[f'wall_ns_{t}t']:6.2f} ns wall "
                                       f"(cpu {trow[f'cpu_ns_{t}t']:.2f})" for t in threads)
        if len(threads) > 1:
            t2 = threads[-1]
            trow["speedup"] = trow["wall_ns_1t"] / trow[f"wall_ns_{t2}t"]
            trow["efficiency"] = trow["speedup"] / t2
            trow["speedup_best"] = trow["wall_ns_best_1t"] / trow[f"wall_ns_best_{t2}t"]
            trow["efficiency_best"] = trow["speedup_best"] / t2
            msg += f"  speed-up {trow['speedup']:.2f}, efficiency {trow['efficiency']:.0%}"
        trows.append(trow)
        if kpath is None:
            load0 = os.getloadavg()[0]
            frow = floor_cost(K, pos, walls, box, target, reps)
            frow["load_average"] = 0.5 * (load0 + os.getloadavg()[0])
            frows.append(frow)
            msg += (f" | floor {frow['floor_ns_per_particle_step']:.2f} ns vs {frow['ns_per_particle_step']:.2f} "
                    f"(x{frow['ratio']:.2f}, max diff {frow['max_pos_diff_cm']:.3g} cm)")
        if ref is not None:
            nps, nbest, nmed, nwall, nbuild = time_numpy(ref, pos, walls, box, np_target, 3)
            rows.append(dict(impl="numpy", threads=1, N=n, steps_per_call=nps, reps=3, ns_per_particle_step=nbest,
                             ns_median=nmed, ns_wall_best=nwall, s_per_step=nbest * n * 1e-9,
                             numpy_build_ns_per_particle=nbuild))
            row["speedup_vs_numpy"] = nbest / row["ns_per_particle_step"]
            msg += f" | numpy {nbest:8.1f} ns ({nps} steps) -> x{row['speedup_vs_numpy']:.1f}"
        print(msg, flush=True)
        big_state = (pos, walls, box)

    # memory at the largest N, in a fresh process
    with tempfile.TemporaryDirectory() as tmp:
        npy = Path(tmp) / "state.npz"
        np.savez(npy, pos=big_state[0], walls=big_state[1], box=big_state[2])
        mem = run_probe(["--probe-memory", str(npy)] + (["--kernels", kpath] if kpath else []))
    n_big = mem["n"]
    mem_row = dict(N=n_big, kernel_peak_bytes_per_particle=mem["kernel_bytes"] / n_big,
                   caller_state_bytes_per_particle=mem["caller_bytes"] / n_big,
                   total_bytes_per_particle=(mem["kernel_bytes"] + mem["caller_bytes"]) / n_big)
    write_csv(out / f"memory{sfx}.csv", [mem_row])

    if frows:
        write_csv(out / f"step_floor{sfx}.csv", frows)
    keys = ["impl", "threads", "N", "steps_per_call", "reps", "ns_per_particle_step", "ns_median", "ns_wall_best",
            "s_per_step", "speedup_vs_numpy", "contacts_per_particle", "list_pairs_per_particle", "fmax_start",
            "prep_s", "numpy_build_ns_per_particle"]
    write_csv(out / f"step_cost{sfx}.csv", rows, keys)
    if len(threads) > 1:
        t2 = threads[-1]
        for r in trows:
            r["target_2t_met"] = (("yes" if r[f"wall_ns_{t2}t"] <= TARGET_NS_2T else "no") + " (median), "
                                  + ("yes" if r[f"wall_ns_best_{t2}t"] <= TARGET_NS_2T else "no") + " (best)"
                                  if r["N"] >= 1e5 else "n/a")
        write_csv(out / f"step_threads{sfx}.csv", trows,
                  ["N", "steps_per_call"]
                  + [f"{k}_{t}t" for t in threads for k in ("wall_ns", "wall_ns_best", "cpu_ns")]
                  + ["speedup", "efficiency", "speedup_best", "efficiency_best", "target_2t_met"])

    nrows = []
    if not args.quick and kpath is None:
        with tempfile.TemporaryDirectory() as tmp:
            nrows = newton_table(SCENES + (["study_finer"] if args.finer else []), Path(tmp))
        write_csv(out / "newton_evals.csv", nrows, [k for k in NEWTON_KEYS if any(k in r for r in nrows)])

    nb = [r for r in rows if r["impl"] == "numba"]
    expo = fit_exponent([r["N"] for r in nb], [r["s_per_step"] for r in nb])
    lines = [f"kernels: {kpath or 'isaflow.methods.isa.relax'}", f"mode: {'quick' if args.quick else 'full'}",
             f"load average (1, 5, 15 min) at start: {load_start}; at end: {load_average()} (2 cores, shared machine)",
             f"compile (cold cache) first call: {comp[0]['first_call_s']:.3f} s; "
             f"cache load (warm cache) first call: {comp[1]['first_call_s']:.3f} s "
             f"(hits {comp[1]['cache_hits']}, misses {comp[1]['cache_misses']})",
             f"fitted exponent of cost per step vs N (N >= 1e4, 1 thread): {expo:.3f}",
             f"memory at N = {n_big}: kernel peak {mem_row['kernel_peak_bytes_per_particle']:.1f} B/particle + "
             f"caller state {mem_row['caller_state_bytes_per_particle']:.1f} = "
             f"{mem_row['total_bytes_per_particle']:.1f} B/particle"]
    for r in nb:
        s = f"N={int(r['N']):8d}: {r['ns_per_particle_step']:7.2f} ns/particle-step (1 thread, CPU)"
        if "speedup_vs_numpy" in r:
            s += f", numpy x{r['speedup_vs_numpy']:.1f}"
        lines.append(s)
    for r in trows:
        if len(threads) > 1:
            t2 = threads[-1]
            lines.append(f"N={int(r['N']):8d}: wall median {r['wall_ns_1t']:.2f} ns (1 thread) vs "
                         f"{r[f'wall_ns_{t2}t']:.2f} ns ({t2} threads): speed-up {r['speedup']:.2f}, "
                         f"parallel efficiency {r['efficiency']:.0%} (best of {reps}: {r['wall_ns_best_1t']:.2f} vs "
                         f"{r[f'wall_ns_best_{t2}t']:.2f} ns, {r['efficiency_best']:.0%}); "
                         f"target <= {TARGET_NS_2T:g} ns at N >= 1e5: {r['target_2t_met']}")
    for r in nrows:
        lines.append(f"newton_lm {r['scene']}: {r['newton_evals']} force evaluations in {r['newton_s']:.3f} s "
                     f"({r['hessian_assemblies']} Hessian assemblies, {r['cg_iterations']} CG iterations); capped "
                     f"{r['capped_evals']} ({r['newton_over_capped']:.2%}), FIRE {r['fire_evals']}")
    lines.append(f"benchmark wall time: {time.perf_counter() - t_start:.1f} s")
    (out / f"summary{sfx}.txt").write_text("\n".join(lines) + "\n")
    (out / "machine.txt").write_text(machine_info())
    print("\n".join(lines))

    tables = {}
    for tag, label in (("", "numba"), ("_before", "numba (before)")):
        p = out / f"step_cost{tag}.csv"
        if p.exists():
            t = [r for r in read_csv(p) if r["impl"] == "numba"]
            tables[label] = t
    p = out / "step_cost.csv"
    if p.exists():
        t = [r for r in read_csv(p) if r["impl"] == "numpy"]
        if t:
            tables["numpy"] = t
    plot(out, tables, trows if len(threads) > 1 else [])


if __name__ == "__main__":
    main()
