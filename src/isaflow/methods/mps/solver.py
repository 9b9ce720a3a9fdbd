"""MPS time stepping on a tank: solve(tank, settings, variant, spacing, ...) -> contract.Result.

Per step (model.py, numba, every particle loop a gather run in parallel): neighbour list, explicit step,
collision model, penetration guard (walls.reflect: a move across a wall line mirrored back), free surface and
source term, pressure equation (pressure.py), pressure correction, particle shifting, penetration guard,
wall-crossing check.  A step is one compiled call with the compiled pressure solver (model.step_cg: model.predict,
pressure.cg_solve, model.correct; any other solver from Python between the two), one step per advance of a stepper
run by driver.drive.
Rest: isaflow.rest (one criterion for every dynamic method).  Units: cm, N, s; pressure N/cm^2
(2D, per cm of thickness).
"""

import collections
import os
import time

# numba's OpenMP threads spin while waiting by default; on a shared (oversubscribed) machine that made every
# parallel loop of a 2-thread run wait for a scheduler time slice (11.7 ms per loop instead of 11 us).  Passive
# waiting is set before numba starts its threads (the first parallel loop), unless the environment says otherwise.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")


def _keep_freed_memory():
    """glibc: serve every allocation below 1 GiB from the heap and never give freed heap back to the system.  A step
    allocates arrays of the lists' size (1.5 MB each at 6,000 particles); by default glibc maps such blocks afresh
    and unmaps them when freed, so every step paid a page fault per 4 kB touched: on the shared 2-core machine one
    pass over the lists took 10 ms on every other call instead of 1.8 ms (1.0 ms with this).  Peak memory is
    unchanged (what a step frees, the next reuses).  Not glibc: nothing to do."""
    import ctypes
    import ctypes.util

    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        libc.mallopt(-3, 1 << 30)  # M_MMAP_THRESHOLD
        libc.mallopt(-1, 1 << 30)  # M_TRIM_THRESHOLD
    except (OSError, AttributeError):
        pass


_keep_freed_memory()

import numba
import numpy as np
import scipy.sparse as sp

from isaflow import driver, rest
from isaflow.contract import Result, wall_resultants
from isaflow.core import units
from isaflow.inputs import InputError
from isaflow.tank import vessel_counts

from . import boundary, model, pressure
from .checks import time_step


def rows_depth(tank, l0):
    """Depth [cm] of the initial liquid block: tank.depth rounded to whole rows of l0 (boundary.liquid_block)."""
    return max(1, int(round(tank.depth / l0))) * l0


