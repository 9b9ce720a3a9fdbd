"""Section 4.4, variant 'water_particles': weakly compressible SPH water inside the solid ring.

Water particles fill the lattice sites with r < a (the ring's own lattice, spacing dx); density by
the continuity equation from rho0, linear EOS p = p0 + K (rho / rho0 - 1), so the water starts at
rest at p0.  The ring particles are the water's wall: in the water's sums a ring particle b within
2 h of water particle a stands for water of mass m and the pressure and density of a (mirror
pressure), so a full lattice support (water + ring) is in equilibrium at uniform p, and the ring
takes the equal and opposite force, m^2 2 p_a / rho_a^2 grad_a W_ab: the pressure traction on the
ring, spread over the layers the kernel reaches.  The ring's velocity enters the continuity
equation, so as the ring expands the water's density and pressure drop (by K dA / A).  Monaghan
artificial viscosity alpha (settings).  The kernel, the eq. 9 bracket with its viscosity and the
equation of state are the SPH package's (methods.sph.kernels.kernel_wf, pair_momentum;
methods.sph.eos.pressure_of, linear: p = p0 + c0^2 (rho - rho0), c0^2 = K / rho0).

Coupling 'stop_at_boundary' (the paper's section 3, run as its own case): the ring particles take no part in
the water's sums; a water particle in contact with a ring particle (centres closer than one particle length
dx, the cubic particles touching) that moves towards it is given the force that stops its relative normal
motion within the step, m (v_rel . n) / dt along the line of centres, and the ring particle the opposite
force ("a force on the particles in contact proportional to what is needed to stop the particle from
crossing the boundary and stop it from further travel").  Units cm, N, s.
"""

import time

import numpy as np
from ...core.jit import njit

from isaflow.core import smoothing as SM
from isaflow.core.neighbours import build_pairs
from isaflow.methods.sph.eos import pressure_of
from isaflow.methods.sph.kernels import kernel_wf, pair_momentum

JIT = dict(cache=True, nogil=True)


@njit(**JIT)
def water_pressure(rho, rho0, c0, p0):
    """p0 + the SPH package's linear equation of state c0^2 (rho - rho0) [N/cm^2]."""
    return p0 + pressure_of(rho, rho0, c0, 1.0, False, False)


COUPLINGS = {"mirror_pressure": 0, "stop_at_boundary": 1}


@njit(**JIT)
def water_forces(pos, vel, rho, nw, m, h, kind, norm, K, rho0, p0, alpha, c0, fw, fs, drho, mirror=True):
    """Forces fw (nw, 2) on the water, fs (N - nw, 2) of the water on the ring [N], and drho/dt (nw,).

    pos, vel (N, 2): water first (nw), then the ring.  m: water particle mass; norm = sigma / h^2;
    K = rho0 c0^2 the bulk modulus (the equation of state takes c0).  mirror: the ring particles stand in the
    water's sums (coupling mirror_pressure); False: they do not (coupling stop_at_boundary, stop_contacts)."""
    box = np.empty(4)
    box[0] = pos[:, 0].min()
    box[1] = pos[:, 1].min()
    box[2] = pos[:, 0].max() + 1e-9
    box[3] = pos[:, 1].max() + 1e-9
    pi, pj, npair = build_pairs(pos, box, 2.0 * h)
    fw[:, :] = 0.0
    fs[:, :] = 0.0
    drho[:] = 0.0
    ih = 1.0 / h
    for k in range(npair):
        a = pi[k]
        b = pj[k]
        if a >= nw and b >= nw:
            continue
        if a >= nw:  # water first
            a, b = b, a
        if b >= nw and not mirror:
            continue
        dx = pos[a, 0] - pos[b, 0]
        dy = pos[a, 1] - pos[b, 1]
        r2 = dx * dx + dy * dy
        if r2 == 0.0 or r2 >= 4.0 * h * h:
            continue
        _, g = kernel_wf(r2, ih, kind, norm)  # grad_a W = g (x_a - x_b)
        dvx = vel[a, 0] - vel[b, 0]
        dvy = vel[a, 1] - vel[b, 1]
        pa = water_pressure(rho[a], rho0, c0, p0)
        if b < nw:
            rb = rho[b]
            pb = water_pressure(rb, rho0, c0, p0)
        else:
            rb = rho[a]
            pb = pa
        vr = dvx * dx + dvy * dy
        coef = -m * m * pair_momentum(pa / rho[a] ** 2, pb / rb**2, vr, r2, h, alpha, c0, 0.5 * (rho[a] + rb)) * g
        fx = coef * dx
        fy = coef * dy
        fw[a, 0] += fx
        fw[a, 1] += fy
        drho[a] += m * vr * g
        if b < nw:
            fw[b, 0] -= fx
            fw[b, 1] -= fy
            drho[b] += m * vr * g
        else:
            fs[b - nw, 0] -= fx
            fs[b - nw, 1] -= fy


