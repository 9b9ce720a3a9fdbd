"""Theory of the ISA lattice: rhombic elements (paper section 5) and the stiffness of the linear force laws.

Units: length cm, force N, stiffness N/cm.
"""

import numpy as np

from ...core import fixed_order as FO


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


def stiffness_matrix(pos, walls, wall_l_u, wall_r_u, pair_l_u, pair_r_u):
    """Hessian (2N, 2N) [N/cm] of the potential energy of the linear force laws, sparse (CSR).

    Pair/wall-end terms: k n n^T - (R / l)(I - n n^T) with k = r_u / l_u; a
    wall's interior contributes k n n^T.  Pairs come from the shared cell list.
    """
    from scipy import sparse

    from ...core.neighbours import build_pairs

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
        L2 = FO.dot2(e, e)
        t = FO.dot2(pos - [x0, y0], e) / L2
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
