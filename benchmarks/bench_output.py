"""Output cost: a run that asks for less output (no solver.history) is not slower.

What: the refined single vessel (application 2, 684 particles, capped variant, ~20,000
steps to f_tol) relaxed in one process with two output settings, alternating, each
`--repeats` times after a warm-up:
- lean: solver.history = {} (the run file holds the final state only);
- full: max|F| recorded every step, wall resultants and vessel counts at every chunk
  end, 20 state snapshots.
Both relax the same scene from the same start, so they take the same steps.

Measured per repetition: solver wall-clock time (contract.Result.wall_time, the
compiled loop plus the Python bookkeeping between chunks) and the time to build and
write the netCDF run file.  Units: s.

Output: benchmarks/results/output_cost.csv (one row per repetition) and the medians
on stdout.  Runtime ~15 s.
Run: python benchmarks/bench_output.py [--repeats 7] [--resolution refined]
"""

import argparse
import tempfile
import time
from pathlib import Path

import pandas as pd

from isaflow import run

# Parameters
ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results" / "output_cost.csv"
WHY = "inferred: benchmark of the run file's cost"
SETTINGS = {
    "lean": {"solver.history": {"value": {}, "source": WHY}},
    "full": {"solver.history": {"value": {"every": 1, "walls": True, "vessels": True, "snapshots": 20},
                                "source": WHY}},
}
TANK = ROOT / "config" / "tanks" / "single.yaml"
ISA_SETTINGS = ROOT / "config" / "methods" / "isa.yaml"


def one_run(resolution, overrides, tmp):
    """(steps, status, solver s, file s, file bytes) of one capped relaxation of the single tank and its run file
    (isaflow.run: the command line's path)."""
    path = Path(tmp) / "run.nc"
    if path.exists():
        path.unlink()
    p = run.prepare("isa", str(TANK), "capped", resolution, str(path), str(ISA_SETTINGS), overrides, None,
                    ("converged", "cycle", "step_limit"), 1)
    result, started, finished = run.solve(p, log=lambda msg: None)
    t0 = time.perf_counter()
    run.write(p, result, started, finished)
    t_file = time.perf_counter() - t0
    return result.steps, result.status, result.wall_time, t_file, path.stat().st_size


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--resolution", default="refined", help="ISA resolution of the single tank")
    args = ap.parse_args(argv)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        one_run(args.resolution, SETTINGS["lean"], tmp)  # warm-up: compilation and caches
        for rep in range(args.repeats):
            order = list(SETTINGS) if rep % 2 == 0 else list(SETTINGS)[::-1]
            for name in order:
                steps, status, t_solve, t_file, size = one_run(args.resolution, SETTINGS[name], tmp)
                rows.append(dict(setting=name, repeat=rep, steps=steps, status=status, solver_s=t_solve,
                                 file_s=t_file, total_s=t_solve + t_file, file_bytes=size,
                                 overrides=str(SETTINGS[name]["solver.history"]["value"])))
    df = pd.DataFrame(rows)
    OUT.parent.mkdir(parents=True, exist_ok=True)
    df.to_csv(OUT, index=False, float_format="%.6g")
    med = df.groupby("setting")[["steps", "solver_s", "file_s", "total_s", "file_bytes"]].median()
    print(med.to_string(float_format=lambda x: f"{x:.4g}"))
    lean, full = med.loc["lean"], med.loc["full"]
    assert df.groupby("setting")["steps"].nunique().max() == 1 and lean["steps"] == full["steps"]
    print(f"lean / full: solver {lean['solver_s'] / full['solver_s']:.3f}, total {lean['total_s'] / full['total_s']:.3f}"
          f" (<= 1: less output is not slower); file {lean['file_bytes'] / 1e3:.0f} kB vs {full['file_bytes'] / 1e3:.0f} kB")
    print(f"wrote {OUT}")
    return df


if __name__ == "__main__":
    main()
