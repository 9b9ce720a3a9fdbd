"""Weakly compressible SPH kernels (numba): pair passes and the whole step loop.

Arrays (units cm, N, s; masses N s^2/cm, densities N s^2/cm^4, pressures N/cm^2):
- x (n, 2): positions, rows 0..nf-1 liquid particles, rows nf..n-1 wall
  (boundary) particles, which never move;
- v (nf, 2) velocities; rho (n,) densities; p (n,) pressures;
- pairs (pi, pj, m): half list of core.neighbours.build_pairs over all
  particles within rc = 2 h + skin, wall-wall pairs dropped, pi always
  liquid (pj >= nf marks a wall particle), in runs of equal pi: every pass
  keeps pi's running sum in a register along a run (a run's particle is never
  pj inside its run, so every sum still adds the pairs in list order);
  the passes read pi, pj as unsigned (np.uint32) so that numba indexes
  without its negative-index wraparound;
- par (NPAR,) float64 settings, indices below (see :func:`pack`).

Equations: marko2017 eq. 6 (density summation) or the continuity equation,
eq. 9 in its symmetric form -sum_b m_b (P_a/rho_a^2 + P_b/rho_b^2) grad_a W_ab,
Tait or linear equation of state, Monaghan (1992) artificial viscosity, Adami,
Hu & Adams (2012) wall pressure, optional density diffusion (Molteni &
Colagrossi 2009, hydrostatic part removed as Fourtakas et al. 2019).
"""

import numpy as np
from numba import njit

from ...core.geometry import crossed_wall
from ...core.neighbours import build_pairs
from ...core.smoothing import dw as kernel_dw
from ...core.smoothing import w as kernel_w
from .eos import density_of, pressure_of
from .repulsion import wall_repulsion

JIT = dict(cache=True, nogil=True)

# indices into par
(H, MASS, RHO0, C0, GAMMA, ALPHA, DELTA, GRAV, DT, SKIN, KERNEL, NORM, TAIT, CLAMP, SUMMATION,
 WALL_VISC, LJ_D, LJ_R0, NPAR) = range(19)
# return codes of advance()
OK, CROSSED, LEFT_BOX, NONFINITE = range(4)


@njit(**JIT)
def list_pairs(x, nf, box, rc):
    """Pair list over all particles within rc, wall-wall pairs dropped, pi liquid.

    build_pairs' order and orientation (pi runs over its rows), swapped only where
    pi would be a wall particle: the passes keep pi's sums in registers along a run.
    """
    pi, pj, m = build_pairs(x, box, rc)
    k = 0
    for q in range(m):
        a = pi[q]
        b = pj[q]
        if a >= nf:
            a, b = b, a
        if a < nf:
            pi[k] = a
            pj[k] = b
            k += 1
    return pi, pj, k


@njit(inline="always", **JIT)
def pair_kernel(xa, ya, x, b, h, kind, c):
    """(W_ab [1/cm^2], (dW/dr)/r [1/cm^4]) of particle b and a particle at (xa, ya) (0 beyond 2h); c = norm / h^2."""
    dx = xa - x[b, 0]
    dy = ya - x[b, 1]
    r = np.sqrt(dx * dx + dy * dy)
    q = r / h
    if q >= 2.0:
        return 0.0, 0.0
    return c * kernel_w(kind, q), (c * kernel_dw(kind, q) / (h * r) if r > 0.0 else 0.0)


@njit(**JIT)
def kernel_pass(x, pi, pj, m, par, wk, fk):
    """Per pair: wk = W(r) [1/cm^2] and fk = (dW/dr)/r [1/cm^4] (0 beyond 2h), so grad_a W = fk (x_a - x_b)."""
    h = par[H]
    kind = int(par[KERNEL])
    c = par[NORM] / (h * h)
    for k in range(m):
        a = np.uint32(pi[k])
        wk[k], fk[k] = pair_kernel(x[a, 0], x[a, 1], x, np.uint32(pj[k]), h, kind, c)


