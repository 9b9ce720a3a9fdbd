"""Cost of one truncated-SPH column solve (assembly + banded LU + condition estimate) against N.

Run: python benchmarks/bench_sph1d.py  ->  benchmarks/results/sph1d_solve_time.csv
(columns: kernel, ratio, n, seconds_per_solve [s]); compilation excluded (one warm-up call).
"""

import csv
import time
from pathlib import Path

from isaflow.methods.sph1d.column import solve_column

OUT = Path(__file__).parent / "results" / "sph1d_solve_time.csv"
CASES = [("wendland_c2", 1.3), ("wendland_c6", 2.7)]
NS = [64, 256, 1024, 4096, 16384]


def main():
    solve_column(64, 1.3, "wendland_c2")  # compile
    rows = []
    for kernel, ratio in CASES:
        for n in NS:
            reps = max(3, 20000 // n)
            t = time.perf_counter()
            for _ in range(reps):
                solve_column(n, ratio, kernel)
            rows.append((kernel, ratio, n, (time.perf_counter() - t) / reps))
            print(f"{kernel} h/dx={ratio} N={n}: {rows[-1][3] * 1e3:.3f} ms")
    OUT.parent.mkdir(parents=True, exist_ok=True)
    with OUT.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["kernel", "ratio", "n", "seconds_per_solve"])
        w.writerows(rows)


if __name__ == "__main__":
    main()
