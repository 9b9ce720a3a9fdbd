"""Vectorised NumPy version of one step of the paper's algorithm (baseline for bench_step.py).

Same physics as ``isaflow.kernels.relax`` with variant PAPER (paper section 3.3):
forces = weight + wall + pair forces (linear repulsive laws), then every
particle moves by ``du * F / max|F|``; a move that would carry a particle across
a wall is refused.  Units: cm, N.

It is written the way a careful NumPy user would write it, with no Python loop
over particles or pairs (only over the 5 cell-stencil offsets and the 3-7
walls):

* a Verlet pair list with a skin, built from a vectorised cell list
  (``np.argsort`` of the cell index, ``np.repeat``/``np.cumsum`` to expand
  each particle against the particles of its neighbouring cells), rebuilt only
  when the largest real displacement since the last build exceeds skin / 2;
* wall forces and the wall-crossing test only for the particles that were
  within ``wl_u + skin`` of a wall at the last build;
* force accumulation with ``np.bincount`` (faster than ``np.add.at``).
"""

import numpy as np

SQRT2 = np.sqrt(2.0)


def cell_pairs(x, y, box, rc):
    """Half pair list (pi, pj) int64 of all pairs closer than rc, vectorised cell list."""
    n = x.size
    ncx = max(1, int((box[2] - box[0]) / rc))
    ncy = max(1, int((box[3] - box[1]) / rc))
    csx = (box[2] - box[0]) / ncx
    csy = (box[3] - box[1]) / ncy
    cx = np.clip(np.floor((x - box[0]) / csx), 0, ncx - 1).astype(np.int64)
    cy = np.clip(np.floor((y - box[1]) / csy), 0, ncy - 1).astype(np.int64)
    cell = cy * ncx + cx
    order = np.argsort(cell, kind="stable")
    counts = np.bincount(cell, minlength=ncx * ncy)
    cstart = np.cumsum(counts) - counts
    ids = np.arange(n)
    rc2 = rc * rc
    out_i, out_j = [], []
    for ox, oy in ((0, 0), (1, 0), (-1, 1), (0, 1), (1, 1)):  # half stencil
        nx_, ny_ = cx + ox, cy + oy
        ok = (nx_ >= 0) & (nx_ < ncx) & (ny_ < ncy)
        i0 = ids[ok]
        nb = ny_[ok] * ncx + nx_[ok]
        cnt = counts[nb]
        tot = int(cnt.sum())
        if tot == 0:
            continue
        pi = np.repeat(i0, cnt)
        first = np.repeat(cstart[nb], cnt)
        within = np.arange(tot) - np.repeat(np.cumsum(cnt) - cnt, cnt)
        pj = order[first + within]
        keep = (pj > pi) if (ox, oy) == (0, 0) else np.ones(tot, bool)
        dx = x[pi] - x[pj]
        dy = y[pi] - y[pj]
        keep &= dx * dx + dy * dy < rc2
        out_i.append(pi[keep])
        out_j.append(pj[keep])
    if not out_i:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    return np.concatenate(out_i), np.concatenate(out_j)


def segment_distance(x, y, wall):
    """(dx, dy, L2): offsets from the closest point of segment ``wall`` and the segment's squared length."""
    x0, y0, x1, y1 = wall
    ex, ey = x1 - x0, y1 - y0
    L2 = ex * ex + ey * ey
    if L2 > 0.0:
        t = np.clip(((x - x0) * ex + (y - y0) * ey) / L2, 0.0, 1.0)
    else:
        t = np.zeros_like(x)
    return x - (x0 + t * ex), y - (y0 + t * ey), L2


