"""The solid method's report fragment 65 and timing fragment, from run files and the judged claims.

The claims are marko2017's registry rows whose checks read the solid's runs or quantities (the registry,
isaflow.claims_registry), judged by the claims rule (isaflow.judge); the fragment counts them by kind and
verdict class.  Units: cm, N, s.
"""

from pathlib import Path

import pandas as pd

from isaflow import claims as C
from isaflow import claims_registry

from .figures import read_runs


def measured_here(claims, registry=claims_registry.DEFAULT_DIRECTORY):
    """The rows of the judged marko2017 table (results/claims/registry/marko2017.csv, the claims rule's) whose
    checks read a solid run ('solid:...') or a solid quantity ('solid.*'), as the registry declares them."""
    ids = {c["id"] for c in claims_registry.load(registry) for chk in c.get("checks", [])
           if chk["q"].startswith("solid.") or any(r.startswith("solid:") for r in chk.get("runs", []))}
    table = pd.read_csv(claims)
    return table[table["id"].isin(ids)]


def counts_text(table):
    """'n <class>' per kind, the printed method's numerical results apart."""
    t = table.assign(cls=table["verdict"].map(C.verdict_class))
    parts = []
    for kind, g in t.groupby("kind", sort=False):
        n = g["cls"].value_counts()
        parts.append(f"{kind}: " + ", ".join(f"{n[k]} {k}" for k in C.VERDICTS if k in n))
    return "; ".join(parts)


def write_report(table, run_paths, out):
    """results/report/65_solid.md: the verdict counts by kind (the claims head the report) and the runs."""
    lines = ["## Hooke's-law solid particles (Marko 2017, section 4)", "",
             "Variants: `paper` = eqs. 11-16 as printed (normal Hooke springs between linked cubic particles, "
             "unlinked ones only push); `hooke` = the same plus a Poisson contraction of the particle size and "
             "shear springs of modulus G; `objective` = hooke without the pair's rigid rotation (neither is in the "
             "paper). 3D bars are run in 3D, the Hertz plate in 2D plane strain. Settling by kinetic damping (not "
             "stated in the paper); the eq. 27 runs and the sustained-tension bars are undamped. Verdicts are judged "
             "on the printed method (`paper`); the completions are reported beside them. Claims measured here, by "
             "kind: " + counts_text(table) + ".", "",
             "| run | variant | status | steps | simulated time [s] | largest step move [dx] |", "|---|---|---|---|---|---|"]
    for ds in read_runs(run_paths).values():
        move = ds.attrs.get("max_step_move_over_dx")
        lines.append(f"| {ds.attrs['case']} | {ds.attrs['variant']} | {ds.attrs['status']} | {int(ds['steps'])} | "
                     f"{float(ds['sim_time']):.3g} | {'' if move is None else format(float(move), '.3g')} |")
    lines += ["", "Section 4.4 (`vessel` run, variant `pressure_load`): the 2D ring cut from the square lattice "
              "(centre radius in [a, b)), the water replaced by its pressure on the wetted faces, settled by kinetic "
              "damping and run undamped at the paper's step; variant `water_particles`: weakly compressible SPH water "
              "(linear EOS from p0) inside the same ring, coupled step by step, undamped, solid model `objective`; "
              "run `vessel_water_particles_paper`: the same with the printed solid model. Elastic floor (`floor_*` "
              "runs): a steel plate of solid particles under the single tank, simply supported, loaded one-way by the "
              "floor contacts of the rigid-floor runs of the other methods (variant `oneway`) or by the uniform W / "
              "span (`uniform_load`). Runs the claims registry asks for: `hertz_R*` (the plate under disks of the "
              "other stated radii), `hertz_eq27*` (eqs. 26-27 stepping undamped, and eq. 27 without the cap), "
              "`bar_tension_long*` (the bar held in sustained tension, strain x step sweep), `vessel_water_stop_paper` "
              "(the paper's coupling and ring: the paper's version of the vessel) and its `_h*`, `_a*` twins (other "
              "water smoothing lengths and viscosities), `bar_*_sliding_paper` (axial-only grips), "
              "`hertz_loadsteps_paper` (the other interior depths).", "",
              "Figures: `figures/solid_bar.png` (deformed bars and shear block), `figures/solid_hertz.png` "
              "(load and peak pressure against indentation), `figures/solid_vessel.png` (Fig. 7 analogue: ring "
              "radial displacement against time, Lame's value, the paper's 58.7 us), `figures/solid_floor.png` "
              "(elastic-floor deflection per load source against beam theory).", ""]
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    Path(out).write_text("\n".join(lines))
    return out


def write_timing(run_paths, out):
    """Markdown for docs/timing.md: solver time of every solid run."""
    lines = ["## Hooke's-law solid particles: solver times", "",
             "| run | variant | steps | solver time [s] | elastic floor: solver time of its load run [s] |",
             "|---|---|---|---|---|"]
    for ds in read_runs(run_paths).values():
        load = ds.attrs.get("load_wall_time_s")
        lines.append(f"| {ds.attrs['case']} | {ds.attrs['variant']} | {int(ds['steps'])} | {float(ds['wall_time']):.3g} | "
                     f"{'' if load is None else format(float(load), '.3g')} |")
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    Path(out).write_text("\n".join(lines + [""]))


def report(runs, claims, outputs, registry=()):
    """Report fragment and timing fragment, outputs[0:2] (workflow entry point); claims: the judged
    marko2017 table of the claims rule; registry: the registry files (their folder is read)."""
    folder = str(Path(registry[0]).parent) if registry else claims_registry.DEFAULT_DIRECTORY
    write_report(measured_here(claims, folder), runs, outputs[0])
    write_timing(runs, outputs[1])
