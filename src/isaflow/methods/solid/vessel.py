"""Section 4.4 of marko2017: the 2D steel pressure vessel, ring of solid particles around water.

The ring is cut from the square lattice: the particles whose centre radius lies in [a, b), a = 20 dx,
b = a + 5 dx (the kernels' strain factors and Poisson term are per lattice axis x, y, z, so the ring
must keep the lattice's axes; a polar arrangement would need rotated stress frames the kernels do
not have).  Centres in [a, b) give the ring the annulus's area to the lattice count, and faces whose
mean radius is a and b.

Variant 'pressure_load': the water is replaced by its pressure p on the ring's wetted faces (the
lattice faces of ring particles whose neighbour site lies inside r < a): force p dx per face
(per unit thickness), normal to the face, into the solid; what Lame assumes.

Every measure is the radial displacement of the inner particles (those with a wetted face),
compared with the Lame field u(r) at their own centre radii.  Units cm, N, s.
"""

import numpy as np

from . import lattice as L
from . import solve as S
from . import theory as T
from .settings import material_units

MM = 0.1  # cm
NS, US = 1e-9, 1e-6  # s


def ring(dx, na, nb):
    """Square-lattice ring: block of the particles with centre radius in [na dx, nb dx) (integer test on
    the lattice indices, so the ring keeps the lattice's symmetry exactly) and the wetted face normals
    (N, 3): sum over faces whose neighbour site has radius < na dx of the unit vector into the water."""
    n = nb + 1
    full = L.block(2 * n + 1, 2 * n + 1, 1, dx)
    ij = full.index[:, :2] - n
    full.ref[:, :2] = dx * ij
    r2 = (ij**2).sum(1)
    blk = L.select(full, (r2 >= na**2) & (r2 < nb**2))
    ij = blk.index[:, :2] - n
    wet = np.zeros((blk.n, 3))
    for e in ((1, 0), (-1, 0), (0, 1), (0, -1)):
        wet[((ij + e) ** 2).sum(1) < na**2, :2] += e
    return blk, wet


def geometry(v):
    """(dx, a, b) [cm] of the vessel settings v."""
    dx = v["dx_mm"] * MM
    a = v["water_radius_particles"] * dx
    return dx, a, a + v["ring_particles"] * dx


def pressure_state(cfg, damp=1):
    """State of the ring loaded by the water pressure on its wetted faces; returns (state, inner mask)."""
    v = cfg["vessel"]
    dx, a, b = geometry(v)
    blk, wet = ring(dx, v["water_radius_particles"], v["water_radius_particles"] + v["ring_particles"])
    p = v["pressure_Pa"] * 1e-4  # N/cm^2
    mat = S.Material(*material_units(cfg["material"]))
    st = S.State(blk, mat, v["solid_model"], np.ones((blk.n, 3)), damp=damp, fext=-p * dx * wet)
    mask = np.zeros((blk.n, 3), bool)
    mask[:, 2] = True
    S.prescribe(st, mask, np.zeros(3))
    inner = np.abs(wet).sum(1) > 0
    return st, inner


def radial(st, sel):
    """Radial displacements [cm] of the particles sel."""
    ref = st.block.ref[sel, :2]
    rhat = ref / np.hypot(ref[:, 0], ref[:, 1])[:, None]
    return ((st.pos[sel, :2] - ref) * rhat).sum(1)


def lame(cfg, r):
    """Lame u(r) [cm] for the vessel settings at radii r [cm] (theory in SI)."""
    v = cfg["vessel"]
    _, a, b = geometry(v)
    E, nu = cfg["material"]["E_GPa"] * 1e9, cfg["material"]["nu"]
    return T.lame_displacement(np.asarray(r) * 1e-2, a * 1e-2, b * 1e-2, v["pressure_Pa"], E, nu) * 1e2


def settle(cfg):
    """Kinetic-damped relaxation to rest under the pressure load: (state, inner mask, status, msg, resid)."""
    st, inner = pressure_state(cfg, damp=1)
    status, msg, resid, _ = S.relax(st, cfg["solver"]["tol"], cfg["solver"]["max_steps"], label="vessel settle")
    return st, inner, status, msg, resid


def history(cfg, dt, snapshot=None):
    """Undamped response to the pressure applied at t = 0 from rest, at the fixed step dt [s]:
    (t (M,) s, mean inner radial displacement (M,) cm, outer (M,) cm, final state).  snapshot (dict,
    optional) receives 'u_paper': the radial displacement [cm] of every ring particle at the first record
    at or after the paper's vessel.steps, and 'u_min': the smallest radial displacement at every record."""
    v = cfg["vessel"]
    st, inner = pressure_state(cfg, damp=0)
    r = np.hypot(st.block.ref[:, 0], st.block.ref[:, 1])
    outer = r >= r.max() - st.block.dx
    if dt > st.dt_max:
        raise ValueError(f"vessel history: dt {dt:.3g} s above the step rule dx / (4 c) = {st.dt_max:.3g} s (eq. 26)")
    every = v["record_every"]
    n = every * int(np.ceil(v["history_us"] * US / dt / every))
    t, ui, uo = [0.0], [0.0], [0.0]
    ring_all = np.ones(st.block.n, bool)
    u_min, u_paper = [0.0], []

    def sample(_):  # every record_every steps (the stepper's chunk)
        t.append(st.clock[1])
        ur = radial(st, ring_all)
        ui.append(ur[inner].mean())
        uo.append(ur[outer].mean())
        u_min.append(ur.min())
        if not u_paper and st.steps >= v["steps"]:
            u_paper.append(ur)

    S.relax(st, 0.0, n, dt=dt, min_steps=n, chunk=every, label="vessel history", sample=sample)
    if snapshot is not None:
        snapshot.update(u_paper=u_paper[0] if u_paper else np.full(st.block.n, np.nan), u_min=np.array(u_min))
    return np.array(t), np.array(ui), np.array(uo), st


