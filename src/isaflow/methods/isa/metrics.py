"""ISA's own measures of a run file (point particles with the paper's force laws), on top of isaflow.metrics.

Units cm, N.  compressibility: the paper's rhomb-area claim (section 5);
wall_law_usage / law_usage: how much of the force laws' range a state uses;
stress_ratio: K = sigma_xx / sigma_yy of the lattice's interior;
convergence_measures: the paper's update's stability floor; tolerances: the
tolerances of the single-vessel claims, derived from the lattice; run_row: the
metrics table's row.
"""

import numpy as np

from ...metrics import (contact_in_vessel, contact_loads, flow_measures, hydrostatic_errors, layer_pitch,  # noqa: F401
                        level_of, load_errors, pairs, surface_measures, surface_of, vessel_view)
from . import theory


def compressibility(ds, vessel=None, level=None):
    """Area measures of the paper's incompressibility claim (section 5: a rhomb loses at most 8.6 %).

    - area_loss_global: 1 - (B h / N) / (a^2 / 2), the area per particle the
      level implies against the initial lattice's a^2 / 2 (any run);
    - rhomb_loss_mean, rhomb_loss_max: mean and largest 1 - A / A_0 over the
      interior rhombs of the initial rhombic lattice (pos0), A by the shoelace
      formula of the same four particles now; rhomb_loss_surface_mean: the
      rhombs whose top particle is in the top row.  NaN when pos0 is no lattice.
    """
    v = vessel_view(ds, vessel)
    a = float(ds.attrs["spacing"])
    level = level_of(ds, vessel) if level is None else level
    n = int(v["inside"].sum())
    out = dict(area_loss_global=1.0 - v["width"] * (level - v["floor_y"]) / n / (a * a / 2) if n else np.nan,
               rhomb_loss_mean=np.nan, rhomb_loss_max=np.nan, rhomb_loss_surface_mean=np.nan, rhombs=0)
    pos0 = ds["pos0"].values
    quads = theory.rhombs(pos0, a)
    if len(quads) == 0 or not np.isfinite(ds["pos"].values).all():
        return out
    loss = 1.0 - theory.polygon_area(ds["pos"].values, quads) / (a * a / 2)
    top = np.isclose(pos0[quads[:, 2], 1], pos0[:, 1].max())
    inner = loss[~top] if (~top).any() else loss
    out.update(rhomb_loss_mean=float(inner.mean()), rhomb_loss_max=float(inner.max()),
               rhomb_loss_surface_mean=float(loss[top].mean()) if top.any() else np.nan, rhombs=len(quads))
    return out


def wall_law_usage(ds):
    """max_wall_reaction_N: largest |R_b|; wall_gap_reduction: 1 - (smallest particle-wall
    distance) / l_bu, the paper's "distance from boundary ... not reduced more than 10 %"
    (l_bu is the initial boundary distance of both lattices).  Point-particle runs only."""
    if "contact_particle" not in ds or not ds.sizes.get("contact"):
        return dict(max_wall_reaction_N=np.nan, wall_gap_reduction=np.nan)
    mag = np.hypot(*ds["contact_force"].values.T)
    gap = np.hypot(*(ds["pos"].values[ds["contact_particle"].values] - ds["contact_point"].values).T)
    return dict(max_wall_reaction_N=float(mag.max()), wall_gap_reduction=float(1.0 - gap.min() / ds.attrs["forces.wall.l_u"]))


def stress_ratio(ds, vessel=None):
    """Horizontal-to-vertical stress ratio K = sigma_xx / sigma_yy of the lattice.

    Virial sum over particle pairs whose midpoint lies in the interior of the
    vessel (middle 60 % of the width, 10-60 % of the liquid height), away from
    walls and surface.  A fluid has K = 1; the hydrostatic side-wall loads
    scale with K, so 1 - K is the side-wall deficit a solid-like lattice shows.
    Point-particle (ISA) runs only: NaN for methods without the pair law.
    """
    if "forces.pair.l_u" not in ds.attrs:
        return float("nan")
    v = vessel_view(ds, vessel)
    pos = ds["pos"].values
    a = ds.attrs
    (x0, x1), y0 = v["x_range"], v["floor_y"]
    h = level_of(ds, vessel) - y0
    pi, pj = pairs(pos, float(a["forces.pair.l_u"]))
    d = pos[pi] - pos[pj]
    mid = 0.5 * (pos[pi] + pos[pj])
    sel = ((mid[:, 0] > x0 + 0.2 * (x1 - x0)) & (mid[:, 0] < x1 - 0.2 * (x1 - x0))
           & (mid[:, 1] > y0 + 0.1 * h) & (mid[:, 1] < y0 + 0.6 * h))
    dist = np.hypot(d[sel, 0], d[sel, 1])
    force = float(a["forces.pair.r_u"]) * (1 - dist / float(a["forces.pair.l_u"]))  # repulsive magnitude, N
    sxx = np.sum(force * d[sel, 0] ** 2 / dist)
    syy = np.sum(force * d[sel, 1] ** 2 / dist)
    return float(sxx / syy) if syy > 0 else float("nan")


