"""The paper's force laws and the plain force evaluation (numba).

Force laws are repulsive (paper Fig. 1c, 1d):
``R(l) = r_u (1 - l / l_u)^p`` for ``l < l_u``, else 0.  The kept shape is
linear (p = 1, stiffness ``r_u / l_u``); p = 1.5 and p = 2 are the named
options of the ``law`` setting (settings.LAW_EXPONENT; the figures give only
the shape's end points, the text none), not the paper's.  ``wall_*`` is the
particle-wall law (R_b, l_bu of the paper), ``pair_*`` the particle-particle
law (R_p, l_pu); ``p`` arguments default to 1 (linear), whose arithmetic is
unchanged by the option.
Arrays: ``pos`` (N, 2) cm; ``weight`` (N,) N; ``walls`` (W, 4) cm.
"""

import numpy as np
from ...core.jit import njit

from ...core.geometry import segment_closest

JIT = dict(cache=True, nogil=True)


@njit(inline="always", **JIT)
def law_over_d(d, l_u, r_u, p):
    """R(d) / d [N/cm] of the law r_u (1 - d / l_u)^p at 0 < d < l_u (p = 1: the linear law's own arithmetic)."""
    if p == 1.0:
        return r_u * (1.0 / d - 1.0 / l_u)
    return r_u * (1.0 - d / l_u) ** p / d


@njit(**JIT)
def wall_push(px, py, x0, y0, x1, y1, l_u, r_u, p=1.0):
    """Force (fx, fy) [N] of wall segment on a particle at (px, py); p the law's exponent.

    Uses the true point-to-segment distance, so near a segment end the force
    is radial from that end.  A particle exactly on the wall is pushed along
    the wall's left normal (walls are oriented with the liquid on their left).
    """
    cx, cy = segment_closest(px, py, x0, y0, x1, y1)
    dx = px - cx
    dy = py - cy
    d2 = dx * dx + dy * dy
    if d2 >= l_u * l_u:
        return 0.0, 0.0
    d = np.sqrt(d2)
    if d > 0.0:
        s = law_over_d(d, l_u, r_u, p)  # R(d) / d
        return s * dx, s * dy
    ex = x1 - x0
    ey = y1 - y0
    L = np.sqrt(ex * ex + ey * ey)
    return -r_u * ey / L, r_u * ex / L


@njit(**JIT)
def pair_push(dx, dy, l_u, r_u, p=1.0):
    """Force (fx, fy) [N] on particle i from j, with (dx, dy) = x_i - x_j; p the law's exponent.

    Coincident particles are pushed apart along +x (i) / -x (j).
    """
    d2 = dx * dx + dy * dy
    if d2 >= l_u * l_u:
        return 0.0, 0.0
    d = np.sqrt(d2)
    if d > 0.0:
        s = law_over_d(d, l_u, r_u, p)
        return s * dx, s * dy
    return r_u, 0.0


@njit(inline="always", **JIT)
def track_max(fx, fy, fmax, finite):
    """Running max|F| = max(|Fx|, |Fy|) [N] and all-finite flag after one particle."""
    a = abs(fx)
    b = abs(fy)
    return max(fmax, a, b), finite & (a < np.inf) & (b < np.inf)  # False for NaN and inf


@njit(**JIT)
def forces(pos, weight, walls, wall_l_u, wall_r_u, pair_l_u, pair_r_u, pi, pj, m, f, wall_p=1.0, pair_p=1.0):
    """Out-of-balance forces f (N, 2) [N] = weight + wall + pair forces (law exponents wall_p, pair_p).

    Pairs are taken from the first m entries of the neighbour list (pi, pj).
    Returns max|F| = max over particles of max(|Fx|, |Fy|) (paper §3.3);
    NaN if any force or position is non-finite.
    """
    n = pos.shape[0]
    for i in range(n):
        fx = 0.0
        fy = -weight[i]
        px = pos[i, 0]
        py = pos[i, 1]
        for w in range(walls.shape[0]):
            gx, gy = wall_push(px, py, walls[w, 0], walls[w, 1], walls[w, 2], walls[w, 3], wall_l_u, wall_r_u,
                               wall_p)
            fx += gx
            fy += gy
        f[i, 0] = fx
        f[i, 1] = fy
    for k in range(m):
        i = pi[k]
        j = pj[k]
        gx, gy = pair_push(pos[i, 0] - pos[j, 0], pos[i, 1] - pos[j, 1], pair_l_u, pair_r_u, pair_p)
        f[i, 0] += gx
        f[i, 1] += gy
        f[j, 0] -= gx
        f[j, 1] -= gy
    fmax = 0.0
    finite = True
    for i in range(n):
        fmax, finite = track_max(f[i, 0], f[i, 1], fmax, finite & (abs(pos[i, 0]) < np.inf) & (abs(pos[i, 1]) < np.inf))
    if not finite:
        return np.nan
    return fmax


@njit(**JIT)
def wall_contacts(pos, walls, l_u, r_u, p=1.0):
    """All wall-particle contacts with a non-zero force (law exponent p).

    Returns (particle (C,) int64, wall (C,) int64, point (C, 2) [cm] closest
    point on the wall, force (C, 2) [N] exerted by the wall on the particle).
    """
    n = pos.shape[0]
    nw = walls.shape[0]
    c = 0
    for i in range(n):
        for w in range(nw):
            gx, gy = wall_push(pos[i, 0], pos[i, 1], walls[w, 0], walls[w, 1], walls[w, 2], walls[w, 3], l_u, r_u, p)
            if gx != 0.0 or gy != 0.0:
                c += 1
    part = np.empty(c, np.int64)
    wall = np.empty(c, np.int64)
    point = np.empty((c, 2))
    force = np.empty((c, 2))
    c = 0
    for i in range(n):
        for w in range(nw):
            gx, gy = wall_push(pos[i, 0], pos[i, 1], walls[w, 0], walls[w, 1], walls[w, 2], walls[w, 3], l_u, r_u, p)
            if gx != 0.0 or gy != 0.0:
                cx, cy = segment_closest(pos[i, 0], pos[i, 1], walls[w, 0], walls[w, 1], walls[w, 2], walls[w, 3])
                part[c] = i
                wall[c] = w
                point[c, 0] = cx
                point[c, 1] = cy
                force[c, 0] = gx
                force[c, 1] = gy
                c += 1
    return part, wall, point, force
