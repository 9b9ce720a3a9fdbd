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
crossing the boundary and stop it from further travel").

The coupled loop is compiled (:func:`coupled`, run in stretches between records by isaflow.driver.drive through
:class:`Coupled`): one pair list of the water with the water and the ring (core.neighbours.build_pairs at 2 h
plus a skin, :func:`water_list`), rebuilt only when a particle has moved half the skin; the stop contacts are
the ring candidates of that list (ascending, as a search over every ring particle takes them); the ring steps
in the solid's 2D layout (kernels.relax, one step at a time).  Units cm, N, s.
"""

import numpy as np
from ...core.jit import njit

from isaflow import driver
from isaflow.core import smoothing as SM
from isaflow.core.neighbours import build_pairs
from isaflow.methods.sph.eos import pressure_of
from isaflow.methods.sph.kernels import kernel_wf, pair_momentum

from .kernels import NONFINITE, RUNNING, UNSTABLE, relax
from .solve import VARIANT_FLAGS, Stepper, log
from .vessel import geometry, pressure_state, radial

JIT = dict(cache=True, nogil=True)


@njit(**JIT)
def water_pressure(rho, rho0, c0, p0):
    """p0 + the SPH package's linear equation of state c0^2 (rho - rho0) [N/cm^2]."""
    return p0 + pressure_of(rho, rho0, c0, 1.0, False, False)


COUPLINGS = {"mirror_pressure": 0, "stop_at_boundary": 1}


@njit(**JIT)
def water_forces(pos, vel, rho, nw, m, h, kind, norm, K, rho0, p0, alpha, c0, fw, fs, drho, mirror=True):
    """Forces fw (nw, 2) on the water, fs (N - nw, 2) of the water on the ring [N], and drho/dt (nw,), from a pair
    list of its own (:func:`pair_forces` over :func:`water_list` at cutoff 2 h).

    pos, vel (N, 2): water first (nw), then the ring.  m: water particle mass; norm = sigma / h^2;
    K = rho0 c0^2 the bulk modulus (the equation of state takes c0).  mirror: the ring particles stand in the
    water's sums (coupling mirror_pressure); False: they do not (coupling stop_at_boundary, stop_contacts)."""
    pi, pj, npair, _, _ = water_list(pos, nw, 2.0 * h)
    pr2 = np.empty(nw)
    pressures(rho, rho0, c0, p0, pr2)
    pair_forces(pi, pj, npair, pos, vel, rho, pr2, nw, m, h, kind, norm, alpha, c0, mirror, fw, fs, drho)


@njit(**JIT)
def pressures(rho, rho0, c0, p0, pr2):
    """pr2 (nw,): each water particle's p / rho^2 (water_pressure) [N/cm^2 per (N s^2/cm^4)^2]."""
    for a in range(rho.shape[0]):
        pr2[a] = water_pressure(rho[a], rho0, c0, p0) / rho[a] ** 2


@njit(**JIT)
def water_list(pos, nw, rc):
    """The pairs closer than rc [cm] with a water particle (core.neighbours.build_pairs over pos (N, 2), water
    first), water first in each pair: (pi, pj, count, and the ring candidates of every water particle in
    ascending order, rows start (nw + 1,), ring (count,) indices into the ring)."""
    box = np.empty(4)
    box[0] = pos[:, 0].min()
    box[1] = pos[:, 1].min()
    box[2] = pos[:, 0].max() + 1e-9
    box[3] = pos[:, 1].max() + 1e-9
    pi, pj, npair = build_pairs(pos, box, rc)
    start = np.zeros(nw + 1, np.int32)
    m = 0
    for k in range(npair):
        a = pi[k]
        b = pj[k]
        if a >= nw and b >= nw:  # ring with ring: the solid's own links
            continue
        if a >= nw:
            a, b = b, a
        pi[m] = a
        pj[m] = b
        m += 1
        if b >= nw:
            start[a + 1] += 1
    for a in range(nw):
        start[a + 1] += start[a]
    ring = np.empty(start[nw], np.int32)
    fill = start[:nw].copy()
    for k in range(m):
        if pj[k] >= nw:
            ring[fill[pi[k]]] = pj[k] - nw
            fill[pi[k]] += 1
    for a in range(nw):  # ascending within each row (a few entries: insertion sort)
        for q in range(start[a] + 1, start[a + 1]):
            x = ring[q]
            r = q - 1
            while r >= start[a] and ring[r] > x:
                ring[r + 1] = ring[r]
                r -= 1
            ring[r + 1] = x
    return pi, pj, m, start, ring


