"""A periodic block of the WCSPH liquid, no walls, no gravity: the tensile-instability test.

marko2017 (sections 1-2) says SPH particles under tension (P < 0) "eventually become unstable regardless
of the size of time-integration steps" and clump.  The claims registry's test (claim mar-1-spam-tensile,
input tension_test_setup) stretches the liquid lattice of a tank run uniformly by ``settings.stretch``
(linear strain: spacing x (1 + stretch), density / (1 + stretch)^2), perturbs every particle by a random
displacement of ``settings.perturbation`` spacings (seed ``settings.seed``) and lets it evolve at rest:
a stretched, periodic liquid is an exact equilibrium at uniform negative pressure, so any growth of the
perturbation is the instability.  The box is the tank's liquid region (first vessel width x depth) made
periodic, stretched with the lattice; the tank's walls are not used and nothing presses on them.

The physics is the tank runs' (kernels.kernel_wf: eq. 4's cubic spline or Wendland C2; eq. 9 in its
symmetric form with Monaghan's viscosity, kernels.pair_momentum; the equation of state eos.pressure_of,
negative pressures as ``settings.negative_pressure`` says; continuity density), the step the same
kick-drift-kick (velocity Verlet) with the continuity density advanced at the drifted positions and the
half-step velocities; dt = cfl h / c0.  Pairs by a periodic cell list (minimum image), every step.
Units cm, N, s.
"""

import math

import numpy as np
from ...core.jit import njit

from ... import driver
from ...contract import Result
from ...core import smoothing
from ...core.units import DENSITY_2D, G, VELOCITY
from .eos import pressure_of
from .kernels import kernel_wf, pair_momentum
from .particles import lattice_shape, liquid_lattice

JIT = dict(cache=True, nogil=True)
OK, NONFINITE = 0, 1


@njit(**JIT)
def cells(x, box, ncx, ncy, head, nxt):
    """Periodic cell list: head (ncx ncy,) first particle of each cell, nxt (n,) the next one (-1 ends);
    particles are pushed in index order, so a cell lists them in decreasing index (deterministic)."""
    head[:] = -1
    for a in range(x.shape[0]):
        cx = int(math.floor(x[a, 0] / box[0] * ncx)) % ncx
        cy = int(math.floor(x[a, 1] / box[1] * ncy)) % ncy
        c = cy * ncx + cx
        nxt[a] = head[c]
        head[c] = a


@njit(**JIT)
def rates(x, v, rho, p, box, ncx, ncy, head, nxt, par, acc, drho):
    """acc (n, 2) [cm/s^2] = -sum_b m (P_a/rho_a^2 + P_b/rho_b^2 + Pi_ab) grad_a W_ab and drho (n,) =
    sum_b m v_ab . grad_a W_ab over the periodic neighbours (minimum image).  par: (h, m, c0, alpha, kind,
    norm).  Returns the smallest pair distance [cm]."""
    h, m, c0, alpha = par[0], par[1], par[2], par[3]
    kind = int(par[4])
    c = par[5] / (h * h)
    ih = 1.0 / h
    lim = 4.0 * h * h
    dmin2 = np.inf
    for a in range(x.shape[0]):
        cxa = int(math.floor(x[a, 0] / box[0] * ncx)) % ncx
        cya = int(math.floor(x[a, 1] / box[1] * ncy)) % ncy
        ax = 0.0
        ay = 0.0
        dr = 0.0
        pa = p[a] / (rho[a] * rho[a])
        for oy in range(-1, 2):
            for ox in range(-1, 2):
                b = head[((cya + oy) % ncy) * ncx + (cxa + ox) % ncx]
                while b >= 0:
                    if b != a:
                        dx = x[a, 0] - x[b, 0]
                        dy = x[a, 1] - x[b, 1]
                        dx -= box[0] * np.rint(dx / box[0])
                        dy -= box[1] * np.rint(dy / box[1])
                        r2 = dx * dx + dy * dy
                        if r2 < dmin2:
                            dmin2 = r2
                        if r2 < lim:
                            _, g = kernel_wf(r2, ih, kind, c)
                            dvx = v[a, 0] - v[b, 0]
                            dvy = v[a, 1] - v[b, 1]
                            vr = dvx * dx + dvy * dy
                            coef = -m * pair_momentum(pa, p[b] / (rho[b] * rho[b]), vr, r2, h, alpha, c0,
                                                      0.5 * (rho[a] + rho[b])) * g
                            ax += coef * dx
                            ay += coef * dy
                            dr += m * vr * g
                    b = nxt[b]
        acc[a, 0] = ax
        acc[a, 1] = ay
        drho[a] = dr
    return np.sqrt(dmin2)


