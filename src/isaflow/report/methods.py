"""Report section and claims: every method on the same tank (single vessel and flow).

Deterministic: errors and end states only; solver times are in figures/methods_error_vs_runtime.* (timing files).
"""

import numpy as np
import pandas as pd

from ..methods import label
from . import md_table, write

CLAIM = '"approximates dynamic behavior with strong damping" (the static analysis ends where a damped liquid ends)'


def _best(g, col):
    """Smallest |col| among the runs that reached their stop criterion (NaN if none)."""
    ok = g[g["status"] == "converged"][col].abs()
    return ok.min() if len(ok) else np.nan


def methods_section(single, flow, outputs):
    """results/report/70_methods.md and results/claims/methods.csv."""
    md, claims = outputs
    s, f = pd.read_csv(single), pd.read_csv(flow)
    rows = []
    for (method, variant), g in s.groupby(["method", "variant"], sort=False):
        rows.append({"method": method, "variant": variant, "runs": len(g),
                     "at rest / converged": int((g["status"] == "converged").sum()),
                     "spacings (cm)": ", ".join(f"{x:.3g}" for x in sorted(g["spacing_cm"].unique(), reverse=True)),
                     "best side err": _best(g, "side_err"), "best per-panel RMS": _best(g, "contact_rms"),
                     "best resultant-height err (cm)": _best(g, "side_height_err_cm")})
    fl = f[["method", "variant", "run", "particles", "status", "left_fraction", "depth", "slope_deg",
            "surface_range_cm", "side_err"]].copy()
    fl["left_fraction"] = fl["left_fraction"].map("{:.1%}".format)
    text = ["## Methods compared on the same tank", "",
            "Every method's run files are judged by the same functions (`isaflow.metrics`) on the same 10 cm wall "
            "panels (per-contact loads for the point particles). Single vessel, W = 9 kN: best errors among the runs "
            "that reached their own stop criterion (solver times against these errors: "
            "`figures/methods_error_vs_runtime.png`, a timing file):", "", md_table(pd.DataFrame(rows)), "",
            "Flow into the second vessel, end states (level: mean top particle per strip above the second floor; a "
            "liquid at rest has slope and range about 0 and leaves at most a film behind):", "", md_table(fl), ""]
    write(text, md)
    isa = f[(f["method"] == "isa") & (f["run"] == "flow_complete_capped")]
    liquid = f[(f["method"] == "sph") & (f["status"] == "converged")].sort_values("spacing_cm")
    if len(isa) and len(liquid):
        i, q = isa.iloc[0], liquid.iloc[0]
        tol = 10 / i["particles"]  # one floor row of the coarse lattice (B / a = 10 particles) as a share
        same = abs(i["left_fraction"] - q["left_fraction"]) <= tol and i["surface_range_cm"] <= i["spacing_cm"] / 2
        measured = (f"ISA (capped, converged): {i['left_fraction']:.0%} left, surface slope {i['slope_deg']:+.1f} deg, "
                    f"range {i['surface_range_cm']:.0f} cm; SPH at rest ({q['run']}): {q['left_fraction']:.0%} left, "
                    f"slope {q['slope_deg']:+.1f} deg, range {q['surface_range_cm']:.1f} cm; tolerance one floor row "
                    f"({tol:.0%}) and a/2")
        verdict, why = ("reproduced", "") if same else (
            "not reproduced", "the static analysis stops in a jammed granular state (a heap and stable floor layers) "
                              f"that the damped liquid of {label('sph', q['variant']).split(':')[0]} does not reach: "
                              "it drains and settles flat.")
    else:
        measured, verdict, why = "no SPH run reached rest", "not testable here (no liquid at rest to compare)", ""
    pd.DataFrame([dict(paper="papadopoulos2016", section="1, 7", claim=CLAIM, measured=measured, verdict=verdict,
                       evidence="figures/methods_error_vs_runtime.png, results/report/70_methods.md",
                       why=why or None)]).to_csv(claims, index=False)