class State:
    """Particles and constants of one run (fluid first, then wall and dummy particles)."""

    def __init__(self, tank, cfg, l0, fluid_pos, fluid_vel):
        self.cfg = cfg
        self.l0 = l0
        self.walls = np.asarray(tank.walls, float)
        self.nf = len(fluid_pos)
        self.thin_mask = boundary.thin_walls(self.walls, tank.vessels)
        layers = cfg["model.pressure_layers"] + cfg["model.dummy_layers"]
        self.pos, self.kind, self.bnd = boundary.assemble_particles(fluid_pos, self.walls, l0, layers,
                                                                    cfg["model.pressure_layers"], self.thin_mask)
        n = len(self.pos)
        thin_idx = np.full(len(self.walls), -1, np.int64)
        thin_idx[self.thin_mask] = np.arange(self.thin_mask.sum())
        self.thin = self.walls[self.thin_mask].copy()
        self.tw = np.full(n, -1, np.int64)  # thin wall of each face particle
        self.tside = np.ones(n, np.int64)
        self.tw[self.nf:] = thin_idx[self.bnd["wall"]]
        self.tside[self.nf:] = self.bnd["side"]
        self.gravity = (0.0, -units.G)  # cm/s^2 (the energy test sets it to zero)
        self.vel = np.zeros_like(self.pos)
        self.vel[: self.nf] = fluid_vel
        self.p = np.zeros(n)
        self.re_n = cfg["model.re_density"] * l0
        self.re_g = cfg["model.re_gradient"] * l0
        self.re_l = cfg["model.re_laplacian"] * l0
        self.re_s = cfg["model.re_surface"] * l0
        self.rmax = max(self.re_n, self.re_g, self.re_l, self.re_s)
        self.skin = cfg["model.list_skin"] * l0
        self.grad_mode = model.GRADIENTS[cfg["model.gradient"]]
        self.n0_n, _ = model.lattice_constants(cfg["model.re_density"], l0)
        self.n0_g, _ = model.lattice_constants(cfg["model.re_gradient"], l0)  # divergence, surface extrapolation
        self.n_grad = model.gradient_norm(self.grad_mode, cfg["model.re_gradient"])  # the gradient's d / n_grad
        self.n0_s, _ = model.lattice_constants(cfg["model.re_surface"], l0)
        self.n0_l, self.lam = model.lattice_constants(cfg["model.re_laplacian"], l0)
        self.weight = tank.weight / self.nf  # N per particle
        self.rho0 = self.weight / units.G / l0**2  # N s^2 / cm^4
        box = np.asarray(tank.escape_box(), float)  # the walls' bounding box, open upwards (a splash may rise and fall back)
        pad = (layers + 1) * l0
        self.grid_box = box + np.array([-pad, -pad, pad, pad])
        self.escape_box = box
        self.graze_depth = cfg["walls.graze_depth"] * l0  # cm: deeper crossings are escapes
        self.counts = np.zeros(4, np.int64)  # list builds, steps with a wall reflection, particles reflected, grazes
        self.deepest = np.zeros(1)  # deepest graze [cm]
        self.panel_wall, self.panel_centre, self.panel_side, self.load_matrix, self.share = boundary.load_map(
            self.walls, self.bnd, cfg["walls.panel_length"])
        self.share_csr, self.loads_csr = _csr(self.share), _csr(self.load_matrix)
        self.pair_state = None  # (positions, distances, list start, list) of the last pressure gradient
        self.load_sum, self.p_sum, self.sum_time = np.zeros((2 * len(self.panel_wall), 2)), np.zeros(self.nf), 0.0
        self.surface_mode = model.SURFACE[cfg["model.surface_pressure"]]
        self.lap_mode = model.LAPLACIANS[cfg["model.pressure_laplacian"]]
        self.div_mode = model.DIVERGENCES[cfg["model.divergence"]]
        self.n_prev = np.zeros(0)  # number density at the start of the previous step (ECS; empty: none yet)
        self.start, self.nbr, self.list_pos = np.zeros(1, np.int64), np.zeros(0, np.int32), np.zeros((0, 2))  # none yet
        self.surf = np.zeros(n, bool)
        self.solve_error = ""
        self.consts_cfg, self.consts = None, None
        self.clock = np.zeros(3, np.int64)  # cycles of model.step_cg's stages, its last call

    builds = property(lambda self: int(self.counts[0]), doc="neighbour-list builds")
    reflect_steps = property(lambda self: int(self.counts[1]), doc="steps with a wall reflection (walls.reflect)")
    reflections = property(lambda self: int(self.counts[2]), doc="particles reflected, summed over the steps")
    grazes = property(lambda self: int(self.counts[3]), doc="steps with a graze")
    deepest_graze = property(lambda self: float(self.deepest[0]), doc="deepest graze [cm]")

    def constants(self, cfg):
        """model.StepConstants of settings cfg (those of the state's build, as a rule) and this run's lattice."""
        if cfg is not self.consts_cfg:
            self.consts_cfg = cfg
            self.solve_settings = (cfg["pressure.solver"], cfg["pressure.rtol"], cfg["pressure.maxiter"],
                                   cfg["model.sound_speed"])
            self.consts = model.step_constants(
                nf=self.nf, l0=self.l0, rmax=self.rmax, skin=self.skin, nu=cfg["model.kinematic_viscosity"],
                ecs=cfg["model.ecs"], re_n=self.re_n, re_g=self.re_g, re_l=self.re_l, re_s=self.re_s, n0_n=self.n0_n,
                n0_g=self.n0_g, n0_s=self.n0_s, n0_l=self.n0_l, lam=self.lam, rho0=self.rho0, n_grad=self.n_grad,
                grad_mode=self.grad_mode, div_mode=self.div_mode, lap_mode=self.lap_mode, surface_mode=self.surface_mode,
                cdist=cfg["model.collision_distance"] * self.l0, restitution=cfg["model.restitution"],
                reflect=cfg["walls.reflect"], behind=cfg["walls.thin_line_of_sight"], beta=cfg["model.beta"],
                dist_thr=cfg["model.surface_distribution"] * self.l0, gamma=cfg["model.gamma_mixed"],
                relax=cfg["model.relaxation"], scope=model.RELAX_SCOPES[cfg["model.relaxation_scope"]],
                clip=cfg["model.clip_negative"], shifting=cfg["model.shifting"], graze=self.graze_depth,
                mass_over_rho=self.weight / units.G / self.rho0)
        return self.consts

    def neighbours(self, pos):
        """Neighbour lists at pos, radius rmax + skin (start, nbr); reused until a particle has moved more
        than skin / 2 from where it was at the build (list_valid), so every pair closer than rmax is in them.
        The rows' order depends on the positions at the build, so a continued run (which builds its own
        lists) matches the run it continues to round-off, not bit for bit.  The lists hold every pair in range
        whatever the thin walls between them (no thin wall passed): which pairs see each other is decided at
        the positions the operators use (distances).  The step builds its own the same way (model.lists_at)."""
        self.list_pos = np.zeros((0, 2))
        self.start, self.nbr, self.list_pos = model.lists_at(pos, self.kind, self.tw, self.tside, self.grid_box,
                                                             self.start, self.nbr, self.list_pos, self.counts,
                                                             self.constants(self.cfg))

    def distances(self, pos):
        """(M,) distance of every list entry at pos, inf where the pair does not see each other across a thin
        wall at pos (the lists hold every pair in range; visibility is that of the positions the operators
        use, so a particle that grazes a thin wall's line between list builds sees, and is seen, as it is now)."""
        return model.visible_distances(pos, self.start, self.nbr, self.tw, self.tside, self.thin, self.rmax + self.skin,
                                       self.cfg["walls.thin_line_of_sight"])

    def list_valid(self, pos):
        """The lists still hold every pair closer than rmax at pos (nobody moved more than skin / 2)."""
        return model.list_holds(pos, self.list_pos, self.nf, self.skin)

    def loads(self):
        """(2P, 2) force of each wall panel on the liquid [N] now (model.panel_loads: by the pair-force reading, the
        wall-liquid pair terms of the last step's pressure gradient at the positions and pressures it used, the
        momentum the walls exchange with the liquid, model.wall_forces; then by the panel reading, the first row's
        pressures times the length of wall each faces)."""
        f = np.zeros((len(self.pos), 2))
        if self.pair_state is not None:
            pos, dist, start, nbr = self.pair_state
            f = model.wall_forces(pos, self.p, self.kind, start, nbr, dist, self.re_g, self.n_grad, self.grad_mode,
                                  self.weight / units.G / self.rho0)
        return model.panel_loads(f[self.nf:], self.p, self.nf, self.share_csr, self.loads_csr)

    def take_means(self):
        """(pair-force loads (P, 2) N, panel loads (P, 2) N, liquid pressures (nf,) N/cm^2): the means over the steps
        since the last call (the current values if no step was taken), and start new sums."""
        if self.sum_time > 0.0:
            load, p = self.load_sum / self.sum_time, self.p_sum / self.sum_time
        else:
            load, p = self.loads(), self.p[: self.nf].copy()
        self.load_sum, self.p_sum, self.sum_time = np.zeros((2 * len(self.panel_wall), 2)), np.zeros(self.nf), 0.0
        return load[: len(self.panel_wall)], load[len(self.panel_wall):], p