@njit(**JIT)
def stop_contacts(xw, vw, xs, vs, m, dt, reach, fw, fs):
    """The stop-at-the-boundary coupling: for every water particle (positions xw, velocities vw after the water's own
    forces) within reach of a ring particle (xs, vs) and moving towards it, the force m (v_rel . n) / dt along the line
    of centres that stops the relative normal motion within the step, added to fw (N, on the water) and, opposite,
    to fs (on the ring); contacts are taken one after the other, each on the velocity the previous ones left.
    Returns the number of contacts that acted."""
    nw, ns = xw.shape[0], xs.shape[0]
    acted = 0
    for a in range(nw):
        vx, vy = vw[a, 0], vw[a, 1]
        for b in range(ns):
            dx = xw[a, 0] - xs[b, 0]
            dy = xw[a, 1] - xs[b, 1]
            r2 = dx * dx + dy * dy
            if r2 >= reach * reach or r2 == 0.0:
                continue
            r = np.sqrt(r2)
            nx, ny = dx / r, dy / r
            vn = (vx - vs[b, 0]) * nx + (vy - vs[b, 1]) * ny
            if vn >= 0.0:  # at rest or moving apart: no stop needed
                continue
            f = -m * vn / dt
            fw[a, 0] += f * nx
            fw[a, 1] += f * ny
            fs[b, 0] -= f * nx
            fs[b, 1] -= f * ny
            vx -= vn * nx
            vy -= vn * ny
            acted += 1
    return acted


def water_sites(na, dx):
    """(M, 2) water particle positions [cm]: the lattice sites with i^2 + j^2 < na^2."""
    i, j = np.meshgrid(np.arange(-na, na + 1), np.arange(-na, na + 1), indexing="ij")
    inside = (i**2 + j**2) < na**2
    return dx * np.column_stack([i[inside], j[inside]]).astype(float)


