"""The section-4 cases of marko2017 as solid runs: bar (tension, compression), shear, Hertz.

Each ``run_<case>(cfg, variant)`` builds the particles from the settings
(settings.checked_values), relaxes them to rest and returns a contract.Result whose
history holds the case's measured numbers (SI-free: cm, N, s; stresses N/cm^2).
"""

import numpy as np

from isaflow.core.units import PA

from . import lattice as L
from . import solve as S
from .settings import claim_run_ids, material_units  # noqa: F401 (claim_run_ids: pure Python, read while the workflow parses)

UM, MM = 1e-4, 0.1  # cm


def _material(cfg):
    return S.Material(*material_units(cfg["material"]))


def _budget(cfg, variant):
    s = cfg["solver"]
    return s["max_steps"] if variant == "hooke" else s["max_steps_mechanism"]


def _bar(cfg, variant):
    """The 4.1 bar of cfg['bar'] (particles nx x ny x nz, spacing dx_mm, centred in x and z, y from 0) as a State of
    variant: (block, state, lattice row j of each particle along y, mask (N, 3) of the components its grips hold:
    the end layers' y, and x and z too with clamped grips, else one end-layer centre particle's)."""
    c = cfg["bar"]
    nx, ny, nz = c["particles"]
    dx = c["dx_mm"] * MM
    b = L.block(nx, ny, nz, dx, (-(nx - 1) / 2 * dx, 0.0, -(nz - 1) / 2 * dx))
    st = S.State(b, _material(cfg), variant, np.ones((b.n, 3)))
    j = b.index[:, 1]
    mask = np.zeros((b.n, 3), bool)
    ends = (j == 0) | (j == ny - 1)
    if c["grips"] == "clamped":
        mask[ends] = True
    else:
        mask[ends, 1] = True
        mask[(j == 0) & (b.index[:, 0] == nx // 2) & (b.index[:, 2] == nz // 2)] = True
    return b, st, j, mask


def run_bar(cfg, variant, sign=+1):
    """4.1: the 5 x 11 x 5 bar pulled (sign +1) or pushed (-1) by pull_um along y.

    Measures: stress sigma_yy at the centre particle and its largest magnitude
    in the middle layer, the per-side width change in x and z at mid-length."""
    c = cfg["bar"]
    nx, ny, nz = c["particles"]
    b, st, j, mask = _bar(cfg, variant)
    disp = np.zeros((b.n, 3))
    disp[j == ny - 1, 1] = sign * c["pull_um"] * UM
    S.prescribe(st, mask, disp)
    status, msg, resid, _ = S.relax(st, cfg["solver"]["tol"], _budget(cfg, variant), label=f"bar {variant}")
    mid = j == ny // 2
    i, k = b.index[:, 0], b.index[:, 2]
    centre = np.flatnonzero(mid & (i == nx // 2) & (k == nz // 2))[0]
    u = st.pos - b.ref
    side_x = 0.5 * (u[mid & (i == nx - 1), 0].mean() - u[mid & (i == 0), 0].mean())
    side_z = 0.5 * (u[mid & (k == nz - 1), 2].mean() - u[mid & (k == 0), 2].mean())
    hist = {
        "sigma_centre": (("record",), [st.sig[centre, 1]], "N cm-2", "sigma_yy of the centre particle"),
        "sigma_peak": (("record",), [sign * np.abs(st.sig[mid, 1]).max()], "N cm-2",
                       "largest |sigma_yy| in the mid-length layer, with the load's sign"),
        "width_change_x": (("record",), [side_x], "cm", "mid-length change of the x half-width (per side)"),
        "width_change_z": (("record",), [side_z], "cm", "mid-length change of the z half-width (per side)"),
        "reaction": (("record",), [st.frc[j == ny - 1, 1].sum()], "N", "y force on the moved end layer"),
    }
    case = "tension" if sign > 0 else "compression"
    return S.result(st, f"bar_{case}", status, msg, resid, hist, {"pull_cm": sign * c["pull_um"] * UM,
                                                                  "grips": c["grips"]})


def run_shear(cfg, variant):
    """4.2: the 11 x 3 x 3 block between a held layer below and a layer moved by deflection_um in x above.

    Measures: the shear traction tau_yx at the centre particle and its largest value."""
    c = cfg["shear"]
    nx, ny, nz = c["particles"]
    g = c["grip_layers"]
    dx = cfg["bar"]["dx_mm"] * MM
    b = L.block(nx, ny + 2 * g, nz, dx)
    st = S.State(b, _material(cfg), variant, np.ones((b.n, 3)))
    j = b.index[:, 1]
    top = j >= ny + g
    mask = np.zeros((b.n, 3), bool)
    mask[(j < g) | top] = True
    disp = np.zeros((b.n, 3))
    disp[top, 0] = c["deflection_um"] * UM
    S.prescribe(st, mask, disp)
    status, msg, resid, _ = S.relax(st, cfg["solver"]["tol"], _budget(cfg, variant), label=f"shear {variant}")
    i, k = b.index[:, 0], b.index[:, 2]
    free = (j >= g) & (j < ny + g)
    centre = np.flatnonzero((i == nx // 2) & (j == (ny + 2 * g) // 2) & (k == nz // 2))[0]
    hist = {
        "tau_centre": (("record",), [st.sig[centre, 3]], "N cm-2", "shear traction tau_yx of the centre particle"),
        "tau_peak": (("record",), [st.sig[free, 3].max()], "N cm-2", "largest tau_yx of the free layers"),
        "height": (("record",), [(ny + 2 * g - 1) * dx], "cm", "distance between held and moved layers"),
    }
    return S.result(st, "shear", status, msg, resid, hist, {"deflection_cm": c["deflection_um"] * UM,
                                                           "grip_layers": g})


def hertz_state(cfg, variant):
    """The 51 x 10 plate (bottom row held, plane strain, unlinked pairs push) and the rigid disk above it."""
    c = cfg["hertz"]
    nx, ny = c["plate"]
    dx = c["dx_um"] * UM
    b = L.block(nx, ny, 1, dx, (-(nx - 1) / 2 * dx, -(ny - 1) * dx, 0.0))
    st = S.State(b, _material(cfg), variant, np.ones((b.n, 3)), push=1)
    mask = np.zeros((b.n, 3), bool)
    mask[b.index[:, 1] == 0] = True
    mask[:, 2] = True
    S.prescribe(st, mask, np.zeros(3))
    return st


def set_depth(st, R, depth):
    """Rigid disk of radius R [cm] touching the plate's top face, pressed depth [cm] into it."""
    st.disk[:] = [0.0, 0.5 * st.block.dx + R - depth, R, 1.0]


def scale_radius_mm(cfg, case):
    """The disk radius [mm] of a case 'hertz_R<r>mm' or 'hertz_R<r>m', one of hertz.scale_radii_mm
    (ValueError otherwise: a run names its radius, the settings give its source)."""
    tag = case[len("hertz_R"):]
    r = float(tag[:-2]) if tag.endswith("mm") else 1e3 * float(tag[:-1]) if tag.endswith("m") else np.nan
    radii = cfg["hertz"]["scale_radii_mm"]
    if not any(np.isclose(r, x, rtol=1e-9) for x in radii):
        raise ValueError(f"case '{case}': radius {r:g} mm is not one of hertz.scale_radii_mm {radii}")
    return r


def run_hertz(cfg, variant, radius_mm=None, case="hertz"):
    """4.3: the disk pressed in increments; per increment the load and the peak contact pressure.

    Load = the plate's force on the disk per unit thickness [N/cm]; peak pressure
    = largest contact force on one top particle / dx [N/cm^2].  radius_mm: the disk radius
    (default hertz.radius_mm; the scale cases of section 4.3 keep plate and depths)."""
    c = cfg["hertz"]
    st = hertz_state(cfg, variant)
    R, dx = (c["radius_mm"] if radius_mm is None else radius_mm) * MM, st.block.dx
    rows = {k: [] for k in ("depth", "load", "pmax", "n_contact", "steps", "status")}
    status, msg, resid = "converged", "", 0.0
    for d in c["depths_um"]:
        set_depth(st, R, d * UM)
        s0 = st.steps
        status, msg, resid, g = S.relax(st, cfg["solver"]["tol"], _budget(cfg, variant), label=f"hertz {variant} {d} um")
        for key, val in zip(rows, (d * UM, g[1], st.pres.max() / dx, int((st.pres > 0).sum()), st.steps - s0,
                                   status)):
            rows[key].append(val)
        if status in ("escaped", "nonfinite"):
            break
    hist = {
        "depth": (("record",), rows["depth"], "cm", "disk indentation delta"),
        "load": (("record",), rows["load"], "N cm-1", "force of the plate on the disk per unit thickness"),
        "pmax": (("record",), rows["pmax"], "N cm-2", "largest contact force on a top particle / dx"),
        "n_contact": (("record",), rows["n_contact"], "1", "top particles in contact"),
        "increment_steps": (("record",), rows["steps"], "1", "steps to rest in this increment"),
        "increment_converged": (("record",), [int(s == "converged") for s in rows["status"]], "1",
                                "1 if the increment came to rest"),
    }
    if status == "converged" and len(rows["depth"]) < len(c["depths_um"]):
        status = "step_limit"
    return S.result(st, case, status, msg, resid, hist, {"radius_cm": R})


def run_hertz_eq27(cfg, variant, cap=True):
    """4.3 stepped as the paper says, undamped (section 3 has no dissipation): every increment runs
    hertz.dt_check_steps steps with dt from eq. 27 (V_max the largest particle speed at the step's
    start), capped by eq. 26 (cap) or not (V_max floored at hertz.eq27_vfloor_m_s).  Per increment: the
    load and peak pressure at its end, the largest move of a particle in one step over dx, the step
    range; samples of the kinetic energy every hertz.eq27_record_every steps."""
    c = cfg["hertz"]
    st = hertz_state(cfg, variant)
    st.damp = 0
    R, dx = c["radius_mm"] * MM, st.block.dx
    vfloor = c["eq27_vfloor_m_s"] * 100.0  # cm/s
    every, n = c["eq27_record_every"], c["dt_check_steps"]
    rows = {k: [] for k in ("depth", "load", "pmax", "move", "dt_min", "dt_max", "status")}
    t, ke = [0.0], [0.0]
    status, msg, resid, overall = "step_limit", "", 0.0, 0.0

    def sample(_):  # every eq27_record_every steps (the stepper's chunk)
        t.append(float(st.clock[1]))
        ke.append(float(st.clock[0]))

    for d in c["depths_um"]:
        set_depth(st, R, d * UM)
        st.clock[6] = 0.0
        st.clock[2], st.clock[3] = np.inf, 0.0
        status, msg, resid, g = S.relax(st, 0.0, n, min_steps=n, chunk=every, cap=cap, vfloor=vfloor,
                                        label=f"hertz eq27 {variant} {d} um", sample=sample)
        overall = max(overall, float(st.clock[6])) if np.isfinite(st.clock[6]) else np.inf
        for key, val in zip(rows, (d * UM, g[1], st.pres.max() / dx, float(st.clock[6]), float(st.clock[2]),
                                   float(st.clock[3]), status)):
            rows[key].append(val)
        if status in ("escaped", "nonfinite"):
            break
    st.clock[6] = overall
    hist = {
        "depth": (("record",), rows["depth"], "cm", "disk indentation delta"),
        "load": (("record",), rows["load"], "N cm-1", "force of the plate on the disk per unit thickness, end of increment"),
        "pmax": (("record",), rows["pmax"], "N cm-2", "largest contact force on a top particle / dx, end of increment"),
        "increment_max_move_over_dx": (("record",), rows["move"], "1",
                                       "largest move of a free particle in one step of the increment / dx"),
        "increment_dt_min": (("record",), rows["dt_min"], "s", "smallest step of the increment"),
        "increment_dt_max": (("record",), rows["dt_max"], "s", "largest step of the increment"),
        "increment_stable": (("record",), [int(s not in ("escaped", "nonfinite")) for s in rows["status"]], "1",
                             "1 if the increment ended without escape or non-finite value"),
        "time": (("sample",), t, "s", "simulated time"),
        "kinetic_energy_t": (("sample",), ke, "N cm", "kinetic energy (per unit thickness)"),
    }
    if status == "step_limit":
        msg = f"undamped, {n} steps per increment (no rest test): {len(rows['depth'])} increments stepped"
    case = "hertz_eq27" if cap else "hertz_eq27_uncapped"
    return S.result(st, case, status, msg, resid, hist, {"radius_cm": R, "dt_rule": "eqs. 26-27" if cap else
                                                         "eq. 27 alone", "vfloor_cm_s": vfloor, "damped": 0})


def run_bar_long(cfg, variant, strain, dt_frac, case="bar_tension_long"):
    """Sustained tension (claims registry input tension_test_setup; not in the paper): the 4.1 bar held
    at axial strain `strain` between its end layers, started at rest from the uniformly stretched
    (affine) positions plus a random perturbation of bar_long.perturbation_dx dx on the free dofs
    (seed bar_long.seed), run undamped for bar_long.steps steps of dt_frac dx / c.  Records every
    bar_long.record_every steps: the largest distance of a particle from its affine position over dx,
    the smallest linked distance and the smallest distance of any two particles over dx, the kinetic
    energy."""
    c, lg = cfg["bar"], cfg["bar_long"]
    dx = c["dx_mm"] * MM
    b, st, _, mask = _bar(cfg, variant)
    st.damp = 0
    affine = np.zeros((b.n, 3))
    affine[:, 1] = strain * b.ref[:, 1]
    S.prescribe(st, mask, affine)
    rng = np.random.default_rng(lg["seed"])
    kick = lg["perturbation_dx"] * dx * rng.uniform(-1.0, 1.0, (b.n, 3)) * st.free
    st.pos[:] = b.ref + affine + kick
    dt = dt_frac * dx / st.mat.c
    x_aff = b.ref + affine
    iu = np.triu_indices(b.n, 1)

    def measures():
        dev = np.sqrt(((st.pos - x_aff) ** 2).sum(1)).max() / dx
        link = np.sqrt(((st.pos[b.lb] - st.pos[b.la]) ** 2).sum(1)).min() / dx
        d2 = ((st.pos[:, None, :] - st.pos[None, :, :]) ** 2).sum(2)[iu]
        return dev, link, float(np.sqrt(d2.min())) / dx

    t, rec = [0.0], [measures()]
    ke = [0.0]

    def sample(_):  # every bar_long.record_every steps (the stepper's chunk)
        t.append(float(st.clock[1]))
        rec.append(measures())
        ke.append(float(st.clock[0]))

    n = lg["steps"]
    status, msg, resid, _ = S.relax(st, 0.0, n, dt=dt, min_steps=n, chunk=lg["record_every"],
                                    label=f"bar long {variant}", sample=sample)
    if status == "step_limit":
        msg = f"undamped, {n} steps of {dt:.4g} s (no rest test)"
    rec = np.array(rec)
    hist = {
        "time": (("sample",), t, "s", "simulated time"),
        "nonaffine_over_dx_t": (("sample",), rec[:, 0], "1", "largest distance of a particle from its affine position / dx"),
        "min_link_over_dx_t": (("sample",), rec[:, 1], "1", "smallest linked distance / dx"),
        "min_pair_over_dx_t": (("sample",), rec[:, 2], "1", "smallest distance between any two particles / dx"),
        "kinetic_energy_t": (("sample",), ke, "N cm", "kinetic energy"),
        "max_nonaffine_over_dx": (("record",), [float(np.nanmax(rec[:, 0])) if np.isfinite(rec[:, 0]).all()
                                                else np.inf], "1", "largest of nonaffine_over_dx_t"),
    }
    return S.result(st, case, status, msg, resid, hist,
                    {"strain": strain, "dt_over_dx_c": dt_frac, "dt_s": dt, "perturbation_dx": lg["perturbation_dx"],
                     "seed": lg["seed"], "grips": c["grips"], "damped": 0})


def long_bar_case(cfg, case):
    """(strain, dt / (dx / c)) of 'bar_tension_long' (bar_long.strain, bar_long.dt_over_dx_c) or
    'bar_tension_long_e<strain %>_dt<dt / (dx / c)>' (one of bar_long.strain_sweep x bar_long.dt_sweep)."""
    lg = cfg["bar_long"]
    if case == "bar_tension_long":
        return lg["strain"], lg["dt_over_dx_c"]
    tag = case[len("bar_tension_long_"):]
    try:
        e, d = tag.split("_dt")
        strain, frac = float(e.removeprefix("e")) / 100.0, float(d)
    except ValueError:
        raise ValueError(f"case '{case}': expected bar_tension_long_e<strain %>_dt<dt c / dx>") from None
    if not any(np.isclose(strain, x) for x in lg["strain_sweep"]) or not any(np.isclose(frac, x) for x in lg["dt_sweep"]):
        raise ValueError(f"case '{case}': strain {strain:g} or dt {frac:g} dx / c outside bar_long.strain_sweep "
                         f"{lg['strain_sweep']} x bar_long.dt_sweep {lg['dt_sweep']}")
    return strain, frac


def run_hertz_dt(cfg, variant, dt_ns):
    """The paper's fixed step dt_ns [ns]: settle the first increment with the step rule (eqs. 26-27),
    then press the second increment at dt_ns for dt_check_steps steps: stable or not?"""
    c = cfg["hertz"]
    st = hertz_state(cfg, variant)
    R = c["radius_mm"] * MM
    set_depth(st, R, c["depths_um"][0] * UM)
    S.relax(st, cfg["solver"]["tol"], _budget(cfg, variant), label=f"hertz dt {dt_ns} ns, first increment")
    set_depth(st, R, c["depths_um"][1] * UM)
    status, msg, resid, g = S.relax(st, cfg["solver"]["tol"], c["dt_check_steps"], dt=dt_ns * 1e-9,
                                    label=f"hertz dt {dt_ns} ns")
    hist = {"load": (("record",), [g[1]], "N cm-1", "force of the plate on the disk per unit thickness")}
    return S.result(st, f"hertz_dt{dt_ns:g}ns", status, msg, resid, hist,
                   {"dt_fixed_s": dt_ns * 1e-9, "dt_over_rule": dt_ns * 1e-9 / st.dt_max})


def water_sweep(cfg, case):
    """The vessel water's setting a case 'vessel_water_stop_h<h / dx>' or '_a<alpha>' changes (one of
    vessel.water_h_sweep, vessel.water_alpha_sweep; claims input vessel_water), {} for the kept water (ValueError
    for a value the settings do not list)."""
    tag = case.removeprefix("vessel_water_stop").removeprefix("vessel_water_particles").lstrip("_")
    if not tag:
        return {}
    key, sweep = {"h": ("water_h_over_dx", "water_h_sweep"), "a": ("water_alpha", "water_alpha_sweep")}.get(tag[0],
                                                                                                        (None, None))
    value = float(tag[1:]) if key and tag[1:].replace(".", "", 1).isdigit() else np.nan
    if key is None or not any(np.isclose(value, x) for x in cfg["vessel"][sweep]):
        raise ValueError(f"case '{case}': expected vessel_water_stop_h<h / dx> or _a<alpha> of vessel.water_h_sweep "
                         "or vessel.water_alpha_sweep")
    return {key: value}


def to_pa(x):
    """N/cm^2 -> Pa."""
    return np.asarray(x, float) / PA


CASES = {"bar_tension": lambda cfg, v: run_bar(cfg, v, +1), "bar_compression": lambda cfg, v: run_bar(cfg, v, -1),
         "shear": run_shear, "hertz": run_hertz}


def run_case(cfg, case, variant, loads=None):
    """Dispatch: case is a key of CASES, 'hertz_dt<ns>' (the paper's fixed step), 'hertz_eq27' and
    'hertz_eq27_uncapped' (undamped, eq. 27 with and without eq. 26's cap), 'hertz_R<r>mm' / 'hertz_R<r>m'
    (other disk radii), 'bar_tension_long[_e<%>_dt<f>]' (sustained tension), 'vessel' (4.4; variant
    pressure_load or water_particles), 'vessel_water_particles' (4.4 with water, the solid model = the
    variant), 'vessel_water_stop' (the same with the paper's stop-at-the-boundary coupling; '_h<h / dx>', '_a<alpha>':
    another water, water_sweep), 'bar_tension_sliding' / 'bar_compression_sliding' (axial-only grips),
    'hertz_loadsteps' (the other depths) or 'floor_<source>' (elastic floor; loads: the rigid-floor run file of
    variant 'oneway')."""
    if case.startswith(("vessel_water_particles", "vessel_water_stop")):
        from .water import run_water_vessel

        coupling = {"coupling": "stop_at_boundary"} if case.startswith("vessel_water_stop") else {}
        r = run_water_vessel({**cfg, "vessel": {**cfg["vessel"], "solid_model": variant, **coupling,
                                                **water_sweep(cfg, case)}})
        r.variant = variant
        r.params["case"] = case
        return r
    if case in ("bar_tension_sliding", "bar_compression_sliding"):  # axial-only grips (claims input bar_grips)
        r = run_bar({**cfg, "bar": {**cfg["bar"], "grips": "sliding"}}, variant, +1 if "tension" in case else -1)
        r.params["case"] = case
        return r
    if case == "hertz_loadsteps":  # hertz.depths_alt_um (claims input hertz_increments)
        return run_hertz({**cfg, "hertz": {**cfg["hertz"], "depths_um": cfg["hertz"]["depths_alt_um"]}}, variant,
                         case=case)
    if case in ("hertz_eq27", "hertz_eq27_uncapped"):
        return run_hertz_eq27(cfg, variant, cap=case == "hertz_eq27")
    if case.startswith("hertz_R"):
        return run_hertz(cfg, variant, scale_radius_mm(cfg, case), case)
    if case.startswith("bar_tension_long"):
        return run_bar_long(cfg, variant, *long_bar_case(cfg, case), case=case)
    if case == "vessel" and variant == "water_particles":
        from .water import run_water_vessel

        return run_water_vessel(cfg)
    if case == "vessel":
        from .vessel import run_vessel

        return run_vessel(cfg, variant)
    if case.startswith("floor_"):
        from .floor import run_floor

        return run_floor(cfg, variant, loads=loads, case=case)
    if case.startswith("hertz_dt"):
        return run_hertz_dt(cfg, variant, float(case[len("hertz_dt"):].removesuffix("ns")))
    return CASES[case](cfg, variant)
