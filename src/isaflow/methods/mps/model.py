"""The stages of one MPS time step (numba): explicit step, collision model, free surface, source term,
pressure-equation assembly, pressure correction, particle shifting, the penetration guard (reflect) and the
wall-crossing check.

Koshizuka & Oka (1996), as the public MPS-Basic code implements it (github.com/MPS-Basic/MPS-Basic,
src/mps.cpp, src/pressure_calculator/implicit.cpp), with the named options of config/methods/mps.yaml.
Operators and neighbour lists in operators.py (re-exported here).  Every loop over particles gathers
from the particle's own neighbour row (numba prange; bit-identical for any thread count).  The stage kernels below
are the reference definitions; a run's step fuses them into few passes over the lists (predict, correct, step_cg
at the end of this file), each giving the same numbers summed in the same order.
Units: cm, s, density N s^2 / cm^4 (2D), pressure N / cm^2.
"""

import collections

import numpy as np
from llvmlite import ir
from numba import literally, prange, types, uint64
from numba.extending import intrinsic

from ...core.jit import njit

from isaflow.core import units
from isaflow.core.geometry import crossed_wall, segment_closest

from .operators import (CUT, DIM, DUMMY, FLUID, GRADIENTS, JIT, PAIRWISE, PAR, VARIATIONAL, WALL,  # noqa: F401
                        distances, divergence, divergence_hs, divergence_term, divergence_value, gradient,
                        gradient_norm, gradient_row, lattice_constants, laplacian, near_thin, neighbour_list,
                        neighbourhood_min, number_density, offsets, pair_distance, plain_row, probe_pressure,
                        recorded_wall_terms, row_span, sees, visible_distances, wall_forces, wall_terms, weight)
from .clusters import anchor_clusters
from .pressure import cg_solve

# source terms of the pressure equation (settings name -> id)
SOURCES = {"standard": 0, "hattori": 1, "mixed": 2}
# free-surface pressure conditions (settings name -> id)
SURFACE = {"zero": 0, "hydrostatic": 1, "extrapolated": 2}
# Laplacian of the pressure equation (settings name -> id)
LAPLACIANS = {"mps": 0, "hl": 1}
# divergence of the source terms (settings name -> id)
DIVERGENCES = {"mps": 0, "hs": 1}


# which terms of the source the relaxation gamma multiplies (settings name -> id): density, the density-deviation
# terms only (never a velocity-divergence term); source, the whole hattori and mixed source terms (the defaults
# before issue 30); standard, the standard source's alone (MPS-Basic, which has only that source)
RELAX_SCOPES = {"density": 0, "source": 1, "standard": 2}


@njit(**JIT)
def relaxation_factors(source, scope, relax):
    """(a_d, a_v): the factors of the density-deviation and of the velocity-divergence terms of source term
    ``source`` (SOURCES) under relaxation scope ``scope`` (RELAX_SCOPES) with relaxation ``relax``.  density:
    (relax, 1) for standard and hattori, (1, 1) for mixed (its density term has its own gamma_m, Tanaka &
    Masunaga 2010); source: (relax, relax) for hattori and mixed; standard: (1, 1) for hattori and mixed.  The
    standard source is (relax, 1) under every scope."""
    if source == 0:
        return relax, 1.0
    if scope == 1:
        return relax, relax
    if scope == 0 and source == 1:
        return relax, 1.0
    return 1.0, 1.0


@njit(**JIT)
def source_term(n_star, div_star, n0, rho0, dt, source, gamma, a_d=1.0, a_v=1.0):
    """Right-hand side of lap P = b [N / cm^4] per particle; a_d, a_v the factors of its density-deviation and
    velocity-divergence terms (relaxation_factors; 1, 1: the sources as their papers print them).

    source 0 standard: a_d rho0 / dt^2 (n0 - n*) / n0 (Koshizuka & Oka 1996; a_d: MPS-Basic's relaxation);
    1 hattori: a_d (rho0 - Rho*) / dt^2 + a_v (rho0 - Rho*) / dt div V*, Rho* = rho0 n* / n0
    (eq. 6 of Hattori et al.; its second term holds div V*, a velocity-divergence term);
    2 mixed: a_v rho0 / dt div V* + a_d gamma rho0 / dt^2 (n0 - n*) / n0 (Tanaka & Masunaga 2010, gamma their
    small relaxation of the density term).
    """
    drho = rho0 * (n0 - n_star) / n0  # rho0 - Rho*
    if source == 0:
        return a_d * drho / dt**2
    if source == 1:
        return a_d * drho / dt**2 + a_v * drho / dt * div_star
    return a_v * rho0 / dt * div_star + a_d * gamma * drho / dt**2


@njit(**PAR)
def source_term_all(n_star, div_star, n0, rho0, dt, source, gamma, relax, scope):
    """(N,) source_term of every particle (dummies' rows are never used), relaxed by ``relax`` under relaxation
    scope ``scope`` (RELAX_SCOPES, relaxation_factors)."""
    n = n_star.shape[0]
    out = np.empty(n)
    a_d, a_v = relaxation_factors(source, scope, relax)
    for i in prange(n):
        out[i] = source_term(n_star[i], div_star[i], n0, rho0, dt, source, gamma, a_d, a_v)
    return out


@njit(**PAR)
def ecs_term(n_now, n_prev, n0, rho0, dt):
    """(N,) error-compensating source (ECS) of Khayyer & Gotoh 2011 (J. Comput. Phys. 230, 3093), added to the
    source term [N / cm^4]: -rho0 / (n0 dt) alpha (Dn/Dt)^k - beta rho0 / (n0 dt^2) (n^k - n0) with
    alpha = |n^k - n0| / n0, beta = |dt / n0 (Dn/Dt)^k| and (Dn/Dt)^k = (n^k - n^{k-1}) / dt, n^k the number
    density at the start of the step and n^{k-1} at the start of the previous one (signs: positive pressure
    where the liquid is compressed or being compressed, as the standard source)."""
    n = n_now.shape[0]
    out = np.empty(n)
    for i in prange(n):
        out[i] = ecs_value(n_now[i], n_prev[i], n0, rho0, dt)
    return out


