"""Free-surface level and hydrostatic theory for the wall loads.

Units: length cm, force N, pressure N/cm (2D: force per unit wall length).
The liquid's specific weight follows from the weight it holds and its
measured level: gamma = W / (B h) [N/cm^2] for a vessel of width B.
"""

import numpy as np


def surface_profile(pos, a, x_range):
    """Free surface as the highest particle of each vertical strip of width ``a``.

    pos (N, 2) cm; a strip width cm (the particle spacing); x_range (xmin, xmax)
    is the vessel: strips start at xmin, particles outside are ignored, strips
    holding no particle are skipped.  Returns (x (S,) cm strip centres, top (S,) cm).
    """
    pos = np.asarray(pos)
    pos = pos[(pos[:, 0] >= x_range[0]) & (pos[:, 0] < x_range[1])]
    strip = np.floor((pos[:, 0] - x_range[0]) / a).astype(int)
    ids = np.unique(strip)
    return x_range[0] + (ids + 0.5) * a, np.array([pos[strip == s, 1].max() for s in ids])


def free_surface_level(pos, a, x_range):
    """Free-surface level [cm]: mean of :func:`surface_profile` (the line one reads off
    the paper's figures); NaN if the vessel is empty."""
    _, top = surface_profile(pos, a, x_range)
    return float(np.mean(top)) if len(top) else float("nan")


def surface_slope(x, top):
    """(slope in degrees of the least-squares line through the profile, max - min [cm]);
    a liquid at rest has both about 0.  NaN for fewer than two strips."""
    if len(x) < 2:
        return float("nan"), float("nan")
    k = np.polyfit(x, top, 1)[0]
    return float(np.degrees(np.arctan(k))), float(top.max() - top.min())


def rhombs(pos0, a, tol=1e-6):
    """(R, 4) particle indices of the rhombic elements of a rhombic lattice (paper section 5).

    A rhomb has its bottom particle i at p, then p + (a/2, a/2), p + (0, a),
    p + (-a/2, a/2) counter-clockwise: diagonals a, sides a / sqrt(2), area a^2 / 2.
    """
    pos0 = np.asarray(pos0, float)
    key = {(round(x / (a / 2)), round(y / (a / 2))): i for i, (x, y) in enumerate(pos0)}
    out = []
    for (ix, iy), i in key.items():
        corners = [key.get((ix + dx, iy + dy)) for dx, dy in ((1, 1), (0, 2), (-1, 1))]
        if None not in corners:
            out.append([i, *corners])
    out = np.array(out, int).reshape(-1, 4)
    ok = np.abs(np.abs(polygon_area(pos0, out)) - a * a / 2) < tol * a * a
    return out[ok]


def polygon_area(pos, quads):
    """(R,) signed shoelace areas [cm^2] of the quadrilaterals pos[quads] (R, 4), counter-clockwise > 0."""
    p = np.asarray(pos)[quads]
    x, y = p[..., 0], p[..., 1]
    return 0.5 * np.sum(x * np.roll(y, -1, axis=1) - np.roll(x, -1, axis=1) * y, axis=1)


def specific_weight(total_weight, width, level, floor_y=0.0):
    """gamma [N/cm^2] of liquid of ``total_weight`` N filling width x (level - floor_y)."""
    return total_weight / (width * (level - floor_y))


def _pressure_integral(wall, s0, s1, gamma, level):
    """Integral of gamma (level - y)_+ ds over wall parameter [s0, s1] (arc length, cm)."""
    x0, y0, x1, y1 = wall
    L = np.hypot(x1 - x0, y1 - y0)
    ey = (y1 - y0) / L
    if ey == 0.0:
        return gamma * max(level - y0, 0.0) * (s1 - s0)
    s_star = (level - y0) / ey  # where the wall crosses the free surface
    lo, hi = (s0, min(s1, s_star)) if ey > 0 else (max(s0, s_star), s1)
    if hi <= lo:
        return 0.0
    mid = 0.5 * (lo + hi)
    return gamma * (level - (y0 + mid * ey)) * (hi - lo)


def wall_total(wall, gamma, level):
    """Hydrostatic force magnitude [N] on a whole wall segment (x0, y0, x1, y1)."""
    L = np.hypot(wall[2] - wall[0], wall[3] - wall[1])
    return _pressure_integral(wall, 0.0, L, gamma, level)