def run_vessel(cfg, variant):
    """The 'pressure_load' vessel: settled state (kinetic damping) and the undamped time history at the
    paper's step; the Lame field at the inner particles' radii; the times that say whether 58.7 us settles."""
    if variant != "pressure_load":
        raise KeyError(f"vessel variant '{variant}' is not implemented (choose from pressure_load, water_particles)")

    v = cfg["vessel"]
    dx, a, b = geometry(v)
    st, inner, status, msg, resid = settle(cfg)
    u_set = radial(st, inner)
    r_in = np.hypot(*st.block.ref[inner, :2].T)
    u_th = lame(cfg, r_in)
    dt = v["dt_ns"] * NS
    snap = {}
    t, ui, uo, hst = history(cfg, dt, snap)
    t_paper = v["steps"] * dt
    u_paper = float(np.interp(t_paper, t, ui))
    # first time the undamped inner wall reaches its settled value (quarter of the breathing swing)
    up = np.flatnonzero(ui >= u_set.mean())
    t_reach = float(t[up[0]]) if up.size else np.nan
    # breathing period: time between successive upward crossings of the settled value
    dev = ui - u_set.mean()
    cross = t[1:][(dev[:-1] < 0) & (dev[1:] >= 0)]
    period = float(np.diff(cross).mean()) if cross.size > 1 else np.nan
    # the same ring at half the particle size (twice the particles across): discretisation error trend
    fine = {**cfg, "vessel": {**v, "dx_mm": v["dx_mm"] / 2, "ring_particles": 2 * v["ring_particles"],
                              "water_radius_particles": 2 * v["water_radius_particles"]}}
    stf, innf, *_ = settle(fine)
    u_fine = radial(stf, innf).mean() / lame(fine, np.hypot(*stf.block.ref[innf, :2].T)).mean()
    c_w = np.sqrt(v["K_GPa"] * 1e9 / v["rho_water_kg_m3"]) * 1e2  # cm/s
    hist = {
        "time": (("sample",), t, "s", "time since the pressure was applied (undamped run)"),
        "u_inner_t": (("sample",), ui, "cm", "mean radial displacement of the inner (wetted) particles, undamped"),
        "u_outer_t": (("sample",), uo, "cm", "mean radial displacement of the outermost layer, undamped"),
        "u_inner_settled": (("record",), [u_set.mean()], "cm", "mean settled inner radial displacement"),
        "u_inner_settled_min": (("record",), [u_set.min()], "cm", "smallest settled inner radial displacement"),
        "u_inner_settled_max": (("record",), [u_set.max()], "cm", "largest settled inner radial displacement"),
        "u_lame_inner": (("record",), [u_th.mean()], "cm", "Lame u(r) averaged over the inner particles' radii"),
        "u_lame_a": (("record",), [float(lame(cfg, a))], "cm", "Lame u at the inner radius a"),
        "u_ratio_half_dx": (("record",), [u_fine], "1", "settled / Lame inner displacement of the ring at dx / 2"),
        "u_paper_end": (("record",), [u_paper], "cm", "undamped mean inner displacement at the paper's 400 steps"),
        "t_paper": (("record",), [t_paper], "s", "the paper's simulated time, steps x dt"),
        "t_first_reach": (("record",), [t_reach], "s", "first time the undamped inner wall reaches the settled value"),
        "breathing_period": (("record",), [period], "s", "period of the undamped ring's breathing oscillation"),
        "t_settle_damped": (("record",), [float(st.clock[1])], "s", "simulated time of the kinetic-damped settling"),
        "t_sound_water": (("record",), [2 * a / c_w], "s", "water sound crossing 2 a / sqrt(K / rho)"),
        "t_sound_steel": (("record",), [(b - a) / st.mat.c], "s", "steel wave crossing of the wall (b - a) / c"),
        "history_dt": (("record",), [dt], "s", "fixed step of the undamped run"),
        "history_wall_time": (("record",), [hst.wall_time], "s", "solver time of the undamped run"),
        "history_max_step_move_over_dx": (("record",), [float(hst.clock[6])], "1",
                                          "largest move of a particle in one step of the undamped run / dx"),
        "u_radial_paper_end": (("particle",), snap["u_paper"], "cm",
                               "radial displacement of every ring particle at the paper's 400 steps, undamped"),
        "u_radial_settled": (("particle",), radial(st, np.ones(st.block.n, bool)), "cm",
                             "settled radial displacement of every ring particle"),
        "u_radial_min_t": (("sample",), snap["u_min"], "cm", "smallest radial displacement of a ring particle, undamped"),
    }
    r = S.result(st, "vessel", status, msg, resid, hist,
                {"a_cm": a, "b_cm": b, "pressure_N_cm2": v["pressure_Pa"] * 1e-4, "solid_model": v["solid_model"],
                 "ring_lattice": "square lattice, centre radius in [a, b)", "n_inner": int(inner.sum()),
                 "dt_s": dt, "paper_steps": v["steps"], "coupling": "pressure_load"})
    r.variant = variant
    return r
