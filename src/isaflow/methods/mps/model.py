"""The two halves of one MPS time step (numba): the explicit step, source term and pressure-equation
assembly (predict), and the pressure correction (correct); the collision model.

Koshizuka & Oka (1996), as the public MPS-Basic code implements it (github.com/MPS-Basic/MPS-Basic,
src/mps.cpp, src/pressure_calculator/implicit.cpp).  Operators in operators.py (re-exported here).
Units: cm, s, density N s^2 / cm^4 (2D), pressure N / cm^2.
"""

import numpy as np
from numba import njit

from isaflow.core.geometry import crossed_wall, segment_closest
from isaflow.core.neighbours import build_pairs  # noqa: F401  (re-exported for tests and benchmarks)

from .operators import (DIM, DUMMY, FLUID, JIT, WALL, divergence, gradient, lattice_constants,  # noqa: F401
                        laplacian, neighbour_offset_sum, number_density, number_density_of_pairs, pair_distances,
                        probe_pressure, weight)

# source terms of the pressure equation (settings name -> id)
SOURCES = {"standard": 0, "hattori": 1, "mixed": 2}


@njit(**JIT)
def source_term(n_star, div_star, n0, rho0, dt, source, gamma, relax=1.0):
    """Right-hand side of lap P = b [N / cm^4] per particle.

    source 0 standard: relax rho0 / dt^2 (n0 - n*) / n0 (Koshizuka & Oka 1996; relax: MPS-Basic's relaxation);
    1 hattori: (rho0 - Rho*) / dt^2 + (rho0 - Rho*) / dt div V*, Rho* = rho0 n* / n0
    (eq. 6 of Hattori et al.); 2 mixed: rho0 / dt div V* + gamma rho0 / dt^2 (n0 - n*) / n0
    (Tanaka & Masunaga 2010).
    """
    drho = rho0 * (n0 - n_star) / n0  # rho0 - Rho*
    if source == 0:
        return relax * drho / dt**2
    if source == 1:
        return drho / dt**2 + drho / dt * div_star
    return rho0 / dt * div_star + gamma * drho / dt**2


@njit(**JIT)
def assemble(pos, kind, dirichlet, b, pi, pj, m, re, n0, lam, diag_extra=0.0):
    """Pressure equation of the non-Dirichlet fluid and wall particles as CSR.

    Row of unknown i: diag_extra P_i + sum_j w_ij (P_i - P_j) = -(lambda n0 / 2d) b_i,
    the MPS Laplacian times -(lambda n0 / 2d) plus the compressibility term
    (as MPS-Basic's PressurePoissonEquation, scaled by rho0 lambda n0 / 2d): symmetric
    positive definite when diag_extra > 0, or when every cluster touches a Dirichlet particle.  Returns (unknown (N,)
    row of each particle or -1, indptr, indices, data, rhs).
    """
    return assemble_pairs(pair_distances(pos, pi, pj, m), kind, dirichlet, b, pi, pj, m, re, n0, lam, diag_extra)


@njit(**JIT)
def assemble_pairs(dist, kind, dirichlet, b, pi, pj, m, re, n0, lam, diag_extra):
    """assemble from the pair distances dist (see operators.pair_distances)."""
    n = kind.shape[0]
    row = np.full(n, -1, np.int64)
    nu = 0
    for i in range(n):
        if kind[i] != DUMMY and not dirichlet[i]:
            row[i] = nu
            nu += 1
    count = np.ones(nu, np.int64)  # diagonal
    for k in range(m):
        i, j = np.uint32(pi[k]), np.uint32(pj[k])
        if row[i] >= 0 and row[j] >= 0:
            if dist[k] < re:
                count[row[i]] += 1
                count[row[j]] += 1
    indptr = np.zeros(nu + 1, np.int64)
    for r in range(nu):
        indptr[r + 1] = indptr[r] + count[r]
    indices = np.empty(indptr[nu], np.int32)
    data = np.zeros(indptr[nu])
    fill = indptr[:-1] + 1
    for r in range(nu):
        indices[indptr[r]] = r
        data[indptr[r]] = diag_extra
    for k in range(m):
        i, j = np.uint32(pi[k]), np.uint32(pj[k])
        if kind[i] == DUMMY or kind[j] == DUMMY or (row[i] < 0 and row[j] < 0):
            continue
        r = dist[k]
        if r >= re:
            continue
        wt = weight(r, re)
        ri, rj = row[i], row[j]
        if ri >= 0:
            data[indptr[ri]] += wt
        if rj >= 0:
            data[indptr[rj]] += wt
        if ri >= 0 and rj >= 0:
            indices[fill[ri]] = rj
            data[fill[ri]] = -wt
            fill[ri] += 1
            indices[fill[rj]] = ri
            data[fill[rj]] = -wt
            fill[rj] += 1
    rhs = np.empty(nu)
    c = -lam * n0 / (2.0 * DIM)
    for i in range(n):
        if row[i] >= 0:
            rhs[row[i]] = c * b[i]
    return row, indptr, indices, data, rhs


