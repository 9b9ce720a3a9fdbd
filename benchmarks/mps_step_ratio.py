"""MPS step cost of this checkout against another commit's, on the same machine state: whole processes interleaved
(base, this, base, this, ...), each timing bench_mps.step_cost in-process with its own commit's code and settings
(the single tank's liquid block of about N = 5,000 particles at rest, the settings' defaults and standard source,
cg_jacobi, one numba thread, 30 warm-up steps, then the medians over STEPS steps of predict, solve and correct,
summed; compile excluded).  The ratio is the median
of this checkout's process medians over the base's.

Writes benchmarks/results/mps_step_ratio.csv (one row per process).  Run:
python benchmarks/mps_step_ratio.py [--base REV] [--rounds R] [--n N]   (REV default: 509ae75, before issue 42's fused
MPS step; 2041002: before issue 30)
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
STEPS = 80
ONE = r"""
import json, sys
from pathlib import Path
import numba
root, bench = Path(sys.argv[1]), sys.argv[4]
sys.path[:0] = [str(root / "src"), bench]
import bench_mps
from isaflow.methods.mps import solver
assert Path(solver.__file__).resolve().is_relative_to(root.resolve()), solver.__file__
numba.set_num_threads(1)
print(json.dumps(bench_mps.step_cost(root, int(sys.argv[2]), steps=int(sys.argv[3]))))
"""


def run(root, n):
    env = dict(os.environ, NUMBA_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1",
               OMP_WAIT_POLICY="PASSIVE")
    env.pop("PYTHONPATH", None)
    out = subprocess.run([sys.executable, "-c", ONE, str(root), str(n), str(STEPS), str(ROOT / "benchmarks")],
                         capture_output=True, text=True, env=env, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--base", default="509ae75")
    ap.add_argument("--rounds", type=int, default=4)
    ap.add_argument("--n", type=int, default=5000)
    args = ap.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        archive = subprocess.run(["git", "-C", str(ROOT), "archive", args.base], capture_output=True, check=True).stdout
        subprocess.run(["tar", "-x", "-C", tmp], input=archive, check=True)
        for k in range(args.rounds):
            for name, root in (("base", Path(tmp)), ("this", ROOT)):
                rows.append(dict(round=k, code=name, rev=args.base if name == "base" else "working tree", **run(root, args.n)))
                print(rows[-1], flush=True)
    df = pd.DataFrame(rows)
    med = df.groupby("code").step_ms.median()
    print(f"median step: base {med['base']:.3g} ms, this {med['this']:.3g} ms, ratio {med['this'] / med['base']:.3f}")
    out = ROOT / "benchmarks" / "results" / "mps_step_ratio.csv"
    out.parent.mkdir(parents=True, exist_ok=True)
    df.to_csv(out, index=False, float_format="%.4g")


if __name__ == "__main__":
    main()