@njit(inline="always", **JIT)
def ecs_value(n_now, n_prev, n0, rho0, dt):
    """One particle's ecs_term [N / cm^4] from its number densities now and at the previous step's start."""
    rate = (n_now - n_prev) / dt
    alpha = abs(n_now - n0) / n0
    beta = abs(dt / n0 * rate)
    return -rho0 / (n0 * dt) * alpha * rate - beta * rho0 / (n0 * dt * dt) * (n_now - n0)


@njit(**PAR)
def explicit(pos, vel, kind, lap, dt, gx, gy, nu):
    """Explicit half (eq. 3): V* = V + dt (nu lap V + g), U* = U + dt V* for the fluid.  Returns (U*, V*)."""
    ps = pos.copy()
    vs = vel.copy()
    for i in prange(pos.shape[0]):
        if kind[i] == FLUID:
            explicit_one(i, pos, vel, ps, vs, lap[i, 0], lap[i, 1], dt, gx, gy, nu)
    return ps, vs


@njit(inline="always", **JIT)
def explicit_one(i, pos, vel, ps, vs, lx, ly, dt, gx, gy, nu):
    """explicit for fluid particle i, lap V_i = (lx, ly): writes ps[i], vs[i]."""
    vs[i, 0] = vel[i, 0] + dt * (nu * lx + gx)
    vs[i, 1] = vel[i, 1] + dt * (nu * ly + gy)
    ps[i, 0] = pos[i, 0] + dt * vs[i, 0]
    ps[i, 1] = pos[i, 1] + dt * vs[i, 1]


@njit(**PAR)
def collide(ps, vs, kind, start, nbr, tw, tside, near, thin, behind, cdist, restitution, rows):
    """Collision model of MPS-Basic (MPS::collision) as a gather: every fluid particle closer than ``cdist``
    [cm] to a listed neighbour (any kind; wall and dummy particles immovable) takes, for each such pair,
    the impulse that removes (1 + e) of the approaching normal relative velocity (equal masses share it)
    and half (fluid-fluid) or all (fluid-wall) of the push back to ``cdist``, all pairs computed from the
    state before the collision (MPS-Basic updates pair by pair in sequence; here every pair's exchange is
    the same from both ends, so momentum is conserved and the order does not matter).  Only pairs that see each
    other across the thin walls at ps collide (operators.visible: tw, tside, near = near_thin(ps, ...), thin,
    behind).  rows (N,) bool: the fluid particles that may collide (may_collide; the others are left as they are).
    Returns (U, V) after the collision."""
    n = ps.shape[0]
    po = ps.copy()
    vo = vs.copy()
    cut2 = cdist * cdist * CUT
    for i in prange(n):
        if kind[i] != FLUID or not rows[i]:
            continue
        plain = plain_row(i, tw, near, thin)
        first, end = row_span(start, i)
        for k in range(first, end):
            j = uint64(nbr[k])
            dx = ps[j, 0] - ps[i, 0]
            dy = ps[j, 1] - ps[i, 1]
            if dx * dx + dy * dy >= cut2 or not sees(i, j, ps, tw, tside, near, thin, behind, plain):
                continue
            r = pair_distance(dx, dy)
            if r >= cdist or r == 0.0:
                continue
            ex = dx / r
            ey = dy / r
            mass = 0.5 if kind[j] == FLUID else 1.0  # 1 / (1/m_i + 1/m_j), unit fluid masses
            rel = (vs[j, 0] - vs[i, 0]) * ex + (vs[j, 1] - vs[i, 1]) * ey
            imp = -(1.0 + restitution) * rel * mass if rel < 0.0 else 0.0
            push = (cdist - r) * mass
            vo[i, 0] -= imp * ex
            vo[i, 1] -= imp * ey
            po[i, 0] -= push * ex
            po[i, 1] -= push * ey
    return po, vo


@njit(**PAR)
def surface(pos, kind, start, nbr, dist, re_s, n0_s, beta, dist_thr, rc):
    """Free-surface particles and their outward normals.

    Fluid or wall particle i is on the free surface when its number density at radius re_s is below
    beta n0_s and, if dist_thr > 0 [cm], a component of sum_j r_ij over its neighbours closer than rc
    exceeds dist_thr (MPS-Basic's particle-distribution test).  Returns (surface (N,) bool, normal (N, 2):
    -sum_j w r_ij normalised, pointing out of the liquid)."""
    n = pos.shape[0]
    n_s = number_density(start, nbr, dist, re_s)
    s, sw = offsets(pos, start, nbr, dist, rc, re_s)
    surf = np.zeros(n, np.bool_)
    normal = np.zeros((n, 2))
    for i in prange(n):
        if kind[i] == DUMMY:
            continue
        surf[i] = on_surface(n_s[i], s[i, 0], s[i, 1], beta, n0_s, dist_thr)
        normal[i, 0], normal[i, 1] = outward(sw[i, 0], sw[i, 1])
    return surf, normal


@njit(inline="always", **JIT)
def on_surface(n_s, sx, sy, beta, n0_s, dist_thr):
    """surface's test of one particle: number density n_s below beta n0_s and (dist_thr > 0) a component of its
    neighbours' offsets sum (sx, sy) beyond dist_thr."""
    f = n_s < beta * n0_s
    if f and dist_thr > 0.0:
        f = abs(sx) > dist_thr or abs(sy) > dist_thr
    return f


@njit(inline="always", **JIT)
def outward(swx, swy):
    """surface's normal of one particle from sum_j w r_ij (swx, swy): its opposite, unit length (0 if the sum is)."""
    L = pair_distance(swx, swy)
    if L > 0.0:
        return -swx / L, -swy / L
    return 0.0, 0.0


