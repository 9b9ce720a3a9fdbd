"""Error measures of a run file of any method, defined once here (units cm, N).

**Free surface.**  A particle method's free surface is where its own
discretisation puts it: the mean over vertical strips (one spacing wide) of
the top particle centre, plus half the vertical pitch of its particle layers
(``layer_pitch``: dy of a square lattice, l0 of MPS, a / 2 of ISA's rhombic
lattice).  A lattice filling [floor, floor + h] with layers of pitch d has its
top centres at h - d / 2, so this surface is exactly h (tests/test_metrics.py).
It is the one convention of the project: every claims row, figure, table and
the methods comparison read a free surface or level this way.
:func:`level_of` is the top-centre mean alone, the building block of the
surface and one value of the claims input ``level_definition`` (the reading
the ISA pair stiffness was calibrated on), never a second convention.

**Two theories of every wall load** (:func:`load_errors`):
- ``reference="tank"``: the tank's liquid (run-file attributes ``tank_*``):
  rho g = W / A fixed by the tank file (A: the first vessel's polygon below its
  depth, B h in a rectangle) and the free surface at rest where the tank's
  liquid ends (theory.rest_level; the single vessel: h = 72.5 cm);
- ``reference="own"``: the method's own liquid: the weight its particles hold
  in the vessel and the depth of its own free surface, gamma = W_v / A_v, A_v the
  vessel's polygon below that surface (B h_v in a rectangular vessel);
- ``reference="level"``: as "own" with the top-centre level as the surface
  (a reading kept for sensitivity only; no table or figure uses it).
Errors: ``floor_err`` (computed floor total - theory) / theory; ``side_err``
(computed - theory) / theory of the wetted side walls' loads together; ``contact_rms`` RMS
over wetted contacts of (computed - theory) / (gamma h a) (units of one floor
contact load, a = panel_length); ``side_height_err`` height of the side
resultant minus h / 3 [cm].

**At rest and on the walls**: the numbers every run driven by isaflow.driver holds as variables with units
(time to rest, residual rms speed over sqrt(g h), surface drift, wall crossings, each wall's load over the
rest window, ISA's max|F| and rms|F|) are defined once in isaflow.at_rest (at_rest.AT_REST): the runs write them,
so their definition is in every run's code, and a change to a measure here reruns no run.
:func:`at_rest_row` reads them as the comparison table's columns.
"""

import numpy as np

from . import at_rest, theory
from . import tank as T
from .core import neighbours as NB, fixed_order as FO


def vessel_view(ds, vessel=None):
    """Walls, contacts and particles of one vessel of a run Dataset.

    vessel: name in ds.vessel, or None for the whole scene.  A wall belongs to
    the vessel when its x-extent touches the vessel's [xmin, xmax]; the floor
    is the lowest horizontal wall among them (none: the lowest wall point, a V's
    vertex).  Returns dict with x_range (cm), width B (cm), floor_y (cm), wall_in
    (W,) and horizontal (W,) bool masks, inside (N,) bool mask of the particles in
    the vessel, polygon [(x, y)] cm (tank.vessel_polygon: the theory's liquid fills it).
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
    # no horizontal wall (a V): the lowest point of the vessel's walls (tank.vessel_floor)
    floor_y = walls[floors, 1].min() if floors.any() else T.vessel_floor(walls.tolist(), x0, x1)
    floor_y = walls[:, [1, 3]].min() if floor_y is None else floor_y
    inside = (pos[:, 0] >= x0) & (pos[:, 0] < x1)
    return dict(x_range=(x0, x1), width=x1 - x0, floor_y=floor_y, wall_in=wall_in, horizontal=horiz, inside=inside,
                polygon=T.vessel_polygon(walls.tolist(), (float(x0), float(x1))))


def vessels(ds):
    """Names of the run's vessels, first (source) to last (receiver); [None] for a single vessel."""
    return [str(n) for n in ds["vessel"].values] if "vessel" in ds.coords else [None]