@njit(**JIT)
def kernel_density_pass(x, rho, nf, pi, pj, m, par, wk, fk):
    """kernel_pass and, in the same sweep, rho[:nf] = sum_b m_b W_ab over liquid and wall particles,
    self included (marko2017 eq. 6)."""
    mass, h = par[MASS], par[H]
    kind = int(par[KERNEL])
    c = par[NORM] / (h * h)
    w0 = mass * par[NORM] / (h * h) * kernel_w(kind, 0.0)
    for a in range(nf):
        rho[a] = w0
    run = -1  # the run's particle pi: its density is summed in ra, its position held in (xa, ya)
    ra = xa = ya = 0.0
    for k in range(m):
        a = np.uint32(pi[k])
        b = np.uint32(pj[k])
        if a != run:
            if run >= 0:
                rho[run] = ra
            run = a
            ra, xa, ya = rho[a], x[a, 0], x[a, 1]
        w, f = pair_kernel(xa, ya, x, b, h, kind, c)
        wk[k] = w
        fk[k] = f
        ra += mass * w
        if b < nf:
            rho[b] += mass * w
    if run >= 0:
        rho[run] = ra


@njit(**JIT)
def density_rate(x, v, rho, nf, pi, pj, m, fk, par, drho):
    """drho (nf,) = continuity sum_b m_b v_ab . grad_a W_ab (walls at rest) plus, with delta > 0,
    the density diffusion delta h c0 sum_b V_b psi_ab . grad_a W_ab among liquid particles, its
    hydrostatic part rho0 g (y_a - y_b) / c0^2 removed.  Uses the cached fk of the pairs."""
    mass, h, c0, rho0, g, delta = par[MASS], par[H], par[C0], par[RHO0], par[GRAV], par[DELTA]
    drho[:nf] = 0.0
    run = -1  # the run's particle pi: its rate is summed in da, its state held in registers
    da = xa = ya = vxa = vya = ra = 0.0
    for k in range(m):
        f = fk[k]
        if f == 0.0:
            continue
        a = np.uint32(pi[k])
        b = np.uint32(pj[k])
        if a != run:
            if run >= 0:
                drho[run] = da
            run = a
            da = drho[a]
            xa, ya, vxa, vya, ra = x[a, 0], x[a, 1], v[a, 0], v[a, 1], rho[a]
        dx = xa - x[b, 0]
        dy = ya - x[b, 1]
        if b >= nf:
            da += mass * f * (vxa * dx + vya * dy)
            continue
        dd = mass * f * ((vxa - v[b, 0]) * dx + (vya - v[b, 1]) * dy)
        da += dd
        drho[b] += dd
        if delta > 0.0:
            d = (rho[b] - ra) - rho0 * g * dy / (c0 * c0)
            t = -2.0 * delta * h * c0 * mass * d * f
            da += t / rho[b]
            drho[b] -= t / ra
    if run >= 0:
        drho[run] = da


