"""The headline findings about the paper's method (results/report/findings.md, the report's summary), from the
metrics and calibration tables.  Every claim's verdict is computed by isaflow.claims from the registry
(config/claims/papadopoulos2016.yaml) and methods.isa.quantities; this file states findings, no verdict."""

import numpy as np
import pandas as pd


def _literal_level(cal, run):
    """Level [cm] of the literal reading k_p = k_b / 2 at the text's k_b = 2000 N/cm."""
    c = cal[(cal["run"] == run) & (cal["k_wall"] == 2000) & np.isclose(cal["ratio"], 0.5)]
    return float(c["level"].iloc[0]) if len(c) else np.nan


def findings(m, cal):
    """The headline findings about the paper's method, as Markdown bullets (from the metrics table)."""
    co, re_, fc = m.loc["single_coarse"], m.loc["single_refined"], m.loc["flow_complete"]
    return [
        f"- The paper's update x += du F / max|F| never reaches its own stop criterion max|F| < 0.1 N on the single "
        f"vessel: it stops in a period-2 cycle at the stability floor lambda_max du / 2 ({co['stability_floor_N']:.3g} N "
        f"coarse, {re_['stability_floor_N']:.3g} N refined). The named variant `capped` reaches 0.1 N in the same state.",
        f"- The pair stiffness k_p was chosen so that the top particle centres sit at the reported levels (72.5 and 75 "
        f"cm); on the one surface (top centres + half the layer pitch) the runs read {co['level']:.2f} and "
        f"{re_['level']:.2f} cm, and the literal k_p = k_b / 2 gives {_literal_level(cal, 'single_coarse'):.1f} and "
        f"{_literal_level(cal, 'single_refined'):.1f} cm.",
        f"- The relaxed lattice is a granular solid, not a liquid: interior stress ratio K = {co['stress_ratio']:.2f} "
        f"(a liquid: 1), side walls {co['side_err']:+.0%} (coarse) and {re_['side_err']:+.0%} (refined) of hydrostatic "
        f"while the floor carries the weight; interior rhombs lose {co['rhomb_loss_mean']:.0%} of their area (claimed: "
        f"at most 8.6 %); after the flow the second vessel holds a heap (slope {fc['slope_deg']:+.1f} deg, range "
        f"{fc['surface_range_cm']:.0f} cm) and {int(fc['particles_left'])} particles stay behind (paper: 14).",
    ]


def findings_file(metrics, calibration, outputs):
    """results/report/findings.md from results/isa/metrics.csv and results/isa/calibration.csv."""
    m = pd.read_csv(metrics).set_index("run")
    cal = pd.read_csv(calibration)
    with open(outputs[0], "w") as fh:
        fh.write("\n".join(findings(m, cal)) + "\n")