def _csr(dense):
    """(indptr, indices, data) of a dense matrix's nonzero entries, row by row in column order."""
    m = sp.csr_matrix(dense)
    m.sort_indices()
    return m.indptr.astype(np.int64), m.indices.astype(np.int64), m.data.astype(float)


def step(s, dt, source, cfg, timers=None):
    """Advance State s by one step: model.predict, the pressure solve, model.correct (with the compiled solver
    cg_jacobi all three in one compiled call, model.step_cg).  Returns (bad, residual, iterations); bad as model.check
    (kind 4: the pressure solve failed outright or gave a non-finite pressure; residual inf).  timers: (3,) s
    accumulated in predict (to the assembled system), solve and correct."""
    c = s.constants(cfg)
    solver, rtol, maxiter, sound = s.solve_settings
    extra = s.lam * s.n0_l / (2.0 * model.DIM * sound**2 * dt**2) if sound > 0 else 0.0
    if solver == "cg_jacobi":
        t0 = time.perf_counter()
        (done, bad, resid, its, failed, s.start, s.nbr, s.list_pos, s.n_prev, pos, vel, p, surf, ps, dist,
         *lists) = model.step_cg(s.pos, s.vel, s.p, s.kind, s.tw, s.tside, s.thin, s.walls, s.grid_box, s.escape_box,
                                 s.start, s.nbr, s.list_pos, s.n_prev, s.counts, s.deepest, s.load_sum, s.p_sum,
                                 s.share_csr, s.loads_csr, c, dt, s.gravity[0], s.gravity[1], model.SOURCES[source],
                                 extra, rtol, maxiter, numba.get_num_threads(), s.clock)
        if timers is not None:  # the stages' share of the call's time, from the cycles each took
            spent = s.clock.sum()
            timers += (time.perf_counter() - t0) * (s.clock / spent if spent > 0 else np.array([1.0, 0.0, 0.0]))
        if failed:
            s.solve_error = pressure.ZERO_DIAGONAL
    else:
        done, bad, resid, its, pos, vel, p, surf, ps, dist, lists = _step_python(s, dt, source, cfg, timers, c, extra)
    if not done:
        return (4, -1, -1), np.inf, its
    s.pair_state = (ps, dist) + tuple(lists)
    s.pos, s.vel, s.p, s.surf = pos, vel, p, surf
    s.sum_time += dt  # wall loads: the momentum exchanged over a sample interval, not one step's force
    return bad, resid, its


