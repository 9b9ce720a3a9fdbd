"""MPS particle operators (numba): Koshizuka & Oka (1996) / Koshizuka, Nobe & Oka (1998), 2D (d = 2).

- weight w(r) = r_e / r - 1 for r < r_e, else 0;
- number density n_i = sum_j w(r_ij);
- gradient <grad phi>_i = d / n0 sum_j (phi_j - phi^_i) r_ij / |r_ij|^2 w(r_ij),
  phi^_i = min(phi_i, phi_j over neighbours) (K&O 1996's stabilised pressure gradient);
- Laplacian <lap phi>_i = 2 d / (lambda n0) sum_j (phi_j - phi_i) w(r_ij);
- divergence <div u>_i = d / n0 sum_j (u_j - u_i) . r_ij / |r_ij|^2 w(r_ij).
r_ij = r_j - r_i; pairs from core.neighbours.build_pairs (read as np.uint32: numba then indexes without
its negative-index wraparound).  Particle kinds: FLUID,
WALL (in the pressure equation and the gradient), DUMMY (number density only).
Units: cm, s, density N s^2 / cm^4 (2D), pressure N / cm^2.
"""

import numpy as np
from numba import njit

JIT = dict(cache=True, nogil=True)
FLUID, WALL, DUMMY = 0, 1, 2
DIM = 2


@njit(inline="always", **JIT)
def weight(r, re):
    """MPS weight r_e / r - 1 (r clamped at 1e-6 r_e so coincident particles stay finite)."""
    if r >= re:
        return 0.0
    return re / max(r, 1e-6 * re) - 1.0


def lattice_constants(re_over_l0, l0=1.0):
    """(n0, lambda [cm^2]) of a full square lattice of spacing l0 for radius r_e = re_over_l0 l0.

    n0 = sum_j w(|r_j|), lambda = sum_j |r_j|^2 w / sum_j w over the lattice
    points j != 0 (Koshizuka & Oka 1996).  n0 does not depend on l0.
    """
    k = int(np.ceil(re_over_l0)) + 1
    g = np.arange(-k, k + 1, dtype=float)
    x, y = np.meshgrid(g, g)
    r = np.hypot(x, y).ravel()
    r = r[(r > 0) & (r < re_over_l0)]
    wts = re_over_l0 / r - 1.0
    return float(wts.sum()), float((r**2 * wts).sum() / wts.sum() * l0**2)


@njit(**JIT)
def pair_distances(pos, pi, pj, m):
    """(m,) distance |r_j - r_i| [cm] of every pair (np.hypot), for operators sharing one pair list."""
    dist = np.empty(m)
    for k in range(m):
        i, j = np.uint32(pi[k]), np.uint32(pj[k])
        dist[k] = np.hypot(pos[j, 0] - pos[i, 0], pos[j, 1] - pos[i, 1])
    return dist


@njit(**JIT)
def number_density(pos, pi, pj, m, re):
    """(N,) number density of every particle from the pair list (pairs beyond r_e ignored)."""
    return number_density_of_pairs(pos.shape[0], pair_distances(pos, pi, pj, m), pi, pj, m, re)


@njit(**JIT)
def number_density_of_pairs(n_particles, dist, pi, pj, m, re):
    """number_density from the pair distances dist (see pair_distances)."""
    n = np.zeros(n_particles)
    for k in range(m):
        wt = weight(dist[k], re)
        n[np.uint32(pi[k])] += wt
        n[np.uint32(pj[k])] += wt
    return n


@njit(**JIT)
def neighbour_offset_sum(pos, pi, pj, m, rc):
    """(N, 2) sum_j (r_j - r_i) [cm] over all neighbours closer than rc (MPS-Basic's particle-distribution test)."""
    out = np.zeros((pos.shape[0], 2))
    for k in range(m):
        i, j = np.uint32(pi[k]), np.uint32(pj[k])
        dx = pos[j, 0] - pos[i, 0]
        dy = pos[j, 1] - pos[i, 1]
        if dx * dx + dy * dy < rc * rc:
            out[i, 0] += dx
            out[i, 1] += dy
            out[j, 0] -= dx
            out[j, 1] -= dy
    return out


