"""What makes the 1D truncated-SPH sweep plausible, and what it will cost (pure Python).

:func:`check` (called by settings.load, so by every run and while the
workflow is parsed) refuses a ratio h/dx outside the range the sweep can
mean (0.5 to 10: from no neighbour to 20 per side), a column whose pressure
over- or underflows, and a sweep whose solves (variants x kernels x ratios x
N, each a banded system of N rows and 2 ceil(2 h/dx) + 1 diagonals) exceed
the memory or the CPU-hour budget (isaflow.budget).  Units: cm, N.
"""

import math

from ... import budget
from ...plausible import finite, require

NS_PER_ROW = 2.0  # ns per row and band entry of a banded LU solve + condition estimate (lower bound)
BYTES_PER_BAND_ENTRY = 8 * 3  # the band, its LU factors and a work copy (float64)
RATIO_MAX = 10.0  # h/dx: support 2h of 20 spacings per side; Merino-Alonso et al. study h/dx up to ~3


def check(s, path):
    """s: {name: value} of the settings (before the ratios are made), with 'variants'."""
    r = s["ratio"]
    require(r["stop"] <= RATIO_MAX, path, "ratio",
            f"h/dx = {r['stop']:g} exceeds {RATIO_MAX:g} (a support of {2 * RATIO_MAX:g} spacings per side; the "
            f"paper's question is the few-neighbour limit, h/dx up to about 3)")
    count = math.floor((r["stop"] - r["start"]) / r["step"] + 0.5) + 1
    finite(path, "ratio", float(count), "number of ratios")
    finite(path, "column", s["column"]["height"] * s["column"]["rho_g"], "floor pressure rho g H [N/cm^2]")
    band = 3 * math.ceil(2 * r["stop"]) + 1
    n_max, n_sum = max(s["n"]), sum(s["n"])
    solves = len(s["variants"]) * len(s["kernels"]) * count
    nbytes = n_max * band * BYTES_PER_BAND_ENTRY + solves * len(s["n"]) * 16
    field_bytes = "n" if n_max * band * BYTES_PER_BAND_ENTRY > nbytes / 2 else "ratio"
    budget.check(path, budget.Cost(n_sum * band, solves, nbytes, NS_PER_ROW,
                                   {"particles": "n", "steps": "ratio", "bytes": field_bytes},
                                   f"{solves:.3g} sweeps of N = {s['n'][0]}..{n_max}, {band} band entries per row"))
