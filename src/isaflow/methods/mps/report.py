"""MPS report fragment (results/report/55_mps.md), timing fragment and the single-vessel table, generated from
results/mps/summary.csv.  The claims on MPS (Hattori et al.; the ISA paper's introduction) are judged by
isaflow.claims from the registry (config/claims/), measures in methods/mps/claims.py."""

from pathlib import Path

import numpy as np
import pandas as pd

from . import settings

def _fmt(x, f="{:.3g}"):
    if x is None or (isinstance(x, float) and np.isnan(x)):
        return "n/a"
    return str(int(x)) if isinstance(x, (int, np.integer)) else f.format(x)


def dt_rows(df):
    """The time-step study's runs plus the single standard run at the same spacing (settings' Courant), by Courant."""
    dt = df[(df.case == "dt") & (df.run.str.startswith("dt_standard"))]
    if not len(dt):
        return dt
    same = df[(df.case == "single") & (df.source_term == "standard") & np.isclose(df.spacing_cm, dt.spacing_cm.iloc[0])]
    return pd.concat([dt, same]).sort_values("courant")


def findings(df):
    """Paragraph on rest and escapes, numbers from the table."""
    single, flows = df[df.case == "single"], df[df.case.isin(["flow", "samefloor"])]
    out = []
    if len(single):
        at_rest = single[single.status == "converged"]
        moving = single[single.status != "converged"]
        out.append(f"Single vessel: {len(at_rest)} of {len(single)} runs at rest (isaflow.rest: kinetic energy / (W h) "
                   f"below {single.rest_energy_ratio.iloc[0]:g} for the rest window).")
        if len(moving):
            out.append(f"The others end at the time limit ({moving.sim_time_s.max():.3g} s) with kinetic energy / (W h) "
                       f"{moving.energy_ratio.min():.2g}-{moving.energy_ratio.max():.2g} (rms speed "
                       f"{moving.rms_speed_cm_s.min():.3g}-{moving.rms_speed_cm_s.max():.3g} cm/s; figures/mps_rest.png).")
    esc = df[df.status == "escaped"]
    if len(esc):
        out.append("Escaped runs (measures are those of that moment): " + "; ".join(
            f"{r.run} ({r.tank}): {r.message}, t = {r.sim_time_s:.3g} s" for r in esc.itertuples()) + ".")
    if len(flows):
        out.append(f"Flows: {int((flows.status != 'escaped').sum())} of {len(flows)} without escape; each continues its "
                   "single run's final state (start_state).")
    grazed = df[df.graze_steps > 0]
    if len(grazed):
        deep = grazed.loc[grazed.deepest_graze_cm.idxmax()]
        out.append(f"Wall-line grazes (a move across a wall line ending within l0/2 of the wall, i.e. short of the first "
                   f"wall-particle row; counted, not escapes) occur in {len(grazed)} of {len(df)} runs, the deepest "
                   f"{deep.deepest_graze_cm:.2g} cm ({deep.deepest_graze_cm / deep.spacing_cm:.0%} of l0, {deep.run}).")
    if "reflected_particles" in df and (df.reflected_particles > 0).any():
        hit = df[df.reflected_particles > 0]
        most = hit.loc[hit.reflected_particles.idxmax()]
        out.append(f"The penetration guard (walls.reflect: a move across a wall line is mirrored back to its side) acted "
                   f"in {len(hit)} of {len(df)} runs, at most on {int(most.reflected_particles)} particles in "
                   f"{int(most.reflect_steps)} steps ({most.run}).")
    return "  ".join(out)


def ranking(df):
    """Sentence: per source term the median over single-vessel runs of the panel-load noise (std/mean) and of the
    per-panel rms error, and which is quieter / more accurate (from the table, no numbers typed)."""
    single = df[df.case == "single"]
    full = single[single.status != "escaped"]
    med = full.groupby("source_term")[["panel_noise_rel", "contact_rms"]].median()
    if med.empty:
        return ""
    parts = [f"{k}: noise {r.panel_noise_rel:.3f}, panel rms error {r.contact_rms:.4f}" for k, r in med.iterrows()]
    left_out = sorted(set(single.source_term) - set(med.index))
    return ("Medians over the single-vessel spacings of the runs that lasted the full time (" + "; ".join(parts)
            + "): quieter wall loads `" + med.panel_noise_rel.idxmin() + "`, more accurate `" + med.contact_rms.idxmin()
            + "`" + (f"; no {', '.join(left_out)} run lasted (their columns above are averaged over the last window "
                     "before the escape)" if left_out else "") + ".")


