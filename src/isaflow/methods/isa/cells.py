"""The neighbour list of core.neighbours.cell_rows built in parallel blocks (numba).

:func:`cell_rows_par` returns exactly what ``core.neighbours.cell_rows`` returns
(same cell order, same rows, same pair order in each row) for any number of
blocks: the counting sort stays serial (a few ns per particle), the pair
search (most of the cost) runs in blocks of particles that write their rows
into private stretches of a scratch array, which are then joined in block
order.  tests/test_isa_parallel.py compares the two on random clouds.
Units: cm.
"""

import numpy as np
from numba import prange

from ...core.jit import njit

from ...core.neighbours import cell_grid, cell_of, cell_rows

JIT = dict(cache=True, nogil=True)
PJIT = dict(cache=True, nogil=True, parallel=True)


@njit(**JIT)
def _search_range(q0, q1, xs, ys, order, cell_q, cstart, ncx, ncy, rc2, out, base, cap, row_start):
    """Rows of particles q0 <= q < q1 (cell order) into out[base:base + cap], row_start[q] relative
    to base, in cell_rows' order (own cell, later entries; then E, NW, N, NE cells).  Returns the
    pair count, or -1 if more than cap pairs (out is then incomplete)."""
    m = 0
    for q in range(q0, q1):
        row_start[q] = m
        c = cell_q[q]
        cy = c // ncx
        cx = c - cy * ncx
        xi = xs[q]
        yi = ys[q]
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
            if m + (b - a) > cap:
                return -1
            for r in range(a, b):  # branch-free: always store, advance only for a pair
                dx = xi - xs[r]
                dy = yi - ys[r]
                out[base + m] = order[r]
                m += dx * dx + dy * dy < rc2
    return m


@njit(**PJIT)
def _search_par(nb, n, xs, ys, order, cell_q, cstart, ncx, ncy, rc2, out, cap, row_start, counts):
    for b in prange(nb):
        counts[b] = _search_range(b * n // nb, (b + 1) * n // nb, xs, ys, order, cell_q, cstart, ncx, ncy, rc2,
                                  out, b * cap, cap, row_start)


@njit(**JIT)
def _join(nb, n, out, cap, offsets, row_start, nbr):
    for b in range(nb):
        off = offsets[b]
        for q in range(b * n // nb, (b + 1) * n // nb):
            row_start[q] += off
        for k in range(offsets[b + 1] - off):
            nbr[off + k] = out[b * cap + k]


@njit(**JIT)
def cell_rows_par(pos, box, rc, order, cstart, row_start, nbr, nb, hint):
    """core.neighbours.cell_rows(pos, box, rc, order, cstart, row_start, nbr), searched in nb parallel
    blocks (nb <= 1: that function itself).  hint: expected pairs per particle (sizes the blocks'
    scratch; a block that overflows it makes the whole build fall back to the serial function).
    Returns (nbr, cstart) as cell_rows does."""
    n = pos.shape[0]
    if nb <= 1 or n < 2 * nb:
        return cell_rows(pos, box, rc, order, cstart, row_start, nbr)
    ncx, ncy, csx, csy = cell_grid(box, rc)
    nc = ncx * ncy
    if cstart.shape[0] != nc + 1:
        cstart = np.empty(nc + 1, np.int32)
    cstart[:] = 0
    cell = np.empty(n, np.int32)
    for i in range(n):
        c = cell_of(pos[i, 0], pos[i, 1], box, ncx, ncy, csx, csy)
        cell[i] = c
        cstart[c + 1] += 1
    for c in range(nc):
        cstart[c + 1] += cstart[c]
    cell_q = np.empty(n, np.int32)
    for i in range(n):  # stable fill: ascending particles within each cell
        c = cell[i]
        order[cstart[c]] = i
        cell_q[cstart[c]] = c
        cstart[c] += 1
    for c in range(nc, 0, -1):
        cstart[c] = cstart[c - 1]
    cstart[0] = 0
    xs = np.empty(n)
    ys = np.empty(n)
    for q in range(n):
        xs[q] = pos[order[q], 0]
        ys[q] = pos[order[q], 1]
    cap = int(hint * (n // nb + 1)) + 64
    out = np.empty(nb * cap, np.int32)
    counts = np.empty(nb, np.int64)
    _search_par(nb, n, xs, ys, order, cell_q, cstart, ncx, ncy, rc * rc, out, cap, row_start, counts)
    offsets = np.empty(nb + 1, np.int64)
    offsets[0] = 0
    for b in range(nb):
        if counts[b] < 0:
            return cell_rows(pos, box, rc, order, cstart, row_start, nbr)
        offsets[b + 1] = offsets[b] + counts[b]
    m = offsets[nb]
    if nbr.shape[0] < m:
        nbr = np.empty(2 * m + 16, np.int32)
    _join(nb, n, out, cap, offsets, row_start, nbr)
    row_start[n] = m
    return nbr, cstart
