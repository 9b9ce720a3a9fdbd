"""What makes the 1D truncated-SPH sweep plausible, and what it will cost (pure Python).

The checks of every method (isaflow.preflight.check; settings.checked_values calls it, so
every run and the workflow while it is parsed): :func:`plausible` refuses a
sweep without a reading (variant) to solve, a ratio range h/dx that is empty or
outside what the sweep can mean (up to 10: 20 neighbours per side), too few N
for the classification window, and a column whose pressure over- or
underflows; :func:`cost` gives the sweep's solves (variants x kernels x ratios x
N, each a banded system of N rows and 2 ceil(2 h/dx) + 1 diagonals) for
isaflow.budget.  The 1D study has no tank (tank is None).  Units: cm, N.
"""

import math

from ... import budget
from ...plausible import finite, require

NS_PER_ROW = 2.0  # ns per row and band entry of a banded LU solve + condition estimate (lower bound)
BYTES_PER_BAND_ENTRY = 8 * 3  # the band, its LU factors and a work copy (float64)
RATIO_MAX = 10.0  # h/dx: support 2h of 20 spacings per side; Merino-Alonso et al. study h/dx up to ~3


def _ratios(r):
    """The number of ratios h/dx from start to stop (inf if it overflows)."""
    x = (r["stop"] - r["start"]) / r["step"]
    return math.floor(x + 0.5) + 1 if math.isfinite(x) else x


def plausible(tank, settings, stability=False):
    """Refuse a sweep that cannot mean anything (settings.Settings of one resolution; InputError naming the file
    and the setting)."""
    s, path = settings.tree(), settings.path
    require(bool(settings.spec.get("variants")), path, "variants", "at least one reading to solve")
    r = s["ratio"]
    require(r["stop"] >= r["start"], path, "ratio", f"stop {r['stop']:g} must be >= start {r['start']:g}")
    require(r["stop"] <= RATIO_MAX, path, "ratio",
            f"h/dx = {r['stop']:g} exceeds {RATIO_MAX:g} (a support of {2 * RATIO_MAX:g} spacings per side; the "
            f"paper's question is the few-neighbour limit, h/dx up to about 3)")
    require(len(s["n"]) >= s["classify"]["window"], path, "n",
            f"{len(s['n'])} values; needs at least classify.window = {s['classify']['window']}")
    finite(path, "ratio", float(_ratios(r)), "number of ratios")
    c = s["column"]
    finite(path, max(("column.height", "column.rho_g"), key=lambda k: abs(math.log10(c[k.split(".")[1]]))),
           c["height"] * c["rho_g"], "floor pressure rho g H [N/cm^2]")


def cost(tank, settings, particles=None):
    """[budget.Cost] of the sweep: every variant, kernel, ratio and N."""
    s = settings.tree()
    band = 3 * math.ceil(2 * s["ratio"]["stop"]) + 1
    n_max, n_sum = max(s["n"]), sum(s["n"])
    solves = len(settings.spec["variants"]) * len(s["kernels"]) * _ratios(s["ratio"])
    nbytes = n_max * band * BYTES_PER_BAND_ENTRY + solves * len(s["n"]) * 16
    field_bytes = "n" if n_max * band * BYTES_PER_BAND_ENTRY > nbytes / 2 else "ratio"
    return [budget.Cost(n_sum * band, solves, nbytes, NS_PER_ROW,
                        {"particles": "n", "steps": "ratio", "bytes": field_bytes},
                        f"{solves:.3g} sweeps of N = {min(s['n'])}..{n_max}, {band} band entries per row")]