@njit(**JIT)
def advance(x, v, rho, p, acc, box, ncx, ncy, par, eos, dt, n_steps, diag):
    """n_steps velocity-Verlet steps of the periodic block (acc must hold the current state's).
    eos: (rho0, c0, gamma, tait, clamp).  diag (3,) out: smallest pair distance over the steps [cm],
    kinetic energy / m at the end [cm^2/s^2], largest move of a particle in one step [cm].
    Returns (code, steps done)."""
    n = x.shape[0]
    head = np.empty(ncx * ncy, np.int64)
    nxt = np.empty(n, np.int64)
    drho = np.empty(n)
    half = 0.5 * dt
    diag[0] = np.inf
    for step in range(n_steps):
        for a in range(n):
            v[a, 0] += half * acc[a, 0]
            v[a, 1] += half * acc[a, 1]
            mv = dt * np.sqrt(v[a, 0] ** 2 + v[a, 1] ** 2)
            if not mv <= diag[2]:
                diag[2] = mv
            x[a, 0] = (x[a, 0] + dt * v[a, 0]) % box[0]
            x[a, 1] = (x[a, 1] + dt * v[a, 1]) % box[1]
        cells(x, box, ncx, ncy, head, nxt)
        # the continuity rate at the drifted positions and half-step velocities (the tank runs' order)
        rates(x, v, rho, p, box, ncx, ncy, head, nxt, par, acc, drho)
        for a in range(n):
            rho[a] += dt * drho[a]
            p[a] = pressure_of(rho[a], eos[0], eos[1], eos[2], eos[3] > 0, eos[4] > 0)
        dmin = rates(x, v, rho, p, box, ncx, ncy, head, nxt, par, acc, drho)
        diag[0] = min(diag[0], dmin)
        ke = 0.0
        for a in range(n):
            v[a, 0] += half * acc[a, 0]
            v[a, 1] += half * acc[a, 1]
            ke += 0.5 * (v[a, 0] ** 2 + v[a, 1] ** 2)
        diag[1] = ke
        if not np.isfinite(ke) or not np.isfinite(dmin):
            return NONFINITE, step + 1
    return OK, n_steps


def nonaffine(x, x0, box):
    """Largest distance [cm] of a particle from its start x0 (the stretched lattice) after the mean
    displacement is removed (minimum image in the periodic box)."""
    d = x - x0
    d -= box * np.rint(d / box)
    d -= d.mean(0)
    return float(np.sqrt((d**2).sum(1)).max())


def run(tank, s, resolution, log=lambda msg: None):
    """The periodic block of the tank's liquid lattice (module docstring) -> contract.Result (status
    step_limit at settings.t_max_block, nonfinite otherwise; no wall contacts), through the one run driver."""
    stepper = _BlockStepper(tank, s, resolution)
    res = driver.drive(stepper, log=log)
    log(res.message)
    return res