@njit(**PAR)
def surface_values(pos, p_prev, kind, surf, normal, start, nbr, dist, re, n0, delta):
    """(N,) Dirichlet pressure [N/cm^2] of the free-surface particles: P = 0 at the free surface, delta [cm]
    outside the particle along its normal, extrapolated linearly to the particle with the normal pressure
    gradient of the previous step's pressures p_prev: P_i = delta max(0, -n_i . grad P_i).  The gradient is
    the consistent one, sum (p_j - p_i) with the corrective matrix (Khayyer & Gotoh 2011), over fluid and
    wall neighbours within re (exact for linear pressure on any arrangement); 0 where it is near singular."""
    n = pos.shape[0]
    out = np.zeros(n)
    a = DIM / n0
    for i in prange(n):
        if not surf[i]:
            continue
        gx = gy = mxx = mxy = myy = 0.0
        for k in range(start[i], start[i + 1]):
            j = nbr[k]
            if kind[j] == DUMMY:
                continue
            wt = weight(dist[k], re)
            if wt == 0.0:
                continue
            dx = pos[j, 0] - pos[i, 0]
            dy = pos[j, 1] - pos[i, 1]
            r2 = dist[k] * dist[k]
            q = (p_prev[j] - p_prev[i]) / r2 * wt
            gx += q * dx
            gy += q * dy
            mxx += dx * dx / r2 * wt
            mxy += dx * dy / r2 * wt
            myy += dy * dy / r2 * wt
        mxx *= a
        mxy *= a
        myy *= a
        det = mxx * myy - mxy * mxy
        if det > 0.01:
            gx, gy = a * (myy * gx - mxy * gy) / det, a * (mxx * gy - mxy * gx) / det
            out[i] = delta * max(0.0, -(normal[i, 0] * gx + normal[i, 1] * gy))
    return out


@njit(**JIT)
def unknown_rows(kind, dirichlet):
    """(N,) row of each particle in the pressure equation (fluid and wall particles not on the surface), -1 else;
    and the number of rows."""
    n = kind.shape[0]
    row = np.full(n, -1, np.int64)
    nu = 0
    for i in range(n):
        if kind[i] != DUMMY and not dirichlet[i]:
            row[i] = nu
            nu += 1
    return row, nu


@njit(**PAR)
def assemble(kind, dirichlet, p_dir, b, start, nbr, dist, re, n0, lam, diag_extra, lap_mode=0):
    """Pressure equation of the non-Dirichlet fluid and wall particles as CSR.

    Row of unknown i: diag_extra P_i + sum_j w_ij (P_i - P_j) = -(lambda n0 / 2d) b_i over fluid and wall
    neighbours j (dummies excluded), Dirichlet neighbours' P_j = p_dir[j] moved to the right-hand side:
    the MPS Laplacian times -(lambda n0 / 2d) plus the compressibility term (MPS-Basic's
    PressurePoissonEquation scaled by rho0 lambda n0 / 2d).  Symmetric; positive definite when
    diag_extra > 0 or every cluster touches a Dirichlet particle.  Row i's entries: the diagonal, then
    its neighbours in list order.  lap_mode (LAPLACIANS) 1: the higher-order Laplacian of Khayyer & Gotoh
    2010 (Appl. Ocean Res. 32, 124), <lap P>_i = 1/n0 sum_j (P_j - P_i) 3 r_e / r^3 (2D), i.e. the weight
    3 r_e / r^3 and the right-hand side -n0 b_i.  Returns (row (N,), indptr, indices, data, rhs)."""
    n = kind.shape[0]
    row, nu = unknown_rows(kind, dirichlet)
    count = np.zeros(nu + 1, np.int64)
    for i in prange(n):
        if row[i] < 0:
            continue
        c = 1
        first, end = row_span(start, i)
        for k in range(first, end):
            if dist[k] < re and row[uint64(nbr[k])] >= 0:
                c += 1
        count[row[i] + 1] = c
    for r in range(nu):
        count[r + 1] += count[r]
    indices = np.empty(count[nu], np.int32)
    data = np.empty(count[nu])
    rhs = np.empty(nu)
    c0 = -lam * n0 / (2.0 * DIM) if lap_mode == 0 else -n0
    for i in prange(n):
        r = row[i]
        if r < 0:
            continue
        q = count[r]
        indices[q] = r
        diag = diag_extra
        extra = 0.0
        q += 1
        first, end = row_span(start, i)
        for k in range(first, end):
            j = uint64(nbr[k])
            if kind[j] == DUMMY or dist[k] >= re:
                continue
            wt = weight(dist[k], re) if lap_mode == 0 else 3.0 * re / max(dist[k], 1e-6 * re) ** 3
            diag += wt
            if row[j] >= 0:
                indices[q] = row[j]
                data[q] = -wt
                q += 1
            else:
                extra += wt * p_dir[j]
        data[count[r]] = diag
        rhs[r] = c0 * b[i] + extra
    return row, count, indices, data, rhs


@njit(**PAR)
def shift(pos, kind, surf, normal, start, nbr, dist, re, n0, coeff, l0):
    """Particle shifting (Fickian, Lind et al. 2012, in MPS form): dr_i = -coeff l0^2 grad C_i with the
    concentration gradient grad C_i = d/n0 sum_j r_ij / r_ij^2 w(r_ij) over neighbours of any kind (0 on the
    full lattice, towards the crowded side elsewhere), limited to 0.2 l0; free-surface particles move only
    along their surface (normal component removed, Lind et al. 2012).  Returns the shifts (N, 2) [cm]."""
    n = pos.shape[0]
    out = np.zeros((n, 2))
    a = DIM / n0
    for i in prange(n):
        if kind[i] != FLUID:
            continue
        gx = gy = 0.0
        for k in range(start[i], start[i + 1]):
            wt = weight(dist[k], re)
            if wt == 0.0:
                continue
            j = nbr[k]
            q = wt / (dist[k] * dist[k])
            gx += q * (pos[j, 0] - pos[i, 0])
            gy += q * (pos[j, 1] - pos[i, 1])
        dx = -coeff * l0 * l0 * a * gx
        dy = -coeff * l0 * l0 * a * gy
        if surf[i]:
            d = dx * normal[i, 0] + dy * normal[i, 1]
            dx -= d * normal[i, 0]
            dy -= d * normal[i, 1]
        L = np.hypot(dx, dy)
        if L > 0.2 * l0:
            dx *= 0.2 * l0 / L
            dy *= 0.2 * l0 / L
        out[i, 0] = dx
        out[i, 1] = dy
    return out


@njit(**PAR)
def update(ps, vs, kind, g, rho0, dt):
    """Pressure half (eqs. 4-5): V = V* - dt / rho0 grad P, U = U* + dt (V - V*) for the fluid."""
    pos = ps.copy()
    vel = vs.copy()
    for i in prange(ps.shape[0]):
        if kind[i] == FLUID:
            update_one(i, ps, vs, pos, vel, g[i, 0], g[i, 1], rho0, dt)
    return pos, vel