def layer_pitch(ds):
    """Vertical pitch [cm] of the run's particle layers (attribute ``layer_pitch``; else the spacing)."""
    p = float(ds.attrs.get("layer_pitch", np.nan))
    return p if np.isfinite(p) else float(ds.attrs["spacing"])


def level_of(ds, vessel=None):
    """Top-centre level [cm] of a vessel (None: the whole scene): the paper's reading."""
    return theory.free_surface_level(ds["pos"].values, float(ds.attrs["spacing"]), vessel_view(ds, vessel)["x_range"])


def surface_of(ds, vessel=None):
    """Free surface [cm] of a vessel: top-centre level + half the layer pitch (module docstring)."""
    return level_of(ds, vessel) + layer_pitch(ds) / 2


def tank_levels(ds):
    """{vessel name (None for a single vessel): free surface [cm] at rest of the tank's liquid}
    (theory.rest_level; a vessel whose floor lies above the common level is empty: its floor)."""
    names = vessels(ds)
    views = [vessel_view(ds, v) for v in names]
    H = theory.rest_level([v["polygon"] for v in views], [v["floor_y"] for v in views],
                          float(ds.attrs["tank_weight"]), float(ds.attrs["tank_rho_g"]))
    return {n: max(H, float(v["floor_y"])) for n, v in zip(names, views)}


def _theory(ds, vessel, reference):
    """(gamma N/cm^2, surface level cm, weight the theory holds N) of one reference (module docstring)."""
    v = vessel_view(ds, vessel)
    if reference == "tank":
        rho_g = float(ds.attrs["tank_rho_g"])
        level = tank_levels(ds)[vessel]
        return rho_g, level, rho_g * theory.liquid_area(v["polygon"], v["floor_y"], level - v["floor_y"])
    weight = float(ds["weight"].values[v["inside"]].sum())
    level = level_of(ds, vessel) if reference == "level" else surface_of(ds, vessel)
    depth = level - v["floor_y"]
    gamma = weight / theory.liquid_area(v["polygon"], v["floor_y"], depth) if depth > 0 else np.nan
    return gamma, level, weight


def load_errors(ds, vessel=None, reference="own"):
    """Level and wall-load errors of a vessel against one theory (module docstring); see contact_loads."""
    return contact_loads(ds, vessel, reference)[0]


def contact_loads(ds, vessel=None, reference="own"):
    """Error measures and per-contact loads of a vessel against one theory.

    Returns (errors dict, (wall, point, computed, theory)): wall (C,) the
    contact's wall index, -1 for contacts of other vessels' liquid (a dividing
    wall has two sides); point (C, 2) cm; computed (C,) N, |R|; theory (C,) N
    from theory.contact_theory, NaN where not this vessel's.
    """
    v = vessel_view(ds, vessel)
    pos = ds["pos"].values
    gamma, level, weight = _theory(ds, vessel, reference)
    h = level - v["floor_y"]
    walls = ds["wall_segment"].values
    cw = np.where(contact_in_vessel(ds, v["x_range"]), ds["contact_wall"].values, -1)
    cp = ds["contact_point"].values
    mag = np.hypot(*ds["contact_force"].values.T)
    th = theory.contact_theory(walls, cw, cp, gamma, level, v["wall_in"])
    out = dict(level=level, depth=h, level_max=float(pos[v["inside"], 1].max()) if v["inside"].any() else np.nan,
               weight=weight, gamma=gamma)
    side_load, side_theory, side_h_err, implied = [], [], [], []
    for w, name in enumerate(str(n) for n in ds["wall"].values):
        if not v["wall_in"][w]:
            continue
        on = cw == w
        total = float(mag[on].sum())
        th_total = theory.wall_total(walls[w], gamma, level)
        out[f"load_{name}"] = total
        out[f"theory_{name}"] = th_total
        if v["horizontal"][w] and np.isclose(walls[w, 1], v["floor_y"]):
            out["floor_err"] = (total - th_total) / th_total if th_total > 0 else np.nan
        elif not v["horizontal"][w] and th_total > 0:
            side_load.append(total)
            side_theory.append(th_total)
            side_h_err.append(theory.resultant_height(cp[on, 1], mag[on]) - v["floor_y"] - h / 3)
            implied.append(theory.implied_level(total, weight, v["width"]) + v["floor_y"])
    # over the wetted side walls together: a dividing wall wetted a few cm deep weighs by its load, not equally
    out["side_err"] = (sum(side_load) - sum(side_theory)) / sum(side_theory) if side_theory else np.nan
    out["side_height_err"] = float(np.mean(side_h_err)) if side_h_err else np.nan
    out["level_implied"] = float(np.mean(implied)) if implied else np.nan
    wet = np.isfinite(th)
    c = (mag[wet] - th[wet]) / (gamma * h * panel_length(ds)) if h > 0 else np.array([])
    out["contact_rms"] = float(np.sqrt(np.mean(c**2))) if len(c) else np.nan
    out["contact_max"] = float(np.abs(c).max()) if len(c) else np.nan
    return out, (cw, cp, mag, th)