def _step_python(s, dt, source, cfg, timers, c, extra):
    """step with any other pressure solver (pressure.solve_csr from Python between model.predict and model.correct).
    Returns (done, bad, residual, iterations, pos, vel, p, surf, ps, dist, gradient's lists)."""
    t0 = time.perf_counter()
    (s.start, s.nbr, s.list_pos, s.n_prev, ps, vs, dist, surf, normal, p_dir, row, indptr, indices, data, rhs,
     x0) = model.predict(s.pos, s.vel, s.p, s.kind, s.tw, s.tside, s.thin, s.walls, s.grid_box, s.start, s.nbr,
                         s.list_pos, s.n_prev, s.counts, c, dt, s.gravity[0], s.gravity[1], model.SOURCES[source], extra)
    t1 = time.perf_counter()
    try:
        x, resid, its = pressure.solve_csr(indptr, indices, data, rhs, cfg["pressure.solver"], cfg["pressure.rtol"],
                                           cfg["pressure.maxiter"], x0)
    except (RuntimeError, ValueError, ArithmeticError) as err:  # e.g. SuperLU "matrix is exactly singular"
        x, resid, its = np.full(len(rhs), np.nan), np.inf, 0
        s.solve_error = str(err)
    t2 = time.perf_counter()
    lists = s.start, s.nbr
    done, pos, vel, p, bad = False, s.pos, s.vel, s.p, (4, -1, -1)
    if np.isfinite(resid):
        done, pos, vel, p, bad, s.start, s.nbr, s.list_pos = model.correct(
            s.pos, ps, vs, x, row, p_dir, dist, surf, normal, s.kind, s.tw, s.tside, s.thin, s.walls, s.grid_box,
            s.escape_box, s.start, s.nbr, s.list_pos, s.counts, s.deepest, s.load_sum, s.p_sum, s.share_csr,
            s.loads_csr, c, dt)
    if timers is not None:
        timers += (t1 - t0, t2 - t1, time.perf_counter() - t2 if done else 0.0)
    return done, bad, resid, its, pos, vel, p, surf, ps, dist, lists


def solve(tank, cfg, variant, spacing, t_end, probes, start=None, log=print, threads=None, rest_settings=None):
    """Run MPS with source term ``variant`` on ``tank`` until the liquid is at rest (isaflow.rest) or for
    ``t_end`` s of physical time, whichever comes first.

    spacing l0 [cm]; probes (K, 2) cm; start None (liquid block at rest in the first vessel, depth
    tank.depth rounded to whole rows) or dict(pos, vel, steps, sim_time[, initial_depth]) of the run this
    one continues (the walls are this tank's; the chain's clock and step count go on).
    Snapshots (driver.Recording): every time.snapshot_single s in a single vessel, time.snapshot_flow s in a tank
    of vessels, within time.snapshot_megabytes.  threads: numba threads of the particle
    loops (None: numba's current setting; results do not depend on it).  rest_settings: dict
    (energy_ratio, window) (None: config/rest.yaml).  Wall loads (contacts) are the mean panel forces over
    the last settings 'time.average_window' s.  Returns a contract.Result.
    """
    if variant not in model.SOURCES:
        raise ValueError(f"unknown MPS source term '{variant}' (choose from {', '.join(model.SOURCES)})")
    threads = numba.get_num_threads() if threads is None else int(threads)
    before = numba.get_num_threads()
    numba.set_num_threads(threads)
    try:
        return _solve(tank, cfg, variant, float(spacing), t_end, probes, start, log, threads,
                      rest.load() if rest_settings is None else rest_settings)
    finally:
        numba.set_num_threads(before)


