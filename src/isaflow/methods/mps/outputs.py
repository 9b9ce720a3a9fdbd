"""Workflow entry points of the MPS runs: one run file per run, and the summary table.

Run ids: ``single_<variant>_dx<l0>`` (liquid block at rest in the single
tank) and ``flow_<variant>_dx<l0>`` (continues the single run's final state
with the walls switched to flow_step50's).
"""

import logging
from pathlib import Path

import numpy as np
import pandas as pd

from isaflow import metrics, runfile
from isaflow.scene import load_tank

from . import settings, solver

REFERENCES = ("Koshizuka & Oka (1996), Nucl. Sci. Eng. 123, 421; Hattori, Seta, Shibata & Koshizuka, "
              "'A new derivation of pressure Poisson equation in MPS'; Tanaka & Masunaga (2010), J. Comput. Phys. 229, 4279")
TANKS = {"single": "config/tanks/single.yaml", "flow": "config/tanks/flow_step50.yaml"}


def run_id(case, variant, l0):
    return f"{case}_{variant}_dx{l0:.3g}"


def spacing_of(cfg, case, label):
    """l0 [cm] in the settings whose label (f'{l0:.3g}') is ``label``."""
    for l0 in cfg[f"runs.{case}_spacings"]:
        if f"{l0:.3g}" == label:
            return float(l0)
    raise KeyError(f"no {case} spacing labelled '{label}' in the MPS settings")


def _logger(log_path):
    log = logging.getLogger(f"mps.{log_path}")
    log.setLevel(logging.INFO)
    if log_path:
        Path(log_path).parent.mkdir(parents=True, exist_ok=True)
        log.addHandler(logging.FileHandler(log_path, mode="w"))
    return log


def write_run(cfg_path, case, variant, label, out, log_path=None, start=None):
    """Run one case ('single' or 'flow', the flow from run file ``start``) and write its run file."""
    log = _logger(log_path)
    cfg = settings.load(cfg_path)
    l0 = spacing_of(cfg, case, label)
    tank = load_tank(TANKS[case])
    inputs = {"tank": TANKS[case], "settings": cfg_path}
    first = None
    if case == "flow":
        ds0 = runfile.read(start)
        first = dict(pos=ds0["pos"].values, vel=ds0["velocity"].values, steps=int(ds0["steps"]), sim_time=float(ds0["sim_time"]))
        inputs["start"] = start
        t_end, probes, snaps = cfg["time.flow_time"], cfg["runs.probes_flow"], 6
    else:
        t_end, probes, snaps = cfg["time.single_time"], cfg["runs.probes_single"], 0
    solver.solve(tank, cfg, variant, l0, min(t_end, 5e-3), probes, log=log.info)  # compile outside the timing
    started = runfile.now()
    r = solver.solve(tank, cfg, variant, l0, t_end, probes, start=first, snapshots=snaps, log=log.info)
    log.info(f"{run_id(case, variant, l0)}: {r.status}: {r.message}; {r.force_evals} steps in {r.wall_time:.1f} s")
    ds = runfile.to_dataset(r, tank, runfile.provenance(inputs), started, runfile.now(), l0, REFERENCES)
    runfile.write(ds, out)


def surface_slope(ds, vessel):
    """Slope [1] of a straight line through the strip tops of a vessel's liquid (belongs in metrics)."""
    x0, x1 = ds["vessel_x"].sel(vessel=vessel).values
    pos = ds["pos"].values
    pos = pos[(pos[:, 0] >= x0) & (pos[:, 0] < x1)]
    a = float(ds.attrs["spacing"])
    strip = np.floor((pos[:, 0] - x0) / a).astype(int)
    s = np.unique(strip)
    if len(s) < 2:
        return np.nan
    tops = np.array([pos[strip == k, 1].max() for k in s])
    return float(np.polyfit(x0 + (s + 0.5) * a, tops, 1)[0])


def noise(ds):
    """Wall-load and probe noise over the averaging window: mean over wetted panels of the std of |panel force|
    divided by its mean (1), and the std of each probe's pressure (N/cm^2)."""
    win = ds["in_window"].values.astype(bool)
    mag = np.hypot(*np.moveaxis(ds["hist_panel_force"].values[win], -1, 0))
    mean, std = mag.mean(0), mag.std(0)
    wet = mean > 0.01 * mean.max()
    probe = ds["hist_probe_pressure"].values[win]
    return float(np.mean(std[wet] / mean[wet])), float(np.mean(std[wet])), np.nanstd(probe, axis=0)


def time_to_rest(ds):
    """First sample time [s] after which the rms speed stays below the rest limit (NaN if never)."""
    t = ds["hist_time"].values
    moving = ds["hist_rms_speed"].values >= float(ds.attrs["rest_speed_cm_s"])
    if moving[-1]:
        return np.nan
    last = np.flatnonzero(moving)
    return float(t[last[-1] + 1]) if len(last) else float(t[0])


def summary_row(path):
    """One summary row of a run file."""
    ds = runfile.read(path)
    a = ds.attrs
    case = Path(path).stem.split("_")[0]
    row = dict(run=Path(path).stem, case=case, source_term=a["variant"], spacing_cm=float(a["spacing"]),
               particles=int(ds.sizes["particle"]), wall_time_s=float(ds["wall_time"]), pressure_solves=int(ds["force_evals"]),
               steps=int(ds["steps"]), sim_time_s=float(ds["sim_time"]), dt_s=float(a["dt_s"]), status=a["status"],
               max_solve_residual=float(a["max_solve_residual"]), ms_per_step=1e3 * float(ds["wall_time"]) / int(ds["force_evals"]),
               rms_speed_cm_s=float(ds["residual"]), time_to_rest_s=time_to_rest(ds))
    rel, absn, probe = noise(ds)
    row.update(panel_noise_rel=rel, panel_noise_N=absn)
    for k, p in enumerate(probe):
        row[f"probe{k}_std_N_cm2"] = float(p)
    vessel = None
    if "vessel" in ds.coords:
        names = [str(v) for v in ds["vessel"].values]
        vessel = names[-1]
        fm = metrics.flow_measures(ds)
        w = float(ds["weight"].values[0])
        row.update(mass_left_N=fm["particles_left"] * w, mass_left_frac=fm["particles_left"] / ds.sizes["particle"],
                   second_level_cm=metrics.load_errors(ds, vessel)["level"], second_slope=surface_slope(ds, vessel),
                   mass_conserved=fm["mass_conserved"])
    if case == "single" or (vessel and row["mass_left_frac"] < 0.5):
        row.update(metrics.hydrostatic_errors(ds, vessel=vessel))
    return row


def summary(paths, out):
    """results/mps/summary.csv: one row per run file."""
    df = pd.DataFrame([summary_row(p) for p in paths])
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    df.to_csv(out, index=False, float_format="%.6g")
    return df
