"""MPS time stepping on a tank: solve(tank, settings, variant, spacing) -> contract.Result.

Per step: model.predict (numba: explicit step, number density, source, CSR
system), pressure.solve (scipy / pyamg), model.correct (numba: gradient,
velocity and position correction, wall-crossing check).  The pressure solve
is a sparse-library call, so the step loop runs in Python around two compiled
halves.  Units: cm, N, s; pressure N/cm^2 (2D, per cm of thickness).
"""

import time

import numpy as np

from isaflow.contract import Result
from isaflow.core import units
from isaflow.core.geometry import bounding_box

from . import boundary, model, pressure

LOG_EVERY = 30.0  # s of wall time between progress lines


def vessels(tank):
    """[(name, (xmin, xmax) cm)] of the tank's vessels; one spanning the walls if it names none."""
    w = tank.walls
    return tank.vessels or [("vessel", (float(w[:, [0, 2]].min()), float(w[:, [0, 2]].max())))]


def first_vessel(tank):
    """(x range (cm, cm), floor y cm) of the tank's first vessel (floor: horizontal wall spanning it)."""
    x0, x1 = vessels(tank)[0][1]
    w = tank.walls
    span = np.minimum(np.maximum(w[:, 0], w[:, 2]), x1) - np.maximum(np.minimum(w[:, 0], w[:, 2]), x0)
    floors = np.isclose(w[:, 1], w[:, 3]) & (span > 0)
    return (x0, x1), float(w[floors, 1].max())


def time_step(tank, l0, courant):
    """dt [s] = courant l0 / sqrt(2 g H), H = liquid top minus the lowest wall point (free-fall speed)."""
    _, floor = first_vessel(tank)
    H = floor + tank.depth - tank.walls[:, [1, 3]].min()
    return courant * l0 / np.sqrt(2.0 * units.G * H)


class State:
    """Particles and constants of one run (fluid first, then wall and dummy particles)."""

    def __init__(self, tank, cfg, l0, fluid_pos, fluid_vel):
        self.l0 = l0
        self.walls = tank.walls
        self.nf = len(fluid_pos)
        layers = cfg["model.pressure_layers"] + cfg["model.dummy_layers"]
        self.pos, self.kind, self.bnd = boundary.assemble_particles(fluid_pos, self.walls, l0, layers,
                                                                    cfg["model.pressure_layers"])
        self.vel = np.zeros_like(self.pos)
        self.vel[: self.nf] = fluid_vel
        self.p = np.zeros(len(self.pos))
        self.re_n = cfg["model.re_density"] * l0
        self.re_g = cfg["model.re_gradient"] * l0
        self.re_l = cfg["model.re_laplacian"] * l0
        self.n0_n, _ = model.lattice_constants(cfg["model.re_density"], l0)
        self.n0_g, _ = model.lattice_constants(cfg["model.re_gradient"], l0)
        self.n0_l, self.lam = model.lattice_constants(cfg["model.re_laplacian"], l0)
        self.weight = tank.weight / self.nf  # N per particle
        self.rho0 = self.weight / units.G / l0**2  # N s^2 / cm^4
        box = bounding_box(self.walls)
        pad = (layers + 1) * l0
        self.grid_box = box + np.array([-pad, -pad, pad, pad])
        self.escape_box = box
        self.graze_depth = cfg["walls.graze_depth"] * l0  # cm: deeper crossings are escapes
        self.grazes, self.deepest_graze = 0, 0.0  # steps with a graze, deepest graze [cm]
        self.panel_wall, self.panel_centre, self.load_matrix = boundary.load_map(self.walls, self.bnd, cfg["walls.panel_length"])

    def panel_forces(self):
        """(P, 2) force of each wall panel on the liquid [N] from the wall particles' pressures."""
        return (self.load_matrix @ self.p[self.nf:]).reshape(-1, 2)


def step(s, dt, source, cfg, timers=None):
    """Advance State s by one step.  Returns (bad, residual, iterations); bad as model.correct
    (kind 4: the pressure solve failed outright or gave a non-finite pressure; residual inf)."""
    t0 = time.perf_counter()
    ps, vs, n_star, div, dirichlet, pi, pj, m, system = model.predict(
        s.pos, s.vel, s.kind, s.grid_box, dt, 0.0, -units.G, cfg["model.kinematic_viscosity"], s.re_n, s.re_g, s.re_l,
        s.n0_n, s.n0_g, s.n0_l, s.lam, cfg["model.beta"], s.rho0, model.SOURCES[source], cfg["model.gamma_mixed"],
        cfg["model.relaxation"], cfg["model.sound_speed"], cfg["model.collision_distance"] * s.l0, cfg["model.restitution"],
        cfg["model.surface_distribution"] * s.l0)
    row, indptr, indices, data, rhs = system
    t1 = time.perf_counter()
    A = pressure.csr(indptr, indices, data)
    unk = row >= 0
    x0 = np.zeros(A.shape[0])
    x0[row[unk]] = s.p[unk]
    try:
        x, resid, its = pressure.solve(A, rhs, cfg["pressure.solver"], cfg["pressure.rtol"], cfg["pressure.maxiter"], x0)
    except (RuntimeError, ValueError, ArithmeticError) as err:  # e.g. SuperLU "matrix is exactly singular"
        x, resid, its = np.full(A.shape[0], np.nan), np.inf, 0
        s.solve_error = str(err)
    if not np.all(np.isfinite(x)):
        resid = np.inf
    t2 = time.perf_counter()
    if not np.isfinite(resid):
        if timers is not None:
            timers += (t1 - t0, t2 - t1, 0.0)
        return (4, -1, -1), resid, its
    p = np.zeros(len(s.pos))
    p[unk] = x[row[unk]]
    if cfg["model.clip_negative"]:
        p = np.maximum(p, 0.0)
    pos, vel, _, bad, graze = model.correct(s.pos, ps, vs, p, s.kind, pi, pj, m, s.re_g, s.n0_g, s.rho0, dt, s.walls,
                                            s.escape_box, s.graze_depth)
    s.pos, s.vel, s.p = pos, vel, p
    if graze > 0.0:
        s.grazes += 1
        s.deepest_graze = max(s.deepest_graze, graze)
    if timers is not None:
        timers += (t1 - t0, t2 - t1, time.perf_counter() - t2)
    return bad, resid, its


