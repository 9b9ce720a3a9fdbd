"""Report fragment and timing fragment of the SPH runs, generated from results/sph/summary.csv (its claims are
the registry's, judged by the claims rule)."""

from pathlib import Path

import numpy as np
import pandas as pd

from ...figures.animation import report_line

def _fmt(x, f=".3g"):
    return "n/a" if x is None or (isinstance(x, float) and not np.isfinite(x)) else format(x, f)


def fragment(df):
    """Markdown of report section 50 from the summary table."""
    out = ["## Weakly compressible SPH on the same tank", "",
           "The liquid of marko2017 section 2 (cubic spline eq. 4, symmetric pressure gradient eq. 9) with the "
           "continuity equation in place of eq. 6's summed density (variant `wcsph`; eq. 6 literally is variant "
           "`wcsph_eq6`: its density is deficient within 2h of the free surface, so the surface band reads low), "
           "completed with a Tait equation of state, Monaghan's artificial viscosity, Adami et al. (2012) wall "
           "particles on every wetted wall face (both faces of the thin dividing wall) with a Lennard-Jones safety "
           "net (marko2017 eq. 7) and a leapfrog step (config/methods/sph.yaml gives every setting and its source).  "
           "At rest means isaflow.rest's criterion (kinetic energy / (W h) below its ratio for its window); wall "
           "loads are the wall-particle forces on the liquid averaged over the final rest window, summed over the "
           "10 cm wall panels.  The weakly compressible column at rest is short of the tank's 72.5 cm by "
           "g H^2 / (2 c0^2) and of its side load rho g H^2 / 2 = 3,262.5 N by (2/3) g H / c0^2 (0.20 %).",
           "", "### Single vessel", "",
           "Errors against the tank's theory (3,262.5 N per side wall, surface 72.5 cm) and against the run's own "
           "weight and depth (isaflow.metrics; the surface is the top particle centres + dy/2).", "",
           "| variant | particles | spacing (cm) | outcome | t (s) | time to rest (s) | final rms speed (cm/s) "
           "| surface (cm) | side err tank | side err own | floor err tank | per-panel RMS tank |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in df[df.case == "single"].sort_values(["variant", "spacing_cm"], ascending=[True, False]).itertuples():
        out.append(f"| {r.variant} | {r.particles} | {r.spacing_cm:.3g} | {r.status} | {r.sim_time_s:.2f} | "
                   f"{_fmt(r.time_to_rest_s, '.2f')} | {r.rms_speed_cm_s:.3g} | {_fmt(r.surface_cm, '.2f')} | "
                   f"{_fmt(r.side_err_tank, '+.2%')} | {_fmt(r.side_err_own, '+.2%')} | "
                   f"{_fmt(r.floor_err_tank, '+.2%')} | {_fmt(r.contact_rms_tank)} |")
    out += ["", "### Flows into the second vessel", "",
            "Flows continue the single run's state and clock (t below); they run until at rest or 40 s after the "
            "opening (flow time).  Second-vessel surface against the tank's level at rest (step: -13.75 cm, the "
            "first vessel empties; same floor: 24.17 cm in both vessels).", "",
            "| run | tank | particles | outcome | t (s) | flow time (s) | final rms speed (cm/s) | particles left | "
            "weight left | first surface (cm) | second surface (cm) | tank level (cm) | slope (deg) | side err tank "
            "| side err own |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in df[df.case.isin(["flow", "samefloor"])].sort_values(["tank", "particles"]).itertuples():
        out.append(f"| {r.run} | {r.tank} | {r.particles} | {r.status} | {r.sim_time_s:.1f} | {r.run_time_s:.1f} | "
                   f"{r.rms_speed_cm_s:.3g} | {r.particles_left} | {r.left_fraction:.1%} | "
                   f"{_fmt(r.first_surface_cm, '.2f')} | {_fmt(r.second_surface_cm, '.2f')} | "
                   f"{r.second_tank_surface_cm:.2f} | {_fmt(r.second_slope_deg, '.2g')} | "
                   f"{_fmt(r.second_side_err_tank, '+.1%')} | {_fmt(r.second_side_err_own, '+.1%')} |")
    out += ["", "### Stability cases", "", "| case | particles | outcome | t (s) | rms speed (cm/s) |", "|---|---|---|---|---|"]
    for r in df[df.case == "stab"].itertuples():
        out.append(f"| {r.stability_case}: {r.stability_label} | {r.particles} | {r.status} | {r.sim_time_s:.2f} | "
                   f"{r.rms_speed_cm_s:.3g} |")
    out += ["", "Figures: `figures/sph_single.png` (particles coloured by pressure, per-panel loads against "
            "hydrostatics), `figures/sph_flow.png` (final flow states and surfaces), `figures/sph_flow_snapshots.png`.", "",
            report_line("figures/sph_flow_animation.gif", "the finest WCSPH flow (flow_wcsph_dx2.5), particles coloured "
                        "by speed"), ""]
    return "\n".join(out)


def timing(df):
    """Markdown for docs/timing.md: solver time and cost per particle-step of every SPH run."""
    out = ["## Weakly compressible SPH: solver times (results/sph/summary.csv)", "",
           "| run | particles | threads | outcome | simulated t of the run (s) | wall time (s) | ns/particle-step |",
           "|---|---|---|---|---|---|---|"]
    for r in df.sort_values(["case", "variant", "spacing_cm"], ascending=[True, True, False]).itertuples():
        out.append(f"| {r.run} | {r.particles} | {r.threads} | {r.status} | {r.run_time_s:.2f} | {r.wall_time_s:.1f} | "
                   f"{r.ns_per_particle_step:.0f} |")
    return "\n".join(out + [""])


def write(summary, outputs):
    """outputs: the report fragment and the timing fragment, from the summary table."""
    df = pd.read_csv(summary)
    report_out, timing_out = outputs
    Path(timing_out).parent.mkdir(parents=True, exist_ok=True)
    Path(timing_out).write_text(timing(df))
    for path in outputs:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
    Path(report_out).write_text(fragment(df))
