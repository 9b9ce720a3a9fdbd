"""Report section: applications 1-2, the single vessel (levels, steps, times, loads, calibration)."""

from pathlib import Path

import pandas as pd
import yaml

from ..metrics import tolerances
from . import comparison, md_table, write


def single_section(metrics, calibration, config, outputs):
    """Fragment for applications 1-2 (levels, steps, times, loads, calibration)."""
    cfg = yaml.safe_load(Path(config).read_text())
    m = pd.read_csv(metrics).set_index("run")
    rows = []
    tol_rows = []
    for base, paper in cfg["paper"].items():
        if base not in m.index:
            continue
        for run in [r for r in (base, f"{base}_capped") if r in m.index]:
            r = m.loc[run].to_dict()
            tol = tolerances(r, r["spacing_cm"], r["particles"], r["f_tol_N"])
            tag = f"{base} [{r['variant']}]"
            rows.append(comparison(f"{tag} free-surface level (cm)", paper["level"], round(r["level"], 2),
                                   round(r["level"] - paper["level"], 2), tol["level"][0],
                                   "see calibration"))
            stop = "converged" if r["converged"] else f"{r['status']} (never < 0.1 N)"
            rows.append(comparison(f"{tag} steps to max|F| < 0.1 N", f"about {paper['steps']:,.0f}",
                                   f"{int(r['steps']):,} ({stop})", None,
                                   note="differs: literal update cannot converge, see Convergence" if not r["converged"]
                                   else f"{r['steps'] / paper['steps']:.1f}x the paper's steps"))
            rows.append(comparison(f"{tag} computing time (s)", paper["time_s"], f"{r['wall_time_s']:.3g}", None,
                                   note=f"{paper['time_s'] / max(r['wall_time_s'], 1e-9):.0f}x faster"))
            rows.append(comparison(f"{tag} final max|F| (N)", "< 0.1", f"{r['residual']:.3g}",
                                   round(max(r["residual"] - 0.1, 0.0), 3), 0.0, "literal update stalls in a cycle"))
            for key, label in (("floor", "floor total / W - 1"), ("side", "side walls total / (W h/2B) - 1")):
                val = r[f"{key}_err"]
                rows.append(comparison(f"{tag} {label}", "satisfactory (figure)", f"{val:+.3f}", round(val, 4),
                                       tol[key][0], "lattice is not a fluid: see Wall loads"))
            val = r["side_height_err"]
            rows.append(comparison(f"{tag} side resultant height - h/3 (cm)", "h/3 (theory)", f"{val:+.2f}",
                                   round(val, 2), tol["side_height"][0], "see Wall loads"))
            tol_rows += [{"run": run, "check": k, "tolerance": v[0], "derivation": v[1]} for k, v in tol.items()]
    cal = pd.read_csv(calibration)
    single = m.loc[[r for r in m.index if r.startswith("single_")]]
    conv = single[["variant", "du_cm", "status", "steps", "band_lo_N", "band_hi_N", "lambda_max",
                   "stability_floor_N"]].reset_index()
    loads = single[["variant", "level", "level_implied", "floor_err", "side_err", "stress_ratio", "side_height_err",
                    "contact_rms"]].reset_index()
    paper_runs = single[single["variant"] == "paper"]
    mid = 0.5 * (paper_runs["band_lo_N"] + paper_runs["band_hi_N"])
    text = ["## Applications 1-2: single vessel (Figures 5-8)", "",
            "Paper value | ours | difference | verdict, for every number the paper states about the single "
            "vessel. `[paper]` rows run section 3.3 literally; `[capped]` rows run the named capped-step variant.", "",
            md_table(pd.DataFrame(rows)), "", "### Tolerances", "",
            "Derived from the discretisation before looking at results (`isaflow.metrics.tolerances`):", "",
            md_table(pd.DataFrame(tol_rows)), "", "### Convergence", "",
            "Does the literal algorithm reach max|F| < 0.1 N? No, on either lattice (`figures/convergence_single.png`). "
            "The update x += du F / max|F| is gradient descent on the potential energy with gain du / max|F|; "
            "it is linearly unstable along the stiffest mode once du / max|F| > 2 / lambda_max, i.e. for "
            "max|F| < lambda_max du / 2. So max|F| cannot fall below that floor: the iteration settles into a "
            "period-2 cycle whose band is centred on it (band midpoint / floor = "
            + ", ".join(f"{r}: {mid[r] / paper_runs.loc[r, 'stability_floor_N']:.3f}" for r in paper_runs.index)
            + "). lambda_max is the largest eigenvalue of the final state's stiffness matrix (`theory.step_floor`). "
            "The paper's '2,000 / 8,000 steps to < 0.1 N' cannot be reproduced with its own update; besides, with "
            "at most du per step no particle descends more than 2,000 x 0.1 mm = 20 cm (coarse) or "
            "8,000 x 0.025 mm = 20 cm (refined), less than the 22.5-27.5 cm the top rows descend to reach the "
            "reported levels, so the paper's step counts are approximate in any case. The `capped` variant "
            "(step no longer grows once max|F| < f_ref = du (k_b + 6 k_p), = w here) converges to the same state.", "",
            md_table(conv), "", "### Wall loads", "",
            "Floors carry the weight to within the residual forces. Side walls carry less than the hydrostatic "
            "gamma h^2 / 2: the relaxed lattice is a solid, not a fluid; its interior horizontal/vertical stress "
            "ratio K = sigma_xx / sigma_yy (virial, `metrics.stress_ratio`) is below 1, so the walls see K times "
            "the hydrostatic thrust near the bottom. `level_implied` is the level that would give the measured "
            "side thrust in a fluid. The refined lattice's larger deficit is not explained by its interior K alone; "
            "the alternative reading `single_refined_lbu25` (l_bu = a/2) shows how strongly the wall law near "
            "the walls sets the side loads, at the price of a level far from the paper's.", "",
            md_table(loads), "", "### Calibration of the free-surface level", "",
            "Level of every calibration run (capped variant, `figures/calibration_free_surface.png`); "
            "`consistent` marks runs within a/4 of the paper's level:", ""]
    levels = {k: v["level"] for k, v in cfg["paper"].items()}
    cal["paper_level"] = [levels.get(s.removesuffix("_lbu25")) for s in cal["run"]]
    cal["consistent"] = (cal["level"] - cal["paper_level"]).abs() <= cal["spacing"] / 4
    text += [md_table(cal[["run", "k_wall", "ratio", "level", "level_max", "paper_level", "consistent", "status", "steps"]]), ""]
    both = _consistent_pairs(cal)
    text += ["(k_b, k_p/k_b) consistent with **both** reported levels (coarse 72.5 cm and refined 75 cm, "
             "same reading of the refined walls): " + (", ".join(both) if both else "none"), ""]
    write(text, outputs[0])


def _consistent_pairs(cal):
    out = []
    for ref in sorted({r for r in cal["run"] if "refined" in r}):
        c = cal[cal["run"] == "single_coarse"].set_index(["k_wall", "ratio"])["consistent"]
        f = cal[cal["run"] == ref].set_index(["k_wall", "ratio"])["consistent"]
        for key in c.index.intersection(f.index):
            if c[key] and f[key]:
                out.append(f"k_b = {key[0]:g} N/cm, k_p/k_b = {key[1]:g} (k_p = {key[0] * key[1]:g} N/cm) with {ref}")
    return out
