"""The MPS summary table (called through workflow/scripts/call.py): one row per run file, the shared
measures (metrics.run_row) with MPS's own (wall-load and probe noise, rest, cost, grazes).

Run ids (config/methods/mps.yaml, runs): ``single_<variant>_dx<l0>`` (liquid block at rest in the single
tank), ``flow_<variant>_dx<l0>`` and ``samefloor_<variant>_dx<l0>`` (continue the single run's final state on
the flow tanks), ``stiff_<case>`` and ``dt_<...>_c<courant>`` (the time-step study); the case is the id's prefix.
"""

import re
from pathlib import Path

import numpy as np
import pandas as pd

from isaflow import metrics, runfile
from isaflow.core import fixed_order as FO
from isaflow.core.units import G


def noise(ds):
    """Wall-load and probe noise over the averaging window: mean over wetted panels of the std of |panel force|
    divided by its mean (1), the same std in N, and the std of each probe's pressure (N/cm^2)."""
    win = ds["in_window"].values.astype(bool)
    mag = np.hypot(*np.moveaxis(ds["sample_panel_force"].values[win], -1, 0))
    mean, std = mag.mean(0), mag.std(0)
    wet = mean > 0.01 * mean.max() if mean.max() > 0 else mean > 0
    probe = ds["sample_probe_pressure"].values[win]
    if not wet.any():
        return np.nan, np.nan, np.nanstd(probe, axis=0)
    return float(np.mean(std[wet] / mean[wet])), float(np.mean(std[wet])), np.nanstd(probe, axis=0)


def time_to_rest(ds):
    """Time [s] after the run's start at which the quiet stretch that made it at rest began (isaflow.rest: the
    run file's variable time_to_rest, at_rest.AT_REST); NaN if it never came to rest."""
    return float(ds["time_to_rest"]) if "time_to_rest" in ds else np.nan


SIDE_LOAD = 3262.5  # N, rho g h^2 / 2 of the single tank (72.5 cm, 9000 N): the side-wall load every method is judged on


def side_loads(ds):
    """Mean side-wall load [N] by the contacts' reading (pair forces for a momentum-conserving gradient, else the
    panel pressures; run attribute wall_load_reading, wall_balance) and its error against SIDE_LOAD; NaN for tanks
    other than the single vessel."""
    load = wall_balance(ds, "pair" if ds.attrs.get("wall_load_reading") == "pair forces" else "panel")[0]
    return load, load / SIDE_LOAD - 1.0


READINGS = {"pair": "sample_pair_force", "panel": "sample_panel_pressure_force"}  # wall-load readings: variable


def wall_series(ds, reading="pair"):
    """Wall loads of the single vessel per sample by one reading (READINGS: pair forces, the primary, or panel
    pressures), each the mean over the steps of its sample interval: dict of (S,) arrays [N] side (the mean of
    |sum of horizontal forces| on the left and right walls), floor (vertical force on the floor) and vertical (the
    vertical forces of floor and side walls together: the liquid's weight at rest); None for other tanks, and
    for the panel reading of a run file without it."""
    if ds.attrs.get("scene") != "single" or READINGS[reading] not in ds:
        return None
    F = ds[READINGS[reading]].values
    names = [str(n) for n in ds["wall"].values]
    cw = ds["contact_wall"].values
    left, floor, right = (F[:, cw == names.index(w)].sum(1) for w in ("left", "floor", "right"))
    return dict(side=0.5 * (np.abs(left[:, 0]) + np.abs(right[:, 0])), floor=floor[:, 1],
                vertical=left[:, 1] + floor[:, 1] + right[:, 1])


def wall_balance(ds, reading="pair"):
    """(side, floor, vertical) [N] of wall_series averaged over the run's averaging window; NaN where it has none."""
    series = wall_series(ds, reading)
    if series is None:
        return np.nan, np.nan, np.nan
    win = ds["in_window"].values.astype(bool)
    return tuple(float(series[k][win].mean()) for k in ("side", "floor", "vertical"))


def pressure_profile(pos, p, l0, rho_g, depth, below=2.5):
    """(slope / rho g, rms scatter / (rho g depth)) of the liquid pressures p [N/cm^2] against depth below the
    liquid's top (top particle centre + l0/2) for the particles deeper than ``below`` l0 (a least-squares line;
    the top rows, where the free surface's P = 0 sits, are left out).  rho_g [N/cm^3], depth [cm]."""
    d = pos[:, 1].max() + 0.5 * l0 - pos[:, 1]
    deep = d > below * l0
    if deep.sum() < 3:
        return np.nan, np.nan
    slope, intercept = FO.line(d[deep], p[deep])
    res = p[deep] - (slope * d[deep] + intercept)
    return slope / rho_g, float(np.sqrt(np.mean(res**2)) / (rho_g * depth))