@njit(**JIT)
def collide(ps, vs, kind, pi, pj, m, dist, restitution):
    """Collision model of MPS-Basic (MPS::collision): every pair closer than ``dist`` [cm] with a fluid
    particle exchanges the normal relative velocity with restitution e if it approaches, and both are
    pushed apart to ``dist`` (equal masses; wall and dummy particles immovable).  In place."""
    for k in range(m):
        i, j = np.uint32(pi[k]), np.uint32(pj[k])
        if kind[i] != FLUID and kind[j] != FLUID:
            continue
        dx = ps[j, 0] - ps[i, 0]
        dy = ps[j, 1] - ps[i, 1]
        r = np.sqrt(dx * dx + dy * dy)
        if r >= dist or r == 0.0:
            continue
        ex = dx / r
        ey = dy / r
        mi = 1.0 if kind[i] == FLUID else 0.0  # inverse masses (rho0 cancels)
        mj = 1.0 if kind[j] == FLUID else 0.0
        mass = 1.0 / (mi + mj)
        rel = (vs[j, 0] - vs[i, 0]) * ex + (vs[j, 1] - vs[i, 1]) * ey
        imp = -(1.0 + restitution) * rel * mass if rel < 0.0 else 0.0
        push = (dist - r) * mass
        vs[i, 0] -= imp * mi * ex
        vs[i, 1] -= imp * mi * ey
        vs[j, 0] += imp * mj * ex
        vs[j, 1] += imp * mj * ey
        ps[i, 0] -= push * mi * ex
        ps[i, 1] -= push * mi * ey
        ps[j, 0] += push * mj * ex
        ps[j, 1] += push * mj * ey