def coupled_history(cfg, dt, steps, every, outcome=None):
    """Undamped ring + SPH water from rest at p0, fixed step dt [s]: (t (M,) s, mean inner radial
    displacement (M,) cm, mean water pressure (M,) N/cm^2, ring state, inner mask, water density).
    Stops early when a ring particle escapes (moves a full width) or a value turns non-finite; outcome
    (dict, optional) receives 'status', 'message', 'steps' and 'water_max_move_over_dx' (the largest move
    of a water particle in one step / dx)."""
    from . import solve as S
    from .vessel import geometry, pressure_state, radial

    v = cfg["vessel"]
    dx, a, _ = geometry(v)
    st, inner = pressure_state(cfg, damp=0)
    st.fext[:] = 0.0
    if dt > st.dt_max:
        raise ValueError(f"water_particles: dt {dt:.3g} s above the step rule dx / (4 c) = {st.dt_max:.3g} s (eq. 26)")
    xw = water_sites(v["water_radius_particles"], dx)
    nw = len(xw)
    rho0 = v["rho_water_kg_m3"] * 1e-8  # kg/m^3 -> N s^2 / cm^4
    K, p0 = v["K_GPa"] * 1e5, v["pressure_Pa"] * 1e-4  # N/cm^2
    c0 = np.sqrt(K / rho0)
    m = rho0 * dx**2
    h = v["water_h_over_dx"] * dx
    kind = SM.kernel_id(v["water_kernel"])
    norm = SM.NORM[kind, 2] / h**2
    vw, rho = np.zeros_like(xw), np.full(nw, rho0)
    fw, fs, drho = np.zeros((nw, 2)), np.zeros((st.block.n, 2)), np.zeros(nw)
    stop = v.get("coupling", "mirror_pressure") == "stop_at_boundary"
    fc, fcs = np.zeros((nw, 2)), np.zeros((st.block.n, 2))
    contacts = 0
    t, ui, pw = [0.0], [0.0], [p0]
    ring_all = np.ones(st.block.n, bool)
    ur = [np.zeros(st.block.n)]  # radial displacement of every ring particle at every record
    ur_paper = np.full(st.block.n, np.nan)
    t0 = time.perf_counter()
    status, message, wmove, done = "step_limit", f"{steps} steps of {dt:.4g} s", 0.0, 0
    for step in range(1, steps + 1):
        pos = np.vstack([xw, st.pos[:, :2]])
        vel = np.vstack([vw, st.vel[:, :2]])
        water_forces(pos, vel, rho, nw, m, h, kind, norm, K, rho0, p0, v["water_alpha"], c0, fw, fs, drho, not stop)
        if stop:  # the paper's coupling: the contact forces that stop the water at the ring (stop_contacts)
            fc[:] = 0.0
            fcs[:] = 0.0
            contacts += stop_contacts(xw, vw + dt * fw / m, st.pos[:, :2], st.vel[:, :2], m, dt, dx * (1 + 1e-9), fc, fcs)
            fw += fc
            fs += fcs
        st.fext[:, :2] = fs
        ring, msg, _, _ = S.relax(st, 0.0, 1, dt=dt, min_steps=1, chunk=1, log_every=1e9)
        vw += dt * fw / m
        xw += dt * vw
        rho += dt * drho
        move = float(np.sqrt((vw**2).sum(1)).max()) * dt / dx
        wmove = move if not move <= wmove else wmove
        done = step
        if ring in ("escaped", "nonfinite") or not np.isfinite(move) or not np.isfinite(rho).all():
            status = ring if ring in ("escaped", "nonfinite") else "nonfinite"
            message = msg if ring in ("escaped", "nonfinite") else f"water: non-finite value at step {step}"
            break
        if step == v["steps"]:
            ur_paper = radial(st, ring_all)
        if step % every == 0:
            t.append(step * dt)
            ur.append(radial(st, ring_all))
            ui.append(ur[-1][inner].mean())
            pw.append(float(np.mean(p0 + c0 * c0 * (rho - rho0))))  # water_pressure, vectorised
    st.wall_time = time.perf_counter() - t0  # the coupled loop: water and ring
    if outcome is not None:
        outcome.update(status=status, message=message, steps=done, water_max_move_over_dx=wmove, ur=np.array(ur),
                       ur_paper=ur_paper, contacts=contacts)
    return np.array(t), np.array(ui), np.array(pw), st, inner, rho


COUPLING_TEXT = {
    "mirror_pressure": "ring particles within 2h stand for water of the water particle's mass, pressure and density; "
                       "the ring takes the opposite force (no stop-at-the-boundary force)",
    "stop_at_boundary": "the paper's section 3 coupling: the ring takes no part in the water's sums; a water particle "
                        "touching a ring particle (centres closer than dx) and moving towards it gets the force "
                        "m (v_rel . n) / dt that stops its relative normal motion within the step, the ring particle "
                        "the opposite force"}


