"""Pair list of the SPH (numba): cell columns, wall visibility, and the colouring that makes the
pair passes parallel and bit-identical to serial.

Units cm.  Arrays: x (n, 2) positions, rows 0..nf-1 liquid, nf..n-1 wall particles;
walls (W, 4) wall segments x0, y0, x1, y1.

The list is a half list (each pair once) built over a grid of cells at least rc wide, traversed
column by column (cell index cx ncy + cy) with the half stencil own cell (later entries), N, SE, E,
NE: a pair's two particles therefore lie in the same cell column or in the next one, so the pairs
of column c write only to particles of columns c and c + 1.  Processing all even columns
(concurrently, each column by one thread in list order), then all odd ones, every particle
receives its pair terms in one fixed order whatever the number of threads: the parallel sums are
bit-identical to the serial ones (the serial passes use the same even-then-odd order).

Visibility (thin walls): a liquid-liquid pair is kept only if the segment between the two does not
cross a wall; a liquid-wall pair only if it meets one (touching counts) (a wall particle stands for the solid behind the
wall face the liquid particle sees; the particles behind the other face of a thin dividing wall
lie on the liquid's own side and are not seen).  Wall-wall pairs are dropped; in every pair the
first index is a liquid particle.
"""

import numpy as np
from ...core.jit import njit

from ...core.neighbours import cell_grid

JIT = dict(cache=True, nogil=True)


@njit(**JIT)
def segment_meets_wall(px, py, qx, qy, walls, strict):
    """True if the segment (px, py)-(qx, qy) meets a wall segment: touching counts, unless strict
    (then only a proper crossing, so that a liquid particle lying on a wall still sees the liquid)."""
    for w in range(walls.shape[0]):
        ax = walls[w, 0]
        ay = walls[w, 1]
        ex = walls[w, 2] - ax
        ey = walls[w, 3] - ay
        d1 = ex * (py - ay) - ey * (px - ax)
        d2 = ex * (qy - ay) - ey * (qx - ax)
        if (d1 > 0.0 and d2 > 0.0) or (d1 < 0.0 and d2 < 0.0) or (strict and d1 * d2 >= 0.0):
            continue
        mx = qx - px
        my = qy - py
        d3 = mx * (ay - py) - my * (ax - px)
        d4 = mx * (walls[w, 3] - py) - my * (walls[w, 2] - px)
        if (d3 > 0.0 and d4 > 0.0) or (d3 < 0.0 and d4 < 0.0) or (strict and d3 * d4 >= 0.0):
            continue
        if d1 == 0.0 and d2 == 0.0:  # collinear: they meet only if the projections overlap
            L2 = ex * ex + ey * ey
            t0 = ((px - ax) * ex + (py - ay) * ey) / L2
            t1 = ((qx - ax) * ex + (qy - ay) * ey) / L2
            if max(t0, t1) < 0.0 or min(t0, t1) > 1.0:
                continue
        return True
    return False


@njit(**JIT)
def wall_distance2(px, py, walls):
    """Squared distance [cm^2] of a point to the nearest wall segment."""
    best = np.inf
    for w in range(walls.shape[0]):
        ax = walls[w, 0]
        ay = walls[w, 1]
        ex = walls[w, 2] - ax
        ey = walls[w, 3] - ay
        L2 = ex * ex + ey * ey
        t = ((px - ax) * ex + (py - ay) * ey) / L2 if L2 > 0.0 else 0.0
        t = min(1.0, max(0.0, t))
        dx = px - (ax + t * ex)
        dy = py - (ay + t * ey)
        best = min(best, dx * dx + dy * dy)
    return best