@njit(**JIT)
def forces(x, v, rho, p, nf, pi, pj, m, wk, fk, par, acc, wall_force, wsum, p_rho2):
    """Pressures (liquid: equation of state; walls: Adami et al. 2012 eq. 27) and accelerations.

    rho[:nf] is read; rho[nf:] and p are overwritten.  acc (nf, 2) cm/s^2
    includes gravity; wall_force (nw, 2) N: force of each wall particle on the
    liquid; wsum (nw, 3) and p_rho2 (n,) (P / rho^2 per particle) scratch.  Every pair force is applied with opposite
    signs to both particles (eq. 9 in its symmetric form).
    """
    mass, rho0, c0, gamma = par[MASS], par[RHO0], par[C0], par[GAMMA]
    h, g = par[H], par[GRAV]
    tait, clamp = par[TAIT] > 0, par[CLAMP] > 0
    for a in range(nf):
        p[a] = pressure_of(rho[a], rho0, c0, gamma, tait, clamp)
    # walls at rest: p_w = (sum_f p_f W_wf + g . sum_f rho_f r_wf W_wf) / sum_f W_wf
    wsum[:] = 0.0
    for k in range(m):
        b = np.uint32(pj[k])
        if b >= nf and wk[k] > 0.0:
            a = np.uint32(pi[k])
            q = b - nf
            wsum[q, 0] += wk[k]
            wsum[q, 1] += p[a] * wk[k]
            wsum[q, 2] += rho[a] * (-g) * (x[b, 1] - x[a, 1]) * wk[k]
    for q in range(wsum.shape[0]):
        pw = 0.0
        if wsum[q, 0] > 0.0:
            pw = (wsum[q, 1] + wsum[q, 2]) / wsum[q, 0]
        if clamp and pw < 0.0:
            pw = 0.0
        p[nf + q] = pw
        rho[nf + q] = density_of(pw, rho0, c0, gamma, tait)
    for a in range(p.shape[0]):
        p_rho2[a] = p[a] / (rho[a] * rho[a])
    alpha = par[ALPHA]
    wall_visc = par[WALL_VISC] > 0
    eps2 = 0.01 * h * h
    for a in range(nf):
        acc[a, 0] = 0.0
        acc[a, 1] = -g
    wall_force[:] = 0.0
    run = -1  # the run's particle pi: its acceleration is summed in (sx, sy), its state held in registers
    sx = sy = xa = ya = vxa = vya = ra = pa = 0.0
    for k in range(m):
        f = fk[k]
        if f == 0.0:
            continue
        a = np.uint32(pi[k])
        b = np.uint32(pj[k])
        if a != run:
            if run >= 0:
                acc[run, 0] = sx
                acc[run, 1] = sy
            run = a
            sx, sy = acc[a, 0], acc[a, 1]
            xa, ya, vxa, vya, ra, pa = x[a, 0], x[a, 1], v[a, 0], v[a, 1], rho[a], p_rho2[a]
        dx = xa - x[b, 0]
        dy = ya - x[b, 1]
        wall = b >= nf
        if wall:
            dvx = vxa
            dvy = vya
        else:
            dvx = vxa - v[b, 0]
            dvy = vya - v[b, 1]
        rb = rho[b]
        s = pa + p_rho2[b]
        vr = dvx * dx + dvy * dy
        if vr < 0.0 and alpha > 0.0 and (wall_visc or not wall):
            mu = h * vr / (dx * dx + dy * dy + eps2)
            s += -alpha * c0 * mu / (0.5 * (ra + rb))
        s *= mass * f
        ax = -s * dx
        ay = -s * dy
        sx += ax
        sy += ay
        if wall:
            wall_force[b - nf, 0] += mass * ax
            wall_force[b - nf, 1] += mass * ay
        else:
            acc[b, 0] -= ax
            acc[b, 1] -= ay
    if run >= 0:
        acc[run, 0] = sx
        acc[run, 1] = sy


@njit(**JIT)
def evaluate(x, v, rho, p, nf, pi, pj, m, wk, fk, par, acc, wall_force, wsum):
    """Kernels, densities (summed, eq. 6, or rho[:nf] as given) and forces of a state (see forces)."""
    if par[SUMMATION] > 0:
        kernel_density_pass(x, rho, nf, pi, pj, m, par, wk, fk)
    else:
        kernel_pass(x, pi, pj, m, par, wk, fk)
    forces(x, v, rho, p, nf, pi, pj, m, wk, fk, par, acc, wall_force, wsum, np.empty(x.shape[0]))