class NumpyRelax:
    """State of the vectorised PAPER relaxation (positions kept as separate x, y arrays)."""

    def __init__(self, pos, weight, walls, box, wl_u, wr_u, pl_u, pr_u, du, skin):
        self.x = np.array(pos[:, 0], float)
        self.y = np.array(pos[:, 1], float)
        self.weight = np.asarray(weight, float)
        self.walls = np.asarray(walls, float)
        self.box = np.asarray(box, float)
        self.wl_u, self.wr_u, self.pl_u, self.pr_u = wl_u, wr_u, pl_u, pr_u
        self.du, self.skin = du, skin
        self.n_builds = 0
        self.build()
        self.fx, self.fy = self.forces()

    @property
    def pos(self):
        return np.column_stack([self.x, self.y])

    def build(self):
        """Verlet pair list (cutoff pl_u + skin) and near-wall particle lists (wl_u + skin)."""
        self.pi, self.pj = cell_pairs(self.x, self.y, self.box, self.pl_u + self.skin)
        self.near = []
        for w in self.walls:
            dx, dy, _ = segment_distance(self.x, self.y, w)
            self.near.append(np.flatnonzero(dx * dx + dy * dy < (self.wl_u + self.skin) ** 2))
        self.near_any = np.unique(np.concatenate(self.near)) if self.near else np.zeros(0, np.int64)
        self.xb, self.yb = self.x.copy(), self.y.copy()
        self.moved = 0.0
        self.n_builds += 1

    def forces(self):
        """(fx, fy) out-of-balance forces [N] at the current positions."""
        n = self.x.size
        fx = np.zeros(n)
        fy = -self.weight.copy()
        for w, idx in zip(self.walls, self.near):  # wall forces, near-wall particles only
            dx, dy, L2 = segment_distance(self.x[idx], self.y[idx], w)
            d2 = dx * dx + dy * dy
            hit = d2 < self.wl_u ** 2
            d = np.sqrt(d2[hit])
            pos_d = d > 0.0
            s = np.zeros_like(d)
            s[pos_d] = self.wr_u * (1.0 / d[pos_d] - 1.0 / self.wl_u)
            gx, gy = s * dx[hit], s * dy[hit]
            if not pos_d.all():  # exactly on the wall: pushed along its left normal
                L = np.sqrt(L2)
                gx[~pos_d] = -self.wr_u * (w[3] - w[1]) / L
                gy[~pos_d] = self.wr_u * (w[2] - w[0]) / L
            np.add.at(fx, idx[hit], gx)
            np.add.at(fy, idx[hit], gy)
        dx = self.x[self.pi] - self.x[self.pj]
        dy = self.y[self.pi] - self.y[self.pj]
        d2 = dx * dx + dy * dy
        with np.errstate(divide="ignore", invalid="ignore"):
            s = np.where(d2 < self.pl_u ** 2, self.pr_u * (1.0 / np.sqrt(d2) - 1.0 / self.pl_u), 0.0)
            gx = s * dx
            gy = s * dy
        zero = d2 == 0.0
        if zero.any():  # coincident particles: pushed apart along +x / -x
            gx[zero] = self.pr_u
            gy[zero] = 0.0
        fx += np.bincount(self.pi, gx, n) - np.bincount(self.pj, gx, n)
        fy += np.bincount(self.pi, gy, n) - np.bincount(self.pj, gy, n)
        return fx, fy

    def crossed(self, sx, sy):
        """Index of the first particle whose move (sx, sy) crosses a wall, or -1."""
        idx = self.near_any
        if self.moved + SQRT2 * self.du >= self.wl_u + self.skin:
            idx = np.arange(self.x.size)  # list no longer bounds who can reach a wall
        x0, y0 = self.x[idx], self.y[idx]
        x1, y1 = x0 + sx[idx], y0 + sy[idx]
        hit = np.zeros(idx.size, bool)
        for ax, ay, bx, by in self.walls:
            ex, ey = bx - ax, by - ay
            s0 = ex * (y0 - ay) - ey * (x0 - ax)
            s1 = ex * (y1 - ay) - ey * (x1 - ax)
            mx, my = x1 - x0, y1 - y0
            t0 = mx * (ay - y0) - my * (ax - x0)
            t1 = mx * (by - y0) - my * (bx - x0)
            hit |= (s0 * s1 < 0.0) & (t0 * t1 <= 0.0)
        return int(idx[np.argmax(hit)]) if hit.any() else -1

    def step(self):
        """One PAPER step; returns max|F| before it, or raises if a move would cross a wall."""
        fmax = max(np.abs(self.fx).max(), np.abs(self.fy).max())
        scale = self.du / fmax
        sx, sy = scale * self.fx, scale * self.fy
        i = self.crossed(sx, sy)
        if i >= 0:
            raise RuntimeError(f"particle {i} would cross a wall")
        self.x += sx
        self.y += sy
        self.moved += SQRT2 * self.du
        if self.moved > 0.5 * self.skin:
            dmax = np.sqrt(((self.x - self.xb) ** 2 + (self.y - self.yb) ** 2).max())
            if dmax > 0.5 * self.skin:
                self.build()
            else:
                self.moved = dmax
        self.fx, self.fy = self.forces()
        return fmax

    def run(self, n_steps):
        for _ in range(n_steps):
            self.step()