def _table(df, cols, heads):
    lines = ["| " + " | ".join(heads) + " |", "|" + "---|" * len(heads)]
    for r in df.itertuples():
        lines.append("| " + " | ".join(f(getattr(r, c, np.nan)) if callable(f) else str(getattr(r, c))
                                       for c, f in cols) + " |")
    return lines


def fragment(df, cfg):
    """Markdown of the MPS section."""
    g = lambda x: _fmt(x)  # noqa: E731
    single, flow, stiff = df[df.case == "single"], df[df.case.isin(["flow", "samefloor"])], df[df.case == "stiff"]
    lines = ["## MPS with three pressure source terms", "",
             "Koshizuka & Oka's semi-implicit MPS as the public MPS-Basic code implements it (pressure equation over "
             "fluid and wall particles, dummies excluded, free-surface particles P = 0, compressibility term on the "
             "diagonal, negative pressures clipped, gradient with the neighbourhood minimum, collision model), with "
             f"K&O 1996's number-density radius {cfg['model.re_density']:g} l0 for the source term and the surface test "
             "(only the outermost row is P = 0), wall and dummy rows behind both faces of the dividing wall (each face seen "
             "only from its side), on the shared tank, with the pressure equation's source term as the variant: `standard` "
             f"(rho0/dt^2)(n0 - n*)/n0, `hattori` (eq. 6 of Hattori et al., Rho* = rho0 n*/n0) and `mixed` (Tanaka & "
             f"Masunaga 2010, gamma_m = {cfg['model.gamma_mixed']:g}), each multiplied by MPS-Basic's relaxation "
             f"{cfg['model.relaxation']:g}.  For a liquid at rest div V* is about 0, so `hattori` is the standard source "
             "on the tank; the flows are where they differ.  Wall loads are the first wall row's pressures integrated over "
             f"10 cm panels, averaged over the last {cfg['time.average_window']:g} s; noise is the std over that window.  "
             "Rest: isaflow.rest (one criterion for every dynamic method).", ""]
    by_term = single.groupby("source_term", sort=False).agg(
        runs=("run", "size"), at_rest=("status", lambda x: int((x == "converged").sum())),
        escaped=("escapes", "sum"), side_err_min=("side_err_3262", "min"), side_err_max=("side_err_3262", "max"),
        rms_min=("rms_speed_cm_s", "min"), rms_max=("rms_speed_cm_s", "max"),
        noise_median=("panel_noise_rel", "median")).reset_index()
    lines += ["Single vessel, per source term over the spacings "
              f"{', '.join(f'{x:.3g}' for x in sorted(single.spacing_cm.unique(), reverse=True))} cm (every run: "
              f"[`docs/tables/{SINGLE_TABLE}`](tables/{SINGLE_TABLE})); side load against rho g h^2 / 2 = 3262.5 N:", ""]
    lines += _table(by_term, [("source_term", None), ("runs", g), ("at_rest", g), ("escaped", g), ("side_err_min", g),
                              ("side_err_max", g), ("rms_min", g), ("rms_max", g), ("noise_median", g)],
                    ["source term", "runs", "at rest", "escaped", "side err min", "side err max", "final rms min cm/s",
                     "final rms max cm/s", "panel noise std/mean (median)"])
    lines += [""] + _table(flow, [("run", None), ("tank", None), ("status", None), ("sim_time_s", g), ("mass_left_frac", g),
                                  ("level", g), ("rms_speed_cm_s", g), ("time_to_rest_s", g), ("graze_steps", g),
                                  ("message", None)],
                           ["flow run", "tank", "status", "t end s", "mass left (fraction)", "second-vessel level cm",
                            "final rms cm/s", "time to rest s", "graze steps", "why it stopped"])
    lines += ["", "Stiff and extreme cases (standard source, single vessel): " + "; ".join(
        f"{r.run.removeprefix('stiff_')}: {r.label}" for r in stiff.itertuples()) + ".", ""]
    lines += _table(stiff, [("run", None), ("status", None), ("rms_speed_cm_s", g), ("floor_err", g), ("message", None),
                            ("escape_depth_cm", g)],
                    ["case", "status", "rms speed cm/s", "floor err", "why it stopped", "depth behind the wall cm"])
    lines += ["", ranking(df), "", findings(df)]
    dts = dt_rows(df)
    if len(dts):
        lines += ["", f"Time-step study (standard source, single vessel, l0 = {dts.spacing_cm.iloc[0]:.3g} cm, "
                  f"{dts.sim_time_s.max():.2g} s):", ""]
        lines += _table(dts, [("run", None), ("courant", g), ("dt_s", g), ("status", None), ("panel_noise_rel", g),
                              ("probe1_std_N_cm2", g), ("contact_rms", g), ("rms_speed_cm_s", g)],
                        ["run", "Courant", "dt s", "status", "panel noise std/mean", "probe (50, 35) std N/cm2",
                         "panel rms err", "rms speed cm/s"])
    counts = df.groupby(["case", "status"]).size()
    lines += ["", "Outcomes: " + "; ".join(f"{c} {s}: {n}" for (c, s), n in counts.items()) + "."]
    lines += ["", "Settings and their sources: " + "; ".join(
        f"`{k}` = {v} ({cfg.sources[k]})" for k, v in cfg.items() if k.startswith(("model.", "time.courant", "pressure.solver"))), ""]
    return "\n".join(lines)


