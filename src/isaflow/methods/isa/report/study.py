"""Report section: error against run time, FIRE, stability map and extreme cases (config/methods/isa_study.yaml)."""

from pathlib import Path

import numpy as np
import pandas as pd

from ....contract import OUTCOMES
from ..solver import DETECTED_BY
from ..plan import VARIANTS
from ..tables import recommend, resolution_table
from ....report import md_table, write
from ....inputs import read_yaml
from ....settings import plain



def map_boundaries(df):
    """Plain-language boundaries of each variant's outcomes on the stability map."""
    text = []
    for var in [v for v in VARIANTS if v in set(df["variant"])]:
        g = df[df["variant"] == var]
        parts = []
        for status in OUTCOMES:
            s = g[g["status"] == status]
            if len(s):
                parts.append(f"{status} at {len(s)}/{len(g)} points (k_b du/w {s['k_du_over_w'].min():.2g}-"
                             f"{s['k_du_over_w'].max():.2g}, du/a {s['du_over_a'].min():.0e}-{s['du_over_a'].max():.0e})")
        esc = g[g["status"] == "escaped"]
        first = (f"; the smallest escaping du/a is {esc['du_over_a'].min():.2g} "
                 f"(du = {esc['du_cm'].min():g} cm)") if len(esc) else "; no escape on the map"
        text.append(f"- **{var}**: " + "; ".join(parts) + first + ".")
    return "\n".join(text)


def report_section(errors, fire_ratio, fire_grid, stability_map, cases, study_config, outputs, targets=None):
    """results/report/30_study.md (+ docs/tables/study_recommendation.csv, study_cases.csv): error against
    work, FIRE's force evaluations, the stability map and the extreme cases, with no timing in the text."""
    md, rec_csv, cases_csv = outputs
    study = plain(read_yaml(study_config)[1])["study"]  # the values of the sourced file
    targets = targets or study["error_runtime"]["targets"]
    err = pd.read_csv(errors)
    fr = pd.read_csv(fire_ratio)
    grid = pd.read_csv(fire_grid)
    smap = pd.read_csv(stability_map)
    cs = pd.read_csv(cases)
    rec = recommend(err, targets)
    rec.to_csv(rec_csv, index=False, float_format="%.6g")
    res = resolution_table(err)
    cs["height_ratio"] = (cs["top_cm"] - cs["floor_cm"]) / (cs["top0_cm"] - cs["floor_cm"])
    keep = ["case", "note", "variant", "particles", "status", "outcome_detail", "steps", "residual", "level_cm",
            "height_ratio", "wall_use", "pair_use", "message"] + [c for c in cs.columns if c.startswith("particles_")]
    cs[[c for c in keep if c in cs.columns]].to_csv(cases_csv, index=False, float_format="%.6g")
    ratio = required = study["fire_tuning"]["required_ratio"]
    t = ["## Error against work, and numerical stability (the paper's method)", "",
         f"{len(err)} relaxations of the single vessel over {err['lattice'].nunique()} lattices "
         f"({', '.join(f'a = {a:g} cm' for a in sorted(err['a_cm'].unique(), reverse=True))}), du from "
         f"{err['du_factor'].min():g}x to {err['du_factor'].max():g}x the paper's rule du = w / (10 k_p), and the "
         "three update rules (`paper`; the variants `capped` and `fire`, not in the paper). Full table with "
         "wall-clock times (a timing file, made by the workflow and not tracked): "
         "`results/isa/study/error_vs_runtime.csv`; figure `figures/error_vs_runtime.png` (not tracked either); "
         "the same errors against the work (particle-steps, the same in every run), tracked: "
         "[`figures/error_vs_work.png`](../figures/error_vs_work.png).", "",
         "**What resolution buys** (capped equilibrium at the paper's du; range over all converged runs of the "
         "lattice):", "", md_table(res), "",
         "**Which configuration to pick**: for each target, the converged run with the least work (particle-steps) "
         "among the (lattice, rule) families whose converged runs *all* meet it "
         "([`docs/tables/study_recommendation.csv`](tables/study_recommendation.csv)):", ""]
    for _, r in rec.iterrows():
        if r["run"] != "none":
            t.append(f"- `{r['measure']}` within {r['target']:g}: `{r['run']}` ({r['lattice']}, {r['variant']}, "
                     f"{int(r['steps']):,} steps); its family's worst case {r['family_worst']:.3g}.")
        else:
            t.append(f"- `{r['measure']}` within {r['target']:g}: no family guarantees it (best worst case "
                     f"{r['family_worst']:.3g}); `{r['by_chance']}` meets it at its du only.")
    t += ["", f"**FIRE** ({len(grid)} tuning runs): force evaluations to f_tol against the capped update's "
          f"(target {required:g}x):"]
    for _, r in fr.iterrows():
        if pd.notna(r.get("fire_best_steps", np.nan)):
            t.append(f"- {r['lattice']}: {int(r['fire_best_steps'])} against {int(r['capped_steps'])} steps, "
                     f"**{r['ratio_vs_capped']:.1f}x** ({'meets' if r['ratio_vs_capped'] >= ratio else 'misses'} the "
                     f"target); level within {abs(r['level_diff_cm']):.2f} cm of the capped equilibrium.")
    t += ["", "**Stability map** (coarse lattice; k_b and k_p scaled together; `figures/stability_map.png`):", "",
          map_boundaries(smap), "", "Outcomes and where the solver detects them:", ""]
    t += [f"- `{k}`: {v} ({DETECTED_BY[k]})." for k, v in OUTCOMES.items() if k in DETECTED_BY]
    t += ["", "**Extreme cases** ([`docs/tables/study_cases.csv`](tables/study_cases.csv)): "
          + "; ".join(f"{c}: " + ", ".join(f"{g.loc[i, 'variant']} {g.loc[i, 'status']}" for i in g.index)
                      for c, g in cs.groupby("case", sort=False)) + ".", ""]
    write(t, md)
