"""Neighbour lists shared by every method: one cell-list builder (numba).

``cell_rows`` finds all pairs closer than a cutoff, each once (a half list),
stored by rows of a cell-sorted particle order (counting sort into the cells of
:func:`cell_grid`, :func:`cell_of`; cache-friendly force passes);
``build_pairs`` returns the same pairs in the same order as two index arrays.
"""

import numpy as np
from .jit import njit

JIT = dict(cache=True, nogil=True)


@njit(inline="always", **JIT)
def cell_grid(box, rc):
    """(ncx, ncy, csx, csy): cell counts and sizes [cm] of a grid over box with cells >= rc."""
    ncx = max(1, int((box[2] - box[0]) / rc))
    ncy = max(1, int((box[3] - box[1]) / rc))
    return ncx, ncy, (box[2] - box[0]) / ncx, (box[3] - box[1]) / ncy


@njit(inline="always", **JIT)
def cell_of(x, y, box, ncx, ncy, csx, csy):
    """Flat cell index of point (x, y); points outside the box are clamped into edge cells."""
    cx = min(ncx - 1, max(0, int((x - box[0]) / csx)))
    cy = min(ncy - 1, max(0, int((y - box[1]) / csy)))
    return cy * ncx + cx


@njit(**JIT)
def push_pair(a, b, m, x, y):
    """Store (x, y) at index m of the int32 arrays (a, b), doubling them when full.
    Returns the (possibly new) arrays."""
    if m == a.shape[0]:
        a2 = np.empty(2 * m + 16, np.int32)
        b2 = np.empty(2 * m + 16, np.int32)
        a2[:m] = a[:m]
        b2[:m] = b[:m]
        a, b = a2, b2
    a[m] = x
    b[m] = y
    return a, b


@njit(**JIT)
def build_pairs(pos, box, rc):
    """Half neighbour list of all pairs closer than ``rc`` via a cell list.

    box: (4,) ``xmin, ymin, xmax, ymax`` [cm] of the cell grid (particles
    outside are clamped into edge cells, which stays correct, only slower).
    Returns (pi, pj, m): int32 arrays whose first m entries are the pairs,
    cell by cell (ascending particles within a cell), each particle's partners
    in its own cell (later entries), then the E, NW, N, NE cells.
    :func:`cell_rows`' rows expanded.  O(N) for bounded density.
    """
    n = pos.shape[0]
    order = np.empty(n, np.int32)
    row_start = np.empty(n + 1, np.int32)
    pj, _ = cell_rows(pos, box, rc, order, np.empty(1, np.int32), row_start, np.empty(8 * n + 16, np.int32))
    m = row_start[n]
    pi = np.empty(pj.shape[0], np.int32)
    for q in range(n):
        i = order[q]
        for k in range(row_start[q], row_start[q + 1]):
            pi[k] = i
    return pi, pj, m


@njit(**JIT)
def cell_rows(pos, box, rc, order, cstart, row_start, nbr):
    """The pair list of :func:`build_pairs`, in the same order, stored by rows.

    The particles are counting-sorted into the same cells; order (N,) int32
    receives them cell by cell (ascending within a cell, i.e. the order in
    which :func:`build_pairs` visits them), cstart (ncx ncy + 1,) int32 the
    cell boundaries in order.  Row q holds the pairs (order[q], nbr[k]) for
    row_start[q] <= k < row_start[q + 1], in :func:`build_pairs`' order.  nbr (cap,)
    int32 is reused and returned (grown when full); cstart is returned too
    (reallocated if the grid changed size).
    """
    n = pos.shape[0]
    ncx, ncy, csx, csy = cell_grid(box, rc)
    nc = ncx * ncy
    if cstart.shape[0] != nc + 1:
        cstart = np.empty(nc + 1, np.int32)
    cstart[:] = 0
    cell = row_start[:n]  # scratch: row_start is rewritten below, after the cells are used
    for i in range(n):
        c = cell_of(pos[i, 0], pos[i, 1], box, ncx, ncy, csx, csy)
        cell[i] = c
        cstart[c + 1] += 1
    for c in range(nc):
        cstart[c + 1] += cstart[c]
    # stable fill: ascending particles within each cell
    for i in range(n):
        c = cell[i]
        order[cstart[c]] = i
        cstart[c] += 1
    for c in range(nc, 0, -1):
        cstart[c] = cstart[c - 1]
    cstart[0] = 0
    xs = np.empty(n)  # coordinates in cell order: contiguous reads in the pair search
    ys = np.empty(n)
    for q in range(n):
        xs[q] = pos[order[q], 0]
        ys[q] = pos[order[q], 1]
    rc2 = rc * rc
    m = 0
    for cy in range(ncy):
        for cx in range(ncx):
            c = cy * ncx + cx
            for q in range(cstart[c], cstart[c + 1]):
                row_start[q] = m
                xi = xs[q]
                yi = ys[q]
                # half stencil: own cell (later entries), E, NW, N, NE
                for k in range(5):
                    if k == 0:
                        a = q + 1
                        b = cstart[c + 1]
                    else:
                        nx_ = cx + (1, -1, 0, 1)[k - 1]
                        ny_ = cy + (0, 1, 1, 1)[k - 1]
                        if nx_ < 0 or nx_ >= ncx or ny_ >= ncy:
                            continue
                        a = cstart[ny_ * ncx + nx_]
                        b = cstart[ny_ * ncx + nx_ + 1]
                    if m + (b - a) > nbr.shape[0]:
                        grown = np.empty(2 * (m + b - a) + 16, np.int32)
                        grown[:m] = nbr[:m]
                        nbr = grown
                    for r in range(a, b):  # branch-free: always store, advance only for a pair
                        dx = xi - xs[r]
                        dy = yi - ys[r]
                        nbr[m] = order[r]
                        m += dx * dx + dy * dy < rc2
    row_start[n] = m
    return nbr, cstart
