"""Report section: applications 3-6, the flows and Table 1."""

from pathlib import Path

import pandas as pd
import yaml

from . import comparison, md_table, write


def flow_section(metrics, table1, config, outputs):
    """Fragment for applications 3-6 (flows, Table 1)."""
    cfg = yaml.safe_load(Path(config).read_text())
    paper = cfg["flow"]["paper"]
    m = pd.read_csv(metrics).set_index("run")
    rows = []
    if "flow_incomplete" in m.index:
        r = m.loc["flow_incomplete"]
        n = int(r["particles"])
        rows.append(comparison("app. 3: steps (from the start of app. 1)", f"{paper['incomplete_steps']:,.0f}",
                               f"{int(r['steps']):,}", None, note="set by the scene"))
        frac = r["particles_second"] / n
        rows.append(comparison("app. 3: share transferred at step 100,000", "more than half",
                               f"{frac:.0%} ({int(r['particles_second'])} of {n})", None,
                               note="agrees" if frac > 0.5 else "differs"))
        # equilibrium bounds |sum F_x| by N f_tol; the paper's ">> 0" means far above that, to the right
        rows.append(comparison("app. 3: sum of horizontal wall reactions on the liquid (N)", ">> 0, to the right",
                               f"{r['sum_fx_N']:+.0f} (equilibrium: |.| <= N f_tol = {n * r['f_tol_N']:.0f})", None,
                               note="agrees" if r["sum_fx_N"] > 5 * n * r["f_tol_N"] else "differs"))
        rows.append(comparison("app. 3: max|F| (N)", ">> 0.1", f"{r['residual']:.3g}", None,
                               note="agrees" if r["residual"] > 1 else "differs"))
    for run in ("flow_complete", "flow_complete_capped"):
        if run not in m.index:
            continue
        r = m.loc[run]
        n = int(r["particles"])
        a = r["spacing_cm"]
        half_row = r["first_width_cm"] / a / 2
        tag = f"app. 4 [{r['variant']}]"
        stop = "converged" if r["converged"] else f"{r['status']}, never < 0.1 N"
        rows.append(comparison(f"{tag}: steps to complete", f"about {paper['complete_steps']:,.0f}",
                               f"{int(r['steps']):,} ({stop})", None,
                               note=f"{r['steps'] / paper['complete_steps']:.2f}x the paper's"))
        rows.append(comparison(f"{tag}: particles left in the first vessel", paper["particles_left"],
                               int(r["particles_left"]), int(r["particles_left"] - paper["particles_left"]),
                               half_row, "robust to du (Flow sensitivity): a stable multilayer stays behind"))
        rows.append(comparison(f"{tag}: second-vessel level above its floor (cm)", paper["level_second"],
                               round(r["depth"], 2), round(r["depth"] - paper["level_second"], 2), a / 4))
        expected = (n - r["particles_left"]) / n * paper["level_first"] / 2
        rows.append(comparison(f"{tag}: level expected from the particles moved, ((N-left)/N) x 72.5/2 (cm)",
                               paper["level_expected"], round(expected, 2), round(r["depth"] - expected, 2), a / 4,
                               "ours vs its own expectation"))
        rows.append(comparison(f"{tag}: final max|F| (N)", "< 0.1", f"{r['residual']:.3g}",
                               round(max(r["residual"] - 0.1, 0), 3), 0.0, "literal update stalls in a cycle"))
        tol = max(r["residual"], r["f_tol_N"]) * n / r["weight"]
        rows.append(comparison(f"{tag}: second-vessel floor total / W_2 - 1", "satisfactory (figure)",
                               f"{r['floor_err']:+.3f}", round(r["floor_err"], 4), tol,
                               "first-vessel particles at the step lean on the second vessel's liquid"))
        rows.append(comparison(f"{tag}: second-vessel side walls / hydrostatic - 1", "satisfactory (figure)",
                               f"{r['side_err']:+.3f}", round(r["side_err"], 4), (a / 4) / r["depth"],
                               f"locked-in lateral stress: K = {r['stress_ratio']:.2f} (see Wall loads)"))
    sens = [s for s in cfg["flow"]["sensitivity"] if s in m.index]
    sens_df = m.loc[sens, ["scene", "variant", "du_cm", "steps", "status", "particles_left", "depth", "stress_ratio"]]
    refined = [s for s in ("flow_refined_incomplete", "flow_refined_complete") if s in m.index]
    ref_df = m.loc[refined, ["particles", "du_cm", "steps", "status", "residual", "particles_left", "depth",
                             "floor_err", "side_err"]]
    t1 = pd.read_csv(table1)
    text = ["## Applications 3-6: flow into the second vessel (Figures 9-10, Table 1)", "",
            md_table(pd.DataFrame(rows)), "",
            "Tolerances: level a/4 (as for the single vessel); particles left: half a floor row, B/(2a) = 5 "
            "particles (what stays behind is a stack of floor rows of B/a = 10); floor: N max|F| / W_2 "
            "(vertical equilibrium); side walls: (a/4)/depth.", "",
            "### Flow sensitivity (geometry reading and step length)", "",
            md_table(sens_df.reset_index()), "",
            "### Refined flows (Table 1 rows 5-6, never run by the paper)", "",
            md_table(ref_df.reset_index()), "",
            "### Table 1", "", md_table(t1), ""]
    write(text, outputs[0])