@njit(**JIT)
def build(x, nf, box, rc, walls, pi, pj, reach):
    """Half pair list within rc by cell columns, filtered for visibility (module docstring).

    box (4,) cm: the cell grid (particles outside are clamped into edge cells); pi, pj int32
    arrays reused as storage (grown when full).  Returns (pi, pj, m, col, wrow, wpair, close,
    dwall): the first m entries of pi (liquid), pj (liquid or wall); col (ncx + 1,) the pair
    range of each cell column; wrow (n - nf + 1,), wpair: the pairs of wall particle q are
    wpair[wrow[q]:wrow[q + 1]] (ascending); dwall (nf,) cm: each liquid particle's distance to
    the nearest wall; close: the liquid particles with dwall < reach (ascending).
    """
    n = x.shape[0]
    ncx, ncy, csx, csy = cell_grid(box, rc)
    nc = ncx * ncy
    cell = np.empty(n, np.int64)
    cstart = np.zeros(nc + 1, np.int64)
    for i in range(n):
        cx = min(ncx - 1, max(0, int((x[i, 0] - box[0]) / csx)))
        cy = min(ncy - 1, max(0, int((x[i, 1] - box[1]) / csy)))
        c = cx * ncy + cy
        cell[i] = c
        cstart[c + 1] += 1
    for c in range(nc):
        cstart[c + 1] += cstart[c]
    fill = cstart[:nc].copy()
    order = np.empty(n, np.int64)
    for i in range(n):  # ascending particles within each cell
        order[fill[cell[i]]] = i
        fill[cell[i]] += 1
    rc2 = rc * rc
    near = np.empty(n, np.bool_)
    for i in range(n):
        near[i] = wall_distance2(x[i, 0], x[i, 1], walls) < rc2
    col = np.empty(ncx + 1, np.int64)
    m = 0
    for cx in range(ncx):
        col[cx] = m
        for cy in range(ncy):
            c = cx * ncy + cy
            for q in range(cstart[c], cstart[c + 1]):
                i = order[q]
                xi = x[i, 0]
                yi = x[i, 1]
                wi = i >= nf
                for s in range(5):  # own cell (later entries), N, SE, E, NE
                    if s == 0:
                        lo = q + 1
                        hi = cstart[c + 1]
                    else:
                        nx_ = cx + (0, 1, 1, 1)[s - 1]
                        ny_ = cy + (1, -1, 0, 1)[s - 1]
                        if nx_ >= ncx or ny_ < 0 or ny_ >= ncy:
                            continue
                        cc = nx_ * ncy + ny_
                        lo = cstart[cc]
                        hi = cstart[cc + 1]
                    for r in range(lo, hi):
                        j = order[r]
                        wj = j >= nf
                        if wi and wj:
                            continue
                        dx = xi - x[j, 0]
                        dy = yi - x[j, 1]
                        if dx * dx + dy * dy >= rc2:
                            continue
                        if wi or wj:
                            if not segment_meets_wall(xi, yi, x[j, 0], x[j, 1], walls, False):
                                continue
                        elif near[i] and near[j] and segment_meets_wall(xi, yi, x[j, 0], x[j, 1], walls, True):
                            continue
                        if m == pi.shape[0]:
                            pi2 = np.empty(2 * m + 1024, np.int32)
                            pj2 = np.empty(2 * m + 1024, np.int32)
                            pi2[:m] = pi[:m]
                            pj2[:m] = pj[:m]
                            pi = pi2
                            pj = pj2
                        if wi:
                            pi[m] = j
                            pj[m] = i
                        else:
                            pi[m] = i
                            pj[m] = j
                        m += 1
    col[ncx] = m
    nw = n - nf
    wrow = np.zeros(nw + 1, np.int64)
    for k in range(m):
        if pj[k] >= nf:
            wrow[pj[k] - nf + 1] += 1
    for q in range(nw):
        wrow[q + 1] += wrow[q]
    wpair = np.empty(wrow[nw], np.int64)
    wfill = wrow[:nw].copy()
    for k in range(m):
        if pj[k] >= nf:
            q = pj[k] - nf
            wpair[wfill[q]] = k
            wfill[q] += 1
    dwall = np.empty(nf)
    count = 0
    for i in range(nf):
        dwall[i] = np.sqrt(wall_distance2(x[i, 0], x[i, 1], walls))
        count += dwall[i] < reach
    close = np.empty(count, np.int64)
    count = 0
    for i in range(nf):
        if dwall[i] < reach:
            close[count] = i
            count += 1
    return pi, pj, m, col, wrow, wpair, close, dwall
