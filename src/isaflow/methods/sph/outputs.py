"""Workflow entry points of the SPH runs (called through workflow/scripts/call.py, stderr is the
rule's log): run files and the summary table.

Run ids: ``single_<variant>_<res>`` (single vessel from hydrostatic density at
rest), ``flow_<variant>_<res>`` (continues the single run's final state with
the walls switched to flow_step50's) and ``stab_<case>`` (stability cases);
<res> is ``n<count>`` (a target particle count) or ``dx<spacing cm>``.
"""

import logging
import sys
from pathlib import Path

import numpy as np
import pandas as pd

from isaflow import metrics, runfile, theory
from isaflow.tank import load as load_tank

from . import settings, solver

REFERENCES = ("Marko (2017), Computation 5, 33 (section 2); Monaghan (1992), Annu. Rev. Astron. Astrophys. 30, 543; "
              "Monaghan (1994), J. Comput. Phys. 110, 399; Adami, Hu & Adams (2012), J. Comput. Phys. 231, 7057; "
              "Molteni & Colagrossi (2009), Comput. Phys. Commun. 180, 861")


def res_id(resolution):
    """'n180' or 'dx2.5' of a resolution entry of the settings."""
    return f"n{resolution['particles']}" if "particles" in resolution else f"dx{resolution['spacing']:g}"


def resolution_of(spec, case, rid):
    for r in spec["runs"][case]:
        if res_id(r) == rid:
            return {k: v for k, v in r.items() if k != "source"}
    raise KeyError(f"no {case} resolution '{rid}' in the SPH settings")


def _logger():
    log = logging.getLogger("isaflow.sph")
    log.setLevel(logging.INFO)
    if not log.handlers:
        log.addHandler(logging.StreamHandler(sys.stderr))
    return log


def run_case(cfg, tank, outputs, case, variant, rid, start=None, threads=1):
    """Run one case ('single', 'flow' from run file ``start``, or 'stab' with rid the case name) with the
    settings file ``cfg`` in the tank file ``tank`` on ``threads`` numba threads (the results do not
    depend on it; recorded as the run file's ``threads``); write its run file outputs[0].  A flow
    continues the start run's clock and step count."""
    log, cfg_path, out = _logger(), cfg, outputs[0]
    spec = settings.load(cfg_path)
    solver.warm_up(threads)  # compile outside the timing
    inputs = {"tank": tank, "settings": cfg_path}
    tank = load_tank(tank)
    kw = {}
    if case == "flow":
        kw["start"] = runfile.read(start)
        inputs["start"] = start
    elif case == "stab":
        st = spec["runs"]["stability"][rid]
        kw.update(resolution=st["resolution"], on_wall=st.get("on_wall", False),
                  overrides={k: v["value"] for k, v in st.get("set", {}).items()})
    else:
        kw["resolution"] = resolution_of(spec, case, rid)
    started = runfile.now()
    res = solver.solve(tank, variant, settings_path=cfg_path, log=log.info, threads=threads, **kw)
    if case == "stab":
        res.params["stability_case"] = rid
        res.params["stability_label"] = spec["runs"]["stability"][rid]["label"]
    log.info(f"{Path(out).stem}: {res.status}: {res.message}; {res.wall_time:.1f} s wall, {res.steps} steps, "
             f"{len(res.pos)} particles")
    ds = runfile.to_dataset(res, tank, runfile.provenance(inputs), started, runfile.now(),
                            spacing=float(np.sqrt(res.params["cell_dx"] * res.params["cell_dy"])),
                            references=REFERENCES)
    runfile.write(ds, out)


def level(ds, vessel=None):
    """Free-surface level [cm] of a vessel: theory.free_surface_level with strips one spacing wide."""
    return theory.free_surface_level(ds["pos"].values, float(ds.attrs["spacing"]), metrics.vessel_view(ds, vessel)["x_range"])


def surface_slope(ds, vessel):
    """Slope [degrees] of a least-squares line through the strip tops of a vessel's surface
    (strips as theory.free_surface_level).  Belongs in metrics."""
    v = metrics.vessel_view(ds, vessel)
    pos = ds["pos"].values[v["inside"]]
    a = float(ds.attrs["spacing"])
    if len(pos) < 2:
        return np.nan
    strip = np.floor((pos[:, 0] - v["x_range"][0]) / a).astype(int)
    tops = np.array([[pos[strip == s, 0].mean(), pos[strip == s, 1].max()] for s in np.unique(strip)])
    if len(tops) < 2:
        return np.nan
    return float(np.degrees(np.arctan(np.polyfit(tops[:, 0], tops[:, 1], 1)[0])))