def run_row(ds, vessel=None):
    """One metrics-table row (dict) of an ISA run Dataset: loads against the paper's level reading (top
    centres), the lattice's measures, and the shared surface (metrics.surface_of) with the wall-load
    errors against the tank's theory and the run's own depth (NaN where a measure does not apply)."""
    row = dict(
        resolution=ds.attrs.get("resolution", ""),
        method=ds.attrs.get("method", "isa"),
        variant=ds.attrs["variant"],
        particles=int(ds.sizes["particle"]),
        du_cm=float(ds.attrs.get("solver.du", np.nan)),
        spacing_cm=float(ds.attrs["spacing"]),
        f_tol_N=float(ds.attrs.get("solver.f_tol", np.nan)),
        steps=int(ds["steps"]),
        wall_time_s=float(ds["wall_time"]),
        status=ds.attrs["status"],
        converged=bool(int(ds["converged"])),
        residual=float(ds["residual"]),
    )
    total = ds["wall_resultant"].values.sum(0)
    W = float(ds["weight"].values.sum())
    row["balance_x_N"] = abs(total[0])
    row["balance_y_N"] = abs(total[1] - W)
    if vessel is None and "vessel" in ds.coords:
        vessel = str(ds["vessel"].values[-1])  # flows: wall loads of the receiving vessel
    if "vessel" in ds.coords:
        row.update(flow_measures(ds))
    row["loads_vessel"] = vessel or "all"
    row.update(load_errors(ds, vessel, "own"))  # the one surface (metrics.surface_of)
    row.update(surface_measures(ds, vessel))
    row["surface"] = surface_of(ds, vessel)
    for ref in ("tank", "own"):
        e = load_errors(ds, vessel, ref)
        row.update({f"{k}_{ref}": e.get(k, np.nan) for k in ("floor_err", "side_err", "contact_rms")})
    row.update(compressibility(ds, vessel, row["level"]))
    row.update(wall_law_usage(ds))
    row["stress_ratio"] = stress_ratio(ds, vessel)
    row.update(convergence_measures(ds))
    return row


EIGEN_LIMIT = 5000  # particles: largest run whose stiffest mode is computed (sparse Lanczos, < 1 s)


def convergence_measures(ds):
    """lambda_max [N/cm] of the final state's stiffness matrix and the literal
    update's stability floor lambda_max du / 2 [N] (theory.step_floor; ISA runs
    only, up to EIGEN_LIMIT particles; NaN otherwise), and the max|F| band [N] of the last records."""
    a = ds.attrs
    out = {"lambda_max": np.nan, "stability_floor_N": np.nan, "band_lo_N": np.nan, "band_hi_N": np.nan}
    if a.get("method") == "isa" and ds.sizes["particle"] <= EIGEN_LIMIT and np.isfinite(ds["pos"].values).all():
        lam, floor = theory.step_floor(ds["pos"].values, ds["wall_segment"].values, a["forces.wall.l_u"], a["forces.wall.r_u"],
                                       a["forces.pair.l_u"], a["forces.pair.r_u"], a["solver.du"])
        out.update(lambda_max=lam, stability_floor_N=floor)
    if "hist_fmax_lo" in ds:
        out.update(band_lo_N=float(ds["hist_fmax_lo"].values[-10:].min()),
                   band_hi_N=float(ds["hist_fmax_hi"].values[-10:].max()))
    return out