@njit(inline="always", **JIT)
def update_one(i, ps, vs, pos, vel, gx, gy, rho0, dt):
    """update for fluid particle i, grad P_i = (gx, gy): writes pos[i], vel[i]."""
    vel[i, 0] = vs[i, 0] - dt / rho0 * gx
    vel[i, 1] = vs[i, 1] - dt / rho0 * gy
    pos[i, 0] = ps[i, 0] - dt * dt / rho0 * gx
    pos[i, 1] = ps[i, 1] - dt * dt / rho0 * gy


@njit(**PAR)
def reflect(pos_old, pos, vel, kind, walls, restitution, gap):
    """Wall-penetration guard: a fluid particle whose move pos_old -> pos crosses a wall segment
    (crossed_wall: from either side of a thin wall) is put back on the side it came from, at its mirror
    image in the wall's line (at least ``gap`` cm from it), and the normal component of its velocity into
    the wall is reversed times ``restitution`` (the collision model's inelastic impulse against an
    immovable wall: v_n -> -e v_n).  Repeated for a move that then crosses another wall (a corner); a move
    still crossing after 4 reflections ends at pos_old.  Returns (pos, vel, reflected (N,) bool); the
    inputs are not changed."""
    po = pos.copy()
    vo = vel.copy()
    hit = np.zeros(pos.shape[0], np.bool_)
    for i in prange(pos.shape[0]):
        if kind[i] != FLUID:
            continue
        x0 = pos_old[i, 0]
        y0 = pos_old[i, 1]
        x1 = pos[i, 0]
        y1 = pos[i, 1]
        if not (np.isfinite(x1) and np.isfinite(y1)):
            continue
        vx = vel[i, 0]
        vy = vel[i, 1]
        done = False
        for _ in range(4):
            w = crossed_wall(x0, y0, x1, y1, walls)
            if w < 0:
                done = True
                break
            hit[i] = True
            ax = walls[w, 0]
            ay = walls[w, 1]
            ex = walls[w, 2] - ax
            ey = walls[w, 3] - ay
            L = np.hypot(ex, ey)
            nx = -ey / L
            ny = ex / L
            if (x0 - ax) * nx + (y0 - ay) * ny < 0.0:  # came from a thin wall's back
                nx = -nx
                ny = -ny
            d1 = (x1 - ax) * nx + (y1 - ay) * ny  # <= 0: behind the line
            push = max(-2.0 * d1, -d1 + gap)
            x1 += push * nx
            y1 += push * ny
            vn = vx * nx + vy * ny
            if vn < 0.0:
                vx -= (1.0 + restitution) * vn * nx
                vy -= (1.0 + restitution) * vn * ny
        if not done:
            x1 = x0
            y1 = y0
        po[i, 0] = x1
        po[i, 1] = y1
        vo[i, 0] = vx
        vo[i, 1] = vy
    return po, vo, hit


@njit(**JIT)
def check(pos_old, pos, vel, kind, walls, box, graze):
    """First bad particle of a step: (kind of failure, particle, wall), deepest graze [cm].

    0 fine, 1 non-finite position or velocity, 2 crossed a wall (from pos_old) and ended more than
    ``graze`` [cm] from it, 3 more than ``graze`` outside the box (4,).  A crossing that ends within
    ``graze`` of the wall segment is a graze: its depth is returned, the step goes on."""
    bad = (0, -1, -1)
    deepest = 0.0
    for i in range(pos.shape[0]):
        if kind[i] != FLUID:
            continue
        if not (np.isfinite(pos[i, 0]) and np.isfinite(pos[i, 1]) and np.isfinite(vel[i, 0]) and np.isfinite(vel[i, 1])):
            return (1, i, -1), deepest
        w = crossed_wall(pos_old[i, 0], pos_old[i, 1], pos[i, 0], pos[i, 1], walls)
        if w >= 0:
            cx, cy = segment_closest(pos[i, 0], pos[i, 1], walls[w, 0], walls[w, 1], walls[w, 2], walls[w, 3])
            depth = np.hypot(pos[i, 0] - cx, pos[i, 1] - cy)
            if depth > graze:
                return (2, i, w), deepest
            deepest = max(deepest, depth)
        elif (pos[i, 0] < box[0] - graze or pos[i, 0] > box[2] + graze or pos[i, 1] < box[1] - graze
              or pos[i, 1] > box[3] + graze):
            return (3, i, -1), deepest
    return bad, deepest


# --- one step in two compiled calls around the pressure solve ------------------------------------------------------
# predict: the neighbour lists, the explicit half, collisions, the guard, the free surface, the source term and the
# pressure system; correct: the pressure half, shifting, the guard, the check and the wall loads' sums.  Each pass
# over the lists computes its pairs' distances itself (operators.pair_distance, a pair beyond every radius cut on its
# squared distance first) and gives every particle the same numbers, summed in the same order, as the stage kernels
# above do (the standalone kernels are the reference: tests/test_mps.py).

# the step's constants (settings and the run's lattice constants; StepConstants, built by step_constants)
STEP_CONSTANTS = {
    "nf": int, "l0": float, "rmax": float, "skin": float, "nu": float, "ecs": bool, "re_n": float, "re_g": float,
    "re_l": float, "re_s": float, "n0_n": float, "n0_g": float, "n0_s": float, "n0_l": float, "lam": float,
    "rho0": float, "n_grad": float, "grad_mode": int, "div_mode": int, "lap_mode": int, "surface_mode": int,
    "cdist": float, "restitution": float, "reflect": bool, "behind": bool, "beta": float, "dist_thr": float,
    "gamma": float, "relax": float, "scope": int, "clip": bool, "shifting": float, "graze": float,
    "mass_over_rho": float,
}
StepConstants = collections.namedtuple("StepConstants", list(STEP_CONSTANTS))


def step_constants(**values):
    """StepConstants of the given values, each of its STEP_CONSTANTS type (one compiled signature)."""
    return StepConstants(**{k: t(values[k]) for k, t in STEP_CONSTANTS.items()})


@njit(**JIT)
def list_holds(pos, list_pos, nf, skin):
    """The lists built at list_pos still hold every pair closer than their radius less skin at pos: no fluid particle
    (the first nf) moved more than skin / 2 (a non-finite move: no)."""
    if list_pos.shape[0] != pos.shape[0]:
        return False
    lim = (0.5 * skin) ** 2
    for i in range(nf):
        dx = pos[i, 0] - list_pos[i, 0]
        dy = pos[i, 1] - list_pos[i, 1]
        if not dx * dx + dy * dy <= lim:
            return False
    return True


