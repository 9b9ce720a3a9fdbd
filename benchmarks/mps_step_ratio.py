"""MPS step cost of this checkout against another commit's, on the same machine state: whole processes interleaved
(base, this, base, this, ...), each timing bench_mps.py's case in-process (the single tank's liquid block of about
N = 5,000 particles at rest, the settings' defaults and standard source, cg_jacobi, one numba thread, 30 warm-up
steps, then the median over STEPS steps of predict + solve + correct, compile excluded).  The ratio is the median
of this checkout's process medians over the base's.

Writes benchmarks/results/mps_step_ratio.csv (one row per process).  Run:
python benchmarks/mps_step_ratio.py [--base REV] [--rounds R] [--n N]   (REV default: 2041002, before issue 30)
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
import numpy as np
import numba
from pathlib import Path
root = Path(sys.argv[1])
sys.path.insert(0, str(root / "src"))
from isaflow.methods.mps import boundary, settings, solver
from isaflow.tank import load as load_tank
assert Path(solver.__file__).resolve().is_relative_to(root.resolve()), solver.__file__
n, steps = int(sys.argv[2]), int(sys.argv[3])
numba.set_num_threads(1)
tank = load_tank(root / "config/tanks/single.yaml")
l0 = 100.0 / round(np.sqrt(n * 100.0 / 72.5))
cfg = settings.load(root / "config/methods/mps.yaml")
xr, floor = solver.first_vessel(tank)
fluid = boundary.liquid_block(xr, floor, tank.depth, l0)
s = solver.State(tank, cfg, l0, fluid, np.zeros_like(fluid))
dt = solver.time_step(tank, l0, cfg["time.courant"])
for _ in range(30):
    solver.step(s, dt, "standard", cfg)
per = []
for _ in range(steps):
    t = np.zeros(3)
    solver.step(s, dt, "standard", cfg, t)
    per.append(t)
per = np.array(per) * 1e3
print(json.dumps(dict(particles=s.nf, step_ms=float(np.median(per.sum(1))), predict_ms=float(np.median(per[:, 0])),
                      solve_ms=float(np.median(per[:, 1])), correct_ms=float(np.median(per[:, 2])))))
"""


def run(root, n):
    env = dict(os.environ, NUMBA_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1",
               OMP_WAIT_POLICY="PASSIVE")
    env.pop("PYTHONPATH", None)
    out = subprocess.run([sys.executable, "-c", ONE, str(root), str(n), str(STEPS)], capture_output=True, text=True,
                         env=env, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--base", default="2041002")
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
