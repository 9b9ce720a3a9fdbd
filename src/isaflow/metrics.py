"""Error measures of a run file, defined once here (units cm, N).

Wall-load errors compare the computed wall reactions with the hydrostatic
theory built from the weight the vessel holds and its measured level
(theory.py):
- ``floor_err``: (computed floor total - theory) / theory (theory = weight held);
- ``side_err``: mean over the side walls of (computed - theory) / theory, where
  a side wall's theoretical total is gamma h^2 / 2 = W h / (2 B);
- ``contact_rms``: RMS over wetted contacts of (computed - theoretical contact
  force) / (theoretical floor contact force gamma h a), i.e. in units of one
  floor contact load;
- ``side_height_err``: height of the side-wall resultant minus h / 3, cm;
- ``level_implied``: the level implied by the side-wall loads, 2 B F_side / W;
- ``balance_y``, ``balance_x``: |sum of wall reactions + total weight| per
  component, N (equilibrium requires <= N f_tol).
"""

import numpy as np

from . import theory
from .core import neighbours as NB


def vessel_view(ds, vessel=None):
    """Walls, contacts and particles of one vessel of a run Dataset.

    vessel: name in ds.vessel, or None for the whole scene.  A wall belongs to
    the vessel when its x-extent touches the vessel's [xmin, xmax]; the floor
    is the lowest horizontal wall among them.  Returns dict with x_range (cm),
    width B (cm), floor_y (cm), wall_in (W,) and horizontal (W,) bool masks,
    inside (N,) bool mask of the particles in the vessel.
    """
    walls = ds["wall_segment"].values
    pos = ds["pos"].values
    if vessel is None:
        x0, x1 = walls[:, [0, 2]].min(), walls[:, [0, 2]].max()
    else:
        x0, x1 = ds["vessel_x"].sel(vessel=vessel).values
    eps = 1e-9
    wx0, wx1 = walls[:, [0, 2]].min(1), walls[:, [0, 2]].max(1)
    overlap = np.minimum(wx1, x1) - np.maximum(wx0, x0)
    vertical = wx1 - wx0 <= eps
    wall_in = (overlap > eps) | (vertical & (overlap >= -eps))
    horiz = np.isclose(walls[:, 1], walls[:, 3])
    floors = wall_in & horiz
    floor_y = walls[floors, 1].min() if floors.any() else walls[:, [1, 3]].min()
    inside = (pos[:, 0] >= x0) & (pos[:, 0] < x1)
    return dict(x_range=(x0, x1), width=x1 - x0, floor_y=floor_y, wall_in=wall_in, horizontal=horiz, inside=inside)


def level_of(ds, vessel=None):
    """Free-surface level [cm] of a vessel (None: the whole scene) of a run Dataset."""
    return theory.free_surface_level(ds["pos"].values, float(ds.attrs["spacing"]), vessel_view(ds, vessel)["x_range"])


def load_errors(ds, vessel=None):
    """Level and wall-load error measures of a vessel (see module docstring)."""
    return contact_loads(ds, vessel)[0]


def contact_loads(ds, vessel=None):
    """Error measures and per-contact loads of a vessel.

    Returns (load_errors dict, (wall, point, computed, theory)): wall (C,) the
    contact's wall index, -1 for contacts of other vessels' particles (a
    dividing wall has two sides); point (C, 2) cm; computed (C,) N, |R_b|;
    theory (C,) N from theory.contact_theory, NaN where not this vessel's.
    """
    v = vessel_view(ds, vessel)
    pos = ds["pos"].values
    a = float(ds.attrs["spacing"])
    weight = float(ds["weight"].values[v["inside"]].sum())
    level = theory.free_surface_level(pos, a, v["x_range"])
    h = level - v["floor_y"]
    gamma = theory.specific_weight(weight, v["width"], level, v["floor_y"])
    walls = ds["wall_segment"].values
    # contacts of this vessel's liquid only (a dividing wall has two sides)
    cw = np.where(contact_in_vessel(ds, v["x_range"]), ds["contact_wall"].values, -1)
    cp = ds["contact_point"].values
    mag = np.hypot(*ds["contact_force"].values.T)
    th = theory.contact_theory(walls, cw, cp, gamma, level, v["wall_in"])
    names = list(ds["wall"].values)
    out = dict(level=level, depth=h, level_max=float(pos[v["inside"], 1].max()) if v["inside"].any() else np.nan,
               weight=weight, gamma=gamma)
    side_err, side_h_err, implied = [], [], []
    for w, name in enumerate(names):
        if not v["wall_in"][w]:
            continue
        on = cw == w
        total = float(mag[on].sum())
        th_total = theory.wall_total(walls[w], gamma, level)
        out[f"load_{name}"] = total
        out[f"theory_{name}"] = th_total
        if v["horizontal"][w] and np.isclose(walls[w, 1], v["floor_y"]):
            out["floor_err"] = (total - th_total) / th_total
        elif not v["horizontal"][w] and th_total > 0:
            side_err.append((total - th_total) / th_total)
            side_h_err.append(theory.resultant_height(cp[on, 1], mag[on]) - v["floor_y"] - h / 3)
            implied.append(theory.implied_level(total, weight, v["width"]) + v["floor_y"])
    out["side_err"] = float(np.mean(side_err)) if side_err else np.nan
    out["side_height_err"] = float(np.mean(side_h_err)) if side_h_err else np.nan
    out["level_implied"] = float(np.mean(implied)) if implied else np.nan
    wet = np.isfinite(th)
    c = (mag[wet] - th[wet]) / (gamma * h * panel_length(ds))
    out["contact_rms"] = float(np.sqrt(np.mean(c**2))) if len(c) else np.nan
    out["contact_max"] = float(np.abs(c).max()) if len(c) else np.nan
    return out, (cw, cp, mag, th)