@njit(**JIT)
def lists_at(pos, kind, tw, tside, grid_box, start, nbr, list_pos, counts, c):
    """(start, nbr, list_pos): the lists, rebuilt at pos (counts[0] += 1) unless they still hold there (list_holds);
    radius rmax + skin, every pair whatever the thin walls (visibility is decided at the positions used)."""
    if list_holds(pos, list_pos, c.nf, c.skin):
        return start, nbr, list_pos
    counts[0] += 1
    start, nbr = neighbour_list(pos, kind, grid_box, c.rmax + c.skin, tw, tside, np.zeros((0, 4)))
    return start, nbr, pos.copy()


@njit(inline="always", **JIT)
def _explicit_row(i, pos, vel, kind, start, nbr, tw, tside, near, thin, behind, cut2, re_l, re_n, lap, ecs, vis):
    """Row i's sums of explicit_pass: (x, y) of sum_j (v_j - v_i) w(r; re_l) over its fluid and wall neighbours (lap),
    sum_j w(r; re_n) over all (ecs), and its nearest listed neighbour's squared distance.  lap, ecs and vis (check
    visibility: the tank has thin walls) are constants at the call sites that matter: a pass's inner loop compiled
    with only the work it does (a loop-invariant test per list entry costs as much as an addition here)."""
    plain = plain_row(i, tw, near, thin)
    lx = ly = nd = 0.0
    m2 = np.inf
    first, end = row_span(start, i)
    for k in range(first, end):
        j = uint64(nbr[k])
        dx = pos[j, 0] - pos[i, 0]
        dy = pos[j, 1] - pos[i, 1]
        r2 = dx * dx + dy * dy
        m2 = min(m2, r2)
        if r2 >= cut2 or (vis and not sees(i, j, pos, tw, tside, near, thin, behind, plain)):
            continue
        r = pair_distance(dx, dy)
        if ecs:
            nd += weight(r, re_n)
        if lap and kind[j] != DUMMY:
            wt = weight(r, re_l)
            lx += (vel[j, 0] - vel[i, 0]) * wt
            ly += (vel[j, 1] - vel[i, 1]) * wt
    return lx, ly, nd, m2


@njit(**JIT)
def _explicit_any(i, pos, vel, kind, start, nbr, tw, tside, near, thin, behind, cut2, re_l, re_n, lap, ecs, vis):
    """_explicit_row with its flags as arguments, a function of its own: the named options' case (ECS, or no
    viscosity), called out of explicit_pass' parallel loop rather than numba-inlined into it a third time (compile
    time; the settings' case keeps its two inlined copies with constant flags, where the step's cost is)."""
    return _explicit_row(i, pos, vel, kind, start, nbr, tw, tside, near, thin, behind, cut2, re_l, re_n, lap, ecs, vis)


@njit(**PAR)
def explicit_pass(pos, vel, kind, start, nbr, tw, tside, near, thin, c, dt, gx, gy):
    """The explicit half (explicit) with the Laplacian of the velocity (laplacian, re_l, if nu > 0) and, with ECS, the
    number density at pos (number_density, re_n) in one pass.  Returns (U*, V*, n (N,); empty without ECS, near (N,)
    bool: the fluid particles that may come closer than the collision distance cdist to a neighbour at U*, from their
    nearest listed neighbour at pos and every fluid particle's move; all of them if a move is too large to tell)."""
    n = pos.shape[0]
    ps = pos.copy()
    vs = vel.copy()
    n_now = np.zeros(n if c.ecs else 0)
    nearest = np.full(n, np.inf)  # squared distance of each fluid row's nearest listed neighbour at pos
    lap = c.nu > 0.0
    plain = lap and not c.ecs  # the settings' case: fluid rows only, the Laplacian alone
    vis = thin.shape[0] > 0
    cl = 2.0 * DIM / (c.lam * c.n0_l)
    cut2 = max(c.re_l if lap else 0.0, c.re_n if c.ecs else 0.0) ** 2 * CUT
    for i in prange(n):
        fluid = kind[i] == FLUID
        lx = ly = 0.0
        if plain and fluid:
            if vis:
                lx, ly, _, nearest[i] = _explicit_row(i, pos, vel, kind, start, nbr, tw, tside, near, thin, c.behind,
                                                      cut2, c.re_l, c.re_n, True, False, True)
            else:
                lx, ly, _, nearest[i] = _explicit_row(i, pos, vel, kind, start, nbr, tw, tside, near, thin, c.behind,
                                                      cut2, c.re_l, c.re_n, True, False, False)
            lx *= cl
            ly *= cl
        elif not plain and ((fluid and lap) or (c.ecs and kind[i] != DUMMY)):
            lx, ly, nd, nearest[i] = _explicit_any(i, pos, vel, kind, start, nbr, tw, tside, near, thin, c.behind, cut2,
                                                   c.re_l, c.re_n, fluid and lap, c.ecs, vis)
            if c.ecs:
                n_now[i] = nd
            lx *= cl
            ly *= cl
        if fluid:
            explicit_one(i, pos, vel, ps, vs, lx, ly, dt, gx, gy, c.nu)
    return ps, vs, n_now, may_collide(pos, ps, kind, nearest, c.cdist, c.rmax if lap or c.ecs else 0.0)


@njit(**JIT)
def may_collide(pos, ps, kind, nearest, cdist, reach):
    """(N,) bool: the fluid particles i with sqrt(nearest[i]) - |ps_i - pos_i| - max_j |ps_j - pos_j| < cdist (plus
    1e-9 of it), the others' listed neighbours all stay at cdist or more (triangle inequality); every fluid particle
    when 2 max |ps - pos| + cdist reaches ``reach`` (a pair that close at ps may have been beyond the squared
    distances seen in nearest)."""
    n = pos.shape[0]
    move = np.zeros(n)
    most = 0.0
    for i in range(n):
        if kind[i] == FLUID:
            move[i] = pair_distance(ps[i, 0] - pos[i, 0], ps[i, 1] - pos[i, 1])
            most = max(most, move[i])
    out = np.zeros(n, np.bool_)
    whole = not (cdist + 2.0 * most) * (1.0 + 1e-9) < reach
    for i in range(n):
        if kind[i] == FLUID:
            out[i] = whole or np.sqrt(nearest[i]) - move[i] - most < cdist * (1.0 + 1e-9)
    return out


