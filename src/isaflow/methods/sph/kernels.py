"""Weakly compressible SPH kernels (numba): pair passes and the whole step loop.

Arrays (units cm, N, s; masses N s^2/cm, densities N s^2/cm^4, pressures N/cm^2):
- x (n, 2): positions, rows 0..nf-1 liquid particles, rows nf..n-1 wall
  (boundary) particles, which never move;
- v (nf, 2) velocities; rho (n,) densities; p (n,) pressures;
- lst: the pair list of :func:`pairs.build`, a tuple (pi, pj, m, col, wrow, wpair, close,
  dwall): half list, pi liquid, pj liquid or wall (pj >= nf), grouped by cell columns so that
  the pair passes run the even columns, then the odd ones, each column in list order
  (in parallel with ``threads`` > 1, bit-identical to the serial passes: see pairs);
- par (NPAR,) float64 settings, indices below (see solver.pack).

Equations: marko2017 eq. 6 (density summation) or the continuity equation
drho_a/dt = sum_b m_b v_ab . grad_a W_ab (Monaghan 1992), eq. 9 in its symmetric
form -sum_b m_b (P_a/rho_a^2 + P_b/rho_b^2 + Pi_ab) grad_a W_ab, Tait or linear equation
of state, Monaghan (1992) artificial viscosity Pi_ab, Adami, Hu & Adams (2012) wall
pressure, optional density diffusion (Molteni & Colagrossi 2009, hydrostatic part removed
as Fourtakas et al. 2019).  Per-particle loops run over fixed chunks of CHUNK particles and
reduce chunk by chunk in chunk order, so they too do not depend on the thread count.
"""

import numpy as np
from numba import prange

from ...core.jit import njit

from ...core.geometry import crossed_wall
from ...core.smoothing import dw as kernel_dw
from ...core.smoothing import w as kernel_w
from .eos import density_of, pressure_of
from .pairs import build
from .repulsion import wall_repulsion

JIT = dict(cache=True, nogil=True)
PJIT = dict(cache=True, nogil=True, parallel=True)
CHUNK = 1024  # particles per chunk of the per-particle loops (fixed: results do not depend on threads)

# indices into par
(H, MASS, RHO0, C0, GAMMA, ALPHA, DELTA, GRAV, DT, SKIN, KERNEL, NORM, TAIT, CLAMP, SUMMATION,
 WALL_VISC, LJ_D, LJ_R0, NPAR) = range(19)
# return codes of advance()
OK, CROSSED, LEFT_BOX, NONFINITE = range(4)
KERNELS, FORCES = range(2)  # the pair passes (_pair_pass)


def list_pairs(x, nf, box, rc, walls, reach=0.0):
    """The pair list tuple (pi, pj, m, col, wrow, wpair, close, dwall) of all particles x within rc
    (pairs.build; close: the liquid particles within ``reach`` of a wall at the build)."""
    return build(x, nf, box, rc, walls, np.empty(16, np.int32), np.empty(16, np.int32), reach)


@njit(inline="always", **JIT)
def reach_of(par):
    """Distance [cm] from a wall within which, at a list build, a particle can feel the Lennard-Jones net
    before the next build: r0 + skin / 2 (a particle moves less than skin / 2 between builds)."""
    return par[LJ_R0] + 0.5 * par[SKIN]


@njit(inline="always", **JIT)
def shape(kind, q):
    """(f(q), f'(q)) of the kernel's unnormalised shape, branch-free (core.smoothing.w, dw to round-off;
    0 for q >= 2): cubic spline f = (2 - q)_+^3 / 4 - (1 - q)_+^3, Wendland C2 (1 - q/2)_+^4 (1 + 2 q)."""
    if kind == 0:
        t = 2.0 - q
        t = t if t > 0.0 else 0.0
        u = 1.0 - q
        u = u if u > 0.0 else 0.0
        return 0.25 * t * t * t - u * u * u, 3.0 * u * u - 0.75 * t * t
    if kind == 1:
        o = 1.0 - 0.5 * q
        o = o if o > 0.0 else 0.0
        o3 = o * o * o
        return o3 * o * (1.0 + 2.0 * q), -5.0 * q * o3
    return kernel_w(kind, q), kernel_dw(kind, q)


