"""MPS report fragment (results/report/55_mps.md), timing fragment and the single-vessel table, generated from
results/mps/summary.csv.  The claims on MPS (Hattori et al.; the ISA paper's introduction) are judged by
isaflow.claims from the registry (config/claims/), quantities in methods/mps/quantities.py."""

from pathlib import Path

import numpy as np
import pandas as pd

from ...core.units import G
from ...figures.animation import report_line
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
             "diagonal, negative pressures clipped, collision model), with the pressure force of Hamiltonian MPS "
             f"(Suzuki, Koshizuka & Oka 2007; `model.gradient` = `{cfg['model.gradient']}`): C sum_j (P_i + P_j) r_e r_ij / "
             "r^3, the transpose of the number density's Jacobian, so pressure works only by changing number densities "
             "(K&O's gradient with the neighbourhood minimum is a named option: the `kog_*` runs below).  One radius "
             f"{cfg['model.re_density']:g} l0 for number density, gradient, surface test and Laplacian; wall and dummy rows "
             "behind both faces of the dividing wall (each face seen only from its side), on the shared tank, with the "
             "pressure equation's source term as the variant: `standard` (rho0/dt^2)(n0 - n*)/n0, `hattori` (eq. 6 of "
             f"Hattori et al., Rho* = rho0 n*/n0) and `mixed` (Tanaka & Masunaga 2010, gamma_m = {cfg['model.gamma_mixed']:g}); "
             f"MPS-Basic's relaxation {cfg['model.relaxation']:g} multiplies the density-deviation terms of standard and "
             f"hattori (`relaxation_scope` = `{cfg['model.relaxation_scope']}`), never a velocity-divergence term.  For a "
             "liquid at rest div V* is about 0, so `hattori` is the standard source on the tank; the flows are where they "
             "differ.  Wall loads by two readings, each the mean over the steps of a sample interval (they alternate from "
             "step to step): the pair-force reading (the wall particles' terms of the liquid's pressure gradients per 10 "
             "cm panel, the momentum the walls exchange with the liquid; the contacts every comparison uses) and the panel "
             "reading (first-row wall pressure times the wall length it faces); averaged over the last "
             f"{cfg['time.average_window']:g} s.  Rest: isaflow.rest (one criterion for every dynamic method); a run's final "
             "state is the mean and maximum of e = KE / (W h) over the rest window, never one sample.", ""]
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
    pct = lambda x: _fmt(100 * x, "{:+.1f}")  # noqa: E731
    lines += ["", "Every single-vessel run: time to rest (from the start; n/a: not at rest), e over the last rest window "
              "(mean, max), wall-load errors against the tank (side 3262.5 N, floor and floor + side-wall verticals W = "
              "9000 N; %) by the pair-force and the panel reading, and the pressures below 2.5 l0 against depth (slope "
              "over rho0 g, rms scatter over rho0 g h; window means):", ""]
    lines += _table(single.sort_values(["source_term", "spacing_cm"], ascending=[True, False]),
                    [("source_term", None), ("spacing_cm", g), ("status", None), ("time_to_rest_s", g),
                     ("window_energy_mean", g), ("window_energy_max", g), ("side_err_pair", pct), ("side_err_panel", pct),
                     ("floor_err_pair", pct), ("floor_err_panel", pct), ("vertical_err_pair", pct),
                     ("vertical_err_panel", pct), ("p_slope", g), ("p_scatter", g)],
                    ["source term", "l0 cm", "status", "rest from s", "e mean", "e max", "side % pair", "side % panel",
                     "floor % pair", "floor % panel", "verticals % pair", "verticals % panel", "p slope / rho0 g",
                     "p scatter / rho0 g h"])
    before = df[df.case == "kog"]
    if len(before):
        lines += ["", "The same columns with the settings before issue 30 (`kog_*`: K&O gradient with the neighbourhood "
                  "minimum, radii 2.1 / 2.1 / 3.1 / 2.1 l0, the whole hattori and mixed sources relaxed; "
                  "figures/mps_rest.png, dashed).  Their contacts are the panel reading: the K&O gradient's sums are not "
                  "pairwise, so its wall terms are no momentum exchange, and the pair column shows how little of the "
                  "weight they carry (the liquid holds itself up by internal terms that do not cancel):", ""]
        lines += _table(before.sort_values(["source_term", "spacing_cm"], ascending=[True, False]),
                        [("source_term", None), ("spacing_cm", g), ("status", None), ("sim_time_s", g),
                         ("window_energy_mean", g), ("window_energy_max", g), ("rms_speed_cm_s", g),
                         ("side_err_pair", pct), ("side_err_panel", pct)],
                        ["source term", "l0 cm", "status", "t end s", "e mean", "e max", "rms cm/s (window)",
                         "side % pair", "side % panel"])
    lines += ["", peer_comparison(df)]
    lines += [""] + _table(flow, [("run", None), ("tank", None), ("status", None), ("sim_time_s", g), ("mass_left_frac", g),
                                  ("level", g), ("rms_speed_cm_s", g), ("time_to_rest_s", g), ("escapes", g),
                                  ("reflected_particles", g), ("reflect_steps", g), ("graze_steps", g), ("message", None)],
                           ["flow run", "tank", "status", "t end s", "mass left (fraction)", "second-vessel level cm",
                            "rms cm/s (window)", "time to rest s", "escapes", "guard: particles reflected",
                            "guard: steps", "graze steps", "why it stopped"])
    lines += ["", report_line("figures/mps_flow_animation.gif", "the standard source term's flow at l0 = 3.45 cm "
                              "(flow_standard_dx3.45), particles coloured by speed")]
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