@njit(inline="always", **JIT)
def _terms_row(i, ps, vs, start, nbr, tw, tside, near, thin, behind, cut2, re_n, re_g, rmax, dist, div, vis):
    """Row i of pressure_terms: stores its entries' distances (inf: cut or unseen); returns (number density, K&O
    divergence sum (div), sum_j r_ij over r < rmax (x, y)).  div and vis are constants in each compiled version of
    _terms_row_fixed."""
    plain = plain_row(i, tw, near, thin)
    nd = dv = sx = sy = 0.0
    first, end = row_span(start, i)
    for k in range(first, end):
        j = uint64(nbr[k])
        dx = ps[j, 0] - ps[i, 0]
        dy = ps[j, 1] - ps[i, 1]
        if dx * dx + dy * dy >= cut2 or (vis and not sees(i, j, ps, tw, tside, near, thin, behind, plain)):
            dist[k] = np.inf
            continue
        r = pair_distance(dx, dy)
        dist[k] = r
        nd += weight(r, re_n)
        if div and r < re_g:
            dv += divergence_term(False, i, j, ps, vs, r, re_g)
        if r < rmax:
            sx += dx
            sy += dy
    return nd, dv, sx, sy


@njit(**JIT)
def _terms_row_fixed(i, ps, vs, start, nbr, tw, tside, near, thin, behind, cut2, re_n, re_g, rmax, dist, div, vis):
    """_terms_row compiled once per value of its flags (numba.literally: div and vis literal constants at
    pressure_terms' four call sites), a function of its own that the parallel loop calls.  Numba-inlined into the
    loop itself, the four copies took 34 of the method's 85 s of compiling (parfor passes over the inlined bodies);
    as four small functions 12 s, at the same step cost to 1 %."""
    literally(div)
    literally(vis)
    return _terms_row(i, ps, vs, start, nbr, tw, tside, near, thin, behind, cut2, re_n, re_g, rmax, dist, div, vis)


@njit(inline="always", **JIT)
def _terms_tail(i, nd, div, n_s, sx, sy, c, dt, source, a_d, a_v, n_now, n_prev):
    """Particle i's (free surface, number-density test alone, source term) of pressure_terms from its sums: number
    density nd, divergence div, the surface test's number density n_s and offsets (sx, sy)."""
    bi = source_term(nd, div, c.n0_n, c.rho0, dt, source, c.gamma, a_d, a_v)
    if c.ecs:
        bi = bi + ecs_value(n_now[i], n_prev[i], c.n0_n, c.rho0, dt)
    return on_surface(n_s, sx, sy, c.beta, c.n0_s, c.dist_thr), n_s < c.beta * c.n0_s, bi


@njit(**PAR)
def pressure_terms(ps, vs, kind, start, nbr, tw, tside, near, thin, c, n_now, n_prev, dt, source):
    """At the predicted state: every list entry's distance (visible_distances; inf beyond rmax or unseen; the dummies'
    rows are empty, neighbour_list), the free surface (surface; normals only where used: surface_mode, shifting) and
    the source term (number density re_n, divergence re_g, source_term_all relaxed, plus ecs_term with ECS): one pass
    for the settings' operators, the named alternatives (a surface radius of its own, the hs divergence, normals) each
    a pass of its own over the stored distances.  Returns (dist (M,), surf (N,), low (N,): n* < beta n0 at re_s, the
    surface test's number-density half (clusters.anchor_clusters), normal (N, 2), b (N,))."""
    n = ps.shape[0]
    dist = np.empty(nbr.shape[0])
    surf = np.zeros(n, np.bool_)
    low = np.zeros(n, np.bool_)
    normal = np.zeros((n, 2))
    b = np.zeros(n)
    cut2 = c.rmax * c.rmax * CUT
    mps_div = source != 0 and c.div_mode == 0  # the standard source has no divergence term
    hs_div = source != 0 and c.div_mode == 1
    normals = c.surface_mode != 0 or c.shifting > 0.0
    alone = not hs_div and c.re_s == c.re_n and not normals  # no named alternative: one pass does it all
    vis = thin.shape[0] > 0
    a_d, a_v = relaxation_factors(source, c.scope, c.relax)
    keep = 0 if alone else n
    nd, div, offs = np.zeros(keep), np.zeros(keep), np.zeros((keep, 2))
    for i in prange(n):
        if kind[i] == DUMMY:
            continue
        if mps_div and vis:
            nd_i, dv, sx, sy = _terms_row_fixed(i, ps, vs, start, nbr, tw, tside, near, thin, c.behind, cut2, c.re_n,
                                                c.re_g, c.rmax, dist, True, True)
        elif mps_div:
            nd_i, dv, sx, sy = _terms_row_fixed(i, ps, vs, start, nbr, tw, tside, near, thin, c.behind, cut2, c.re_n,
                                                c.re_g, c.rmax, dist, True, False)
        elif vis:
            nd_i, dv, sx, sy = _terms_row_fixed(i, ps, vs, start, nbr, tw, tside, near, thin, c.behind, cut2, c.re_n,
                                                c.re_g, c.rmax, dist, False, True)
        else:
            nd_i, dv, sx, sy = _terms_row_fixed(i, ps, vs, start, nbr, tw, tside, near, thin, c.behind, cut2, c.re_n,
                                                c.re_g, c.rmax, dist, False, False)
        div_i = divergence_value(False, dv, c.n0_g) if mps_div else 0.0
        if alone:
            surf[i], low[i], b[i] = _terms_tail(i, nd_i, div_i, nd_i, sx, sy, c, dt, source, a_d, a_v, n_now, n_prev)
        else:
            nd[i], div[i], offs[i, 0], offs[i, 1] = nd_i, div_i, sx, sy
    if alone:
        return dist, surf, low, normal, b
    if hs_div:
        div = divergence_hs(ps, vs, start, nbr, dist, c.re_g, c.n0_g)
    n_s = number_density(start, nbr, dist, c.re_s) if c.re_s != c.re_n else nd
    sw = offsets(ps, start, nbr, dist, c.rmax, c.re_s)[1] if normals else offs
    for i in prange(n):
        if kind[i] == DUMMY:
            continue
        surf[i], low[i], b[i] = _terms_tail(i, nd[i], div[i], n_s[i], offs[i, 0], offs[i, 1], c, dt, source, a_d,
                                            a_v, n_now, n_prev)
        if normals:
            normal[i, 0], normal[i, 1] = outward(sw[i, 0], sw[i, 1])
    return dist, surf, low, normal, b