@njit(inline="always", **JIT)
def kernel_wf(r2, ih, kind, c):
    """(W [1/cm^2], (dW/dr)/r [1/cm^4]) at squared distance r2 [cm^2] (0, 0 beyond 2h); ih = 1 / h,
    c = norm / h^2.  f'(0) = 0, so r = 0 gives (dW/dr)/r = 0."""
    r = np.sqrt(r2)
    f, df = shape(kind, r * ih)
    return c * f, c * ih * df / (r if r > 1e-300 else 1e-300)


@njit(inline="always", **JIT)
def pair_momentum(pa_rho2, pb_rho2, vr, r2, h, alpha, c0, rho_mean):
    """P_a/rho_a^2 + P_b/rho_b^2 + Pi_ab [cm^2/s^2 per density, i.e. cm^6/(N s^4)]: the bracket of eq. 9 with
    Monaghan's (1992) viscosity Pi_ab = -alpha c0 mu / rho_mean, mu = h min(v_ab . x_ab, 0) / (r^2 + 0.01 h^2)
    (approaching pairs only; written without a branch)."""
    return pa_rho2 + pb_rho2 - alpha * c0 * h * min(vr, 0.0) / ((r2 + 0.01 * h * h) * rho_mean)


@njit(**JIT)
def kernel_range(lo, hi, x, v, rho, nf, pi, pj, par, wk, fk, out):
    """Pairs lo..hi-1: wk = W, fk = (dW/dr)/r (so grad_a W = fk (x_a - x_b)); out (nf,) += the summed
    density m W (SUMMATION) or the continuity rate m v_ab . grad_a W (walls at rest) plus, with
    delta > 0, the density diffusion delta h c0 sum_b V_b psi_ab . grad_a W_ab among liquid particles,
    its hydrostatic part rho0 g (y_a - y_b) / c0^2 removed.  Along a run of equal pi its sum is held
    in a register (pi is never pj within its run), which adds the terms in list order all the same."""
    mass, h, c0, rho0, g, delta = par[MASS], par[H], par[C0], par[RHO0], par[GRAV], par[DELTA]
    kind = int(par[KERNEL])
    c = par[NORM] / (h * h)
    ih = 1.0 / h
    summation = par[SUMMATION] > 0
    run = -1
    sa = xa = ya = vxa = vya = ra = ira = 0.0
    for k in range(lo, hi):
        a = np.uint32(pi[k])
        b = np.uint32(pj[k])
        if a != run:
            if run >= 0:
                out[run] = sa
            run = a
            sa = out[a]
            xa, ya, vxa, vya, ra = x[a, 0], x[a, 1], v[a, 0], v[a, 1], rho[a]
            ira = 1.0 / ra
        dx = xa - x[b, 0]
        dy = ya - x[b, 1]
        w, f = kernel_wf(dx * dx + dy * dy, ih, kind, c)
        wk[k] = w
        fk[k] = f
        if summation:
            sa += mass * w
            if b < nf:
                out[b] += mass * w
        elif b >= nf:
            sa += mass * f * (vxa * dx + vya * dy)
        else:
            dd = mass * f * ((vxa - v[b, 0]) * dx + (vya - v[b, 1]) * dy)
            if delta > 0.0:
                rb = rho[b]
                t = -2.0 * delta * h * c0 * mass * f * ((rb - ra) - rho0 * g * dy / (c0 * c0))
                sa += dd + t / rb
                out[b] += dd - t * ira
            else:
                sa += dd
                out[b] += dd
    if run >= 0:
        out[run] = sa