# The peer MPS-Basic (C++, its default settings: K&O gradient, standard source with relaxation 0.2, collision model,
# dt = 2 ms) on this project's single vessel at l0 = 1.25 cm (4,640 liquid particles), 3 s, measured by the
# developers (../shared/peers.md, "MPS, hydrostatic column"): rms speed at 1 s and 3 s [cm/s], floor and side-wall
# load errors averaged over 1-3 s against W and rho g h^2 / 2, ms per step on one thread.  Not at rest.
PEER = dict(code="MPS-Basic", spacing_cm=1.25, rms_1s=8.3, rms_3s=8.7, floor_err=0.018, side_err=0.023, ms_per_step=46.0,
            particles=4640)


def peer_comparison(df):
    """Sentence: the peer MPS-Basic against the project's standard-source single runs (the run at the peer's spacing
    when there is one), numbers from the table and PEER."""
    depth = 72.5  # cm, the tank's depth (the peer's 58 rows of 1.25 cm are exactly the tank's liquid)
    e_peer = PEER["rms_3s"] ** 2 / (2 * G * depth)  # KE / (W h) of equal masses (isaflow.rest)
    mine = df[(df.source_term == "standard") & df.case.isin(["single", "peer"])].sort_values("spacing_cm")
    if not len(mine):
        return ""
    parts = [f"l0 = {r.spacing_cm:.3g} cm: {r.status}" + (f" from {r.time_to_rest_s:.3g} s" if r.status == "converged" else "")
             + f", e over the last rest window {r.window_energy_mean:.2g} (max {r.window_energy_max:.2g}), side "
             f"{100 * r.side_err_pair:+.1f} %, floor {100 * r.floor_err_pair:+.1f} % (pair forces; panel reading "
             f"{100 * r.side_err_panel:+.1f} / {100 * r.floor_err_panel:+.1f} %)"
             for r in mine.itertuples()]
    return (f"Peer: {PEER['code']} with its defaults on this tank at l0 = {PEER['spacing_cm']:g} cm (../shared/peers.md) is "
            f"not at rest: rms {PEER['rms_1s']:g} / {PEER['rms_3s']:g} cm/s at 1 / 3 s, e = {e_peer:.2g} at 3 s, floor "
            f"{100 * PEER['floor_err']:+.1f} %, side {100 * PEER['side_err']:+.1f} % (averages over 1-3 s, its own panel "
            f"pressures), {PEER['ms_per_step']:g} ms per step on one thread.  This project's standard source: "
            + "; ".join(parts) + ".  Same tank (weight, depth, rho g); the project's spacings other than the peer's hold "
            "whole rows (72.22 / 72.41 cm, weight held at 9000 N).  This project's time per step at each spacing: "
            "docs/timing.md (a timing would make this report differ between runs of the same commit).")


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


