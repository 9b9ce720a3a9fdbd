"""ISA's timing fragment of docs/timing.md: Table 1's times, step cost, compile cache, output cost.

Kept out of docs/replication.md so that the report is byte-identical between runs of the same commit."""

from pathlib import Path

import numpy as np
import pandas as pd

from ....report import comparison, md_table, write


def timing_fragment(step_cost, compile, memory, machine, output_cost, table1, table1_md, outputs, targets):
    """results/bench/10_isa.md: Table 1 with times, cost per particle-step, NumPy ratio, memory, compile cache,
    Table 1 total, output cost, each judged against ``targets`` (config/methods/isa_workflow.yaml speed_targets:
    ns_per_particle_step, numpy_ratio, bytes_per_particle, growth_exponent, table1_solver_s)."""
    t = targets
    sc = pd.read_csv(step_cost)
    nb = sc[sc["impl"] == "numba"].set_index("N")
    npy = sc[sc["impl"] == "numpy"].set_index("N")
    big = nb[nb.index >= 10_000]
    fit = np.polyfit(np.log(big.index.values), np.log(big["ns_per_particle_step"].values * big.index.values), 1)[0]
    ratio = (npy["ns_per_particle_step"] / nb["ns_per_particle_step"]).dropna()
    mem = pd.read_csv(memory).iloc[-1]
    comp = pd.read_csv(compile)
    t1 = pd.read_csv(table1)
    ours_total = float(t1["ours_solver_s"].iloc[3] + t1["ours_solver_s"].iloc[5])  # rows 4 and 6 hold every run
    paper_total = sum(_seconds(x) for x in t1["paper_time"])
    oc = pd.read_csv(output_cost).groupby("setting")[["solver_s", "file_bytes"]].median()
    table = pd.DataFrame({"N": nb.index, "numba ns/particle-step": nb["ns_per_particle_step"].values,
                          "numpy ns/particle-step": [npy["ns_per_particle_step"].get(n, np.nan) for n in nb.index]})
    table["numpy / numba"] = table["numpy ns/particle-step"] / table["numba ns/particle-step"]
    worst, lo = big["ns_per_particle_step"].max(), ratio[ratio.index >= 10_000].min()
    cached = int(comp["cache_hits"].iloc[1]) > 0 and comp["first_call_s"].iloc[1] < comp["first_call_s"].iloc[0]
    targets = [
        comparison("cost per particle-step, N >= 10,000 (ns)", f"target <= {t['ns_per_particle_step']:g}",
                   f"{worst:.1f} (max)", round(worst - t["ns_per_particle_step"], 2), None,
                   "meets" if worst <= t["ns_per_particle_step"] else "misses"),
        comparison("speed-up over the vectorised NumPy step, N >= 10,000", f"target >= {t['numpy_ratio']:g}x",
                   f"{lo:.1f}x - {ratio[ratio.index >= 10_000].max():.1f}x", None,
                   note="misses: see below" if lo < t["numpy_ratio"] else "meets"),
        comparison("memory at N = 1e6 (bytes/particle)", f"target <= {t['bytes_per_particle']:g}",
                   f"{mem['total_bytes_per_particle']:.0f}", None,
                   note="meets" if mem["total_bytes_per_particle"] <= t["bytes_per_particle"] else "misses"),
        comparison("growth exponent of cost vs N (N >= 1e4)", f"target <= {t['growth_exponent']:g}", f"{fit:.3f}", None,
                   note="meets" if fit <= t["growth_exponent"] else "misses"),
        comparison("numba compile vs cache load (s)", "second run reuses the cache",
                   f"{comp['first_call_s'].iloc[0]:.2f} vs {comp['first_call_s'].iloc[1]:.3f} "
                   f"(cache hits {int(comp['cache_hits'].iloc[1])})", None, note="meets" if cached else "misses"),
        comparison("solver time of Table 1's six rows together (s)", f"{paper_total:,.0f} s ({paper_total / 3600:.2f} h)",
                   f"{ours_total:.1f}", None,
                   note=(f"meets target < {t['table1_solver_s']:g} s" if ours_total < t["table1_solver_s"]
                         else f"misses target < {t['table1_solver_s']:g} s") + f"; {paper_total / ours_total:,.0f}x faster"),
        comparison("run without history vs with full history (solver s)", "not slower",
                   f"{oc.loc['lean', 'solver_s']:.3f} vs {oc.loc['full', 'solver_s']:.3f} "
                   f"({oc.loc['lean', 'file_bytes'] / 1e3:.0f} vs {oc.loc['full', 'file_bytes'] / 1e3:.0f} kB)", None,
                   note="meets" if oc.loc["lean", "solver_s"] <= oc.loc["full", "solver_s"] else "misses"),
    ]
    text = ["## Table 1 (paper's steps and times next to ours)", "", Path(table1_md).read_text().split("\n", 1)[1].strip(), "",
            "## Speed of the paper's method (benchmarks/)", "",
            f"Measured by `benchmarks/bench_step.py` (CPU time of the compiled step of the paper's update on a relaxed "
            f"lattice, one core) and `benchmarks/bench_output.py`; machine: "
            f"{Path(machine).read_text().strip().splitlines()[0]}.", "",
            md_table(pd.DataFrame(targets)), "", md_table(table), "",
            "The NumPy reference (`benchmarks/numpy_reference.py`) is already a Verlet-list step with wall work "
            "only near the walls; at about 2.8 listed pairs per particle its arithmetic alone (a square root and a "
            "division per pair) costs a few ns per particle even vectorised, so a 40x ratio would need the "
            "compiled step to run at about 1.5 ns per particle-step: not reachable with this algorithm. The ratio "
            "approaches 40x only at N = 180, where NumPy's per-call overhead dominates.", ""]
    write(text, outputs[0])


def _seconds(text):
    """'5.0 sec' / '1.5 min' / '4.5 hr' -> seconds."""
    value, unit = text.split()
    return float(value) * {"sec": 1, "min": 60, "hr": 3600}[unit]
