"""Cost of one step of the paper's algorithm (compiled ``methods.isa.relax.relax``, variant PAPER) vs N.

Run: ``python benchmarks/bench_step.py [--quick]`` (a plain script, not a test).

Scene (units cm, N): the paper's application-1 liquid made wide.  A rhombic
lattice (``isaflow.scene.rhombic_lattice``, a = 10 cm) of 19 rows alternating
n and n + 1 particles (N = 19 n + 9; n = 9 is the paper's 180-particle case) in
a rectangular vessel of height 100 cm and width (n + 1) a, particle weight
50 N, wall law l_u = 5 cm / r_u = 10 kN, pair law l_u = a / sqrt(2) /
r_u = 500 l_u N, du = 0.01 cm, skin 0.3 l_u (the solver's default), f_tol
1e-30 N so no run stops early.  The depth stays that of the paper and only
the width grows, so the contact structure per particle is the same at every N.

The liquid is relaxed before timing: the small cases directly (20,000 steps),
the large ones by tiling a relaxed 1,890-particle vessel: its left 450 cm,
k copies of its central 100 cm strip and its right 450 cm (particles chosen by
their initial lattice x, so every tile holds whole lattice columns).

Outputs (benchmarks/results/, or results/quick/ with --quick): step_cost[_TAG].csv, compile[_TAG].csv,
memory[_TAG].csv, summary[_TAG].txt, machine.txt, step_cost.png.
``--kernels FILE --tag before`` times another single-file copy of the kernels (e.g. the
version before optimisation, ``git show 09b8875:src/isaflow/kernels.py``).
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
HEAL_STEPS = 2000

FULL_N = [180, 684, 3000, 10_000, 30_000, 100_000, 300_000, 1_000_000]
QUICK_N = [180, 684, 3000, 10_000, 30_000]


def load_kernels(path):
    """The kernels to time: isaflow's (relax loop, force evaluation, neighbour list as one
    namespace) or another copy of a single kernels file (an older version)."""
    if path is None:
        from types import SimpleNamespace

        from isaflow.core import neighbours
        from isaflow.methods.isa import forces, relax
        return SimpleNamespace(relax=relax.relax, PAPER=relax.PAPER, RUNNING=relax.RUNNING,
                               forces=forces.forces, build_pairs=neighbours.build_pairs)
    path = Path(path).resolve()  # imported by name so numba's cache can find it again
    sys.path.insert(0, str(path.parent))
    return importlib.import_module(path.stem)


def lattice(n_row):
    """Initial (N, 2) positions [cm], walls (3, 4) [cm] and box of the vessel with rows of n_row / n_row + 1."""
    from isaflow.scene import rhombic_lattice
    width = (n_row + 1) * A
    pos = rhombic_lattice(A, ROWS, [n_row, n_row + 1], width / 2, 5.0)
    walls = np.array([[0, HEIGHT, 0, 0], [0, 0, width, 0], [width, 0, width, HEIGHT]], float)
    box = np.array([0.0, 0.0, width, HEIGHT])
    return pos, walls, box


def run_relax(K, pos, walls, box, n_steps):
    """kernels.relax, variant PAPER, in place on pos; returns (steps, status, fmax_hist)."""
    n = len(pos)
    f = np.zeros_like(pos)
    hist = np.zeros(max(n_steps, 1))
    steps, status, _ = K.relax(pos, np.zeros_like(pos), np.full(n, WEIGHT), walls, box, WL_U, WR_U, PL_U, PR_U,
                               K.PAPER, DU, 1.0, 0.1, F_TOL, n_steps, SKIN, f, hist)
    assert status == K.RUNNING and steps == n_steps, (steps, status)
    return f, hist


def relaxed_state(K, n_target, base_cache, relax_steps, heal_steps):
    """Relaxed wide-vessel state with about n_target particles: (pos, walls, box)."""
    n_row = max(9, round((n_target - 9) / ROWS))
    if n_row <= DIRECT_MAX_N_ROW:
        pos, walls, box = lattice(n_row)
        run_relax(K, pos, walls, box, relax_steps)
        return pos, walls, box
    if "base" not in base_cache:
        pos, walls, box = lattice(BASE_N_ROW)
        run_relax(K, pos, walls, box, relax_steps)
        base_cache["base"] = pos
    p = base_cache["base"]
    wb = (BASE_N_ROW + 1) * A
    k = max(2, round(n_target / len(p)))
    mirror = np.column_stack([wb - p[:, 0], p[:, 1]])
    pos = np.ascontiguousarray(np.concatenate([(mirror if c % 2 else p) + [c * wb, 0.0] for c in range(k)]))
    width = k * wb
    walls = np.array([[0, HEIGHT, 0, 0], [0, 0, width, 0], [width, 0, width, HEIGHT]], float)
    box = np.array([0.0, 0.0, width, HEIGHT])
    run_relax(K, pos, walls, box, heal_steps)  # close the seams where inner walls were removed
    return pos, walls, box


def time_numba(K, pos, walls, box, target, reps):
    """Best and median ns per particle-step of relax over reps calls of n_steps each."""
    n = len(pos)
    n_steps = max(200, int(np.ceil(target / n)))
    ts, tw = [], []
    for _ in range(reps):
        t0, w0 = time.process_time(), time.perf_counter()
        run_relax(K, pos, walls, box, n_steps)
        ts.append(time.process_time() - t0)
        tw.append(time.perf_counter() - w0)
    ts = np.array(ts) / (n_steps * n) * 1e9
    return n_steps, ts.min(), float(np.median(ts)), min(tw) / (n_steps * n) * 1e9


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
    """NumPy reference forces == compiled forces on a perturbed small relaxed case; also one step."""
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
    K.relax(p1, np.zeros_like(p1), w, walls, box, WL_U, WR_U, PL_U, PR_U, K.PAPER, DU, 1.0, 0.1, F_TOL, 5,
            SKIN, f, np.zeros(5))
    st.run(5)
    np.testing.assert_allclose(st.pos, p1, rtol=0, atol=1e-9)
    np.testing.assert_allclose(np.column_stack([st.fx, st.fy]), f, rtol=1e-10, atol=1e-7)
    return float(np.abs(f).max())


# ---- subprocess probes ---------------------------------------------------------------------------------

def probe_compile(kernels_path):
    """First call of relax in this process (compile or cache load); prints JSON."""
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
    st = K.relax.stats
    print(json.dumps(dict(import_s=t_import, first_call_s=t_first, second_call_s=t_second,
                          cache_hits=sum(st.cache_hits.values()), cache_misses=sum(st.cache_misses.values()))))


def status_kb(key):
    for line in open("/proc/self/status"):
        if line.startswith(key):
            return int(line.split()[1])
    return -1


def probe_memory(kernels_path, npy):
    """Peak RSS growth during relax on the state saved in npy; prints JSON."""
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
    K.relax(pos, vel, weight, walls, box, WL_U, WR_U, PL_U, PR_U, K.PAPER, DU, 1.0, 0.1, F_TOL, 100, SKIN, f, hist)
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
    lines = [f"cpu model (/proc/cpuinfo): {model}", f"llvm host cpu: {host}",
             f"logical cores: {os.cpu_count()}", "numba threads used: 1 (kernels are not parallel)",
             f"python: {platform.python_version()} ({platform.python_implementation()})",
             f"numba: {numba.__version__}", f"numpy: {np.__version__}", f"platform: {platform.platform()}"]
    try:
        lscpu = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
        lines += [ln.strip() for ln in lscpu.splitlines() if "cache" in ln or "MHz" in ln or "Model name" in ln]
    except OSError:  # pragma: no cover
        pass
    return "\n".join(lines) + "\n"


def fit_exponent(ns, cost_per_step):
    ns, c = np.asarray(ns, float), np.asarray(cost_per_step, float)
    sel = ns >= 1e4
    if sel.sum() < 2:
        return float("nan")
    return float(np.polyfit(np.log(ns[sel]), np.log(c[sel]), 1)[0])


def plot(outdir, tables):
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
        ax.loglog(ns, ns_ps, mk, color=col, label=f"{label}: cost/step ~ N^{p:.2f} (fit N >= 1e4)")
    ax.axhline(20.0, color="k", lw=0.8, ls=":", label="target 20 ns")
    ax.set_xlabel("N, particles [-]")
    ax.set_ylabel("CPU time per particle-step [ns]")
    ax.set_title("kernels.relax (PAPER) vs vectorised NumPy, 1 core")
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(outdir / "step_cost.png", dpi=150)


def read_csv(path):
    with open(path) as fh:
        rows = list(csv.DictReader(fh))
    for r in rows:
        for k in ("N", "ns_per_particle_step"):
            r[k] = float(r[k])
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="reduced N list (< 60 s)")
    ap.add_argument("--kernels", help="time this copy of kernels.py instead of isaflow.methods.isa.relax")
    ap.add_argument("--tag", default="", help="suffix of the output files, e.g. 'before'")
    ap.add_argument("--no-numpy", action="store_true", help="skip the NumPy reference")
    ap.add_argument("--out", help="output folder (default benchmarks/results, or benchmarks/results/quick with --quick)")
    ap.add_argument("--probe-compile", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--probe-memory", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.probe_compile:
        return probe_compile(args.kernels)
    if args.probe_memory:
        return probe_memory(args.kernels, args.probe_memory)

    t_start = time.perf_counter()
    out = Path(args.out or (HERE / "results" / "quick" if args.quick else HERE / "results"))
    out.mkdir(parents=True, exist_ok=True)
    sfx = f"_{args.tag}" if args.tag else ""
    kpath = str(Path(args.kernels).resolve()) if args.kernels else None
    (out / "machine.txt").write_text(machine_info())

    # compile vs cache load, in fresh processes with a private cache directory
    comp = measure_compile(kpath)
    with open(out / f"compile{sfx}.csv", "w", newline="") as fh:
        wr = csv.DictWriter(fh, ["run", "import_s", "first_call_s", "second_call_s", "cache_hits", "cache_misses",
                                 "files_in_cache"])
        wr.writeheader()
        wr.writerows(comp)
    for r in comp:
        print(f"compile: {r['run']:22s} first call {r['first_call_s']:.3f} s  (import {r['import_s']:.3f} s, "
              f"cache hits {r['cache_hits']}, misses {r['cache_misses']})", flush=True)

    K = load_kernels(kpath)
    ref = None
    if not args.no_numpy:
        import numpy_reference as ref
        fm = check_numpy_equivalence(K, ref)
        print(f"numpy reference == compiled forces (max|F| {fm:.4g} N): ok", flush=True)

    n_list = QUICK_N if args.quick else FULL_N
    target = 2e6 if args.quick else 3e7  # particle-steps per timed call
    np_target = 2e5 if args.quick else 1e6
    reps = 3
    relax_steps = 5000 if args.quick else RELAX_STEPS
    heal_steps = 500 if args.quick else HEAL_STEPS
    base = {}
    rows = []
    big_state = None
    for n_target in n_list:
        t0 = time.perf_counter()
        pos, walls, box = relaxed_state(K, n_target, base, relax_steps, heal_steps)
        n = len(pos)
        t_prep = time.perf_counter() - t0
        f, hist = run_relax(K, pos, walls, box, 1)
        pi, pj, m = K.build_pairs(pos, box, PL_U + SKIN)
        d = np.hypot(*(pos[pi[:m]] - pos[pj[:m]]).T)
        contacts = float((d < PL_U).sum()) * 2 / n
        steps, best, med, wall = time_numba(K, pos, walls, box, target, reps)
        row = dict(impl="numba", N=n, steps_per_call=steps, reps=reps, ns_per_particle_step=best,
                   ns_median=med, ns_wall_best=wall, s_per_step=best * n * 1e-9, contacts_per_particle=contacts,
                   list_pairs_per_particle=m / n, fmax_start=hist[0], prep_s=t_prep)
        rows.append(row)
        msg = (f"N={n:8d} numba {best:7.2f} ns/particle-step (median {med:.2f}, {steps} steps x {reps}); "
               f"contacts/particle {contacts:.2f}, max|F| {hist[0]:.3g} N")
        if ref is not None:
            nps, nbest, nmed, nwall, nbuild = time_numpy(ref, pos, walls, box, np_target, reps)
            rows.append(dict(impl="numpy", N=n, steps_per_call=nps, reps=reps, ns_per_particle_step=nbest,
                             ns_median=nmed, ns_wall_best=nwall, s_per_step=nbest * n * 1e-9, numpy_build_ns_per_particle=nbuild))
            row["speedup_vs_numpy"] = nbest / best
            msg += f" | numpy {nbest:8.1f} ns ({nps} steps) -> x{nbest / best:.1f}"
        print(msg, flush=True)
        if n_target == n_list[-1]:
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
    with open(out / f"memory{sfx}.csv", "w", newline="") as fh:
        wr = csv.DictWriter(fh, list(mem_row))
        wr.writeheader()
        wr.writerow(mem_row)

    keys = ["impl", "N", "steps_per_call", "reps", "ns_per_particle_step", "ns_median", "ns_wall_best", "s_per_step",
            "speedup_vs_numpy", "contacts_per_particle", "list_pairs_per_particle", "fmax_start", "prep_s",
            "numpy_build_ns_per_particle"]
    with open(out / f"step_cost{sfx}.csv", "w", newline="") as fh:
        wr = csv.DictWriter(fh, keys)
        wr.writeheader()
        for r in rows:
            wr.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in r.items()})

    nb = [r for r in rows if r["impl"] == "numba"]
    expo = fit_exponent([r["N"] for r in nb], [r["s_per_step"] for r in nb])
    lines = [f"kernels: {kpath or 'isaflow.methods.isa.relax'}", f"mode: {'quick' if args.quick else 'full'}",
             f"compile (cold cache) first call: {comp[0]['first_call_s']:.3f} s; "
             f"cache load (warm cache) first call: {comp[1]['first_call_s']:.3f} s "
             f"(hits {comp[1]['cache_hits']}, misses {comp[1]['cache_misses']})",
             f"fitted exponent of cost per step vs N (N >= 1e4): {expo:.3f}",
             f"memory at N = {n_big}: kernel peak {mem_row['kernel_peak_bytes_per_particle']:.1f} B/particle + "
             f"caller state {mem_row['caller_state_bytes_per_particle']:.1f} = "
             f"{mem_row['total_bytes_per_particle']:.1f} B/particle"]
    for r in nb:
        s = f"N={int(r['N']):8d}: {r['ns_per_particle_step']:7.2f} ns/particle-step"
        if "speedup_vs_numpy" in r:
            s += f", numpy x{r['speedup_vs_numpy']:.1f}"
        lines.append(s)
    lines.append(f"benchmark wall time: {time.perf_counter() - t_start:.1f} s")
    (out / f"summary{sfx}.txt").write_text("\n".join(lines) + "\n")
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
    plot(out, tables)


if __name__ == "__main__":
    main()