@njit(**JIT)
def predict(pos, vel, p_prev, kind, tw, tside, thin, walls, grid_box, start, nbr, list_pos, n_prev, counts, c, dt, gx,
            gy, source, extra):
    """Everything of a step before the pressure solve, from the state (pos, vel; p_prev the last step's pressures):
    the lists (lists_at: at pos, then wherever the predicted positions move), the explicit half (explicit_pass),
    collisions (collide, cdist > 0, if a fluid particle may collide: may_collide), the guard (reflect), then at the
    predicted state the distances, free surface and source (pressure_terms; clusters.anchor_clusters: the surface of a
    droplet the particle-distribution test cleared), the surface pressures (surface_mode) and
    the system (assemble; extra its compressibility term).  n_prev: the number density at the previous step's start
    (ECS; empty: none yet).
    counts (4,) int64 [list builds, reflect steps, reflected particles, grazes] are added to.
    Returns (start, nbr, list_pos, n_now, ps, vs, dist, surf, normal, p_dir, row, indptr, indices, data, rhs, x0):
    the lists, the number density at pos (ECS, else n_prev), the predicted state and its pressure system with its
    start vector (p_prev's unknowns)."""
    reach = c.rmax + c.skin
    start, nbr, list_pos = lists_at(pos, kind, tw, tside, grid_box, start, nbr, list_pos, counts, c)
    ps, vs, n_now, rows = explicit_pass(pos, vel, kind, start, nbr, tw, tside, near_thin(pos, thin, reach), thin, c, dt,
                                        gx, gy)
    if not c.ecs:
        n_now = n_prev
    elif n_prev.shape[0] == 0:
        n_prev = n_now
    start, nbr, list_pos = lists_at(ps, kind, tw, tside, grid_box, start, nbr, list_pos, counts, c)
    if c.cdist > 0.0 and rows.any():
        ps, vs = collide(ps, vs, kind, start, nbr, tw, tside, near_thin(ps, thin, reach), thin, c.behind, c.cdist,
                         c.restitution, rows)
        start, nbr, list_pos = lists_at(ps, kind, tw, tside, grid_box, start, nbr, list_pos, counts, c)
    if c.reflect:
        ps, vs, hit = reflect(pos, ps, vs, kind, walls, c.restitution, 1e-6 * c.l0)
        count_hits(hit, counts)
        start, nbr, list_pos = lists_at(ps, kind, tw, tside, grid_box, start, nbr, list_pos, counts, c)
    dist, surf, low, normal, b = pressure_terms(ps, vs, kind, start, nbr, tw, tside, near_thin(ps, thin, reach), thin,
                                                c, n_now, n_prev, dt, source)
    anchor_clusters(kind, surf, low, start, nbr, dist, c.re_l)
    if c.surface_mode == 2:
        p_dir = surface_values(ps, p_prev, kind, surf, normal, start, nbr, dist, c.re_g, c.n0_g, 0.5 * c.l0)
    else:
        p_dir = np.zeros(ps.shape[0])
        if c.surface_mode == 1:
            h = c.rho0 * units.G * 0.5 * c.l0
            for i in range(ps.shape[0]):
                if surf[i]:
                    p_dir[i] = h * max(normal[i, 1], 0.0)
    row, indptr, indices, data, rhs = assemble(kind, surf, p_dir, b, start, nbr, dist, c.re_l, c.n0_l, c.lam, extra,
                                               c.lap_mode)
    x0 = np.zeros(rhs.shape[0])
    for i in range(ps.shape[0]):
        if row[i] >= 0:
            x0[row[i]] = p_prev[i]
    return start, nbr, list_pos, n_now, ps, vs, dist, surf, normal, p_dir, row, indptr, indices, data, rhs, x0


@njit(**JIT)
def count_hits(hit, counts):
    """Count a reflect call's particles: counts[1] steps with one, counts[2] particles."""
    m = 0
    for i in range(hit.shape[0]):
        m += hit[i]
    if m:
        counts[1] += 1
        counts[2] += m


@njit(**PAR)
def pressure_pass(ps, vs, p, pmin, kind, start, nbr, dist, c, dt):
    """The pressure half (gradient, then update) in one pass.  Returns (U, V, walls (N,): the number of each fluid
    particle's gradient terms that are a boundary particle's, their list entries and pair coefficients wk (M,), wq (M,)
    from start[i] on: recorded_wall_terms)."""
    n = ps.shape[0]
    pos = ps.copy()
    vel = vs.copy()
    walls = np.zeros(n, np.int64)
    wk = np.empty(nbr.shape[0], np.int64)
    wq = np.empty(nbr.shape[0])
    a = DIM / c.n_grad
    variational = c.grad_mode == VARIATIONAL  # the settings' gradient: its own compiled loop
    for i in prange(n):
        if kind[i] == FLUID:
            if variational:
                gx, gy, walls[i] = gradient_row(i, ps, p, pmin, kind, start, nbr, dist, c.re_g, a, VARIATIONAL, True,
                                                wk, wq)
            else:
                gx, gy, walls[i] = gradient_row(i, ps, p, pmin, kind, start, nbr, dist, c.re_g, a, c.grad_mode, True,
                                                wk, wq)
            update_one(i, ps, vs, pos, vel, gx, gy, c.rho0, dt)
    return pos, vel, walls, wk, wq


@njit(inline="always", **JIT)
def sparse_row(ptr, idx, val, x, first, col, r):
    """Row r of the CSR matrix (ptr, idx, val) times x[first + column, col], in column order."""
    s = 0.0
    for k in range(ptr[r], ptr[r + 1]):
        s += val[k] * x[first + idx[k], col]
    return s