def tolerances(row, a, n_particles, f_tol):
    """Tolerances derived from the discretisation (not from the results).

    row: a run_row dict; a lattice diagonal cm.  Returns {name: (tol, why)}:
    - level: a / 4 cm.  The surface is a layer of particles whose rows are
      a / 2 apart, so any reading of it is uncertain by half a row pitch.
    - floor: relative N f_tol / W.  Vertical equilibrium of the whole liquid to
      the paper's own equilibrium standard (every |F| < f_tol): the wall
      reactions balance the weight up to N f_tol.  (N max|F| / W, the old rule,
      could not fail for a run stuck in a cycle: 47 % for the paper's update.)
    - side: relative (a / 4) / (h - floor).  The side total W h / (2 B) inherits the
      level's uncertainty.
    - side_height: a / 4 cm.  Side contacts sit a / 2 apart.
    """
    h = row["depth"]
    return {
        "level": (a / 4, "half a row pitch a/2: the level is a layer of particles"),
        "floor": (n_particles * f_tol / row["weight"], "N f_tol / W: vertical equilibrium to the paper's standard"),
        "side": ((a / 4) / h, "(a/4)/h: the side total W h/(2B) inherits the level's uncertainty"),
        "side_height": (a / 4, "half the a/2 spacing of the side contacts"),
    }


def law_usage(ds):
    """How much of the force laws' range the final state uses (1 = exhausted).

    wall_use = largest wall reaction / R_bu (1: a particle sits on a wall, which
    can push no harder); pair_use = largest pair force / R_pu (1: two particles
    coincide); min_pair_cm: smallest inter-particle distance (NaN without a
    pair in range).  All NaN when positions are not finite.
    """

    pos = ds["pos"].values
    a = ds.attrs
    out = dict(wall_use=np.nan, pair_use=np.nan, min_pair_cm=np.nan)
    if not np.isfinite(pos).all():
        return out
    mag = np.hypot(*ds["contact_force"].values.T)
    out["wall_use"] = float(mag.max() / a["forces.wall.r_u"]) if len(mag) else 0.0
    l_u = float(a["forces.pair.l_u"])
    pi, pj = pairs(pos, l_u)
    if len(pi):
        d = np.hypot(*(pos[pi] - pos[pj]).T)
        out["min_pair_cm"] = float(d.min())
        out["pair_use"] = float(1.0 - d.min() / l_u)
    else:
        out["pair_use"] = 0.0
    return out


def transfer_curve(chain):
    """(t, f) of a flow: time since the opening (s; an ISA update's steps, counted as 1 s each, for the static
    update rules) and the fraction of the particles in the receiving vessel, from the vessel counts recorded at
    chunk ends.  chain: the run Datasets of one flow in order (an ISA chain: application 3, then 4); the first
    one's start is the opening.  A liquid run (SPH, MPS: samples in time) is read from its samples."""
    ds = chain[0]
    if "sample_time" in ds:
        t = ds["sample_time"].values - float(ds.attrs.get("start_time", 0.0))
        f = ds["sample_vessel_count"].values[:, -1] / ds.sizes["particle"]
        return np.concatenate([[0.0], t]), np.concatenate([[f[0]], f])
    ts, fs = [0.0], []
    t0 = int(ds["start_step"])
    x2 = ds["vessel_x"].values[-1]
    x = ds["pos0"].values[:, 0]
    fs.append(float(np.count_nonzero((x >= x2[0]) & (x < x2[1]))) / ds.sizes["particle"])
    for d in chain:
        dt = float(d.attrs["solver.dt"]) if d.attrs.get("variant") == "overdamped" else 1.0
        ts += list((d["sample_step"].values - t0) * dt)
        fs += list(d["sample_vessel_count"].values[:, -1] / d.sizes["particle"])
    return np.array(ts, float), np.array(fs, float)


def normalised_curve(t, f, grid):
    """(f on tau = t / t_50 sampled at grid, t_50): t_50 the first time f reaches half its final value (linear
    between samples); beyond the last sample f keeps its final value (the flow has ended)."""
    half = 0.5 * f[-1]
    k = int(np.argmax(f >= half))
    t50 = t[k] if k == 0 else t[k - 1] + (half - f[k - 1]) * (t[k] - t[k - 1]) / (f[k] - f[k - 1])
    return np.interp(grid * t50, t, f, right=f[-1]), t50
