"""Report section: the paper's method on the single vessel (applications 1-2, Figures 5-8)."""

import pandas as pd
from ..metrics import tolerances
from ....report import md_table, write
from ....inputs import read_yaml
from ....settings import plain

RUN_IDS = ("run ids: `single_coarse` (180 particles, lattice a = 10 cm) and `single_refined` (684, a = 5 cm) run "
           "the paper's update x += du F / max|F| (section 3.3, literally); the suffix `_capped` names the variant "
           "x += du F / max(max|F|, f_ref), not in the paper, which reaches f_tol; `single_refined_lbu25` is the "
           "alternative reading l_bu = a/2 of Fig. 7b.")


def single_section(metrics, calibration, config, outputs):
    """results/report/10_single.md, docs/tables/single_tolerances.csv, docs/tables/calibration.csv."""
    md, tol_csv, cal_csv = outputs
    cfg = plain(read_yaml(config)[1])  # the values of the sourced file
    m = pd.read_csv(metrics).set_index("run")
    runs = [r for r in m.index if r.startswith("single_")]
    t = m.loc[runs]
    show = pd.DataFrame({
        "run": runs, "outcome": t["status"].values, "steps": t["steps"].astype(int).values,
        "level (cm)": t["level"].round(2).values, "floor err": t["floor_err"].map("{:+.1e}".format).values,
        "side err": t["side_err"].map("{:+.3f}".format).values,
        "side resultant - h/3 (cm)": t["side_height_err"].round(2).values,
        "contact RMS (gamma h a)": t["contact_rms"].round(3).values, "K": t["stress_ratio"].round(2).values,
        "rhomb loss (mean, max)": [f"{a:.1%}, {b:.1%}" for a, b in zip(t["rhomb_loss_mean"], t["rhomb_loss_max"])],
        "slope (deg)": t["slope_deg"].round(1).values})
    tol_rows = []
    for run in runs:
        r = m.loc[run].to_dict()
        for k, (v, why) in tolerances(r, r["spacing_cm"], r["particles"], r["f_tol_N"]).items():
            tol_rows.append({"run": run, "check": k, "tolerance": v, "derivation": why})
    pd.DataFrame(tol_rows).to_csv(tol_csv, index=False, float_format="%.6g")
    cal = pd.read_csv(calibration)
    levels = {k: v["level"] for k, v in cfg["paper"].items()}
    cal["paper_level"] = [levels.get(s.removesuffix("_lbu25")) for s in cal["run"]]
    cal["within_a_over_4"] = (cal["level"] - cal["paper_level"]).abs() <= cal["spacing"] / 4
    cal.to_csv(cal_csv, index=False, float_format="%.6g")
    both = _consistent_pairs(cal)
    conv = t[t["variant"] == "paper"]
    text = [
        "## The paper's method: single vessel (applications 1-2, Figures 5-8)", "", RUN_IDS, "",
        md_table(show), "",
        "`err` columns are (computed - hydrostatic) / hydrostatic wall totals; K = sigma_xx / sigma_yy of the "
        "lattice's interior (1 for a fluid); rhomb loss: 1 - A / A_0 of the interior rhombs of the initial lattice; "
        "slope: least-squares slope of the top particle per strip of width a. Tolerances (derived from the lattice, "
        "[`docs/tables/single_tolerances.csv`](tables/single_tolerances.csv)): level a/4, floor N f_tol / W, side "
        "walls (a/4)/h, side resultant a/4.", "",
        "**Convergence.** The paper's update stops in a period-2 cycle (detected, never a convergence) whose max|F| "
        "band is centred on the stability floor lambda_max du / 2 of the final state: "
        + "; ".join(f"`{r}` band {conv.loc[r, 'band_lo_N']:.3g}-{conv.loc[r, 'band_hi_N']:.3g} N, floor "
                    f"{conv.loc[r, 'stability_floor_N']:.3g} N" for r in conv.index)
        + " (`figures/convergence_single.png`).", "",
        f"**Calibration.** {len(cal)} relaxations over k_b and k_p / k_b "
        f"([`docs/tables/calibration.csv`](tables/calibration.csv), `figures/calibration_free_surface.png`). "
        "Pairs that give both reported levels within a/4: " + ("; ".join(both) if both else "none") + ". The "
        "scenes use k_b = 2000 N/cm (page text) and k_p = 500 N/cm: the pair stiffness is calibrated to both levels "
        "(the registry's input k_pair is calibrated against them), so their agreement is no evidence.", ""]
    write(text, md)


def _consistent_pairs(cal):
    out = []
    for ref in sorted({r for r in cal["run"] if "refined" in r}):
        c = cal[cal["run"] == "single_coarse"].set_index(["k_wall", "ratio"])["within_a_over_4"]
        f = cal[cal["run"] == ref].set_index(["k_wall", "ratio"])["within_a_over_4"]
        for key in c.index.intersection(f.index):
            if c[key] and f[key]:
                out.append(f"k_b = {key[0]:g} N/cm, k_p/k_b = {key[1]:g} (k_p = {key[0] * key[1]:g} N/cm) with `{ref}`")
    return out