def run_water_vessel(cfg):
    """Variant 'water_particles': the undamped coupled history at the paper's step; the mean over whole
    breathing cycles against Lame at the pressure the water keeps, p0 / (1 + 2 K u_L / (a p0))."""
    from .solve import result as _result
    from .vessel import NS, US, geometry, lame

    v = cfg["vessel"]
    dx, a, b = geometry(v)
    dt = v["dt_ns"] * NS
    steps = int(np.ceil(v["history_us"] * US / dt))
    out = {}
    t, ui, pw, st, inner, rho = coupled_history(cfg, dt, steps, v["record_every"], out)
    p0, K = v["pressure_Pa"] * 1e-4, v["K_GPa"] * 1e5
    # whole cycles: between the first and the last upward crossing of the history's mean
    dev = ui - ui.mean()
    up = np.flatnonzero((dev[:-1] < 0) & (dev[1:] >= 0)) + 1
    lo, hi = (up[0], up[-1]) if len(up) > 1 else (0, len(t) - 1)
    u_mean, p_mean = float(ui[lo:hi].mean()), float(pw[lo:hi].mean())
    ur_mean = out["ur"][lo:hi].mean(0) if hi > lo else np.full(st.block.n, np.nan)
    r_in = np.hypot(*st.block.ref[inner, :2].T)
    u_l = float(lame(cfg, r_in).mean())
    p_eq = p0 / (1.0 + 2.0 * K * u_l / (a * p0))
    t_paper = v["steps"] * dt
    rec = {
        "u_inner_mean_cycles": ([u_mean], "cm", "mean inner radial displacement over whole breathing cycles"),
        "p_water_mean_cycles": ([p_mean], "N cm-2", "mean water pressure over whole breathing cycles"),
        "p_drop_expected": ([K * 2.0 * u_mean / a], "N cm-2", "K dA / A with dA / A = 2 u_mean / a"),
        "u_lame_inner": ([u_l], "cm", "Lame u(r) at p0 averaged over the inner particles' radii"),
        "u_lame_compressible": ([u_l * p_eq / p0], "cm", "Lame u at the pressure the water keeps, p0 / (1 + 2 K u_L / (a p0))"),
        "p_equilibrium": ([p_eq], "N cm-2", "water pressure once the ring has expanded (Lame ring, linear EOS)"),
        "cycles_from": ([t[lo]], "s", "start of the averaging window"),
        "cycles_to": ([t[hi]], "s", "end of the averaging window"),
        "u_paper_end": ([float(np.interp(t_paper, t, ui))], "cm", "mean inner displacement at the paper's 400 steps"),
        "t_paper": ([t_paper], "s", "the paper's simulated time, steps x dt"),
        "n_water": ([len(rho)], "1", "water particles"),
        "water_max_step_move_over_dx": ([out["water_max_move_over_dx"]], "1",
                                        "largest move of a water particle in one step / dx"),
    }
    hist = {k: (("record",), val, u, ln) for k, (val, u, ln) in rec.items()}
    hist.update({
        "u_radial_paper_end": (("particle",), out["ur_paper"], "cm",
                               "radial displacement of every ring particle at the paper's 400 steps (NaN: not reached)"),
        "u_radial_mean_cycles": (("particle",), ur_mean, "cm",
                                 "radial displacement of every ring particle averaged over whole breathing cycles"),
        "u_radial_min_t": (("sample",), out["ur"].min(1), "cm", "smallest radial displacement of a ring particle"),
        "time": (("sample",), t, "s", "time since the start from rest at p0 (undamped, alpha viscosity)"),
        "u_inner_t": (("sample",), ui, "cm", "mean radial displacement of the inner (wetted) particles"),
        "p_water_t": (("sample",), pw, "N cm-2", "mean water pressure"),
    })
    msg = (f"undamped coupled run, {steps} steps of {dt:.4g} s (no rest test)" if out["status"] == "step_limit" else
           f"undamped coupled run stopped after {out['steps']} of {steps} steps: {out['message']}")
    r = _result(st, "vessel", out["status"], msg, float("nan"), hist,
                {"a_cm": a, "b_cm": b, "pressure_N_cm2": p0, "solid_model": v["solid_model"],
                 "water_kernel": v["water_kernel"], "water_h_cm": v["water_h_over_dx"] * dx,
                 "water_alpha": v["water_alpha"], "ring_lattice": "square lattice, centre radius in [a, b)",
                 "K_N_cm2": K, "rho_water_N_s2_cm4": v["rho_water_kg_m3"] * 1e-8, "dt_s": dt, "paper_steps": v["steps"],
                 "history_steps": steps, "coupling": v.get("coupling", "mirror_pressure"),
                 "coupling_description": COUPLING_TEXT[v.get("coupling", "mirror_pressure")],
                 "stop_contacts": int(out["contacts"])})
    r.variant = "water_particles"
    return r
