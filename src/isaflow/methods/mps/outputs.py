"""Workflow entry points of the MPS runs (called through workflow/scripts/call.py): one run file
per run, the stiff and extreme cases, and the summary table.

Run ids: ``single_<variant>_dx<l0>`` (liquid block at rest in the single tank, run until at rest
by isaflow.rest or settings time.single_time), ``flow_<variant>_dx<l0>`` in a flow tank (flow_step50,
flow_samefloor: the rule names the tank and the output), continuing the single run's final state (run
file ``start``; the chain's clock and step count go on; without ``start``, the block at rest: the
opening appears at t = 0), ``stiff_<case>`` (settings 'stiff') and ``dt_standard_c<courant>``
(settings 'dt_study').  ``threads``: numba threads of the run (None: numba's default); recorded in the
run file, results do not depend on it.
Every function logs to stderr (call.py sends it to the rule's log).
"""

import logging
import re
import sys
from pathlib import Path

import numpy as np
import pandas as pd

from isaflow import metrics, runfile
from isaflow.tank import load as load_tank

from . import boundary, settings, solver

REFERENCES = ("Koshizuka & Oka (1996), Nucl. Sci. Eng. 123, 421; MPS-Basic (github.com/MPS-Basic/MPS-Basic); "
              "Hattori, Seta, Shibata & Koshizuka, 'A new derivation of pressure Poisson equation in MPS'; "
              "Tanaka & Masunaga (2010), J. Comput. Phys. 229, 4279")
STIFF_CASES = ("large_dt", "small_re", "no_relaxation", "on_wall")


def run_id(case, variant, l0):
    return f"{case}_{variant}_dx{l0:.3g}"


def spacing_of(cfg, case, label):
    """l0 [cm] in the settings whose label (f'{l0:.3g}') is ``label``."""
    for l0 in cfg[f"runs.{case}_spacings"]:
        if f"{l0:.3g}" == label:
            return float(l0)
    raise KeyError(f"no {case} spacing labelled '{label}' in the MPS settings")


def _logger(name):
    log = logging.getLogger(f"mps.{name}")
    log.setLevel(logging.INFO)
    if not log.handlers:
        log.addHandler(logging.StreamHandler(sys.stderr))
    return log


def _run_and_write(tank, tank_path, cfg, variant, l0, t_end, probes, out, name, start=None, inputs=None, snaps=0,
                   threads=None):
    log = _logger(name)
    solver.solve(tank, cfg, variant, l0, min(t_end, 5e-3), probes, start=start, log=log.info, threads=threads)  # compile
    started = runfile.now()
    r = solver.solve(tank, cfg, variant, l0, t_end, probes, start=start, snapshots=snaps, log=log.info, threads=threads)
    log.info(f"{name}: {r.status}: {r.message}; {r.force_evals} steps in {r.wall_time:.1f} s")
    prov = runfile.provenance({"tank": tank_path, "settings": cfg.path, **(inputs or {})})
    runfile.write(runfile.to_dataset(r, tank, prov, started, runfile.now(), l0, REFERENCES), out)
    return r


def start_state(path):
    """solver.solve's start dict from a run file: its final positions and velocities, step count, time and
    the chain's initial depth."""
    ds = runfile.read(path)
    return dict(pos=ds["pos"].values, vel=ds["velocity"].values, steps=int(ds["steps"]), sim_time=float(ds["sim_time"]),
                initial_depth=float(ds.attrs["initial_depth"]), spacing=float(ds.attrs["spacing"]),
                origin=f"final state of {Path(path).name} ({ds.attrs['status']}, t = {float(ds['sim_time']):.3f} s)")


def run_case(cfg, tank, outputs, case, variant, label, start=None, threads=None):
    """Run one case and write outputs[0]: 'single' from the liquid block at rest in the tank's first vessel;
    'flow' in the flow tank ``tank``, continuing the run file ``start`` (the single run's final state) or,
    without it, from the block at rest (the opening appears at t = 0)."""
    settings_ = settings.load(cfg)
    l0 = spacing_of(settings_, case, label)
    inputs, st = {}, None
    if case == "flow":
        t_end, probes, snaps = settings_["time.flow_time"], settings_["runs.probes_flow"], 6
        if start is not None:
            st = start_state(start)
            if f"{st['spacing']:.3g}" != label:
                raise ValueError(f"{start}: spacing {st['spacing']:.3g} cm, the flow asks for {label}")
            inputs["start"] = start
    else:
        t_end, probes, snaps = settings_["time.single_time"], settings_["runs.probes_single"], 0
    _run_and_write(load_tank(tank), tank, settings_, variant, l0, t_end, probes, outputs[0], run_id(case, variant, l0),
                   start=st, inputs=inputs, snaps=snaps, threads=threads)


def run_dt(cfg, tank, outputs, courant, threads=None):
    """Time-step study: the single vessel with the standard source at settings dt_study.spacing and Courant
    number ``courant`` (a label, f'{c:g}' of one of dt_study.courants); write outputs[0]."""
    base = settings.load(cfg)
    c = next(float(x) for x in base["dt_study.courants"] if f"{x:g}" == courant)
    settings_ = base.with_overrides(**{"time.courant": c})
    _run_and_write(load_tank(tank), tank, settings_, "standard", base["dt_study.spacing"], base["time.single_time"],
                   base["runs.probes_single"], outputs[0], f"dt_standard_c{courant}", threads=threads)