def escape_depth(ds):
    """Distance [cm] behind the wall of the particle an 'escaped' message names ('particle K crossed wall NAME');
    NaN for other runs.  Shows whether an escape is a graze of the wall line or a particle through the wall rows."""
    m = re.search(r"particle (\d+) crossed wall '([^']+)'", ds.attrs.get("status_message", ""))
    if not m:
        return np.nan
    walls = ds["wall_segment"].values
    w = [str(n) for n in ds["wall"].values].index(m.group(2))
    a, b = walls[w, :2], walls[w, 2:]
    t = (b - a) / np.hypot(*(b - a))
    normal = np.array([-t[1], t[0]])  # liquid on the wall's left
    return float(-FO.dot2(ds["pos"].values[int(m.group(1))] - a, normal))


def summary_row(path):
    """One summary row of a run file: metrics.run_row plus MPS noise, cost and rest measures."""
    ds = runfile.read(path)
    a = ds.attrs
    stem = a.get("run_id", Path(path).stem)
    case = stem.split("_")[0]
    side, side_err = side_loads(ds)
    row = dict(run=stem, case=case, tank=a["scene"], source_term=a["variant"], courant=float(a["time.courant"]), dt_s=float(a["dt_s"]),
               sim_time_s=float(ds["sim_time"]), start_state=a.get("start_state", ""),
               relaxation=float(a.get("model.relaxation", np.nan)), label=a.get("run_label", ""),
               max_solve_residual=float(a["max_solve_residual"]), rms_speed_cm_s=float(ds["residual"]),
               escapes=int(a.get("escapes", int(a["status"] == "escaped"))), energy_ratio=float(a["final_energy_ratio"]),
               rest_energy_ratio=float(a["rest_energy_ratio"]), time_to_rest_s=time_to_rest(ds),
               side_load_N=side, side_err_3262=side_err, threads=int(a.get("threads", 1)),
               max_speed_cm_s=float(ds["sample_max_speed"].values[-1]), message=a.get("status_message", ""),
               escape_depth_cm=escape_depth(ds), graze_steps=int(a.get("graze_steps", 0)),
               deepest_graze_cm=float(a.get("deepest_graze_cm", 0.0)),
               reflected_particles=int(a.get("reflected_particles", 0)), reflect_steps=int(a.get("reflect_steps", 0)),
               ms_per_step=1e3 * float(ds["wall_time"]) / max(1, int(ds["force_evals"])))
    W = float(ds.attrs.get("tank_weight", np.nan))
    for reading in READINGS:
        side_r, floor_r, vert_r = wall_balance(ds, reading)
        row.update({f"side_err_{reading}": side_r / SIDE_LOAD - 1.0, f"floor_err_{reading}": floor_r / W - 1.0,
                    f"vertical_err_{reading}": vert_r / W - 1.0})
    if "pressure_mean" in ds:
        rho_g = float(a["rho0_N_s2_cm4"]) * G
        row["p_slope"], row["p_scatter"] = pressure_profile(ds["pos"].values, ds["pressure_mean"].values,
                                                            float(a["spacing"]), rho_g, float(a["initial_depth"]))
    row.update(window_energy_mean=float(a.get("window_energy_ratio_mean", np.nan)),
               window_energy_max=float(a.get("window_energy_ratio_max", np.nan)),
               gradient=a.get("model.gradient", ""))
    rel, absn, probe = noise(ds)
    u = ds["sample_rms_speed"].values
    row.update(panel_noise_rel=rel, panel_noise_N=absn, min_rms_speed_cm_s=float(u.min()),
               min_rms_time_s=float(ds["sample_time"].values[int(np.argmin(u))]))
    for k, p in enumerate(probe):
        row[f"probe{k}_std_N_cm2"] = float(p)
    m = metrics.run_row(ds)
    row.update({k: v for k, v in m.items() if k not in row})
    if "vessel" in ds.coords:
        w = float(ds["weight"].values[0])
        row.update(mass_left_N=m["particles_left"] * w, mass_left_frac=m["particles_left"] / ds.sizes["particle"])
    return row


def summary(runs, outputs):
    """outputs[0] (results/mps/summary.csv): one row per run file."""
    df = pd.DataFrame([summary_row(p) for p in runs])
    Path(outputs[0]).parent.mkdir(parents=True, exist_ok=True)
    df.to_csv(outputs[0], index=False, float_format="%.6g")
    return df