def _vessel_counts(pos, tank):
    return [int(np.count_nonzero((pos[:, 0] >= a) & (pos[:, 0] < b))) for _, (a, b) in vessels(tank)]


def solve(tank, cfg, variant, spacing, t_end, probes, start=None, snapshots=0, log=print):
    """Run MPS with source term ``variant`` on ``tank`` for ``t_end`` s of physical time.

    spacing l0 [cm]; probes (K, 2) cm; start None (liquid block at rest in the
    first vessel, depth tank.depth rounded to whole rows) or dict(pos, vel,
    steps, sim_time) of the run this one continues (the walls are this tank's).
    snapshots: number of evenly spaced position snapshots kept.  Wall loads
    (contacts) are the mean panel forces over the last settings
    'time.average_window' s.  Returns a contract.Result.
    """
    if variant not in model.SOURCES:
        raise ValueError(f"unknown MPS source term '{variant}' (choose from {', '.join(model.SOURCES)})")
    l0 = float(spacing)
    if start is None:
        xr, floor = first_vessel(tank)
        fpos, fvel, step0, t0 = boundary.liquid_block(xr, floor, tank.depth, l0), None, 0, 0.0
        fvel = np.zeros_like(fpos)
    else:
        fpos, fvel, step0, t0 = np.asarray(start["pos"], float), np.asarray(start["vel"], float), int(start["steps"]), float(start["sim_time"])
    s = State(tank, cfg, l0, fpos, fvel)
    pos0 = s.pos[: s.nf].copy()
    dt = time_step(tank, l0, cfg["time.courant"])
    nsteps = int(np.ceil(t_end / dt - 1e-9))
    every = max(1, int(round(cfg["time.sample_interval"] / dt)))
    snap_at = set(np.linspace(0, nsteps, snapshots).round().astype(int)) if snapshots else set()
    u_rest = np.sqrt(2.0 * cfg["time.rest_fraction"] * units.G * l0)
    probes = np.asarray(probes, float).reshape(-1, 2)
    rec = {k: [] for k in ("time", "panel", "probe", "rms", "vmax", "count", "resid", "iters")}
    snaps, snap_t = [], []
    fail_tol = cfg["pressure.rtol"] * cfg["pressure.fail_factor"]
    status, message, max_resid, iters = None, "", 0.0, []
    timers = np.zeros(3)
    wall0 = time.perf_counter()
    last_log = wall0
    k = 0
    for k in range(1, nsteps + 1):
        bad, resid, its = step(s, dt, variant, cfg, timers)
        max_resid = max(max_resid, resid)
        iters.append(its)
        t = t0 + k * dt
        if bad[0] == 1:
            status, message = "nonfinite", f"step {step0 + k}: particle {bad[1]} has a non-finite position or velocity"
        elif bad[0] == 2:
            status, message = ("escaped", f"step {step0 + k}: particle {bad[1]} crossed wall '{tank.wall_names[bad[2]]}' "
                                          f"(more than {s.graze_depth:.3g} cm past it)")
        elif bad[0] == 3:
            status, message = "escaped", f"step {step0 + k}: particle {bad[1]} left the walls' bounding box by more than {s.graze_depth:.3g} cm"
        elif bad[0] == 4 or not resid <= fail_tol:
            status, message = "solver_failed", f"step {step0 + k}: pressure solve residual {resid:.3g} > {fail_tol:.3g} after {its} iterations"
        v = s.vel[: s.nf]
        speed2 = (v**2).sum(1)
        if k % every == 0 or status or k == nsteps:
            rec["time"].append(t)
            rec["panel"].append(s.panel_forces())
            rec["probe"].append(model.probe_pressure(s.pos, s.p, s.kind, probes, s.re_n))
            rec["rms"].append(np.sqrt(speed2.mean()))
            rec["vmax"].append(np.sqrt(speed2.max()))
            rec["count"].append(_vessel_counts(s.pos[: s.nf], tank))
            rec["resid"].append(resid)
            rec["iters"].append(its)
        if k in snap_at:
            snaps.append(s.pos[: s.nf].copy())
            snap_t.append(t)
        if status:
            break
        now = time.perf_counter()
        if now - last_log > LOG_EVERY:
            log(f"mps {variant} l0={l0:g} cm: step {k}/{nsteps}, t = {t:.3f} s, rms speed {rec['rms'][-1] if rec['rms'] else 0:.3g} cm/s")
            last_log = now
    wall = time.perf_counter() - wall0
    rms = float(np.sqrt((s.vel[: s.nf] ** 2).sum(1).mean()))
    if status is None:
        at_rest = rms < u_rest
        status = "converged" if at_rest else "step_limit"
        message = (f"step {step0 + k}: t = {t0 + k * dt:.3f} s, rms speed {rms:.3g} cm/s "
                   f"{'<' if at_rest else '>='} rest limit {u_rest:.3g} cm/s")
    times = np.array(rec["time"])
    panels = np.array(rec["panel"])
    window = times >= times[-1] - cfg["time.average_window"] + 1e-12
    hist = {
        "hist_time": (("sample",), times, "s", "time of sample"),
        "hist_panel_force": (("sample", "contact", "xy"), panels, "N", "force of each wall panel on the liquid"),
        "hist_probe_pressure": (("sample", "probe"), np.array(rec["probe"]).reshape(len(times), -1), "N cm-2", "pressure at fixed probe"),
        "hist_rms_speed": (("sample",), np.array(rec["rms"]), "cm s-1", "rms speed of the liquid particles"),
        "hist_max_speed": (("sample",), np.array(rec["vmax"]), "cm s-1", "largest liquid particle speed"),
        "hist_vessel_count": (("sample", "vessel"), np.array(rec["count"]), "1", "particles per vessel"),
        "hist_solve_residual": (("sample",), np.array(rec["resid"]), "1", "relative residual of the pressure solve"),
        "hist_solve_iterations": (("sample",), np.array(rec["iters"]), "1", "iterations of the pressure solve"),
        "probe_point": (("probe", "xy"), probes, "cm", "pressure probe position"),
        "in_window": (("sample",), window.astype(np.int8), "1", "1 if the sample is in the averaging window"),
    }
    if snaps:
        hist["snap_time"] = (("snapshot",), np.array(snap_t), "s", "time of position snapshot")
        hist["snap_pos"] = (("snapshot", "particle", "xy"), np.array(snaps), "cm", "liquid particle positions at snapshot")
    fields = {
        "pressure": (("particle",), s.p[: s.nf].copy(), "N cm-2", "pressure of each liquid particle at the end"),
        "velocity": (("particle", "xy"), s.vel[: s.nf].copy(), "cm s-1", "velocity of each liquid particle at the end"),
    }
    nb = np.bincount(s.kind, minlength=3)
    params = {
        "source_term": variant, "spacing_cm": l0, "dt_s": dt, "rho0_N_s2_cm4": s.rho0, "particle_weight_N": s.weight,
        "re_density_cm": s.re_n, "re_gradient_cm": s.re_g, "re_laplacian_cm": s.re_l, "n0_density": s.n0_n, "n0_laplacian": s.n0_l,
        "lambda_cm2": s.lam, "beta": cfg["model.beta"], "relaxation": cfg["model.relaxation"],
        "sound_speed_cm_s": cfg["model.sound_speed"], "n0_gradient": s.n0_g,
        "surface_distribution": cfg["model.surface_distribution"], "kinematic_viscosity_cm2_s": cfg["model.kinematic_viscosity"],
        "gamma_mixed": cfg["model.gamma_mixed"], "courant": cfg["time.courant"], "pressure_solver": cfg["pressure.solver"],
        "pressure_rtol": cfg["pressure.rtol"], "max_solve_residual": max_resid, "mean_solve_iterations": float(np.mean(iters)),
        "rest_speed_cm_s": u_rest, "average_window_s": cfg["time.average_window"], "wall_particles": int(nb[model.WALL]),
        "dummy_particles": int(nb[model.DUMMY]), "time_predict_s": timers[0], "time_solve_s": timers[1],
        "time_correct_s": timers[2], "collision_distance_cm": cfg["model.collision_distance"] * l0, "restitution": cfg["model.restitution"], "settings_file": cfg.path,
        "panel_length": cfg["walls.panel_length"], "graze_depth_cm": s.graze_depth, "graze_steps": s.grazes,
        "deepest_graze_cm": s.deepest_graze,
    }
    return Result(
        method="mps", variant=variant, pos0=pos0, pos=s.pos[: s.nf].copy(), weight=np.full(s.nf, s.weight),
        contact_wall=s.panel_wall, contact_point=s.panel_centre, contact_force=panels[window].mean(0),
        status=status, message=message, steps=step0 + k, start_step=step0, wall_time=wall, force_evals=k,
        residual=rms, residual_name="rms speed", residual_units="cm s-1", sim_time=t0 + k * dt,
        history=hist, fields=fields, params=params)
