"""MPS report fragment (results/report/55_mps.md) and claims rows, generated from results/mps/summary.csv."""

from pathlib import Path

import numpy as np
import pandas as pd

from . import settings

CLAIM_COLUMNS = ["paper", "section", "claim", "measured", "verdict", "evidence", "why"]


def _fmt(x, f="{:.3g}"):
    return "n/a" if x is None or (isinstance(x, float) and np.isnan(x)) else f.format(x)


def noise_bound(row):
    """Relative panel-load noise that counts as 'suppressed': l0 / h, the relative hydrostatic head over one
    spacing (the resolution error of a panel load), derived from the discretisation, not from the results."""
    return row.spacing_cm / row.depth if row.depth > 0 else np.nan


def claims(df):
    """Claims rows: Hattori's checkable statement and the Papadopoulos introduction's claim on MPS oscillations."""
    single = df[df.case == "single"].copy()
    single["bound"] = [noise_bound(r) for r in single.itertuples()]
    std = single[single.source_term == "standard"]
    quiet = std[std.panel_noise_rel < std.bound]
    rest = single[single.status == "converged"]
    rows = [dict(
        paper="hattori", section="eqs. (1)-(5)",
        claim="By adding the equation (3) and the equation (5), we obtain the discrete time Navier-Stokes equation (1) and (2).",
        measured="one MPS step satisfies (1)-(2) to relative 1e-9 with grad P taken at U* and rho0 for Rho[n+1]; "
                 "at U[n+1] (as eq. 1 writes it) it does not (strict xfail)",
        verdict="reproduced",
        evidence="tests/test_mps.py::test_eqs_3_and_5_add_up_to_the_discrete_navier_stokes_eqs_1_2",
        why="an algebraic identity of the two half steps"),
        dict(
        paper="papadopoulos2016", section="1 (introduction)",
        claim="in the MPS method (Moving Particles Semi-Implicit) ... some high frequency oscillations are suppressed, "
              "depending on time step-length, because of the implicit nature of the method, with no additional technique for suppression",
        measured="single vessel, standard source: panel-load noise std/mean "
                 + ", ".join(f"{r.panel_noise_rel:.3f} (bound l0/h {r.bound:.3f}, l0 {r.spacing_cm:.3g} cm)" for r in std.itertuples())
                 + f"; runs at rest (any source term): {len(rest)} of {len(single)}",
        verdict="reproduced" if len(std) and len(quiet) == len(std) and len(rest) == len(single) else "not reproduced",
        evidence="results/mps/summary.csv (panel_noise_rel, status), figures/mps_wall_loads.png, figures/mps_rest.png",
        why="suppressed = wall-load noise below the resolution error l0/h of a panel load and the liquid coming to rest")]
    return pd.DataFrame(rows, columns=CLAIM_COLUMNS)


def _table(df, cols, heads):
    lines = ["| " + " | ".join(heads) + " |", "|" + "---|" * len(heads)]
    for r in df.itertuples():
        lines.append("| " + " | ".join(f(getattr(r, c, np.nan)) if callable(f) else str(getattr(r, c))
                                       for c, f in cols) + " |")
    return lines


def fragment(df, cfg):
    """Markdown of the MPS section."""
    g = lambda x: _fmt(x)  # noqa: E731
    single, flow, stiff = df[df.case == "single"], df[df.case == "flow"], df[df.case == "stiff"]
    lines = ["## MPS with three pressure source terms (issue 11)", "",
             "Koshizuka & Oka's semi-implicit MPS as the public MPS-Basic code implements it (pressure equation over "
             "fluid and wall particles, dummies excluded, surface particles P = 0, compressibility term on the diagonal, "
             "negative pressures clipped, gradient with the neighbourhood minimum, collision model), on the shared tank, "
             "with the pressure equation's source term as the variant: `standard` gamma (rho0/dt^2)(n0 - n*)/n0 "
             f"(relaxation gamma = {cfg['model.relaxation']:g}), `hattori` (eq. 6 of Hattori et al. literally, Rho* = rho0 n*/n0 "
             "standing in for rho0/det(dU*/dxi)) and `mixed` (Tanaka & Masunaga 2010).  For a liquid at rest div V* is "
             "about 0, so `hattori` reduces to the unrelaxed standard source on the tank; the flow is where they differ.  "
             "Wall loads are the first wall row's pressures integrated over 10 cm panels, averaged over the last "
             f"{cfg['time.average_window']:g} s; noise is the std over that window.  At rest means rms speed below "
             f"sqrt(2 x {cfg['time.rest_fraction']:g} g l0) (kinetic pressure below {100 * cfg['time.rest_fraction']:g} % "
             "of the hydrostatic step between neighbours).", ""]
    lines += _table(single, [("run", None), ("status", None), ("particles", g), ("ms_per_step", g), ("side_err", g),
                             ("floor_err", g), ("contact_rms", g), ("panel_noise_rel", g), ("rms_speed_cm_s", g),
                             ("rest_speed_cm_s", g)],
                    ["single run", "status", "particles", "ms/step", "side err", "floor err", "panel rms err",
                     "panel noise std/mean", "rms speed cm/s", "rest limit cm/s"])
    lines += [""] + _table(flow, [("run", None), ("status", None), ("mass_left_frac", g), ("level", g), ("slope_deg", g),
                                  ("panel_noise_rel", g), ("time_to_rest_s", g), ("message", None)],
                           ["flow run", "status", "mass left (fraction)", "second-vessel level cm", "slope deg",
                            "panel noise", "time to rest s", "why it stopped"])
    lines += ["", "Stiff and extreme cases (standard source, single vessel, "
              f"l0 = {cfg['stiff.spacing']:g} cm, {cfg['stiff.duration']:g} s): large_dt Courant "
              f"{cfg['stiff.courant_large']:g}; small_re all radii {cfg['stiff.re_small']:g} l0; no_relaxation gamma = "
              f"{cfg['stiff.relaxation_none']:g} (K&O 1996 literally); on_wall one particle started at "
              f"{tuple(cfg['stiff.on_wall_point'])} cm on the floor.", ""]
    lines += _table(stiff, [("run", None), ("status", None), ("rms_speed_cm_s", g), ("floor_err", g), ("message", None)],
                    ["case", "status", "rms speed cm/s", "floor err", "why it stopped"])
    counts = df.groupby(["case", "status"]).size()
    lines += ["", "Outcomes: " + "; ".join(f"{c} {s}: {n}" for (c, s), n in counts.items()) + "."]
    if len(single):
        big = single.sort_values("particles").iloc[-1]
        lines += ["", f"Cost per step of the largest single run ({big.particles} liquid particles plus walls): "
                  f"{big.ms_per_step:.3g} ms on a shared, loaded machine (target: 50 ms for 5,000 particles; "
                  f"pressure solver `{cfg['pressure.solver']}`; benchmarks/results/mps_step_cost.csv for 180-20,000)."]
    lines += ["", "Settings and their sources: " + "; ".join(
        f"`{k}` = {v} ({cfg.sources[k]})" for k, v in cfg.items() if k.startswith(("model.", "time.courant", "pressure.solver"))), ""]
    return "\n".join(lines)


def write(summary, cfg, outputs):
    """outputs = [claims CSV, report fragment] from the summary table and the settings file."""
    df = pd.read_csv(summary, keep_default_na=True)
    cfg_ = settings.load(cfg)
    for p in outputs:
        Path(p).parent.mkdir(parents=True, exist_ok=True)
    claims(df).to_csv(outputs[0], index=False)
    Path(outputs[1]).write_text(fragment(df, cfg_))