def row(path):
    """One summary row of a run file: identity, cost, outcome and the metrics' error measures."""
    ds = runfile.read(path)
    a = ds.attrs
    out = dict(run=Path(path).stem, case=Path(path).stem.split("_")[0], variant=a["variant"],
               resolution=a["resolution"], spacing_cm=float(a["spacing"]), particles=int(ds.sizes["particle"]),
               wall_particles=int(a["wall_particles"]), wall_time_s=float(ds["wall_time"]),
               force_evals=int(ds["force_evals"]), status=a["status"], sim_time_s=float(ds["sim_time"]),
               rms_speed_cm_s=float(ds["residual"]), stability_case=a.get("stability_case", ""),
               ns_per_particle_step=float(ds["wall_time"]) / max(int(ds["steps"]) - int(ds["start_step"]), 1)
               / ds.sizes["particle"] * 1e9, threads=int(a.get("threads", 1)),
               escaped=a["status"] == "escaped", time_to_rest_s=float(a.get("time_to_rest", np.nan)),
               start_time_s=float(a.get("start_time", 0.0)), final_energy_ratio=float(a.get("final_energy_ratio", np.nan)))
    out["run_time_s"] = out["sim_time_s"] - out["start_time_s"]
    depth, width = float(a["liquid_depth"]), float(a["first_vessel_width"])
    tank_gamma = float(ds["weight"].values.sum()) / (width * depth)  # rho g of the tank, N/cm^3
    out["side_theory_tank_N"] = tank_gamma * depth**2 / 2  # rho g H^2 / 2 of the tank (3262.5 N)
    vessel = None
    if "vessel" in ds.coords:
        names = [str(n) for n in ds["vessel"].values]
        vessel = names[-1]
        w = ds["weight"].values
        x = ds["pos"].values[:, 0]
        x0, x1 = ds["vessel_x"].sel(vessel=names[0]).values
        out["mass_left_N"] = float(w[(x >= x0) & (x < x1)].sum())
        out["mass_left_fraction"] = out["mass_left_N"] / float(w.sum())
        out.update(metrics.flow_measures(ds))
        out["surface_slope_deg"] = surface_slope(ds, vessel)
        gamma = w.sum() / (float(a["first_vessel_width"]) * float(a["liquid_depth"]))  # rho g, N/cm^3
        v2 = metrics.vessel_view(ds, vessel)
        out["level_cm"] = level(ds, vessel)
        out["surface_cm"] = out["level_cm"] + float(a["cell_dy"]) / 2  # top particle centres + half a cell
        out["surface_expected_cm"] = v2["floor_y"] + (w.sum() - out["mass_left_N"]) / (gamma * v2["width"])
    else:  # single vessel: side walls and surface against the tank's own depth (3262.5 N, 72.5 cm)
        names = [str(n) for n in ds["wall"].values]
        res = ds["wall_resultant"].values
        sides = [abs(res[names.index(n), 0]) for n in ("left", "right") if n in names]
        if sides:
            out["side_err_tank"] = float(np.mean(sides)) / out["side_theory_tank_N"] - 1
        pos = ds["pos"].values
        nx = int(round(float(a["first_vessel_width"]) / float(a["cell_dx"])))
        out["surface_cm"] = float(np.sort(pos[:, 1])[-nx:].mean() + float(a["cell_dy"]) / 2)
        out["surface_err_tank_cm"] = out["surface_cm"] - float(a["liquid_depth"])
    if np.isfinite(ds["pos"].values).all():
        try:
            out.update(metrics.hydrostatic_errors(ds, vessel=vessel))
        except (KeyError, ValueError, IndexError) as err:  # measures that do not apply to this run
            out["metrics_error"] = str(err)
    return out


def summary(runs, outputs):
    """outputs[0] (results/sph/summary.csv): one row per run file."""
    df = pd.DataFrame([row(p) for p in runs])
    Path(outputs[0]).parent.mkdir(parents=True, exist_ok=True)
    df.to_csv(outputs[0], index=False)
    return df
