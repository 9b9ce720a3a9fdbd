"""The benchmark page's table of every method against its floor and its peers: results/bench/05_floors.md.

Reads the CSVs the benchmarks write (bench_step.py: step_floor.csv, bench_sph.py: sph_step_cost.csv, bench_mps.py:
mps_step_cost.csv, bench_solid.py: solid_step_cost.csv); a CSV missing, or without floor rows, reads 'not run'.
Run: python benchmarks/floors.py OUT [FOLDER]   (FOLDER: benchmarks/results), or snakemake -c1 results/bench/05_floors.md
"""

import sys
from pathlib import Path

import numpy as np
import pandas as pd

# peers of ../shared/peers.md on the project's tanks, one thread: method -> [(particles, code, ns per particle-step)]
PEERS = {"ISA": [(n, "LAMMPS fire", s / evals / n * 1e9) for n, evals, s in  # per force evaluation, single vessel
                 ((684, 1046, 54e-3), (2664, 2455, 0.48), (10512, 6862, 5.4), (101700, 35081, 285.0))],
         "SPH": [(5000, "PySPH", 1076.0), (20000, "PySPH", 1003.0)],  # per fluid particle, hydrostatic tank
         "MPS": [(4640, "MPS-Basic", 46e-3 / 4640 * 1e9)]}  # whole step per liquid particle, 4,640-particle column
# method: (CSV, rows with a floor, case, particles, ns per particle-step, floor ns, ratio columns, the method's
# figure in its peer's units if those differ)
FLOORS = {"ISA": ("step_floor.csv", None, lambda r: "wide vessel, paper's update", "N", "ns_per_particle_step",
                  "floor_ns_per_particle_step", "ratio", None),
          "SPH": ("sph_step_cost.csv", "floor_ratio", lambda r: f"single vessel, {r['variant']}", "N",
                  "project_ns_per_particle_step_1thread_floor_rounds", "floor_ns_per_particle_step_1thread",
                  "floor_ratio", None),
          "MPS": ("mps_step_cost.csv", "floor_ratio", lambda r: "single tank, the step's operators (no solve)",
                  "all_particles", "ops_ns_per_particle_step", "floor_ns_per_particle_step", "floor_ratio",
                  "ns_per_liquid_particle_step"),
          "solid": ("solid_step_cost.csv", "ratio", lambda r: f"{r['case']}, {r['variant']}", "n",
                    "ns_per_particle_step", "floor_ns_per_particle_step", "ratio", None)}


def ns_text(ns):
    """Three significant figures, whole nanoseconds from 100 up."""
    return f"{ns:,.0f}" if ns >= 100 else f"{ns:.3g}"


def floor_table(out, folder="benchmarks/results"):
    """Write the table to out: per method and row of its CSV in folder, ns per particle-step (1 thread), the floor
    (the fused minimal loop its benchmark times beside it), their ratio and the nearest peer (within a factor 2 in
    particles)."""
    text = ["## Every method against its floor and its peers", "",
            "ns per particle-step on 1 thread (MPS: every particle, its step without the pressure solve); floor: the "
            "same arithmetic over the same pair lists in one compiled loop, timed interleaved with the method (each "
            "benchmark's docstring says what it includes); ratio = method / floor. Peers (../shared/peers.md, 1 "
            "thread, the nearest particle count within a factor 2): LAMMPS fire per force evaluation on the single "
            "vessel, PySPH per fluid particle on the hydrostatic tank, MPS-Basic per liquid particle of its whole "
            "step (beside it the method's own whole step in those units).", "",
            "| method | case | particles | ns per particle-step | floor ns | ratio | peer |",
            "|---|---|---|---|---|---|---|"]
    for method, (name, has, case, n, ns, fl, ratio, own) in FLOORS.items():
        path = Path(folder) / name
        df = pd.read_csv(path) if path.exists() else pd.DataFrame()
        df = df[df[has].notna()] if has in df else df.iloc[:0] if has else df
        if df.empty:
            text.append(f"| {method} | not run ({path}) | | | | | |")
        for _, r in df.iterrows():
            near = [p for p in PEERS.get(method, []) if 0.5 <= p[0] / r[n] <= 2.0]
            peer = min(near, key=lambda p: abs(np.log(p[0] / r[n])), default=None)
            cell = f"{peer[1]} {peer[2]:,.0f} ({peer[0]:,} particles)" if peer else "–"
            if peer and own:
                cell += f"; this method {r[own]:,.0f}"
            text.append(f"| {method} | {case(r)} | {int(r[n]):,} | {ns_text(r[ns])} | {ns_text(r[fl])} | "
                        f"{r[ratio]:.2f} | {cell} |")
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    Path(out).write_text("\n".join(text) + "\n\n")


if __name__ == "__main__":
    floor_table(*sys.argv[1:])