def contact_in_vessel(ds, x_range):
    """(C,) bool: the contact loads liquid of the vessel [xmin, xmax).

    With a ``contact_particle`` variable (point-particle methods) the contact
    belongs to its particle's vessel; otherwise (wall panels) to the vessel on
    the liquid side (left) of its wall, a hair off the contact point.
    """
    if "contact_particle" in ds:
        x = ds["pos"].values[ds["contact_particle"].values, 0]
    else:
        seg = ds["wall_segment"].values[ds["contact_wall"].values]
        e = seg[:, 2:] - seg[:, :2]
        left_nx = -e[:, 1] / np.hypot(e[:, 0], e[:, 1])
        x = ds["contact_point"].values[:, 0] + 1e-6 * left_nx
    return (x >= x_range[0]) & (x < x_range[1])


def panel_length(ds):
    """Wall length [cm] one contact stands for: the panel length of continuum methods,
    the particle spacing a of point-particle methods (the unit of per-contact errors)."""
    return float(ds.attrs.get("panel_length", ds.attrs["spacing"]))


def surface_measures(ds, vessel=None):
    """Flatness of the free surface of a vessel: slope_deg (least-squares line through the
    top particle of each strip of width a), surface_range_cm (max - min of those tops).
    A liquid at rest has both about 0; a heap does not."""
    v = vessel_view(ds, vessel)
    x, top = theory.surface_profile(ds["pos"].values, float(ds.attrs["spacing"]), v["x_range"])
    slope, rng = theory.surface_slope(x, top)
    return dict(slope_deg=slope, surface_range_cm=rng)


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
    return dict(max_wall_reaction_N=float(mag.max()), wall_gap_reduction=float(1.0 - gap.min() / ds.attrs["wall_l_u"]))


def pairs(pos, cutoff):
    """(i, j) int arrays of the particle pairs closer than cutoff [cm] (shared cell list)."""
    box = np.array([pos[:, 0].min(), pos[:, 1].min(), pos[:, 0].max() + 1e-9, pos[:, 1].max() + 1e-9])
    pi, pj, m = NB.build_pairs(pos, box, cutoff)
    return pi[:m], pj[:m]


def stress_ratio(ds, vessel=None):
    """Horizontal-to-vertical stress ratio K = sigma_xx / sigma_yy of the lattice.

    Virial sum over particle pairs whose midpoint lies in the interior of the
    vessel (middle 60 % of the width, 10-60 % of the liquid height), away from
    walls and surface.  A fluid has K = 1; the hydrostatic side-wall loads
    scale with K, so 1 - K is the side-wall deficit a solid-like lattice shows.
    Point-particle (ISA) runs only: NaN for methods without the pair law.
    """
    if "pair_l_u" not in ds.attrs:
        return float("nan")
    v = vessel_view(ds, vessel)
    pos = ds["pos"].values
    a = ds.attrs
    (x0, x1), y0 = v["x_range"], v["floor_y"]
    h = theory.free_surface_level(pos, float(a["spacing"]), v["x_range"]) - y0
    pi, pj = pairs(pos, float(a["pair_l_u"]))
    d = pos[pi] - pos[pj]
    mid = 0.5 * (pos[pi] + pos[pj])
    sel = ((mid[:, 0] > x0 + 0.2 * (x1 - x0)) & (mid[:, 0] < x1 - 0.2 * (x1 - x0))
           & (mid[:, 1] > y0 + 0.1 * h) & (mid[:, 1] < y0 + 0.6 * h))
    dist = np.hypot(d[sel, 0], d[sel, 1])
    force = float(a["pair_r_u"]) * (1 - dist / float(a["pair_l_u"]))  # repulsive magnitude, N
    sxx = np.sum(force * d[sel, 0] ** 2 / dist)
    syy = np.sum(force * d[sel, 1] ** 2 / dist)
    return float(sxx / syy) if syy > 0 else float("nan")