def contact_in_vessel(ds, x_range):
    """(C,) bool: the contact loads liquid of the vessel [xmin, xmax).

    With a ``contact_particle`` variable (point-particle methods) the contact
    belongs to its particle's vessel; otherwise (wall panels) to the vessel on
    the side of its wall the load comes from, a hair off the contact point: the
    liquid side (left) of the wall, or its back (right) where ``contact_side``
    is 1 (the back face of a thin wall wetted on both faces).
    """
    if "contact_particle" in ds:
        x = ds["pos"].values[ds["contact_particle"].values, 0]
    else:
        seg = ds["wall_segment"].values[ds["contact_wall"].values]
        e = seg[:, 2:] - seg[:, :2]
        left_nx = -e[:, 1] / np.hypot(e[:, 0], e[:, 1])
        side = ds["contact_side"].values if "contact_side" in ds else np.zeros(len(seg))
        x = ds["contact_point"].values[:, 0] + 1e-6 * left_nx * (1 - 2 * side)
    return (x >= x_range[0]) & (x < x_range[1])


def normal_loads(ds, vessel=None):
    """{wall name: normal load [N]} of the walls of a vessel (None: the whole scene): the contacts of the vessel's
    liquid (contact_loads) resolved on each wall's normal into that liquid (the left normal; a thin wall's back
    face, contact_side 1, the right one), the load the hydrostatic theory gives (theory.wall_total); the contacts'
    magnitudes (load_errors' load_<wall>) add any tangential part a discrete wall carries."""
    v = vessel_view(ds, vessel)
    walls = ds["wall_segment"].values
    cw = np.where(contact_in_vessel(ds, v["x_range"]), ds["contact_wall"].values, -1)
    force = ds["contact_force"].values
    side = ds["contact_side"].values if "contact_side" in ds else np.zeros(len(cw))
    out = {}
    for w, name in enumerate(str(n) for n in ds["wall"].values):
        if not v["wall_in"][w]:
            continue
        e = walls[w, 2:] - walls[w, :2]
        n = np.array([-e[1], e[0]]) / np.hypot(e[0], e[1])
        on = cw == w
        out[name] = float(np.sum(FO.dot2(force[on], n) * (1 - 2 * side[on])))
    return out


def weight_on_walls(ds):
    """The weight the walls carry: walls_vertical_N, the vertical resultant [N] of every wall contact on the liquid,
    and walls_weight_err = walls_vertical_N / the weight the run holds - 1 (0 for a liquid at rest: the walls carry
    its weight, however they slope)."""
    fy = float(np.asarray(ds["contact_force"].values, float)[:, 1].sum())
    held = float(ds["weight"].values.sum())
    return dict(walls_vertical_N=fy, walls_weight_err=fy / held - 1 if held > 0 else np.nan)


def panel_length(ds):
    """Wall length [cm] one contact stands for: the panel length of continuum methods,
    the particle spacing a of point-particle methods (the unit of per-contact errors)."""
    return float(ds.attrs.get("panel_length", ds.attrs["spacing"]))