@njit(**JIT)
def predict(pos, vel, kind, box, dt, gx, gy, nu, re_n, re_g, re_l, n0_n, n0_g, n0_l, lam, beta, rho0, source, gamma,
            relax, sound, coll_dist, restitution, dist_thr=0.0):
    """Explicit half of a step (eq. 3) and the pressure equation at the moved positions.

    Fluid: V* = V + dt (nu lap V + g), U* = U + dt V* (walls fixed), then the
    collision model if coll_dist > 0 (cm; see collide).  Then at U*: n* (radius
    re_n), div V* (re_g), free surface (n* < beta n0 and, if dist_thr > 0 [cm], a
    component of sum_j r_ij over the neighbours beyond dist_thr: MPS-Basic's
    particle-distribution test; fluid and wall particles get Dirichlet P = 0), source term (relax: relaxation of the standard
    source) and the CSR system (see assemble) with the compressibility term
    1 / (rho0 c^2 dt^2) of sound speed ``sound`` [cm/s] (0: none).
    Returns (pos*, vel*, n*, div*, dirichlet, (pi, pj, m) at U*, (row, indptr, indices, data, rhs)).
    """
    rmax = max(re_n, re_l)
    pi, pj, m = build_pairs(pos, box, rmax)
    lap = laplacian(pos, vel, kind, pi, pj, m, re_l, n0_l, lam)
    ps = pos.copy()
    vs = vel.copy()
    for i in range(pos.shape[0]):
        if kind[i] == FLUID:
            vs[i, 0] = vel[i, 0] + dt * (nu * lap[i, 0] + gx)
            vs[i, 1] = vel[i, 1] + dt * (nu * lap[i, 1] + gy)
            ps[i, 0] = pos[i, 0] + dt * vs[i, 0]
            ps[i, 1] = pos[i, 1] + dt * vs[i, 1]
    if coll_dist > 0.0:
        pi, pj, m = build_pairs(ps, box, coll_dist)
        collide(ps, vs, kind, pi, pj, m, coll_dist, restitution)
    pi, pj, m = build_pairs(ps, box, rmax)
    dist = pair_distances(ps, pi, pj, m)
    n_star = number_density_of_pairs(ps.shape[0], dist, pi, pj, m, re_n)
    div = divergence(ps, vs, pi, pj, m, re_g, n0_g)
    dirichlet = np.zeros(pos.shape[0], np.bool_)
    b = np.zeros(pos.shape[0])
    offsets = neighbour_offset_sum(ps, pi, pj, m, rmax)
    for i in range(pos.shape[0]):
        if kind[i] != DUMMY:
            dirichlet[i] = n_star[i] < beta * n0_n
            if dirichlet[i] and dist_thr > 0.0:
                dirichlet[i] = abs(offsets[i, 0]) > dist_thr or abs(offsets[i, 1]) > dist_thr
            b[i] = source_term(n_star[i], div[i], n0_n, rho0, dt, source, gamma, relax)
    extra = 0.0
    if sound > 0.0:  # alpha / dt^2 with alpha = 1 / (rho0 c^2), times the row scale lambda n0 rho0 / (2 d)
        extra = lam * n0_l / (2.0 * DIM * sound**2 * dt**2)
    system = assemble_pairs(dist, kind, dirichlet, b, pi, pj, m, re_l, n0_l, lam, extra)
    return ps, vs, n_star, div, dirichlet, pi, pj, m, system


@njit(**JIT)
def correct(pos_old, ps, vs, p, kind, pi, pj, m, re_g, n0_g, rho0, dt, walls, box, graze):
    """Pressure half of a step (eqs. 4-5): V' = -dt / rho0 grad P, U' = dt V'.

    Returns (pos, vel, grad P (N, 2), bad, deepest graze [cm]): bad = (kind of
    failure, particle, wall): 0 fine, 1 non-finite, 2 crossed a wall (from
    pos_old) and ended more than ``graze`` [cm] from it, 3 more than ``graze``
    outside the box.  A
    crossing that ends within ``graze`` of the wall segment is a graze: its
    distance is returned (0.0 when there is none), the step goes on.
    """
    g = gradient(ps, p, kind, pi, pj, m, re_g, n0_g)
    pos = ps.copy()
    vel = vs.copy()
    bad = (0, -1, -1)
    deepest = 0.0
    for i in range(pos.shape[0]):
        if kind[i] != FLUID:
            continue
        vel[i, 0] = vs[i, 0] - dt / rho0 * g[i, 0]
        vel[i, 1] = vs[i, 1] - dt / rho0 * g[i, 1]
        pos[i, 0] = ps[i, 0] - dt * dt / rho0 * g[i, 0]
        pos[i, 1] = ps[i, 1] - dt * dt / rho0 * g[i, 1]
        if bad[0] != 0:
            continue
        if not (np.isfinite(pos[i, 0]) and np.isfinite(pos[i, 1]) and np.isfinite(vel[i, 0]) and np.isfinite(vel[i, 1])):
            bad = (1, i, -1)
            continue
        w = crossed_wall(pos_old[i, 0], pos_old[i, 1], pos[i, 0], pos[i, 1], walls)
        if w >= 0:
            cx, cy = segment_closest(pos[i, 0], pos[i, 1], walls[w, 0], walls[w, 1], walls[w, 2], walls[w, 3])
            depth = np.hypot(pos[i, 0] - cx, pos[i, 1] - cy)
            if depth > graze:
                bad = (2, i, w)
            else:
                deepest = max(deepest, depth)
        elif (pos[i, 0] < box[0] - graze or pos[i, 0] > box[2] + graze or pos[i, 1] < box[1] - graze
              or pos[i, 1] > box[3] + graze):
            bad = (3, i, -1)
    return pos, vel, g, bad, deepest
