"""The SPH summary table (called through workflow/scripts/call.py): one row per run file, the shared
measures (metrics.comparison_row) with SPH's own columns.

Run ids (config/methods/sph.yaml, runs): ``single_<variant>_<res>`` (single vessel from hydrostatic density
at rest), ``flow_<variant>_<res>`` and ``samefloor_<variant>_<res>`` (continue the single run's state at
rest on the flow tanks), ``stab_<case>`` (stability cases); <res> is ``n<count>`` or ``dx<spacing cm>``.
"""

from pathlib import Path

import numpy as np
import pandas as pd

from isaflow import metrics, runfile


def row(path):
    """One summary row of a run file: metrics.comparison_row, its case (the run id's prefix) and SPH's own
    columns (wall particles, cost per particle-step, stability case, time since the opening)."""
    ds = runfile.read(path)
    a = ds.attrs
    out = metrics.comparison_row(ds)
    run = a.get("run_id", Path(path).stem)
    out.update(run=run, case=run.split("_")[0], wall_particles=int(a["wall_particles"]),
               force_evals=int(ds["force_evals"]), rms_speed_cm_s=float(ds["residual"]),
               stability_case=run.removeprefix("stab_") if run.startswith("stab_") else "",
               stability_label=a.get("run_label", ""),
               ns_per_particle_step=float(ds["wall_time"]) / max(int(ds["steps"]) - int(ds["start_step"]), 1)
               / ds.sizes["particle"] * 1e9, escaped=a["status"] == "escaped",
               start_time_s=float(a.get("start_time", 0.0)))
    out["run_time_s"] = out["sim_time_s"] - out["start_time_s"]
    if "vessel" in ds.coords:
        out.update(metrics.flow_measures(ds))
    return out


def summary(runs, outputs):
    """outputs[0] (results/sph/summary.csv): one row per run file."""
    df = pd.DataFrame([row(p) for p in runs])
    Path(outputs[0]).parent.mkdir(parents=True, exist_ok=True)
    df.to_csv(outputs[0], index=False)
    return df