@njit(**JIT)
def divergence(pos, vel, pi, pj, m, re, n0):
    """(N,) MPS divergence of vel [1/s] (all neighbours, wall velocity 0)."""
    div = np.zeros(pos.shape[0])
    for k in range(m):
        i, j = np.uint32(pi[k]), np.uint32(pj[k])
        dx = pos[j, 0] - pos[i, 0]
        dy = pos[j, 1] - pos[i, 1]
        r2 = dx * dx + dy * dy
        wt = weight(np.sqrt(r2), re)
        if wt == 0.0:
            continue
        s = ((vel[j, 0] - vel[i, 0]) * dx + (vel[j, 1] - vel[i, 1]) * dy) / r2 * wt
        div[i] += s
        div[j] += s  # (u_i - u_j) . (r_i - r_j) is the same product
    return div * (DIM / n0)


@njit(**JIT)
def laplacian(pos, f, kind, pi, pj, m, re, n0, lam):
    """(N, C) MPS Laplacian of f (N, C) over fluid and wall neighbours (dummies excluded)."""
    out = np.zeros_like(f)
    for k in range(m):
        i, j = np.uint32(pi[k]), np.uint32(pj[k])
        if kind[i] == DUMMY or kind[j] == DUMMY:
            continue
        wt = weight(np.hypot(pos[j, 0] - pos[i, 0], pos[j, 1] - pos[i, 1]), re)
        for c in range(f.shape[1]):
            d = (f[j, c] - f[i, c]) * wt
            out[i, c] += d
            out[j, c] -= d
    return out * (2.0 * DIM / (lam * n0))


@njit(**JIT)
def gradient(pos, p, kind, pi, pj, m, re, n0):
    """(N, 2) MPS pressure gradient with p^_i = min over neighbours (K&O 1996).

    Fluid and wall particles take part; dummy particles (no pressure) do not,
    neither in the sum nor in the minimum (as MPS-Basic's calPressureGradient).
    """
    n = pos.shape[0]
    pmin = p.copy()
    for k in range(m):
        i, j = np.uint32(pi[k]), np.uint32(pj[k])
        if kind[i] == DUMMY or kind[j] == DUMMY:
            continue
        if np.hypot(pos[j, 0] - pos[i, 0], pos[j, 1] - pos[i, 1]) < re:
            pmin[i] = min(pmin[i], p[j])
            pmin[j] = min(pmin[j], p[i])
    g = np.zeros((n, 2))
    for k in range(m):
        i, j = np.uint32(pi[k]), np.uint32(pj[k])
        dx = pos[j, 0] - pos[i, 0]
        dy = pos[j, 1] - pos[i, 1]
        if kind[i] == DUMMY or kind[j] == DUMMY:
            continue
        r2 = dx * dx + dy * dy
        wt = weight(np.sqrt(r2), re)
        if wt == 0.0:
            continue
        a = (p[j] - pmin[i]) / r2 * wt
        b = (p[i] - pmin[j]) / r2 * wt
        g[i, 0] += a * dx
        g[i, 1] += a * dy
        g[j, 0] -= b * dx
        g[j, 1] -= b * dy
    return g * (DIM / n0)


@njit(**JIT)
def probe_pressure(pos, p, kind, probes, re):
    """(K,) pressure [N/cm^2] at fixed points: MPS-weighted mean of fluid particle pressures (NaN if none in range)."""
    out = np.full(probes.shape[0], np.nan)
    for k in range(probes.shape[0]):
        sw = 0.0
        sp = 0.0
        for i in range(pos.shape[0]):
            if kind[i] != FLUID:
                continue
            wt = weight(np.hypot(pos[i, 0] - probes[k, 0], pos[i, 1] - probes[k, 1]), re)
            sw += wt
            sp += wt * p[i]
        if sw > 0.0:
            out[k] = sp / sw
    return out