def timing(df, cfg):
    """Markdown for docs/timing.md: ms per step of every MPS run."""
    g = lambda x: _fmt(x)  # noqa: E731
    lines = ["## MPS: cost per step (results/mps/summary.csv)", "",
             f"Pressure solver `{cfg['pressure.solver']}`.", ""]
    lines += _table(df.sort_values(["case", "run"]), [("run", None), ("status", None), ("particles", g), ("ms_per_step", g)],
                    ["run", "status", "particles", "ms/step"])
    mine = df[(df.source_term == "standard") & df.case.isin(["single", "peer"])].sort_values("spacing_cm")
    if len(mine):
        lines += ["", f"Against the peer {PEER['code']} ({PEER['ms_per_step']:g} ms per step on one thread at l0 = "
                      f"{PEER['spacing_cm']:g} cm, ../shared/peers.md), this project's standard source: "
                  + "; ".join(f"l0 = {r.spacing_cm:.3g} cm {r.ms_per_step:.3g} ms per step" for r in mine.itertuples())
                  + "."]
    return "\n".join(lines + [""])


def floor(bench):
    """Markdown table of the step-cost benchmark's floor rows (cg_jacobi, one thread): ns per particle-step of the
    step's operators (the step without its pressure solve) against one fused pass over the same lists and matrix
    (benchmarks/bench_mps.py floor_pass), and of the whole step per liquid particle against the peer."""
    b = pd.read_csv(bench)
    if "floor_ratio" not in b:
        return ""
    b = b[b.floor_ratio.notna()].sort_values("liquid_particles")
    lines = [f"| liquid / all particles | operators ns/particle-step | floor | operators / floor | whole step ns per "
             f"liquid particle-step | {PEER['code']} |", "|---|---|---|---|---|---|"]
    for r in b.itertuples():
        lines.append(f"| {r.liquid_particles:,} / {r.all_particles:,} | {r.ops_ns_per_particle_step:.0f} | "
                     f"{r.floor_ns_per_particle_step:.0f} | {r.floor_ratio:.2f} | {r.ns_per_liquid_particle_step:,.0f} | "
                     f"{r.peer_ns_per_liquid_particle_step:,.0f} |")
    return ("Operators against their floor (thread CPU time, one numba thread, shared 2-core machine, load average "
            f"{b.load_average.min():.1f}-{b.load_average.max():.1f}; {PEER['code']}: {PEER['ms_per_step']:g} ms per step "
            f"at l0 = {PEER['spacing_cm']:g} cm, {PEER['particles']:,} liquid particles, ../shared/peers.md):\n\n"
            + "\n".join(lines) + "\n")


def bench_fragment(bench, outputs):
    """outputs = [the benchmarks page's MPS fragment] from the step-cost benchmark."""
    Path(outputs[0]).parent.mkdir(parents=True, exist_ok=True)
    Path(outputs[0]).write_text(f"## MPS: step-cost benchmark (benchmarks/results/mps_step_cost.csv)\n\n{cost(bench)}\n\n"
                                f"{floor(bench)}")


SINGLE_TABLE = "mps_single.csv"  # every single-vessel run, next to the report
SINGLE_COLUMNS = ["run", "source_term", "spacing_cm", "particles", "status", "side_err_3262", "side_err", "floor_err",
                  "side_err_pair", "side_err_panel", "floor_err_pair", "floor_err_panel", "vertical_err_pair",
                  "vertical_err_panel", "p_slope", "p_scatter", "contact_rms", "panel_noise_rel", "rms_speed_cm_s",
                  "window_energy_mean", "window_energy_max", "time_to_rest_s", "escapes", "graze_steps",
                  "deepest_graze_cm"]


def write(summary, cfg, outputs):
    """outputs = [report fragment, timing fragment, docs/tables/mps_single.csv] from the summary table and the
    settings file."""
    df = pd.read_csv(summary, keep_default_na=True)
    cfg_ = settings.resolved(cfg)
    for p in outputs:
        Path(p).parent.mkdir(parents=True, exist_ok=True)
    Path(outputs[0]).write_text(fragment(df, cfg_) + "\n")
    Path(outputs[1]).write_text(timing(df, cfg_))
    df[df.case == "single"][SINGLE_COLUMNS].to_csv(outputs[2], index=False, float_format="%.6g")