class _BlockStepper:
    """The periodic block for driver.drive: one advance is one chunk of settings.chunk_time, a sample after each
    (no rest test: the block runs to t_max_block unless a value becomes non-finite)."""

    t0 = 0.0

    def __init__(self, tank, s, resolution):
        x0, x1 = tank.vessels[0][1]
        width, depth = x1 - x0, tank.depth
        nx, ny = lattice_shape(width, depth, resolution.get("particles"), resolution.get("spacing"))
        pos, (dx, dy) = liquid_lattice(0.0, 0.0, width, depth, nx, ny)
        e = s["stretch"]
        self.box = box = np.array([width, depth]) * (1.0 + e)
        self.lattice = pos * (1.0 + e)
        self.spacing = math.sqrt(dx * dy) * (1.0 + e)
        rng = np.random.default_rng(s["seed"])
        self.x = self.lattice + s["perturbation"] * self.spacing * rng.uniform(-1.0, 1.0, self.lattice.shape)
        kind = smoothing.kernel_id(s["kernel"])
        h = s["h_factor"] * math.sqrt(dx * dy)
        c0 = s["sound_speed_factor"] * math.sqrt(2 * G * s["max_drop"])
        self.mass = mass = tank.weight / (nx * ny) / G
        rho_ref = mass / (dx * dy)  # the continuity density of the unstretched lattice (as the tank runs)
        if s["density"] != "continuity" or s.get("delta", 0.0) > 0.0:
            raise ValueError("periodic block: only the continuity density without density diffusion is implemented "
                             "(settings.density, settings.delta)")
        self.ncx, self.ncy = ncx, ncy = int(box[0] // (2 * h)), int(box[1] // (2 * h))
        if min(ncx, ncy) < 3:
            raise ValueError(f"periodic block: {box[0]:.3g} x {box[1]:.3g} cm holds fewer than 3 x 3 cells of 2h = "
                             f"{2 * h:.3g} cm (the minimum image needs them)")
        n = len(self.x)
        self.v = np.zeros_like(self.x)
        self.rho = np.full(n, rho_ref / (1.0 + e) ** 2)
        self.eos = eos = np.array([rho_ref, c0, s["gamma"], float(s["eos"] == "tait"),
                                   float(s["negative_pressure"] == "clamp")])
        self.p = np.array([pressure_of(r, *eos[:3], eos[3] > 0, eos[4] > 0) for r in self.rho])
        self.p_start = float(self.p.mean())
        self.par = np.array([h, mass, c0, s["alpha"], float(kind), smoothing.NORM[kind, 2]])
        self.dt = s["cfl"] * h / c0
        self.acc, drho = np.zeros_like(self.x), np.zeros(n)
        head, nxt = np.empty(ncx * ncy, np.int64), np.empty(n, np.int64)
        cells(self.x, box, ncx, ncy, head, nxt)
        dmin0 = rates(self.x, self.v, self.rho, self.p, box, ncx, ncy, head, nxt, self.par, self.acc, drho)
        self.n_total = max(1, int(round(s["t_max_block"] / self.dt)))
        self.n_chunk = max(1, int(round(s["chunk_time"] / self.dt)))
        self.diag = np.zeros(3)
        self.rec = {k: [] for k in ("t", "nonaffine", "dmin", "vrms", "p_mean")}
        self.s, self.nx, self.ny, self.dx, self.dy, self.h, self.c0, self.rho_ref = s, nx, ny, dx, dy, h, c0, rho_ref
        self.done = 0
        self._sample(0.0, dmin0)

    def _sample(self, t, dmin):
        rec, n = self.rec, len(self.x)
        rec["t"].append(t)
        rec["nonaffine"].append(nonaffine(self.x, self.lattice, self.box) / self.spacing)
        rec["dmin"].append(dmin / self.spacing)
        rec["vrms"].append(math.sqrt(2 * self.diag[1] / n) if np.isfinite(self.diag[1]) else np.inf)
        rec["p_mean"].append(float(self.p.mean()))

    def advance(self):
        k = min(self.n_chunk, self.n_total - self.done)
        code, steps = advance(self.x, self.v, self.rho, self.p, self.acc, self.box, self.ncx, self.ncy, self.par,
                              self.eos, self.dt, k, self.diag)
        self.done += steps
        if code == NONFINITE:
            return "nonfinite", f"a non-finite value at step {self.done} (t = {self.done * self.dt:.4g} s)"
        return None

    def record(self):
        self._sample(self.done * self.dt, self.diag[0])
        return None  # no rest sample

    def spent(self):
        return self.done >= self.n_total

    def fraction_done(self):
        return self.done / self.n_total

    def limit_message(self, monitor):
        return (f"periodic block, {self.done} steps of {self.dt:.4g} s to t = {self.done * self.dt:.4g} s "
                "(no rest test)")

    def progress(self, monitor):
        return f"sph periodic block: t = {self.done * self.dt:.3f} s, step {self.done} of {self.n_total}"

    def result(self, run):
        s, rec, box, e, n = self.s, self.rec, self.box, self.s["stretch"], len(self.x)
        dx, dy, done, dt = self.dx, self.dy, self.done, self.dt
        na = np.array(rec["nonaffine"])
        history = {
            "sample_time": (("sample",), np.array(rec["t"]), "s", "time of the sample"),
            "nonaffine_over_dx_t": (("sample",), na, "1", "largest distance of a particle from its stretched-lattice "
                                    "start, mean drift removed, / spacing"),
            "min_pair_over_dx_t": (("sample",), np.array(rec["dmin"]), "1",
                                   "smallest distance between two particles since the last sample / spacing"),
            "sample_rms_speed": (("sample",), np.array(rec["vrms"]), VELOCITY, "rms speed"),
            "sample_mean_pressure": (("sample",), np.array(rec["p_mean"]), "N cm-2", "mean particle pressure"),
        }
        fields = {
            "pressure": (("particle",), self.p.copy(), "N cm-2", "particle pressure (equation of state)"),
            "density": (("particle",), self.rho.copy(), DENSITY_2D, "particle density"),
            "velocity": (("particle", "xy"), self.v.copy(), VELOCITY, "particle velocity"),
        }
        params = {}  # the settings themselves reach the run file under their dotted keys (run.write)
        params.update(
            domain="periodic_block", box_width=float(box[0]), box_height=float(box[1]), cell_dx=dx * (1 + e),
            cell_dy=dy * (1 + e), smoothing_length=self.h, sound_speed=self.c0, dt=dt, particle_mass=self.mass,
            rho_ref=self.rho_ref, initial_pressure=self.p_start,
            max_nonaffine_over_dx=float(np.nanmax(na)) if np.isfinite(na).all() else math.inf,
            max_step_move_over_dx=float(self.diag[2]) / self.spacing, layer_pitch=dy * (1 + e),
            held_weight=float(self.mass * G * n), initial_depth=float(box[1]), t_max=s["t_max_block"], threads=1,
            tank_difference=f"periodic block without walls or gravity: the tank's liquid lattice ({self.nx} x {self.ny}) "
                            f"stretched by {e:g} in a periodic {box[0]:.4g} x {box[1]:.4g} cm box; the tank's walls "
                            "are not used (no wall loads)")
        return Result(
            method="sph", variant="custom", pos0=self.lattice, pos=self.x.copy(), weight=np.full(n, self.mass * G),
            contact_wall=np.zeros(0, int), contact_point=np.zeros((0, 2)), contact_force=np.zeros((0, 2)),
            status=run.status, message=run.message, steps=done, start_step=0, wall_time=run.wall_time,
            force_evals=2 * done + 1, residual=rec["vrms"][-1], residual_name="rms speed", residual_units=VELOCITY,
            sim_time=done * dt, history=history, fields=fields, params=params, spacing=self.spacing)


def warm_up():
    """Compile (or load from numba's cache) the block's kernels on a 4 x 4 lattice, so timings exclude it."""
    from ...tank import Tank

    tank = Tank("warm-up", {"name": "box", "walls": [{"name": "f", "from": [0, 0], "to": [4, 0]}],
                            "liquid": {"weight": 1.0, "depth": 4.0}}, "")
    s = dict(kernel="cubic_spline", h_factor=0.3, sound_speed_factor=1.0, max_drop=1.0, density="continuity", delta=0.0,
             gamma=7.0, eos="tait", negative_pressure="keep", alpha=0.1, cfl=0.1, stretch=0.0, perturbation=0.0,
             seed=0, t_max_block=1e-4, chunk_time=1e-4)
    run(tank, s, {"spacing": 1.0})