@njit(**JIT)
def advance(x, v, rho, p, nf, walls, box, grid_box, par, n_steps, xref, pi, pj, m, wk, fk, acc,
            wall_force, wsum, force_sum, panel0, npanel, panel_sum, diag):
    """Velocity Verlet (kick-drift-kick) for n_steps steps; acc must hold the current state's.

    Summed density: a function of the positions.  Continuity density: a
    position-like variable, rho_{n+1} = rho_n + dt/2 (D(x_n) + D(x_{n+1})) with
    both rates D taken at the half-step velocities (trapezoidal drift), so the
    pressure is never a half step behind the positions.  Rebuilds the pair
    list (cells over grid_box) when a particle has moved more than skin / 2
    since the last build (xref).  Stops early if a particle crosses a wall,
    leaves box (the walls' bounding box), or a value is not finite.
    force_sum (nw, 2) += wall_force every step; panel_sum (P, 2) += the
    wall_repulsion forces on the panels (panel0, npanel per wall).  diag (4,) out: max over the
    steps of the rms speed [cm/s], final kinetic energy [N cm], list builds,
    offending particle (or -1).  Returns (code, steps done, pi, pj, m, wk, fk).
    """
    dt = par[DT]
    half = 0.5 * dt
    lim2 = (0.5 * par[SKIN]) ** 2
    rc = 2.0 * par[H] + par[SKIN]
    summation = par[SUMMATION] > 0
    mass = par[MASS]
    rate0 = np.zeros(nf)
    rate1 = np.zeros(nf)
    rho_n = np.zeros(nf)
    p_rho2 = np.empty(x.shape[0])
    diag[0] = 0.0
    diag[2] = 0.0
    diag[3] = -1.0
    for step in range(n_steps):
        for a in range(nf):
            v[a, 0] += half * acc[a, 0]
            v[a, 1] += half * acc[a, 1]
        if not summation:
            density_rate(x, v, rho, nf, pi, pj, m, fk, par, rate0)
            rho_n[:] = rho[:nf]
        moved2 = 0.0
        for a in range(nf):
            x0 = x[a, 0]
            y0 = x[a, 1]
            x1 = x0 + dt * v[a, 0]
            y1 = y0 + dt * v[a, 1]
            if not (np.isfinite(x1) and np.isfinite(y1)):
                diag[3] = a
                return NONFINITE, step, pi, pj, m, wk, fk
            if crossed_wall(x0, y0, x1, y1, walls) >= 0:
                diag[3] = a
                return CROSSED, step, pi, pj, m, wk, fk
            if x1 < box[0] or x1 > box[2] or y1 < box[1] or y1 > box[3]:
                diag[3] = a
                return LEFT_BOX, step, pi, pj, m, wk, fk
            x[a, 0] = x1
            x[a, 1] = y1
            ddx = x1 - xref[a, 0]
            ddy = y1 - xref[a, 1]
            moved2 = max(moved2, ddx * ddx + ddy * ddy)
        if moved2 > lim2:
            pi, pj, m = list_pairs(x, nf, grid_box, rc)
            if wk.shape[0] < m:
                wk = np.empty(pi.shape[0])
                fk = np.empty(pi.shape[0])
            xref[:nf] = x[:nf]
            diag[2] += 1.0
        if summation:
            kernel_density_pass(x, rho, nf, pi, pj, m, par, wk, fk)
        else:
            kernel_pass(x, pi, pj, m, par, wk, fk)
            density_rate(x, v, rho, nf, pi, pj, m, fk, par, rate1)
            for a in range(nf):
                rho[a] = rho_n[a] + half * (rate0[a] + rate1[a])
        forces(x, v, rho, p, nf, pi, pj, m, wk, fk, par, acc, wall_force, wsum, p_rho2)
        wall_repulsion(x, nf, walls, panel0, npanel, par[LJ_D], par[LJ_R0], mass, acc, panel_sum)
        v2 = 0.0
        for a in range(nf):
            v[a, 0] += half * acc[a, 0]
            v[a, 1] += half * acc[a, 1]
            v2 += v[a, 0] * v[a, 0] + v[a, 1] * v[a, 1]
        if not np.isfinite(v2):
            return NONFINITE, step + 1, pi, pj, m, wk, fk
        diag[0] = max(diag[0], np.sqrt(v2 / nf))
        diag[1] = 0.5 * mass * v2
        for q in range(force_sum.shape[0]):
            force_sum[q, 0] += wall_force[q, 0]
            force_sum[q, 1] += wall_force[q, 1]
    return OK, n_steps, pi, pj, m, wk, fk
