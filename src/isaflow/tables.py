"""Tables every method shares, made from run files only: the methods' comparison on the shared tanks, and on a
tank of the user's (isaflow compare).

Every row is metrics.comparison_row of one run file, so every method is judged by the same functions on
the same tanks, with every run's at-rest and wall numbers (at_rest.AT_REST, units in the column names: time
to rest, residual rms speed over sqrt(g h), free-surface drift and each wall's load mean and standard
deviation over the rest window, particles past a wall, ISA's max|F| and rms|F|); the table holds solver
times (a timing file: results/, never the report's text).
"""

from pathlib import Path

import numpy as np
import pandas as pd

from . import metrics, theory
from .core.geometry import inside_polygon
from .runfile import read


def compare_table(runs, outputs, compare=()):
    """outputs[0]: one metrics.comparison_row per run file, with 'compare' True for the runs of the methods'
    comparison (the paths in ``compare``; the others are single-vessel runs of the error-against-run-time
    figure)."""
    keep = {str(Path(p)) for p in compare}
    rows = []
    for p in runs:
        ds = read(p)
        rows.append({**metrics.comparison_row(ds), "compare": str(Path(p)) in keep, "file": str(p)})
    df = pd.DataFrame(rows)
    Path(outputs[0]).parent.mkdir(parents=True, exist_ok=True)
    df.to_csv(outputs[0], index=False, float_format="%.6g")
    return df


def wall_columns(ds):
    """Every wall's load [N] in a run against the tank's theory, per vessel (prefix '<vessel>_'; none for a single
    vessel): normal_<wall>_N (its contacts on the wall's normal, metrics.normal_loads), load_<wall>_N (their
    magnitudes, metrics.load_errors 'tank'), theory_<wall>_N (the normal load, theory.wall_total),
    theory_fx_<wall>_N and theory_fy_<wall>_N (the liquid's force on the wall, theory.wall_force) and
    wall_err_<wall> = normal load / theory - 1 (NaN on a dry wall)."""
    out = {}
    walls = ds["wall_segment"].values
    names = [str(n) for n in ds["wall"].values]
    for vessel in metrics.vessels(ds):
        p = f"{vessel}_" if vessel else ""
        e = metrics.load_errors(ds, vessel, "tank")
        normal = metrics.normal_loads(ds, vessel)
        poly = metrics.vessel_view(ds, vessel)["polygon"]
        for w, name in enumerate(names):
            if f"theory_{name}" not in e or not _faces(walls[w], poly):
                continue
            th = e[f"theory_{name}"]
            fx, fy = theory.wall_force(walls[w], e["gamma"], e["level"])
            out.update({f"{p}normal_{name}_N": normal[name], f"{p}load_{name}_N": e[f"load_{name}"],
                        f"{p}theory_{name}_N": th, f"{p}theory_fx_{name}_N": float(fx) + 0.0,
                        f"{p}theory_fy_{name}_N": float(fy) + 0.0,
                        f"{p}wall_err_{name}": normal[name] / th - 1 if th > 0 else np.nan})
    return out


def _faces(wall, polygon, eps=1e-6):
    """True if a face of the wall (x0, y0, x1, y1) looks into the vessel's polygon: the point eps cm off its middle on
    its liquid (left) side, or on its back (a thin dividing wall), lies inside."""
    x0, y0, x1, y1 = wall
    L = np.hypot(x1 - x0, y1 - y0)
    mid, n = np.array([(x0 + x1) / 2, (y0 + y1) / 2]), np.array([-(y1 - y0), x1 - x0]) / L
    return bool(inside_polygon(np.array([mid + eps * n, mid - eps * n]), polygon).any())


def tank_table(runs, outputs, skipped=None):
    """outputs[0]: every method on one tank (isaflow compare): for each run file metrics.comparison_row, every
    wall's load against the tank's theory (wall_columns) and the weight the walls carry (metrics.weight_on_walls),
    'compare' True; then a row per method that did not run ({method: (status, reason)}: 'message' its reason,
    'compare' False).  Returns the table."""
    rows = []
    for p in runs:
        ds = read(p)
        finite = bool(np.isfinite(ds["pos"].values).all())
        rows.append({**metrics.comparison_row(ds), **(wall_columns(ds) if finite else {}),
                     **metrics.weight_on_walls(ds), "compare": True, "file": str(p)})
    for method, (status, reason) in (skipped or {}).items():
        rows.append({"method": method, "status": status, "message": reason, "compare": False})
    df = pd.DataFrame(rows)
    Path(outputs[0]).parent.mkdir(parents=True, exist_ok=True)
    df.to_csv(outputs[0], index=False, float_format="%.6g")
    return df