@njit(**JIT)
def pair_list(pos, nw, rc):
    """(:func:`water_list` pairs as one (2, count) int32 array, ring rows start, ring)."""
    pi, pj, m, start, ring = water_list(pos, nw, rc)
    lst = np.empty((2, m), np.int32)
    lst[0, :] = pi[:m]
    lst[1, :] = pj[:m]
    return lst, start, ring


@njit(**JIT)
def pair_forces(pi, pj, npair, pos, vel, rho, pr2, nw, m, h, kind, norm, alpha, c0, mirror, fw, fs, drho):
    """The SPH pair sums of :func:`water_forces` over the list (pi, pj, npair) of :func:`water_list` (every
    pair within 2 h in it; farther ones are skipped), with the water's p / rho^2 (:func:`pressures`)."""
    fw[:, :] = 0.0
    fs[:, :] = 0.0
    drho[:] = 0.0
    ih = 1.0 / h
    for k in range(npair):
        a = pi[k]
        b = pj[k]
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
        if b < nw:
            rb = rho[b]
            pb = pr2[b]
        else:  # mirror: the water particle's own density and pressure
            rb = rho[a]
            pb = pr2[a]
        vr = dvx * dx + dvy * dy
        coef = -m * m * pair_momentum(pr2[a], pb, vr, r2, h, alpha, c0, 0.5 * (rho[a] + rb)) * g
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
    to fs (on the ring); contacts are taken one after the other (ascending ring particles), each on the velocity the
    previous ones left.  Returns the number of contacts that acted (:func:`stop_rows` over a list of its own)."""
    _, _, _, start, ring = water_list(np.concatenate((xw, xs)), xw.shape[0], reach)
    return stop_rows(xw, vw, xs, vs, m, dt, reach, start, ring, fw, fs)


@njit(**JIT)
def stop_rows(xw, vw, xs, vs, m, dt, reach, start, ring, fw, fs):
    """:func:`stop_contacts` over the ring candidates of every water particle (rows start, ring of
    :func:`water_list` at a cutoff of at least reach, ascending)."""
    acted = 0
    for a in range(xw.shape[0]):
        vx, vy = vw[a, 0], vw[a, 1]
        for q in range(start[a], start[a + 1]):
            b = ring[q]
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


@njit(**JIT)
def coupled(X, V, rho, pr2, nw, wpar, mirror, lst, start, ring, anchor, ref, target, free, mass, size, la, lb, L0, e,
            laxis, cnt, disk, E, nu, G, rho_s, poisson, shear, dt, n_steps, sig, strain, frc, pres, clock,
            vir, rot, grad, fw, fs, drho, vp, fc, fcs, diag):
    """n_steps coupled steps of water (X[:nw], V[:nw], rho) and ring (X[nw:], V[nw:], one step of kernels.relax
    in the 2D layout per coupled step, undamped, fixed dt [s]), as the section 4.4 loop: water forces (mirror: the ring in the
    water's sums; else the stop contacts, stop_rows), the ring's step under the water's forces, then the water's
    own step (symplectic Euler: velocity, position, density).

    wpar: (m, h, kind, norm, rho0, c0, p0, alpha, skin [cm], dx).  lst, start, ring: the pairs within 2 h + skin
    (:func:`pair_list`), rebuilt when a particle has moved skin / 2 since the positions anchor; pr2 (the water's
    p / rho^2), vp, fc, fcs: work space; diag: [pairs, list builds, stop contacts, largest water move in one step / dx].  Returns (steps
    done, ring status (kernels codes), water non-finite, lst, start, ring)."""
    m, h, kind, norm, rho0, c0, p0, alpha, skin, dx = wpar
    kind = int(kind)
    n = X.shape[0]
    xw, vw, xs, vs = X[:nw], V[:nw], X[nw:], V[nw:]
    nopush, nolinks, nobox = np.zeros(1, np.int32), np.zeros((1, 1), np.int32), np.zeros(4)  # the ring: no push
    for k in range(n_steps):
        for a in range(n):
            if (X[a, 0] - anchor[a, 0]) ** 2 + (X[a, 1] - anchor[a, 1]) ** 2 > 0.25 * skin * skin:
                lst, start, ring = pair_list(X, nw, 2.0 * h + skin)
                anchor[:, :] = X
                diag[1] += 1.0
                break
        npair = lst.shape[1]
        diag[0] = npair
        pressures(rho, rho0, c0, p0, pr2)
        pair_forces(lst[0], lst[1], npair, X, V, rho, pr2, nw, m, h, kind, norm, alpha, c0, mirror, fw, fs, drho)
        if not mirror:  # the paper's coupling: the contact forces that stop the water at the ring
            for a in range(nw):
                vp[a, 0] = vw[a, 0] + dt * fw[a, 0] / m
                vp[a, 1] = vw[a, 1] + dt * fw[a, 1] / m
            fc[:, :] = 0.0
            fcs[:, :] = 0.0
            diag[2] += stop_rows(xw, vp, xs, vs, m, dt, dx * (1 + 1e-9), start, ring, fc, fcs)
            for a in range(nw):
                fw[a, 0] += fc[a, 0]
                fw[a, 1] += fc[a, 1]
            for b in range(fs.shape[0]):
                fs[b, 0] += fcs[b, 0]
                fs[b, 1] += fcs[b, 1]
        code = relax(xs, vs, ref, target, free, mass, size, la, lb, L0, e, laxis, cnt, nolinks, disk, E, nu, G,
                     rho_s, 2, poisson, shear, 0, dt, 0.0, 1, 1, sig, strain, frc, pres, clock, fs, 0, 1, 0.0, vir,
                     rot, grad, xs, nopush, nopush, nobox)[1]
        vmax = 0.0
        finite = True
        for a in range(nw):
            vw[a, 0] += dt * fw[a, 0] / m
            vw[a, 1] += dt * fw[a, 1] / m
            xw[a, 0] += dt * vw[a, 0]
            xw[a, 1] += dt * vw[a, 1]
            rho[a] += dt * drho[a]
            vmax = max(vmax, np.sqrt(vw[a, 0] * vw[a, 0] + vw[a, 1] * vw[a, 1]))
            finite = finite and np.isfinite(rho[a]) and np.isfinite(vw[a, 0]) and np.isfinite(vw[a, 1])
        move = vmax * dt / dx
        if not move <= diag[3]:
            diag[3] = move
        if code == UNSTABLE or code == NONFINITE or not finite or not np.isfinite(move):
            return k + 1, code, not finite or not np.isfinite(move), lst, start, ring
    return n_steps, RUNNING, False, lst, start, ring


def water_sites(na, dx):
    """(M, 2) water particle positions [cm]: the lattice sites with i^2 + j^2 < na^2."""
    i, j = np.meshgrid(np.arange(-na, na + 1), np.arange(-na, na + 1), indexing="ij")
    inside = (i**2 + j**2) < na**2
    return dx * np.column_stack([i[inside], j[inside]]).astype(float)


SKIN = 0.1  # water pair-list skin / dx (inferred, a cost setting: the water moves ~1e-6 dx, one build per run)


class Coupled:
    """The coupled ring + water loop for isaflow.driver.drive: one advance is one compiled stretch of
    :func:`coupled` up to the next record (every ``every`` steps, and the paper's vessel.steps), the records
    taken in record(); the run's own outcomes (ring escaped, a non-finite value) end it, else its steps do."""

    t0 = 0.0

    def __init__(self, cfg, dt, steps, every):
        v = self.v = cfg["vessel"]
        dx = geometry(v)[0]
        self.st, self.inner = st, inner = pressure_state(cfg, damp=0)
        st.fext[:] = 0.0
        if dt > st.dt_max:
            raise ValueError(f"water_particles: dt {dt:.3g} s above the step rule dx / (4 c) = {st.dt_max:.3g} s (eq. 26)")
        self.ring = Stepper(st, 0.0, steps, dt=dt)  # the ring's 2D layout (its kernel arrays) and link geometry
        if not self.ring.flat:
            raise ValueError("water_particles: the ring must step in the 2D layout (z inert)")
        self.poisson, self.shear = VARIANT_FLAGS[st.variant]
        xw = water_sites(v["water_radius_particles"], dx)
        self.nw = nw = len(xw)
        self.rho0 = rho0 = v["rho_water_kg_m3"] * 1e-8  # kg/m^3 -> N s^2 / cm^4
        K, self.p0 = v["K_GPa"] * 1e5, v["pressure_Pa"] * 1e-4  # N/cm^2
        self.c0 = c0 = np.sqrt(K / rho0)
        self.m = m = rho0 * dx**2
        h = v["water_h_over_dx"] * dx
        kind = SM.kernel_id(v["water_kernel"])
        self.wpar = (m, h, float(kind), SM.NORM[kind, 2] / h**2, rho0, c0, self.p0, float(v["water_alpha"]),
                     SKIN * dx, dx)
        self.mirror = v.get("coupling", "mirror_pressure") != "stop_at_boundary"
        ns = st.block.n
        self.X = np.vstack([xw, self.ring.pos])  # water first, then the ring (the ring's kernel arrays: views)
        self.V = np.zeros_like(self.X)
        self.ring.pos, self.ring.vel = self.X[nw:], self.V[nw:]
        self.rho, self.pr2, self.drho = np.full(nw, rho0), np.zeros(nw), np.zeros(nw)
        self.fw, self.fs, self.vp, self.fc, self.fcs = (np.zeros((k, 2)) for k in (nw, ns, nw, nw, ns))
        self.lst, self.start, self.rows = pair_list(self.X, nw, 2.0 * h + SKIN * dx)
        self.anchor = self.X.copy()
        self.diag = np.array([0.0, 1.0, 0.0, 0.0])  # pairs, list builds, stop contacts, max water move / dx
        self.dt, self.steps, self.every, self.done = dt, steps, every, 0
        self.t, self.ui, self.pw = [0.0], [0.0], [self.p0]
        self.ring_all = np.ones(ns, bool)
        self.ur = [np.zeros(ns)]  # radial displacement of every ring particle at every record
        self.ur_paper = np.full(ns, np.nan)
        self.failed = None

    def advance(self):
        st, b, r, mat = self.st, self.st.block, self.ring, self.st.mat
        L0, e, cnt = b.geometry
        stop = min(self.steps, (self.done // self.every + 1) * self.every)
        if self.done < self.v["steps"]:
            stop = min(stop, self.v["steps"])
        k, code, water_bad, self.lst, self.start, self.rows = coupled(
            self.X, self.V, self.rho, self.pr2, self.nw, self.wpar, self.mirror, self.lst, self.start, self.rows,
            self.anchor, r.ref, r.target, r.free, st.mass, st.size, b.la, b.lb, L0, e, b.axis, cnt,
            st.disk, mat.E, mat.nu, mat.G, mat.rho, self.poisson, self.shear, self.dt, stop - self.done, r.sig,
            r.strain, r.frc, st.pres, st.clock, r.vir, r.rot, r.grad, self.fw, self.fs, self.drho, self.vp,
            self.fc, self.fcs, self.diag)
        self.done += k
        st.pos[:, :2], st.vel[:, :2], st.frc[:, :2] = r.pos, r.vel, r.frc
        st.sig[:, :4], st.strain[:, :2] = r.sig, r.strain
        st.fext[:, :2] = self.fs
        if code in (UNSTABLE, NONFINITE):
            self.failed = ("escaped", r.message("escaped")) if code == UNSTABLE else ("nonfinite", r.message("nonfinite"))
        elif water_bad:
            self.failed = ("nonfinite", f"water: non-finite value at step {self.done}")
        return self.failed

    def record(self):
        if self.failed is not None:
            return
        if self.done == self.v["steps"]:
            self.ur_paper = radial(self.st, self.ring_all)
        if self.done % self.every == 0:
            self.t.append(self.done * self.dt)
            self.ur.append(radial(self.st, self.ring_all))
            self.ui.append(self.ur[-1][self.inner].mean())
            self.pw.append(float(np.mean(self.p0 + self.c0 * self.c0 * (self.rho - self.rho0))))  # water_pressure

    def spent(self):
        return self.done >= self.steps

    def fraction_done(self):
        return self.done / self.steps if self.steps else 1.0

    def limit_message(self, monitor):
        return f"{self.steps} steps of {self.dt:.4g} s"

    def progress(self, monitor):
        return f"vessel with water: step {self.done} of {self.steps}"

    def result(self, run):
        self.st.wall_time = run.wall_time  # the coupled loop: water and ring
        return run


def coupled_history(cfg, dt, steps, every, outcome=None):
    """Undamped ring + SPH water from rest at p0, fixed step dt [s]: (t (M,) s, mean inner radial
    displacement (M,) cm, mean water pressure (M,) N/cm^2, ring state, inner mask, water density).
    Stops early when a ring particle escapes (moves a full width) or a value turns non-finite; outcome
    (dict, optional) receives 'status', 'message', 'steps' and 'water_max_move_over_dx' (the largest move
    of a water particle in one step / dx), the radial displacements 'ur' at every record and 'ur_paper' at
    the paper's step, 'contacts' (stop contacts that acted) and 'list_builds' (of the water's pair list)."""
    c = Coupled(cfg, dt, steps, every)
    run = driver.drive(c, log=log.info)
    status, message = (run.status, run.message)
    if outcome is not None:
        outcome.update(status=status, message=message, steps=c.done, water_max_move_over_dx=float(c.diag[3]),
                       ur=np.array(c.ur), ur_paper=c.ur_paper, contacts=int(c.diag[2]), list_builds=int(c.diag[1]))
    return np.array(c.t), np.array(c.ui), np.array(c.pw), c.st, c.inner, c.rho


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


def warmup():
    """Two coupled steps of a 3-particle-radius vessel with water under each coupling (compiles :func:`coupled`,
    :func:`pair_list` and the kernels they call)."""
    cfg = {"material": {"E_GPa": 207.0, "nu": 0.3, "rho_kg_m3": 7800.0},
           "vessel": {"dx_mm": 23.4, "ring_particles": 2, "water_radius_particles": 3, "pressure_Pa": 1e5,
                      "K_GPa": 2.15, "rho_water_kg_m3": 1000.0, "steps": 1, "solid_model": "objective",
                      "water_kernel": "cubic_spline", "water_h_over_dx": 1.2, "water_alpha": 0.02}}
    for coupling in COUPLINGS:
        coupled_history({**cfg, "vessel": {**cfg["vessel"], "coupling": coupling}}, 1e-7, 2, 1)
