"""Report section: every method on every shared tank, judged by one measure (results/compare/runs.csv).

Deterministic: end states and errors only (solver times are in the timing figure and docs/timing.md).
"""

import numpy as np
import pandas as pd

from ..methods import get
from . import md_table, write

TIMING = ("wall_time_s",)


def _pct(v):
    return "" if not np.isfinite(v) else f"{v:+.1%}"


def _cm(v):
    return "" if not np.isfinite(v) else f"{v:.2f}"


def _outcome(r):
    if r["status"] == "converged":
        return "at rest" if np.isfinite(r["sim_time_s"]) else "converged"
    return str(r["status"]).replace("_", " ")


def at_rest(r):
    """An end state to compare: a static method's end (no simulated time), or a dynamic run at rest (issue 43: a flow
    still moving at its time limit has no end state; its row says so and its end-state cells stay empty)."""
    return not np.isfinite(r["sim_time_s"]) or r["status"] == "converged"


def _vessels(g):
    names = [c[: -len("tank_surface_cm")] for c in g.columns if c.endswith("tank_surface_cm") and g[c].notna().any()]
    return names or [""]


def tank_table(g):
    """One row per run of a tank: outcome, surfaces against the tank's level, wall-load errors of the receiving
    vessel against the tank's theory and the run's own depth, what is left behind, flatness, tank difference."""
    vess = _vessels(g)
    recv = vess[-1]
    rows = []
    for _, r in g.iterrows():
        row = {"method": r["method"], "variant": r["variant"], "resolution": r["resolution"],
               "particles": int(r["particles"]), "outcome": _outcome(r),
               "t (s) / steps": f"{r['sim_time_s']:.3g} s" if np.isfinite(r["sim_time_s"]) else f"{int(r['steps']):,}"}
        if not at_rest(r):
            row["outcome"] += ": not at rest, end state not compared"
            rows.append(row)
            continue
        for v in vess:
            name = v.rstrip("_") or "surface"
            row[f"{name} (cm)"] = _cm(r.get(f"{v}surface_cm", np.nan))
        if len(vess) > 1:
            row["left"] = f"{r['left_fraction']:.1%}"
        row["side err tank"] = _pct(r.get(f"{recv}side_err_tank", np.nan))
        row["side err own"] = _pct(r.get(f"{recv}side_err_own", np.nan))
        row["floor err tank"] = _pct(r.get(f"{recv}floor_err_tank", np.nan))
        row["floor err own"] = _pct(r.get(f"{recv}floor_err_own", np.nan))
        row["slope (deg)"] = f"{r.get(f'{recv}slope_deg', np.nan):+.1f}"
        row["range (cm)"] = f"{r.get(f'{recv}surface_range_cm', np.nan):.1f}"
        row["tank difference"] = r["tank_difference"] if isinstance(r["tank_difference"], str) else ""
        rows.append(row)
    parts = []
    for v in vess:
        level, floor = g[f"{v}tank_surface_cm"].iloc[0], g[f"{v}floor_y_cm"].iloc[0]
        name = v.rstrip("_") or "surface"
        parts.append(f"{name} vessel empty (floor {floor:g} cm)" if level <= floor else f"{name} {level:.2f} cm")
    return pd.DataFrame(rows), ", ".join(parts), recv.rstrip("_")


def methods_section(table, outputs, tanks=()):
    """results/report/70_methods.md and docs/tables/methods_compare.csv (every compared run, no timings);
    tanks: the order of the tank sections."""
    md, csv = outputs
    df = pd.read_csv(table)
    df = df[df["compare"].astype(bool)].drop(columns=["compare", "file", *TIMING])
    order = {t: i for i, t in enumerate(tanks)}
    df = df.sort_values("tank", key=lambda c: c.map(lambda t: order.get(t, len(order))), kind="stable")
    df.to_csv(csv, index=False, float_format="%.6g")
    text = ["## Every method on every tank", "",
            "Every run of every tank method is judged by the same functions (`isaflow.metrics.comparison_row`) "
            "on the same tank. The free surface of a particle method is its top particle centres (mean over strips "
            "one spacing wide) plus half its layer pitch (dy, l0 or the rhombic a / 2): where its own discretisation "
            "puts the liquid's top. Wall-load errors are given twice: against the tank's theory (`tank`: the tank "
            "file's W and rho g, the liquid at rest in its vessels) and against the run's own liquid (`own`: the "
            "weight it holds in the vessel and the depth of its own surface). Dynamic methods run until at rest "
            "(kinetic energy / (W h) below the ratio of `config/rest.yaml` for its window) or their time limit; "
            "'at rest' is written only when met, and a dynamic run still moving at its time limit has no end state to compare (its row says so, its cells are empty). Every difference of a run's liquid from the tank is in the last "
            "column. All columns: [`docs/tables/methods_compare.csv`](tables/methods_compare.csv); solver times "
            "against errors: `figures/methods_error_vs_runtime.png` (a timing figure, made by the run and not tracked); "
            "the same errors, tracked: [`figures/methods_tanks.png`](../figures/methods_tanks.png).",
            ""]
    for tank, g in df.groupby("tank", sort=False):
        t, theory, recv = tank_table(g)
        where = f"those of the {recv} vessel" if recv else "those of the whole vessel"
        text += [f"### Tank `{tank}`", "",
                 f"The tank's liquid at rest: {theory}. Wall-load errors are {where}.", "", md_table(t), ""]
    notes = sorted({f"`{m}`: {get(m).label}" for m in df["method"]})
    text += ["Methods: " + "; ".join(notes) + ".", ""]
    write(text, md)
