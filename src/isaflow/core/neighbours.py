"""The shared neighbour lists (numba): a cell-list builder, serial or in parallel blocks.

Used by ISA's loops (relax, newton, replay, theory), the solid, the measures of isaflow.metrics and SPH's
setup (its wall particles, methods/sph/particles.py).  Not every method's: SPH's pair list
(methods/sph/pairs.py) takes :func:`cell_grid` and builds its own column-ordered list with wall visibility;
SPH's periodic block (methods/sph/block.py) keeps a periodic linked cell list of its own (``cells``), and MPS
(methods/mps/operators.py) counting-sorts particles into cells of its own (``cell_sort``, ``neighbour_list``).

``cell_rows`` finds all pairs closer than a cutoff, each once (a half list),
stored by rows of a cell-sorted particle order (counting sort into the cells of
:func:`cell_grid`, :func:`cell_of`; cache-friendly force passes);
``cell_rows_par`` returns exactly the same (same cell order, rows and pair
order) for any number of blocks: the counting sort stays serial (a few ns per
particle), the row search (most of the cost) runs in blocks of particles that
write their rows into private stretches of a scratch array, then joined in
block order (tests/test_isa_parallel.py); both run the one sort
(:func:`cell_sort`) and the one row search (:func:`search_rows`).
``build_pairs`` returns the same pairs in the same order as two index arrays.
Positions (N, 2) and cutoffs in cm.
"""

import numpy as np
from numba import prange

from .jit import njit

JIT = dict(cache=True, nogil=True)
PJIT = dict(cache=True, nogil=True, parallel=True)


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
def cell_sort(pos, box, rc, order, cstart, cell):
    """Counting sort of the particles into the cells of :func:`cell_grid`: order (N,) int32 receives them
    cell by cell (ascending within a cell), cstart (ncx ncy + 1,) int32 the cell boundaries in order
    (reallocated if the grid changed size); cell (N,) int32 is scratch.  Returns (ncx, ncy, cstart,
    cell_q (N,) int32 the cell of the q-th particle in that order, xs, ys (N,) its coordinates [cm])."""
    n = pos.shape[0]
    ncx, ncy, csx, csy = cell_grid(box, rc)
    nc = ncx * ncy
    if cstart.shape[0] != nc + 1:
        cstart = np.empty(nc + 1, np.int32)
    cstart[:] = 0
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
    xs = np.empty(n)  # coordinates in cell order: contiguous reads in the pair search
    ys = np.empty(n)
    for q in range(n):
        xs[q] = pos[order[q], 0]
        ys[q] = pos[order[q], 1]
    return ncx, ncy, cstart, cell_q, xs, ys


@njit(**JIT)
def search_rows(q0, q1, xs, ys, order, cell_q, cstart, ncx, ncy, rc2, out, base, cap, row_start, grow):
    """Rows of particles q0 <= q < q1 (cell order, :func:`cell_sort`) into out[base:base + cap], row_start[q]
    relative to base: the partners closer than sqrt(rc2) [cm] in the own cell (later entries), then the E,
    NW, N, NE cells.  Returns (pair count, out).  More than cap pairs: out is replaced by a larger copy if
    grow (base 0), else the count is -1 (out then incomplete)."""
    m = 0
    c = -1
    cx = cy = 0
    for q in range(q0, q1):
        row_start[q] = m
        if cell_q[q] != c:  # cells ascend with q: their coordinates once per cell
            c = cell_q[q]
            cy = c // ncx
            cx = c - cy * ncx
        xi = xs[q]
        yi = ys[q]
        for k in range(5):  # half stencil: own cell (later entries), E, NW, N, NE
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
                if not grow:
                    return -1, out
                grown = np.empty(2 * (m + b - a) + 16, np.int32)
                grown[:m] = out[:m]
                out = grown
                cap = out.shape[0]
            for r in range(a, b):  # branch-free: always store, advance only for a pair
                dx = xi - xs[r]
                dy = yi - ys[r]
                out[base + m] = order[r]
                m += dx * dx + dy * dy < rc2
    return m, out


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
    # row_start[:n] is the sort's scratch: the rows are written after the cells are used
    ncx, ncy, cstart, cell_q, xs, ys = cell_sort(pos, box, rc, order, cstart, row_start[:n])
    m, nbr = search_rows(0, n, xs, ys, order, cell_q, cstart, ncx, ncy, rc * rc, nbr, 0, nbr.shape[0], row_start,
                         True)
    row_start[n] = m
    return nbr, cstart


@njit(**PJIT)
def _search_par(nb, n, xs, ys, order, cell_q, cstart, ncx, ncy, rc2, out, cap, row_start, counts):
    for b in prange(nb):
        counts[b] = search_rows(b * n // nb, (b + 1) * n // nb, xs, ys, order, cell_q, cstart, ncx, ncy, rc2, out,
                                b * cap, cap, row_start, False)[0]


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
    """:func:`cell_rows` (pos, box, rc, order, cstart, row_start, nbr), searched in nb parallel blocks
    (nb <= 1: that function itself).  hint: expected pairs per particle (sizes the blocks' scratch; a
    block that overflows it makes the whole build fall back to the serial function).  Returns (nbr,
    cstart) as cell_rows does."""
    n = pos.shape[0]
    if nb <= 1 or n < 2 * nb:
        return cell_rows(pos, box, rc, order, cstart, row_start, nbr)
    ncx, ncy, cstart, cell_q, xs, ys = cell_sort(pos, box, rc, order, cstart, np.empty(n, np.int32))
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