def contact_theory(walls, contact_wall, contact_point, gamma, level, wall_mask=None):
    """Theoretical hydrostatic force magnitude [N] on each wall contact.

    Each contact carries the pressure over its tributary length: from the wall
    start (or midway to the previous contact along the wall) to midway to the
    next contact (or the wall end).  contact_wall (C,) int, contact_point (C, 2)
    cm.  Contacts on walls not in wall_mask (W,) bool get NaN.
    """
    walls = np.asarray(walls, float)
    out = np.full(len(contact_wall), np.nan)
    for w, seg in enumerate(walls):
        if wall_mask is not None and not wall_mask[w]:
            continue
        idx = np.flatnonzero(contact_wall == w)
        if len(idx) == 0:
            continue
        L = np.hypot(seg[2] - seg[0], seg[3] - seg[1])
        s = np.hypot(contact_point[idx, 0] - seg[0], contact_point[idx, 1] - seg[1])
        order = np.argsort(s)
        ss = s[order]
        bounds = np.concatenate([[0.0], 0.5 * (ss[1:] + ss[:-1]), [L]])
        for k, c in enumerate(idx[order]):
            out[c] = _pressure_integral(seg, bounds[k], bounds[k + 1], gamma, level)
    return out


def resultant_height(contact_point_y, magnitude):
    """Height [cm] of the resultant of parallel contact loads (sum F y / sum F)."""
    tot = np.sum(magnitude)
    return float(np.sum(magnitude * contact_point_y) / tot) if tot > 0 else float("nan")


def implied_level(side_load, total_weight, width):
    """Level [cm] implied by a side-wall load: F = gamma h^2 / 2 with gamma = W / (B h)."""
    return 2.0 * width * side_load / total_weight


def stiffness_matrix(pos, walls, wall_l_u, wall_r_u, pair_l_u, pair_r_u):
    """Hessian (2N, 2N) [N/cm] of the potential energy of the linear force laws, sparse (CSR).

    Pair/wall-end terms: k n n^T - (R / l)(I - n n^T) with k = r_u / l_u; a
    wall's interior contributes k n n^T.  Pairs come from the shared cell list.
    """
    from scipy import sparse

    from .core.neighbours import build_pairs

    pos = np.asarray(pos, float)
    n = len(pos)
    eye = np.eye(2)
    rows, cols, vals = [], [], []

    def add(i, j, b):
        for a in range(2):
            for c in range(2):
                rows.append(2 * i + a)
                cols.append(2 * j + c)
                vals.append(b[a, c])

    def block(d, l_u, r_u, line=False):
        l = np.hypot(*d)
        nn = np.outer(d, d) / l**2
        b = (r_u / l_u) * nn
        if not line:
            b -= r_u * (1.0 - l / l_u) / l * (eye - nn)
        return b

    lo, hi = pos.min(0), pos.max(0) + 1e-9
    pi, pj, m = build_pairs(pos, np.array([lo[0], lo[1], hi[0], hi[1]]), pair_l_u)
    for i, j in zip(pi[:m], pj[:m]):
        b = block(pos[i] - pos[j], pair_l_u, pair_r_u)
        add(i, i, b)
        add(j, j, b)
        add(i, j, -b)
        add(j, i, -b)
    for x0, y0, x1, y1 in walls:
        e = np.array([x1 - x0, y1 - y0])
        L2 = e @ e
        t = ((pos - [x0, y0]) @ e) / L2
        c = np.array([x0, y0]) + np.clip(t, 0, 1)[:, None] * e
        d = pos - c
        for i in np.flatnonzero(np.hypot(d[:, 0], d[:, 1]) < wall_l_u):
            add(i, i, block(d[i], wall_l_u, wall_r_u, line=0 < t[i] < 1))
    return sparse.coo_matrix((vals, (rows, cols)), shape=(2 * n, 2 * n)).tocsr()


def step_floor(pos, walls, wall_l_u, wall_r_u, pair_l_u, pair_r_u, du):
    """Smallest max|F| [N] at which the paper's update x += du F / max|F| is
    still linearly stable: gradient descent with gain du / max|F| diverges
    along the stiffest mode once du / max|F| > 2 / lambda_max.  Returns
    (lambda_max N/cm, floor = lambda_max du / 2 N); lambda_max by Lanczos
    (scipy.sparse.linalg.eigsh, relative accuracy 1e-10)."""
    from scipy.sparse.linalg import eigsh

    H = stiffness_matrix(pos, walls, wall_l_u, wall_r_u, pair_l_u, pair_r_u)
    if H.shape[0] <= 8:
        lam = float(np.linalg.eigvalsh(H.toarray())[-1])
    else:
        lam = float(eigsh(H, k=1, which="LA", tol=1e-10, v0=np.ones(H.shape[0]), return_eigenvectors=False)[0])
    return lam, 0.5 * lam * du