@njit(**JIT)
def force_range(lo, hi, x, v, rho, p_rho2, nf, pi, pj, par, fk, acc, wall_force):
    """Pairs lo..hi-1: eq. 9 with viscosity, applied with opposite signs to both particles; a wall
    particle's share goes to wall_force (its force on the liquid, N).  Run sums in registers as
    kernel_range."""
    mass, h, c0, alpha = par[MASS], par[H], par[C0], par[ALPHA]
    alpha_wall = alpha if par[WALL_VISC] > 0 else 0.0
    run = -1
    sx = sy = xa = ya = vxa = vya = ra = pa = 0.0
    for k in range(lo, hi):
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
        f = fk[k]
        if b >= nf:
            s = mass * f * pair_momentum(pa, p_rho2[b], vxa * dx + vya * dy, dx * dx + dy * dy, h, alpha_wall, c0,
                                         0.5 * (ra + rho[b]))
            ax = -s * dx
            ay = -s * dy
            sx += ax
            sy += ay
            wall_force[b - nf, 0] += mass * ax
            wall_force[b - nf, 1] += mass * ay
        else:
            s = mass * f * pair_momentum(pa, p_rho2[b], (vxa - v[b, 0]) * dx + (vya - v[b, 1]) * dy,
                                         dx * dx + dy * dy, h, alpha, c0, 0.5 * (ra + rho[b]))
            ax = -s * dx
            ay = -s * dy
            sx += ax
            sy += ay
            acc[b, 0] -= ax
            acc[b, 1] -= ay
    if run >= 0:
        acc[run, 0] = sx
        acc[run, 1] = sy


@njit(**JIT)
def _pass_range(which, lo, hi, x, v, rho, p_rho2, nf, pi, pj, par, wk, fk, out, acc, wall_force):
    """Pairs lo..hi-1 of one pair pass: :func:`kernel_range` (KERNELS) or :func:`force_range` (FORCES)."""
    if which == KERNELS:
        kernel_range(lo, hi, x, v, rho, nf, pi, pj, par, wk, fk, out)
    else:
        force_range(lo, hi, x, v, rho, p_rho2, nf, pi, pj, par, fk, acc, wall_force)