def surface_measures(ds, vessel=None):
    """Flatness of the free surface of a vessel: slope_deg (least-squares line through the
    top particle of each strip one spacing wide), surface_range_cm (max - min of those tops).
    A liquid at rest has both about 0; a heap does not."""
    v = vessel_view(ds, vessel)
    x, top = theory.surface_profile(ds["pos"].values, float(ds.attrs["spacing"]), v["x_range"])
    slope, rng = theory.surface_slope(x, top)
    return dict(slope_deg=slope, surface_range_cm=rng)


def pairs(pos, cutoff):
    """(i, j) int arrays of the particle pairs closer than cutoff [cm] (shared cell list)."""
    box = np.array([pos[:, 0].min(), pos[:, 1].min(), pos[:, 0].max() + 1e-9, pos[:, 1].max() + 1e-9])
    pi, pj, m = NB.build_pairs(pos, box, cutoff)
    return pi[:m], pj[:m]


def flow_measures(ds):
    """Flow diagnostics of a run with vessels (first = source, last = receiver).

    particles_<vessel>: final count per vessel; particles_left: in the first
    vessel; sum_fx_N: horizontal resultant of all wall reactions (the paper's
    sign of non-equilibrium); mass_conserved: every recorded sample accounts
    for every particle in some vessel.
    """
    names = vessels(ds)
    out = {}
    x = ds["pos"].values[:, 0]
    for name in names:
        x0, x1 = ds["vessel_x"].sel(vessel=name).values
        out[f"particles_{name}"] = int(np.count_nonzero((x >= x0) & (x < x1)))
    out["particles_left"] = out[f"particles_{names[0]}"]
    x0, x1 = ds["vessel_x"].sel(vessel=names[0]).values
    out["first_width_cm"] = float(x1 - x0)
    out["sum_fx_N"] = float(ds["wall_resultant"].sel(xy="x").sum())
    if "sample_vessel_count" in ds:
        out["mass_conserved"] = bool((ds["sample_vessel_count"].sum("vessel") == ds.sizes["particle"]).all())
    return out


def hydrostatic_errors(ds, paper_level=None, vessel=None, reference="own"):
    """Error measures of an equilibrium against a paper's level and hydrostatics.

    Keys (units in the names; relative errors are fractions): level_cm (the
    reference's surface); level_err_paper_cm: level - paper_level (NaN when the
    paper reports none); level_err_hydro_cm: level - level_implied, the level a
    hydrostatic liquid of the same weight needs to load the side walls as
    computed (2 B F_side / W); wall_err_<wall> and wall_err_max; floor_err,
    side_err, contact_rms, contact_max, side_height_err_cm as load_errors;
    residual: the solver's final convergence measure.
    """
    e = load_errors(ds, vessel, reference)
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
    for k in ("floor_err", "side_err", "contact_rms", "contact_max"):
        out[k] = e.get(k, np.nan)
    out["side_height_err_cm"] = e["side_height_err"]
    out["residual"] = float(ds["residual"])
    return out