@njit(**JIT)
def panel_loads(f, p, nf, share, loads):
    """(2P, 2) N: the force of each wall panel on the liquid by the pair-force reading (the boundary particles' forces
    f (Nb, 2), wall_forces, split between the panels by share) and then by the panel reading (the first wall row's
    pressures p[nf:] times the wall length they face, loads); share (P x Nb) and loads (2P x Nb) as CSR (indptr,
    indices, data) of boundary.load_map's matrices."""
    npan = share[0].shape[0] - 1
    out = np.empty((2 * npan, 2))
    for q in range(npan):
        for col in range(2):
            out[q, col] = sparse_row(share[0], share[1], share[2], f, 0, col, q)
    pb = p.reshape((p.shape[0], 1))
    for q in range(npan):
        for col in range(2):
            out[npan + q, col] = sparse_row(loads[0], loads[1], loads[2], pb, nf, 0, 2 * q + col)
    return out


@njit(**JIT)
def correct(pos_old, ps, vs, x, row, p_dir, dist, surf, normal, kind, tw, tside, thin, walls, grid_box, escape_box,
            start, nbr, list_pos, counts, deepest, load_sum, p_sum, share, loads, c, dt):
    """Everything of a step after the pressure solve x (predict's system): the pressures (clipped: clip), the pressure
    half (pressure_pass), shifting (shifting > 0), the guard (reflect), the check (check; grazes: counts[3] and
    deepest (1,) cm), and this step's wall loads (panel_loads: the boundary particles' pair forces, wall_forces, through
    share; the panel pressures' forces through loads) and liquid pressures times dt added to load_sum (2P, 2) N s and
    p_sum (nf,).
    Returns (done, pos, vel, p, bad, start, nbr, list_pos); done False (nothing changed) for a non-finite x."""
    n = ps.shape[0]
    for r in range(x.shape[0]):
        if not np.isfinite(x[r]):
            return False, ps, vs, p_dir, (4, -1, -1), start, nbr, list_pos
    p = p_dir.copy()
    for i in range(n):
        if row[i] >= 0:
            p[i] = x[row[i]]
        if c.clip and not p[i] > 0.0:  # np.maximum(p, 0): -0 too becomes 0
            p[i] = 0.0
    pmin = neighbourhood_min(p, kind, start, nbr, dist, c.re_g) if c.grad_mode in (0, 1, 3) else p
    pos, vel, walls_i, wk, wq = pressure_pass(ps, vs, p, pmin, kind, start, nbr, dist, c, dt)
    nf = c.nf
    f = np.zeros((n - nf, 2))  # the boundary particles' forces on the liquid (wall_forces)
    for i in range(nf):
        if walls_i[i]:
            recorded_wall_terms(i, f, nf, ps, kind, start, nbr, dist, c.re_g, DIM / c.n_grad, c.grad_mode,
                                c.mass_over_rho, wk, wq, walls_i[i])
    step_loads = panel_loads(f, p, nf, share, loads)
    for q in range(load_sum.shape[0]):
        for col in range(2):
            load_sum[q, col] += dt * step_loads[q, col]
    for i in range(nf):
        p_sum[i] += dt * p[i]
    if c.shifting > 0.0:
        start, nbr, list_pos = lists_at(pos, kind, tw, tside, grid_box, start, nbr, list_pos, counts, c)
        d2 = visible_distances(pos, start, nbr, tw, tside, thin, c.rmax + c.skin, c.behind)
        pos = pos + shift(pos, kind, surf, normal, start, nbr, d2, c.re_n, c.n0_n, c.shifting, c.l0)
    if c.reflect:
        pos, vel, hit = reflect(pos_old, pos, vel, kind, walls, c.restitution, 1e-6 * c.l0)
        count_hits(hit, counts)
    bad, graze = check(pos_old, pos, vel, kind, walls, escape_box, c.graze)
    if graze > 0.0:
        counts[3] += 1
        deepest[0] = max(deepest[0], graze)
    return True, pos, vel, p, bad, start, nbr, list_pos


@intrinsic
def ticks(typingctx):
    """The processor's cycle counter (llvm.readcyclecounter: the time-stamp counter on x86; 0 where there is none), for
    the stage times of a compiled step (solver.step turns them into seconds by the call's own clock)."""
    def codegen(context, builder, signature, args):
        counter = builder.module.declare_intrinsic("llvm.readcyclecounter", fnty=ir.FunctionType(ir.IntType(64), []))
        return builder.call(counter, [])

    return types.int64(), codegen


@njit(**JIT)
def step_cg(pos, vel, p, kind, tw, tside, thin, walls, grid_box, escape_box, start, nbr, list_pos, n_prev, counts,
            deepest, load_sum, p_sum, share, loads, c, dt, gx, gy, source, extra, rtol, maxiter, threads, clock):
    """One whole step with the compiled pressure solve (pressure.cg_solve): predict, the solve from the last
    pressures, correct (threads: numba's, cg_solve); clock (3,) int64 gets the cycles (ticks) of the three.  Returns (done, bad, residual,
    iterations, failed, start, nbr, list_pos, n_now, pos, vel, p, surf, ps, dist, grad_start, grad_nbr): done False
    when the solve failed (failed: a zero diagonal) or its result is not finite (the state is then the old one but for
    the lists and counters); grad_start, grad_nbr the lists of the pressure gradient (shifting may rebuild them
    after it)."""
    t0 = ticks()
    start, nbr, list_pos, n_now, ps, vs, dist, surf, normal, p_dir, row, indptr, indices, data, rhs, x0 = predict(
        pos, vel, p, kind, tw, tside, thin, walls, grid_box, start, nbr, list_pos, n_prev, counts, c, dt, gx, gy, source,
        extra)
    t1 = ticks()
    x, resid, its, failed = cg_solve(indptr, indices, data, rhs, x0, rtol, maxiter, threads)
    t2 = ticks()
    grad_start, grad_nbr = start, nbr
    done = False
    bad = (4, -1, -1)
    if not failed and np.isfinite(resid):
        done, pos, vel, p, bad, start, nbr, list_pos = correct(
            pos, ps, vs, x, row, p_dir, dist, surf, normal, kind, tw, tside, thin, walls, grid_box, escape_box, start,
            nbr, list_pos, counts, deepest, load_sum, p_sum, share, loads, c, dt)
    clock[0] = t1 - t0
    clock[1] = t2 - t1
    clock[2] = ticks() - t2
    return (done, bad, resid, its, failed, start, nbr, list_pos, n_now, pos, vel, p, surf, ps, dist, grad_start,
            grad_nbr)
