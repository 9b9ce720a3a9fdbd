"""MPS report fragment (results/report/55_mps.md) and claims rows, generated from results/mps/summary.csv."""

from pathlib import Path

import pandas as pd

from . import settings

CLAIM_COLUMNS = ["paper", "section", "claim", "measured", "verdict", "evidence"]


def _fmt(x, f="{:.3g}"):
    return "n/a" if pd.isna(x) else f.format(x)


def claims(df, test_ok=True):
    """Claims rows: Hattori's checkable statement and the Papadopoulos claim on MPS oscillations."""
    single = df[df.case == "single"]
    quiet = single.groupby("source_term")["panel_noise_rel"].median()
    rows = [dict(
        paper="hattori_mps_pressure_poisson", section="eqs. (1)-(5)",
        claim="By adding the equation (3) and the equation (5), we obtain the discrete time Navier-Stokes equation (1) and (2).",
        measured="one MPS step satisfies (1)-(2) to relative 1e-9 with grad P taken at U* and rho0 for Rho[n+1]; "
                 "at U[n+1] (as eq. 1 writes it) it does not (strict xfail)",
        verdict="reproduced" if test_ok else "not reproduced",
        evidence="tests/test_mps.py::test_eqs_3_and_5_add_up_to_the_discrete_navier_stokes_eqs_1_2"),
        dict(
        paper="papadopoulos2016_isa_point_particles", section="1 (introduction)",
        claim="in the MPS method (Moving Particles Semi-Implicit) ... some high frequency oscillations are suppressed, "
              "depending on time step-length, because of the implicit nature of the method, with no additional technique for suppression",
        measured="median over resolutions of std/mean of the single-vessel panel loads: "
                 + ", ".join(f"{k} {v:.2f}" for k, v in quiet.items()),
        verdict="not reproduced" if quiet.get("standard", 0) > 0.1 else "reproduced",
        evidence="results/mps/summary.csv (panel_noise_rel), figures/mps_wall_loads.png")]
    return pd.DataFrame(rows, columns=CLAIM_COLUMNS)


def fragment(df, cfg):
    """Markdown of the MPS section."""
    lines = ["## MPS with three pressure source terms (issue 11)", "",
             "Koshizuka & Oka's MPS on the shared tank, with the pressure Poisson equation's source term as the variant: "
             "`standard` (rho0/dt^2)(n0 - n*)/n0, `hattori` (eq. 6 of Hattori et al., with Rho* = rho0 n*/n0 standing in "
             "for rho0/det(dU*/dxi)) and `mixed` (Tanaka & Masunaga 2010).  For a liquid at rest div V* is about 0, so "
             "`hattori` reduces to `standard` on the tank; the flow is where they differ.  Wall loads are the wall particles' "
             "pressures integrated over 10 cm panels, averaged over the last "
             f"{cfg['time.average_window']:g} s; noise is the std over that window.", "",
             "| run | status | particles | ms/step | side err | floor err | panel rms err | panel noise (std/mean) | rms speed cm/s |",
             "|---|---|---|---|---|---|---|---|---|"]
    for _, r in df[df.case == "single"].iterrows():
        lines.append(f"| {r.run} | {r.status} | {r.particles} | {_fmt(r.ms_per_step)} | {_fmt(r.get('side_err'))} | "
                     f"{_fmt(r.get('floor_err'))} | {_fmt(r.get('contact_rms'))} | {_fmt(r.panel_noise_rel)} | {_fmt(r.rms_speed_cm_s)} |")
    lines += ["", "| flow run | status | mass left (fraction) | second-vessel level cm | slope | time to rest s |", "|---|---|---|---|---|---|"]
    for _, r in df[df.case == "flow"].iterrows():
        lines.append(f"| {r.run} | {r.status} | {_fmt(r.get('mass_left_frac'))} | {_fmt(r.get('second_level_cm'))} | "
                     f"{_fmt(r.get('second_slope'))} | {_fmt(r.time_to_rest_s)} |")
    counts = df.groupby(["case", "status"]).size()
    lines += ["", "Outcomes: " + "; ".join(f"{c} {s}: {n}" for (c, s), n in counts.items()) + ".  Every MPS run here "
              "ends moving or escaped: the liquid at rest develops motion (rms speed in the table, rest limit "
              "rho u^2/2 < 0.001 rho g l0) and particles cross the walls; the flow runs start from those states."]
    big = df.sort_values("particles").iloc[-1]
    lines += ["", f"Cost per step of the largest run ({big.particles} liquid particles plus walls): {big.ms_per_step:.3g} ms "
              "(target: 50 ms for 5,000 particles; pressure solver "
              f"`{cfg['pressure.solver']}`).", "",
              "Settings and their sources: " + "; ".join(f"`{k}` = {v} ({cfg.sources[k]})" for k, v in cfg.items()
                                                       if k.startswith(("model.", "time.courant", "pressure.solver"))), ""]
    return "\n".join(lines)


def write(summary_csv, cfg_path, claims_out, report_out):
    df = pd.read_csv(summary_csv)
    cfg = settings.load(cfg_path)
    for p in (claims_out, report_out):
        Path(p).parent.mkdir(parents=True, exist_ok=True)
    claims(df).to_csv(claims_out, index=False)
    Path(report_out).write_text(fragment(df, cfg))