def comparison_row(ds):
    """The methods' comparison row of a run file: identity, outcome, its at-rest and wall numbers
    (at_rest_row: time to rest, residual speed, surface drift, wall crossings, each wall's load mean and
    standard deviation over the rest window, ISA's max|F| and rms|F|), and for every vessel its surface
    (own and the tank's at rest), weight held and particles, slope and range, and the wall-load
    errors against the tank's theory and against the method's own depth.  Columns per vessel are
    prefixed with the vessel's name (single vessel: no prefix)."""
    a = ds.attrs
    row = dict(method=a["method"], variant=a["variant"], run=a.get("run_id", ""), tank=a.get("tank", a.get("scene")),
               resolution=a.get("resolution", ""), particles=int(ds.sizes["particle"]),
               spacing_cm=float(a["spacing"]), layer_pitch_cm=layer_pitch(ds), status=a["status"],
               steps=int(ds["steps"]), sim_time_s=float(ds["sim_time"]) if "sim_time" in ds else np.nan,
               residual=float(ds["residual"]), residual_name=a.get("residual_name", ""),
               wall_time_s=float(ds["wall_time"]), threads=int(a.get("threads", 1) or 1),
               held_weight_N=float(ds["weight"].values.sum()), tank_weight_N=float(a["tank_weight"]),
               tank_depth_cm=float(a["tank_depth"]), initial_depth_cm=float(a.get("initial_depth", np.nan)),
               tank_difference=str(a.get("tank_difference", "")),
               final_energy_ratio=float(a.get("final_energy_ratio", np.nan)))
    row.update({"time_to_rest_s": np.nan, **at_rest_row(ds)})  # the AT_REST numbers (time to rest first)
    finite = np.isfinite(ds["pos"].values).all()
    names = vessels(ds)
    levels = tank_levels(ds)
    for name in names:
        p = f"{name}_" if name else ""
        v = vessel_view(ds, name)
        row[f"{p}particles"] = int(v["inside"].sum())
        row[f"{p}weight_N"] = float(ds["weight"].values[v["inside"]].sum())
        row[f"{p}floor_y_cm"] = float(v["floor_y"])
        row[f"{p}tank_surface_cm"] = levels[name]
        if not finite or not v["inside"].any():
            continue
        row[f"{p}surface_cm"] = surface_of(ds, name)
        row[f"{p}surface_err_tank_cm"] = row[f"{p}surface_cm"] - levels[name]
        row.update({f"{p}{k}": val for k, val in surface_measures(ds, name).items()})
        for ref in ("tank", "own"):
            e = load_errors(ds, name, ref)
            for k in ("floor_err", "side_err", "contact_rms", "side_height_err"):
                row[f"{p}{k}_{ref}"] = e.get(k, np.nan)
            row[f"{p}side_load_N"] = float(np.mean([e[f"load_{n}"] for n in _side_walls(ds, name)] or [np.nan]))
            row[f"{p}side_theory_{ref}_N"] = float(np.mean([e[f"theory_{n}"] for n in _side_walls(ds, name)] or [np.nan]))
    if len(names) > 1:
        row["left_fraction"] = row[f"{names[0]}_weight_N"] / row["held_weight_N"]
    return row


def _side_walls(ds, vessel):
    """Names of the wetted side walls of a vessel (vertical walls of the vessel with theory > 0)."""
    v = vessel_view(ds, vessel)
    walls = ds["wall_segment"].values
    gamma, level, _ = _theory(ds, vessel, "tank")
    return [str(n) for w, n in enumerate(ds["wall"].values)
            if v["wall_in"][w] and not v["horizontal"][w] and theory.wall_total(walls[w], gamma, level) > 0]


def run_row(ds, vessel=None):
    """One row of any run file: comparison_row plus, for the vessel judged (the receiving one of a flow),
    the loads against its own liquid on the one surface (load_errors 'own'), flow measures and surface flatness."""
    row = comparison_row(ds)
    if vessel is None and "vessel" in ds.coords:
        vessel = vessels(ds)[-1]
    if "vessel" in ds.coords:
        row.update(flow_measures(ds))
    if np.isfinite(ds["pos"].values).all():
        row.update(load_errors(ds, vessel, "own"))
        row.update(surface_measures(ds, vessel))
    return row


# --- the at-rest and wall numbers of a run file, as table columns (defined in isaflow.rest) ------------------------

def at_rest_row(ds):
    """The at-rest and wall numbers of a run file (at_rest.AT_REST) as table columns (units in the names; one column
    per wall and vessel): what the comparison table shows.  Absent numbers (a run no driver made) are left out."""
    row = {}
    units = {"s": "_s", "cm": "_cm", "N": "_N", "1": ""}
    for name, (dims, u, _) in at_rest.AT_REST.items():
        if name not in ds:
            continue
        v = ds[name]
        if not dims:
            row[f"{name}{units[u]}"] = float(v) if name != "wall_crossings" else int(v)
            continue
        # per wall: '<wall>_<name>'; per vessel: '<vessel>_<name>', no prefix for a tank of one unnamed vessel
        prefixes = [f"{n}_" for n in ds[dims[0]].values] if dims[0] in ds.coords else [""] * v.size
        for prefix, val in zip(prefixes, np.atleast_1d(v.values)):
            row[f"{prefix}{name}{units[u]}"] = float(val)
    return row
