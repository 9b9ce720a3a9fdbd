"""The stages of one MPS time step (numba): explicit step, collision model, free surface, source term,
pressure-equation assembly, pressure correction, particle shifting, the penetration guard (reflect) and the
wall-crossing check.

Koshizuka & Oka (1996), as the public MPS-Basic code implements it (github.com/MPS-Basic/MPS-Basic,
src/mps.cpp, src/pressure_calculator/implicit.cpp), with the named options of config/methods/mps.yaml.
Operators and neighbour lists in operators.py (re-exported here).  Every loop over particles gathers
from the particle's own neighbour row (numba prange; bit-identical for any thread count).
Units: cm, s, density N s^2 / cm^4 (2D), pressure N / cm^2.
"""

import numpy as np
from numba import prange

from ...core.jit import njit

from isaflow.core.geometry import crossed_wall, segment_closest

from .operators import (DIM, DUMMY, FLUID, GRADIENTS, JIT, PAIRWISE, PAR, WALL, distances, divergence, divergence_hs,  # noqa: F401
                        gradient, gradient_norm, lattice_constants, laplacian, neighbour_list, number_density, offsets,
                        probe_pressure, visible_distances, wall_forces, weight)

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
        rate = (n_now[i] - n_prev[i]) / dt
        alpha = abs(n_now[i] - n0) / n0
        beta = abs(dt / n0 * rate)
        out[i] = -rho0 / (n0 * dt) * alpha * rate - beta * rho0 / (n0 * dt * dt) * (n_now[i] - n0)
    return out


@njit(**PAR)
def explicit(pos, vel, kind, lap, dt, gx, gy, nu):
    """Explicit half (eq. 3): V* = V + dt (nu lap V + g), U* = U + dt V* for the fluid.  Returns (U*, V*)."""
    ps = pos.copy()
    vs = vel.copy()
    for i in prange(pos.shape[0]):
        if kind[i] == FLUID:
            vs[i, 0] = vel[i, 0] + dt * (nu * lap[i, 0] + gx)
            vs[i, 1] = vel[i, 1] + dt * (nu * lap[i, 1] + gy)
            ps[i, 0] = pos[i, 0] + dt * vs[i, 0]
            ps[i, 1] = pos[i, 1] + dt * vs[i, 1]
    return ps, vs


@njit(**PAR)
def collide(ps, vs, kind, start, nbr, dist, cdist, restitution):
    """Collision model of MPS-Basic (MPS::collision) as a gather: every fluid particle closer than ``cdist``
    [cm] to a listed neighbour (any kind; wall and dummy particles immovable) takes, for each such pair,
    the impulse that removes (1 + e) of the approaching normal relative velocity (equal masses share it)
    and half (fluid-fluid) or all (fluid-wall) of the push back to ``cdist``, all pairs computed from the
    state before the collision (MPS-Basic updates pair by pair in sequence; here every pair's exchange is
    the same from both ends, so momentum is conserved and the order does not matter).  dist (M,) the list
    entries' distances at ps (inf: the pair does not see each other across a thin wall).
    Returns (U, V) after the collision."""
    n = ps.shape[0]
    po = ps.copy()
    vo = vs.copy()
    for i in prange(n):
        if kind[i] != FLUID:
            continue
        for k in range(start[i], start[i + 1]):
            j = nbr[k]
            r = dist[k]
            if r >= cdist or r == 0.0:
                continue
            dx = ps[j, 0] - ps[i, 0]
            dy = ps[j, 1] - ps[i, 1]
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
        f = n_s[i] < beta * n0_s
        if f and dist_thr > 0.0:
            f = abs(s[i, 0]) > dist_thr or abs(s[i, 1]) > dist_thr
        surf[i] = f
        L = np.hypot(sw[i, 0], sw[i, 1])
        if L > 0.0:
            normal[i, 0] = -sw[i, 0] / L
            normal[i, 1] = -sw[i, 1] / L
    return surf, normal


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
        for k in range(start[i], start[i + 1]):
            if dist[k] < re and row[nbr[k]] >= 0:
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
        for k in range(start[i], start[i + 1]):
            j = nbr[k]
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
        if kind[i] != FLUID:
            continue
        vel[i, 0] = vs[i, 0] - dt / rho0 * g[i, 0]
        vel[i, 1] = vs[i, 1] - dt / rho0 * g[i, 1]
        pos[i, 0] = ps[i, 0] - dt * dt / rho0 * g[i, 0]
        pos[i, 1] = ps[i, 1] - dt * dt / rho0 * g[i, 1]
    return pos, vel


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