def run_row(ds, vessel=None):
    """One metrics-table row (dict) of a run Dataset of any method (NaN where a measure does not apply)."""
    row = dict(
        scene=ds.attrs["scene"],
        method=ds.attrs.get("method", "isa"),
        variant=ds.attrs["variant"],
        particles=int(ds.sizes["particle"]),
        du_cm=float(ds.attrs.get("du", np.nan)),
        spacing_cm=float(ds.attrs["spacing"]),
        f_tol_N=float(ds.attrs.get("f_tol", np.nan)),
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
    row.update(load_errors(ds, vessel))
    row.update(surface_measures(ds, vessel))
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
        lam, floor = theory.step_floor(ds["pos"].values, ds["wall_segment"].values, a["wall_l_u"], a["wall_r_u"],
                                       a["pair_l_u"], a["pair_r_u"], a["du"])
        out.update(lambda_max=lam, stability_floor_N=floor)
    if "hist_fmax_lo" in ds:
        out.update(band_lo_N=float(ds["hist_fmax_lo"].values[-10:].min()),
                   band_hi_N=float(ds["hist_fmax_hi"].values[-10:].max()))
    return out


def flow_measures(ds):
    """Flow diagnostics of a run with vessels (first = source, last = receiver).

    particles_<vessel>: final count per vessel; particles_left: in the first
    vessel; sum_fx_N: horizontal resultant of all wall reactions (the paper's
    sign of non-equilibrium); mass_conserved: every recorded sample accounts
    for every particle in some vessel.
    """
    names = [str(n) for n in ds["vessel"].values]
    out = {}
    for name in names:
        x0, x1 = ds["vessel_x"].sel(vessel=name).values
        x = ds["pos"].values[:, 0]
        out[f"particles_{name}"] = int(np.count_nonzero((x >= x0) & (x < x1)))
    out["particles_left"] = out[f"particles_{names[0]}"]
    x0, x1 = ds["vessel_x"].sel(vessel=names[0]).values
    out["first_width_cm"] = float(x1 - x0)
    out["sum_fx_N"] = float(ds["wall_resultant"].sel(xy="x").sum())
    if "hist_vessel_count" in ds:
        out["mass_conserved"] = bool((ds["hist_vessel_count"].sum("vessel") == ds.sizes["particle"]).all())
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


# --- single-vessel error measures of the error-vs-run-time study --------------


def hydrostatic_errors(ds, paper_level=None, vessel=None):
    """Error measures of a single-vessel equilibrium against the paper and hydrostatics.

    Keys (units in the names; relative errors are fractions):
    - level_cm: free-surface level (theory.free_surface_level);
    - level_err_paper_cm: level - paper_level, the level the paper reports for
      this configuration (NaN when it reports none);
    - level_err_hydro_cm: level - level_implied, where level_implied = 2 B F_side / W
      is the level a hydrostatic liquid of the same weight W needs to load the
      side walls (width B) as computed: zero when level and side loads agree;
    - wall_err_<wall>: (computed total - theory) / theory of every wall the
      liquid wets (theory.wall_total); wall_err_max: the largest |wall_err_*|;
    - floor_err, side_err: as load_errors (floor; mean over the side walls);
    - contact_rms, contact_max: RMS and largest per-contact error (computed -
      theory) / (gamma h a) over the wetted contacts (units of one floor-contact
      load; a = metrics.panel_length);
    - side_height_err_cm: height of the side-wall resultant minus h / 3;
    - residual: the solver's own final convergence measure (ISA: max|F|, N).
    """
    e = load_errors(ds, vessel)
    v = vessel_view(ds, vessel)
    out = dict(level_cm=e["level"],
               level_err_paper_cm=e["level"] - paper_level if paper_level is not None else np.nan,
               level_err_hydro_cm=e["level"] - e["level_implied"])
    errs = []
    for w, name in enumerate(str(n) for n in ds["wall"].values):
        th = e.get(f"theory_{name}")
        if v["wall_in"][w] and th:
            out[f"wall_err_{name}"] = (e[f"load_{name}"] - th) / th
            errs.append(abs(out[f"wall_err_{name}"]))
    out["wall_err_max"] = max(errs) if errs else np.nan
    out["floor_err"] = e.get("floor_err", np.nan)
    out["side_err"] = e["side_err"]
    out["contact_rms"] = e["contact_rms"]
    out["contact_max"] = e["contact_max"]
    out["side_height_err_cm"] = e["side_height_err"]
    out["residual"] = float(ds["residual"])
    return out


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
    out["wall_use"] = float(mag.max() / a["wall_r_u"]) if len(mag) else 0.0
    l_u = float(a["pair_l_u"])
    pi, pj = pairs(pos, l_u)
    if len(pi):
        d = np.hypot(*(pos[pi] - pos[pj]).T)
        out["min_pair_cm"] = float(d.min())
        out["pair_use"] = float(1.0 - d.min() / l_u)
    else:
        out["pair_use"] = 0.0
    return out