class _Stepper:
    """MPS on a tank for driver.drive: one advance is one step (its time step dt0, or shorter by the velocity
    Courant condition), a diagnostic sample every time.sample_interval s of simulated time."""

    def __init__(self, tank, cfg, variant, l0, t_end, probes, start, threads):
        self.tank, self.cfg, self.variant, self.l0, self.t_end, self.threads = tank, cfg, variant, l0, t_end, threads
        xr, floor = tank.first_vessel
        if start is None:
            fpos = boundary.liquid_block(xr, floor, tank.depth, l0, tank.vessel_polygon(0), tank.walls)
            if len(fpos) < 2:
                raise InputError(f"{tank.path}: field 'liquid.depth': {len(fpos)} cell(s) of l0 = {l0:.3g} cm lie half "
                                 f"a cell inside the first vessel below the depth; a liquid needs at least 2")
            self.step0, self.t0 = 0, 0.0
            fvel = np.zeros_like(fpos)
            self.depth0 = rows_depth(tank, l0)
            self.origin = "lattice at rest"
        else:
            fpos, fvel = np.asarray(start["pos"], float), np.asarray(start["vel"], float)
            self.step0, self.t0 = int(start["steps"]), float(start["sim_time"])
            self.depth0 = float(start.get("initial_depth", rows_depth(tank, l0)))
            self.origin = str(start.get("origin", "given state"))
        self.s = s = State(tank, cfg, l0, fpos, fvel)
        self.pos0 = s.pos[: s.nf].copy()
        self.dt0 = dt0 = time_step(tank, l0, cfg["time.courant"])
        self.vcfl = cfg["time.velocity_courant"]
        self.nsteps = nsteps = int(np.ceil(t_end / dt0 - 1e-9))  # steps at the base time step
        every = max(1, int(round(cfg["time.sample_interval"] / dt0)))
        self.sample_dt = sample_dt = every * dt0  # s between samples (every base steps, as many shorter ones as it takes)
        self.tol = 1e-6 * dt0
        self.elapsed, self.next_sample, self.dt_min, self.short_steps = 0.0, sample_dt, dt0, 0
        self.probes = np.asarray(probes, float).reshape(-1, 2)
        self.rec = {k: [] for k in ("time", "pair", "panel", "probe", "rms", "vmax", "energy", "count", "resid",
                                    "iters", "surf")}
        self.fail_tol = cfg["pressure.rtol"] * cfg["pressure.fail_factor"]
        self.status, self.max_resid, self.iters = None, 0.0, []
        self.timers = np.zeros(3)
        # (t, interval mean)
        self.p_means = collections.deque(maxlen=int(np.ceil(cfg["time.average_window"] / sample_dt)) + 2)
        self.k = 0
        self.t = self.t0
        self.resid = self.its = None

    def advance(self):
        """One step; (status, message) if it failed (nonfinite, escaped, solver_failed), else None."""
        s, l0, dt0, step0 = self.s, self.l0, self.dt0, self.step0
        self.k += 1
        k = self.k
        dt = dt0
        if self.vcfl > 0.0:  # Courant condition on the largest liquid speed: u_max dt / l0 <= vcfl
            umax = float(np.sqrt(np.max((s.vel[: s.nf] ** 2).sum(1), initial=0.0)))
            if umax * dt0 > self.vcfl * l0:
                dt = self.vcfl * l0 / umax
                self.dt_min = min(self.dt_min, dt)
                self.short_steps += 1
        bad, resid, its = step(s, dt, self.variant, self.cfg, self.timers)
        self.resid, self.its = resid, its
        self.max_resid = max(self.max_resid, resid)
        self.iters.append(its)
        self.elapsed += dt
        self.t = self.t0 + self.elapsed
        status = None
        if bad[0] == 1:
            status, message = "nonfinite", f"step {step0 + k}: particle {bad[1]} has a non-finite position or velocity"
        elif bad[0] == 2:
            status, message = ("escaped", f"step {step0 + k}: particle {bad[1]} crossed wall "
                                          f"'{self.tank.wall_names[bad[2]]}' (more than {s.graze_depth:.3g} cm past it)")
        elif bad[0] == 3:
            x, y = s.pos[bad[1]]
            vx, vy = s.vel[bad[1]]
            where = "over the top" if y > s.escape_box[3] + s.graze_depth else "through a side or the bottom"
            status, message = "escaped", (f"step {step0 + k}: particle {bad[1]} left the walls' bounding box by more "
                                          f"than {s.graze_depth:.3g} cm ({where}: at ({x:.1f}, {y:.1f}) cm, velocity "
                                          f"({vx:.0f}, {vy:.0f}) cm/s)")
        elif bad[0] == 4 or not resid <= self.fail_tol:
            status, message = "solver_failed", (f"step {step0 + k}: pressure solve residual {resid:.3g} > "
                                                f"{self.fail_tol:.3g} after {its} iterations {s.solve_error}").strip()
        self.status = status
        return (status, message) if status else None

    def spent(self):
        return self.elapsed >= self.nsteps * self.dt0 - self.tol

    def fraction_done(self):
        return self.elapsed / (self.nsteps * self.dt0)

    def clock(self):
        """(chain time s, chain step) of the current state (driver.drive's snapshots)."""
        return self.t, self.step0 + self.k

    def state(self):
        """Copies of the liquid's positions, velocities and pressures (driver.drive's snapshots)."""
        s = self.s
        return {"pos": s.pos[: s.nf].copy(), "velocity": s.vel[: s.nf].copy(), "pressure": s.p[: s.nf].copy()}

    def recording(self):
        """The driver's Recording of this run: snapshots every time.snapshot_single s (single vessel) or
        time.snapshot_flow s (a tank of vessels), within time.snapshot_megabytes; the tank's walls, vessels
        and box; the strip width l0 of the free surface."""
        flow = len(self.tank.spec.get("vessels", [])) > 1
        cfg = self.cfg
        return driver.Recording(cfg["time.snapshot_flow"] if flow else cfg["time.snapshot_single"],
                                cfg["time.snapshot_megabytes"], self.s.walls, self.tank.vessels,
                                tuple(self.s.escape_box), self.l0)

    def record(self):
        """A diagnostic sample when one is due (and at the run's last step).
        Returns (t, e) of the sample for the rest monitor, or None."""
        s, rec, t, tol = self.s, self.rec, self.t, self.tol
        sample = None
        if self.elapsed >= self.next_sample - tol or self.status or self.spent():
            while self.next_sample <= self.elapsed + tol:
                self.next_sample += self.sample_dt
            v = s.vel[: s.nf]
            speed2 = (v**2).sum(1)
            e = rest.energy_ratio(0.5 * speed2.sum() * s.weight / units.G, s.weight * s.nf, self.depth0)
            sample = t, e
            rec["time"].append(t)
            pair, panel, p_mean = s.take_means()
            rec["pair"].append(pair)
            rec["panel"].append(panel)
            self.p_means.append((t, p_mean))
            rec["probe"].append(model.probe_pressure(s.pos, s.p, s.kind, self.probes, s.re_n))
            rec["rms"].append(np.sqrt(speed2.mean()))
            rec["vmax"].append(np.sqrt(speed2.max()))
            rec["energy"].append(e)
            rec["count"].append(vessel_counts(s.pos[: s.nf], self.tank.vessels))
            rec["resid"].append(self.resid)
            rec["iters"].append(self.its)
            rec["surf"].append(int(s.surf[: s.nf].sum()))
        return sample

    def rest_message(self, monitor):
        return (f"step {self.step0 + self.k}: t = {self.t:.3f} s, at rest: kinetic energy / (W h) below "
                f"{monitor.limit:g} since t = {monitor.time_to_rest():.3f} s ({monitor.window:g} s window)")

    def _window_energy(self, monitor):
        """(mean e, max e, rms speed [cm/s] of the mean) over the last rest window of samples."""
        e_mean, e_max = rest.window_stats(np.array(self.rec["time"]), np.array(self.rec["energy"]), monitor.window)
        return e_mean, e_max, rest.speed_at(e_mean, self.depth0)  # rms speed of the window's mean kinetic energy

    def limit_message(self, monitor):
        e_mean, e_max, rms_window = self._window_energy(monitor)
        return (f"step {self.step0 + self.k}: t = {self.t0 + self.elapsed:.3f} s (time limit), kinetic energy / (W h) "
                f"over the last {monitor.window:g} s: mean {e_mean:.3g}, max {e_max:.3g} (rms speed "
                f"{rms_window:.3g} cm/s; rest: below {monitor.limit:g} for {monitor.window:g} s)")

    def progress(self, monitor):
        rec = self.rec
        return (f"mps {self.variant} l0={self.l0:g} cm: step {self.k}, t = {self.t:.3f} s of "
                f"{self.t0 + self.nsteps * self.dt0:.3f} s, rms speed {rec['rms'][-1] if rec['rms'] else 0:.3g} cm/s, "
                f"e = {monitor.last:.3g}")

    def result(self, run):
        """contract.Result of the run."""
        s, rec, monitor = self.s, self.rec, run.monitor
        times = np.array(rec["time"])
        pairwise = s.grad_mode in model.PAIRWISE  # momentum exchange is defined: the pair forces are the contacts
        panels = np.array(rec["pair" if pairwise else "panel"])
        window = times >= times[-1] - self.cfg["time.average_window"] + 1e-12
        p_window = [q for tq, q in self.p_means if tq >= times[-1] - self.cfg["time.average_window"] + 1e-12]
        fields = {
            "pressure": (("particle",), s.p[: s.nf].copy(), "N cm-2", "pressure of each liquid particle at the end"),
            "pressure_mean": (("particle",), np.mean(p_window, axis=0), "N cm-2",
                              "pressure of each liquid particle, mean over the steps of the averaging window (the pressure "
                              "alternates from step to step)"),
            "velocity": (("particle", "xy"), s.vel[: s.nf].copy(), "cm s-1", "velocity of each liquid particle at the end"),
        }
        rms_window = self._window_energy(monitor)[2]
        return Result(
            method="mps", variant=self.variant, pos0=self.pos0, pos=s.pos[: s.nf].copy(), weight=np.full(s.nf, s.weight),
            contact_wall=s.panel_wall, contact_point=s.panel_centre, contact_force=panels[window].mean(0),
            status=run.status, message=run.message, steps=self.step0 + self.k, start_step=self.step0,
            wall_time=run.wall_time, force_evals=self.k, residual=rms_window,
            residual_name=f"rms speed over the last {monitor.window:g} s", residual_units="cm s-1",
            sim_time=self.t0 + self.elapsed, history=self._history(times, panels, window, pairwise), fields=fields,
            params=self._params(run, pairwise))

    def _history(self, times, panels, window, pairwise):
        """The run file's sample_* variables (the driver adds the snapshots)."""
        rec, s = self.rec, self.s
        hist = {
            "sample_time": (("sample",), times, "s", "time of sample"),
            "sample_panel_force": (("sample", "contact", "xy"), panels, "N",
                                 "force of each wall panel on the liquid, the contacts' reading: " + ("pair forces (sample_pair_force)"
                                 if pairwise else "panel pressures (sample_panel_pressure_force; this gradient's pair terms are "
                                 "not antisymmetric, so they are no momentum exchange)")),
            "sample_pair_force": (("sample", "contact", "xy"), np.array(rec["pair"]), "N",
                                "force of each wall panel's boundary particles on the liquid: the wall-liquid pair terms of "
                                "the pressure gradient (pair-force reading, model.wall_forces), mean over the steps since the "
                                "previous sample (momentum exchanged / interval)"),
            "sample_panel_pressure_force": (("sample", "contact", "xy"), np.array(rec["panel"]), "N",
                                          "force of each wall panel on the liquid: first-row wall pressure times the wall "
                                          "length it faces (panel reading), mean over the steps since the previous sample"),
            "sample_probe_pressure": (("sample", "probe"), np.array(rec["probe"]).reshape(len(times), -1), "N cm-2", "pressure at fixed probe",
                                    {"missing": "no liquid particle within the probe's radius (a dry probe)"}),
            "sample_wall_resultant": (("sample", "wall", "xy"),
                                      np.array([wall_resultants(s.panel_wall, f, len(s.walls)) for f in panels])
                                      .reshape(len(times), len(s.walls), 2), "N",
                                      "force of each wall on the liquid: sample_panel_force summed over its panels"),
            "sample_rms_speed": (("sample",), np.array(rec["rms"]), "cm s-1", "rms speed of the liquid particles"),
            "sample_max_speed": (("sample",), np.array(rec["vmax"]), "cm s-1", "largest liquid particle speed"),
            "sample_energy_ratio": (("sample",), np.array(rec["energy"]), "1", "kinetic energy / (W h), isaflow.rest"),
            "sample_vessel_count": (("sample", "vessel"), np.array(rec["count"]), "1", "particles per vessel"),
            "sample_solve_residual": (("sample",), np.array(rec["resid"]), "1", "relative residual of the pressure solve"),
            "sample_solve_iterations": (("sample",), np.array(rec["iters"]), "1", "iterations of the pressure solve"),
            "sample_surface_count": (("sample",), np.array(rec["surf"]), "1", "liquid particles on the free surface"),
            "probe_point": (("probe", "xy"), self.probes, "cm", "pressure probe position"),
            "in_window": (("sample",), window.astype(np.int8), "1", "1 if the sample is in the averaging window"),
        }
        return hist

    def _params(self, run, pairwise):
        """The run file's attributes (settings, counters, the tank difference; the driver adds the rest ones)."""
        s, cfg, tank, l0, depth0, timers = self.s, self.cfg, self.tank, self.l0, self.depth0, self.timers
        e_mean, e_max, _ = self._window_energy(run.monitor)
        nb = np.bincount(s.kind, minlength=3)
        rows_note = (f"depth rounded to whole rows: {depth0:.4g} cm (tank {tank.depth:g} cm), weight held at {tank.weight:g} N"
                     if abs(depth0 - tank.depth) > 1e-9 else "none")
        return {  # the settings themselves reach the run file under their dotted keys (run.write); these are derived
            "spacing_cm": l0, "dt_s": self.dt0, "min_dt_s": self.dt_min, "short_steps": self.short_steps,
            "rho0_N_s2_cm4": s.rho0, "particle_weight_N": s.weight,
            "re_density_cm": s.re_n, "re_gradient_cm": s.re_g, "re_laplacian_cm": s.re_l, "re_surface_cm": s.re_s,
            "n0_density": s.n0_n, "n0_laplacian": s.n0_l, "n0_gradient": s.n0_g, "n0_surface": s.n0_s,
            "gradient_norm": s.n_grad, "lambda_cm2": s.lam, "max_solve_residual": self.max_resid,
            "mean_solve_iterations": float(np.mean(self.iters)), "time_limit_s": float(self.t_end),
            "wall_particles": int(nb[model.WALL]), "dummy_particles": int(nb[model.DUMMY]),
            "thin_walls": ",".join(n for n, f in zip(tank.wall_names, s.thin_mask) if f) or "none",
            "time_predict_s": timers[0], "time_solve_s": timers[1], "time_correct_s": timers[2],
            "list_builds": s.builds,
            "collision_distance_cm": cfg["model.collision_distance"] * l0, "panel_length": cfg["walls.panel_length"],
            "graze_depth_cm": s.graze_depth, "graze_steps": s.grazes, "deepest_graze_cm": s.deepest_graze,
            "reflect_steps": s.reflect_steps, "reflected_particles": s.reflections,
            "escapes": int(run.status == "escaped"), "threads": self.threads, "start_state": self.origin,
            "layer_pitch": l0, "held_weight": float(s.weight * s.nf), "initial_depth": depth0,
            "tank_difference": rows_note,
            "final_rms_speed_cm_s": float(np.sqrt((s.vel[: s.nf] ** 2).sum(1).mean())),
            "window_energy_ratio_mean": e_mean, "window_energy_ratio_max": e_max,
            "wall_load_reading": "pair forces" if pairwise else "panel pressures",
        }


def _solve(tank, cfg, variant, l0, t_end, probes, start, log, threads, rest_cfg):
    """Set up the run (_Stepper) and drive it (driver.drive) -> contract.Result; arguments as solve's."""
    stepper = _Stepper(tank, cfg, variant, l0, t_end, probes, start, threads)
    return driver.drive(stepper, rest_cfg, log, recording=stepper.recording())