def stiff_settings(cfg, case):
    """(settings, start) of a stiff or extreme case (STIFF_CASES); start None or a dict for solver.solve."""
    if case == "large_dt":
        return cfg.with_overrides(**{"time.courant": cfg["stiff.courant_large"]}), None
    if case == "small_re":
        r = cfg["stiff.re_small"]
        return cfg.with_overrides(**{"model.re_density": r, "model.re_gradient": r, "model.re_laplacian": r,
                                     "model.re_surface": r}), None
    if case == "no_relaxation":
        return cfg.with_overrides(**{"model.relaxation": cfg["stiff.relaxation_none"]}), None
    if case == "on_wall":
        return cfg, "on_wall"
    raise KeyError(f"unknown MPS stiff case '{case}' (choose from {', '.join(STIFF_CASES)})")


def run_stiff(cfg, tank, outputs, case, threads=None):
    """Run stiff case ``case`` (source term standard, settings 'stiff') in the single tank; write outputs[0]."""
    base = settings.load(cfg)
    settings_, start = stiff_settings(base, case)
    tank_ = load_tank(tank)
    l0 = base["stiff.spacing"]
    if start == "on_wall":
        xr, floor = solver.first_vessel(tank_)
        fluid = boundary.liquid_block(xr, floor, tank_.depth, l0)
        k = int(np.argmin(np.hypot(*(fluid - np.asarray(base["stiff.on_wall_point"]) - [0, l0 / 2]).T)))
        fluid[k] = base["stiff.on_wall_point"]
        start = dict(pos=fluid, vel=np.zeros_like(fluid), steps=0, sim_time=0.0)
    _run_and_write(tank_, tank, settings_, "standard", l0, base["stiff.duration"], base["runs.probes_single"],
                   outputs[0], f"stiff_{case}", start=start, threads=threads)


def noise(ds):
    """Wall-load and probe noise over the averaging window: mean over wetted panels of the std of |panel force|
    divided by its mean (1), the same std in N, and the std of each probe's pressure (N/cm^2)."""
    win = ds["in_window"].values.astype(bool)
    mag = np.hypot(*np.moveaxis(ds["hist_panel_force"].values[win], -1, 0))
    mean, std = mag.mean(0), mag.std(0)
    wet = mean > 0.01 * mean.max() if mean.max() > 0 else mean > 0
    probe = ds["hist_probe_pressure"].values[win]
    if not wet.any():
        return np.nan, np.nan, np.nanstd(probe, axis=0)
    return float(np.mean(std[wet] / mean[wet])), float(np.mean(std[wet])), np.nanstd(probe, axis=0)


def time_to_rest(ds):
    """Time [s] after the run's start at which the quiet stretch that made it at rest began (isaflow.rest);
    NaN if it never came to rest."""
    return float(ds.attrs.get("time_to_rest", np.nan))


SIDE_LOAD = 3262.5  # N, rho g h^2 / 2 of the single tank (72.5 cm, 9000 N): the side-wall load every method is judged on


def side_loads(ds):
    """Mean side-wall load [N] (left and right wall of the first vessel, |panel force| summed over the wall,
    averaged over the window) and its error against SIDE_LOAD; NaN for tanks other than the single vessel."""
    if ds.attrs.get("scene") != "single":
        return np.nan, np.nan
    names = [str(n) for n in ds["wall"].values]
    mag = np.hypot(*ds["contact_force"].values.T)
    cw = ds["contact_wall"].values
    load = float(np.mean([mag[cw == names.index(w)].sum() for w in ("left", "right")]))
    return load, load / SIDE_LOAD - 1.0


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
    return float(-(ds["pos"].values[int(m.group(1))] - a) @ normal)


def summary_row(path):
    """One summary row of a run file: metrics.run_row plus MPS noise, cost and rest measures."""
    ds = runfile.read(path)
    a = ds.attrs
    stem = Path(path).stem
    case = stem.split("_")[0]
    side, side_err = side_loads(ds)
    row = dict(run=stem, case=case, tank=a["scene"], source_term=a["variant"], courant=float(a["courant"]), dt_s=float(a["dt_s"]),
               sim_time_s=float(ds["sim_time"]), start_state=a.get("start_state", ""),
               max_solve_residual=float(a["max_solve_residual"]), rms_speed_cm_s=float(ds["residual"]),
               escapes=int(a.get("escapes", int(a["status"] == "escaped"))), energy_ratio=float(a["final_energy_ratio"]),
               rest_energy_ratio=float(a["rest_energy_ratio"]), time_to_rest_s=time_to_rest(ds),
               side_load_N=side, side_err_3262=side_err, threads=int(a.get("threads", 1)),
               max_speed_cm_s=float(ds["hist_max_speed"].values[-1]), message=a.get("status_message", ""),
               escape_depth_cm=escape_depth(ds), graze_steps=int(a.get("graze_steps", 0)),
               deepest_graze_cm=float(a.get("deepest_graze_cm", 0.0)),
               ms_per_step=1e3 * float(ds["wall_time"]) / max(1, int(ds["force_evals"])))
    rel, absn, probe = noise(ds)
    u = ds["hist_rms_speed"].values
    row.update(panel_noise_rel=rel, panel_noise_N=absn, min_rms_speed_cm_s=float(u.min()),
               min_rms_time_s=float(ds["hist_time"].values[int(np.argmin(u))]))
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