def cost(bench, target_n=5000, target_ms=50.0):
    """Sentence on the step-cost benchmark (benchmarks/results/mps_step_cost.csv): per solver and thread count the
    step time [ms] at the size nearest target_n liquid particles, split into predict / solve / correct, against the
    target."""
    b = pd.read_csv(bench)
    if "threads" not in b:
        b["threads"] = 1
    n = b.liquid_particles.iloc[(b.liquid_particles - target_n).abs().argmin()]
    rows = b[b.liquid_particles == n].sort_values("step_ms")
    parts = [f"`{r.solver}` ({r.threads} thread{'s' if r.threads > 1 else ''}) {r.step_ms:.3g} ms "
             f"({r.predict_ms:.3g} + {r.solve_ms:.3g} + {r.correct_ms:.3g})" for r in rows.itertuples()]
    big = b[b.liquid_particles == b.liquid_particles.max()].sort_values("step_ms").iloc[0]
    return (f"Step cost (benchmarks/bench_mps.py, shared 2-core machine; predict + solve + correct) at {n} liquid "
            f"particles: " + "; ".join(parts) + f".  Target {target_ms:g} ms: "
            + ("met" if rows.step_ms.min() <= target_ms else "not met") + f" (best {rows.step_ms.min():.3g} ms).  At "
            f"{big.liquid_particles} particles the fastest is `{big.solver}` ({big.threads} threads), {big.step_ms:.4g} ms per step.")


def timing(df, cfg, bench):
    """Markdown for docs/timing.md: ms per step of every MPS run and the step-cost benchmark."""
    g = lambda x: _fmt(x)  # noqa: E731
    lines = ["## MPS: cost per step (results/mps/summary.csv, benchmarks/results/mps_step_cost.csv)", "",
             f"Pressure solver `{cfg['pressure.solver']}`.", ""]
    lines += _table(df.sort_values(["case", "run"]), [("run", None), ("status", None), ("particles", g), ("ms_per_step", g)],
                    ["run", "status", "particles", "ms/step"])
    return "\n".join(lines + ["", cost(bench), ""])


SINGLE_TABLE = "mps_single.csv"  # every single-vessel run, next to the report
SINGLE_COLUMNS = ["run", "source_term", "spacing_cm", "particles", "status", "side_err_3262", "side_err", "floor_err",
                  "contact_rms", "panel_noise_rel", "rms_speed_cm_s", "energy_ratio", "time_to_rest_s", "escapes",
                  "graze_steps", "deepest_graze_cm"]


def write(summary, cfg, bench, outputs):
    """outputs = [report fragment, timing fragment, docs/tables/mps_single.csv] from the summary table, the
    settings file and the step-cost benchmark."""
    df = pd.read_csv(summary, keep_default_na=True)
    cfg_ = settings.load(cfg)
    for p in outputs:
        Path(p).parent.mkdir(parents=True, exist_ok=True)
    Path(outputs[0]).write_text(fragment(df, cfg_) + "\n")
    Path(outputs[1]).write_text(timing(df, cfg_, bench))
    df[df.case == "single"][SINGLE_COLUMNS].to_csv(outputs[2], index=False, float_format="%.6g")