@njit(**PJIT)
def _colour_par(which, colour, col, x, v, rho, p_rho2, nf, pi, pj, par, wk, fk, out, acc, wall_force):
    """The columns of one colour (no two of them reach the same particle) in parallel."""
    for cc in prange((col.shape[0] - colour) // 2):
        c = 2 * cc + colour
        _pass_range(which, col[c], col[c + 1], x, v, rho, p_rho2, nf, pi, pj, par, wk, fk, out, acc, wall_force)


@njit(**JIT)
def _pair_pass(which, threads, col, x, v, rho, p_rho2, nf, pi, pj, par, wk, fk, out, acc, wall_force):
    """One pair pass (:func:`_pass_range`) over the cell columns col: the even columns, then the odd ones,
    each column in list order; a colour's columns in parallel if threads > 1 (the same bits)."""
    ncol = col.shape[0] - 1
    for colour in range(2):
        if threads > 1:
            _colour_par(which, colour, col, x, v, rho, p_rho2, nf, pi, pj, par, wk, fk, out, acc, wall_force)
        else:
            for c in range(colour, ncol, 2):
                _pass_range(which, col[c], col[c + 1], x, v, rho, p_rho2, nf, pi, pj, par, wk, fk, out, acc,
                            wall_force)


@njit(**JIT)
def liquid_range(lo, hi, rho, rate, p, p_rho2, acc, par, update):
    """Particles lo..hi-1: rho += dt rate if update (continuity density), pressure (equation of state),
    P / rho^2, and acc reset to gravity."""
    rho0, c0, gamma, g, dt = par[RHO0], par[C0], par[GAMMA], par[GRAV], par[DT]
    tait, clamp = par[TAIT] > 0, par[CLAMP] > 0
    for a in range(lo, hi):
        if update:
            rho[a] += dt * rate[a]
        pa = pressure_of(rho[a], rho0, c0, gamma, tait, clamp)
        p[a] = pa
        p_rho2[a] = pa / (rho[a] * rho[a])
        acc[a, 0] = 0.0
        acc[a, 1] = -g


@njit(**JIT)
def wall_range(lo, hi, x, rho, p, p_rho2, nf, pi, wrow, wpair, wk, par, wall_force):
    """Wall particles lo..hi-1 (at rest): Adami et al. (2012) eq. 27, p_w = (sum_f p_f W_wf +
    g . sum_f rho_f r_wf W_wf) / sum_f W_wf over the liquid particles that see it (p_w >= 0 when
    clamping), rho_w from the inverse equation of state; wall_force reset."""
    rho0, c0, gamma, g = par[RHO0], par[C0], par[GAMMA], par[GRAV]
    tait, clamp = par[TAIT] > 0, par[CLAMP] > 0
    for q in range(lo, hi):
        s0 = 0.0
        s1 = 0.0
        yq = x[nf + q, 1]
        for e in range(wrow[q], wrow[q + 1]):
            k = wpair[e]
            w = wk[k]
            if w > 0.0:
                a = pi[k]
                s0 += w
                s1 += (p[a] - rho[a] * g * (yq - x[a, 1])) * w
        pw = s1 / s0 if s0 > 0.0 else 0.0
        if clamp and pw < 0.0:
            pw = 0.0
        rw = density_of(pw, rho0, c0, gamma, tait)
        p[nf + q] = pw
        rho[nf + q] = rw
        p_rho2[nf + q] = pw / (rw * rw)
        wall_force[q, 0] = 0.0
        wall_force[q, 1] = 0.0


@njit(**PJIT)
def _particles_par(nf, nw, x, rho, rate, p, p_rho2, acc, par, update, pi, wrow, wpair, wk, wall_force):
    for ch in prange((nf + CHUNK - 1) // CHUNK):
        liquid_range(ch * CHUNK, min(nf, (ch + 1) * CHUNK), rho, rate, p, p_rho2, acc, par, update)


@njit(**PJIT)
def _walls_par(nf, nw, x, rho, p, p_rho2, pi, wrow, wpair, wk, par, wall_force):
    for ch in prange((nw + CHUNK - 1) // CHUNK):
        wall_range(ch * CHUNK, min(nw, (ch + 1) * CHUNK), x, rho, p, p_rho2, nf, pi, wrow, wpair, wk, par,
                   wall_force)


@njit(**JIT)
def state_forces(x, v, rho, p, nf, walls, par, lst, wk, fk, acc, wall_force, panel0, npanel, panel_sum,
                 rate, p_rho2, update, threads):
    """Kernels, densities, pressures and accelerations acc (nf, 2) [cm/s^2, gravity included] of a state.

    Summed density: rho[:nf] from the positions.  Continuity density: rate (nf,) = drho/dt at
    (x, v), and rho[:nf] += dt rate if update (else rho[:nf] is the state's).  Then the pressures,
    the wall particles' pressures and densities, eq. 9 and the Lennard-Jones safety net
    (repulsion.wall_repulsion on the particles near a wall; its force on the panels is added to
    panel_sum (P, 2) N).  wall_force (nw, 2) N: force of each wall particle on the liquid.
    """
    pi, pj, m, col, wrow, wpair, close, dwall = lst
    nw = x.shape[0] - nf
    summation = par[SUMMATION] > 0
    if summation:
        h = par[H]
        w0 = par[MASS] * par[NORM] / (h * h) * kernel_w(int(par[KERNEL]), 0.0)
        rho[:nf] = w0
        out = rho
    else:
        rate[:] = 0.0
        out = rate
    _pair_pass(KERNELS, threads, col, x, v, rho, p_rho2, nf, pi, pj, par, wk, fk, out, acc, wall_force)
    if threads > 1:
        _particles_par(nf, nw, x, rho, rate, p, p_rho2, acc, par, update and not summation, pi, wrow, wpair, wk,
                       wall_force)
        _walls_par(nf, nw, x, rho, p, p_rho2, pi, wrow, wpair, wk, par, wall_force)
    else:
        liquid_range(0, nf, rho, rate, p, p_rho2, acc, par, update and not summation)
        wall_range(0, nw, x, rho, p, p_rho2, nf, pi, wrow, wpair, wk, par, wall_force)
    _pair_pass(FORCES, threads, col, x, v, rho, p_rho2, nf, pi, pj, par, wk, fk, out, acc, wall_force)
    wall_repulsion(x, close, walls, panel0, npanel, par[LJ_D], par[LJ_R0], par[MASS], acc, panel_sum)


@njit(**JIT)
def _kick_range(lo, hi, v, acc, half):
    """Particles lo..hi-1: v += half acc (a half kick, half = dt / 2); returns their sum of |v|^2 after it."""
    s = 0.0
    for a in range(lo, hi):
        v[a, 0] += half * acc[a, 0]
        v[a, 1] += half * acc[a, 1]
        s += v[a, 0] * v[a, 0] + v[a, 1] * v[a, 1]
    return s


@njit(**PJIT)
def _kick_par(nf, v, acc, half, part):
    for ch in prange((nf + CHUNK - 1) // CHUNK):
        part[ch] = _kick_range(ch * CHUNK, min(nf, (ch + 1) * CHUNK), v, acc, half)


@njit(**JIT)
def _move_range(lo, hi, x, v, acc, xref, half, dt, box, walls, dwall, slack, finish):
    """Particles lo..hi-1: if finish, the second kick of the last step (v += dt/2 acc) and its |v|^2
    sum; then the first kick of this step and the drift.  A particle whose move could reach a wall
    (dt |v| >= its distance to the walls at the last build minus slack = skin / 2, the most it has
    moved since) is tested (core.geometry.crossed_wall) and, if it would cross, left where it is.
    Returns (sum |v|^2 after the finishing kick, largest squared move since xref, first particle that
    would cross a wall or -1, first particle that left box or became non-finite or -1)."""
    v2 = 0.0
    moved2 = 0.0
    cross = -1
    bad = -1
    for a in range(lo, hi):
        if finish:
            v[a, 0] += half * acc[a, 0]
            v[a, 1] += half * acc[a, 1]
            v2 += v[a, 0] * v[a, 0] + v[a, 1] * v[a, 1]
        v[a, 0] += half * acc[a, 0]
        v[a, 1] += half * acc[a, 1]
        x0 = x[a, 0]
        y0 = x[a, 1]
        x1 = x0 + dt * v[a, 0]
        y1 = y0 + dt * v[a, 1]
        step2 = (x1 - x0) * (x1 - x0) + (y1 - y0) * (y1 - y0)
        reach = dwall[a] - slack
        if not (step2 < reach * reach and reach > 0.0):
            if crossed_wall(x0, y0, x1, y1, walls) >= 0:
                if cross < 0:
                    cross = a
                continue
        if bad < 0 and not (np.isfinite(x1) and np.isfinite(y1) and box[0] <= x1 <= box[2] and box[1] <= y1 <= box[3]):
            bad = a
        x[a, 0] = x1
        x[a, 1] = y1
        ddx = x1 - xref[a, 0]
        ddy = y1 - xref[a, 1]
        moved2 = max(moved2, ddx * ddx + ddy * ddy)
    return v2, moved2, cross, bad


@njit(**PJIT)
def _move_par(nf, x, v, acc, xref, half, dt, box, walls, dwall, slack, finish, part, moved, cross, bad):
    for ch in prange((nf + CHUNK - 1) // CHUNK):
        part[ch], moved[ch], cross[ch], bad[ch] = _move_range(ch * CHUNK, min(nf, (ch + 1) * CHUNK), x, v, acc, xref,
                                                              half, dt, box, walls, dwall, slack, finish)


@njit(**JIT)
def advance(x, v, rho, p, nf, walls, box, grid_box, par, n_steps, xref, lst, wk, fk, acc,
            wall_force, force_sum, panel0, npanel, panel_sum, diag, threads):
    """Velocity Verlet (kick-drift-kick) for n_steps steps; acc must hold the current state's.

    Continuity density is a position-like variable: rho_{n+1} = rho_n + dt D(x_{n+1}, v_{n+1/2}),
    its rate taken in the same pass as the kernels at the drifted positions (for fixed
    positions this is the Stormer-Verlet step of the acoustic system (rho, v)).  A step's
    second kick is done with the next step's first kick and drift, in one pass over the
    particles (the same two additions).  The pair list is rebuilt (cells over grid_box, from
    the positions, so from xref) when a particle has moved more than skin / 2 since the last
    build.  Stops in a step in which a particle would cross a wall (core.geometry.crossed_wall,
    tested for the particles whose move could reach a wall), and after one in which a particle
    left box (the walls' bounding box) or became non-finite.  force_sum (nw, 2) += wall_force
    every step; panel_sum (P, 2) += the Lennard-Jones forces on the panels.  diag (4,) out: max
    over the steps of the rms speed [cm/s], final kinetic energy [N cm], list builds,
    offending particle (or -1).  threads > 1: the parallel passes (bit-identical to the serial
    ones).  Returns (code, steps done, lst, wk, fk).
    """
    dt = par[DT]
    half = 0.5 * dt
    lim2 = (0.5 * par[SKIN]) ** 2
    rc = 2.0 * par[H] + par[SKIN]
    slack = 0.5 * par[SKIN]
    mass = par[MASS]
    n = x.shape[0]
    nch = (nf + CHUNK - 1) // CHUNK
    part = np.zeros(nch)
    moved = np.zeros(nch)
    cross = np.full(nch, -1, np.int64)
    bad = np.full(nch, -1, np.int64)
    rate = np.zeros(nf)
    p_rho2 = np.empty(n)
    diag[0] = 0.0
    diag[2] = 0.0
    diag[3] = -1.0
    for step in range(n_steps + 1):
        finish = step > 0
        if step == n_steps:  # the last step's second kick
            if threads > 1:
                _kick_par(nf, v, acc, half, part)
            else:
                for ch in range(nch):
                    part[ch] = _kick_range(ch * CHUNK, min(nf, (ch + 1) * CHUNK), v, acc, half)
        elif threads > 1:
            _move_par(nf, x, v, acc, xref, half, dt, box, walls, lst[7], slack, finish, part, moved, cross, bad)
        else:
            for ch in range(nch):
                part[ch], moved[ch], cross[ch], bad[ch] = _move_range(
                    ch * CHUNK, min(nf, (ch + 1) * CHUNK), x, v, acc, xref, half, dt, box, walls, lst[7], slack, finish)
        if finish:  # diagnostics of the finished step
            v2 = 0.0
            for ch in range(nch):
                v2 += part[ch]
            if not np.isfinite(v2):
                return NONFINITE, step, lst, wk, fk
            diag[0] = max(diag[0], np.sqrt(v2 / nf))
            diag[1] = 0.5 * mass * v2
        if step == n_steps:
            break
        moved2 = 0.0
        for ch in range(nch):
            moved2 = max(moved2, moved[ch])
            if cross[ch] >= 0:  # a move across a wall stops the run (that particle not moved)
                diag[3] = cross[ch]
                return CROSSED, step, lst, wk, fk
            if bad[ch] >= 0:
                a = bad[ch]
                diag[3] = a
                return (LEFT_BOX if np.isfinite(x[a, 0]) and np.isfinite(x[a, 1]) else NONFINITE), step + 1, lst, wk, fk
        if moved2 > lim2:
            lst = build(x, nf, grid_box, rc, walls, lst[0], lst[1], reach_of(par))
            if wk.shape[0] < lst[2]:
                wk = np.empty(lst[0].shape[0])
                fk = np.empty(lst[0].shape[0])
            xref[:nf] = x[:nf]
            diag[2] += 1.0
        state_forces(x, v, rho, p, nf, walls, par, lst, wk, fk, acc, wall_force, panel0, npanel, panel_sum,
                     rate, p_rho2, True, threads)
        for q in range(force_sum.shape[0]):
            force_sum[q, 0] += wall_force[q, 0]
            force_sum[q, 1] += wall_force[q, 1]
    return OK, n_steps, lst, wk, fk


@njit(**JIT)
def evaluate(x, v, rho, p, nf, walls, par, lst, wk, fk, acc, wall_force, panel0, npanel, panel_sum, threads):
    """Accelerations (and pressures, wall pressures, kernels) of a state without advancing it
    (continuity density: rho[:nf] kept), as advance computes them at the end of a step."""
    state_forces(x, v, rho, p, nf, walls, par, lst, wk, fk, acc, wall_force, panel0, npanel, panel_sum,
                 np.zeros(nf), np.empty(x.shape[0]), False, threads)
