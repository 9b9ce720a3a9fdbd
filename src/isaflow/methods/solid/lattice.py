"""Cubic particle blocks and their contact matrix (links between lattice neighbours)."""

from dataclasses import dataclass, field

import numpy as np


@dataclass
class Block:
    """A block of cubic particles of size dx [cm] on a regular lattice.

    ref (N, 3) cm reference (unstrained) centres, index (N, 3) int lattice
    indices (i, j, k), shape (nx, ny, nz), dim 2 or 3 (2: nz == 1, z = 0).
    Links (the paper's contact matrix): la, lb (L,) int32 particle pairs of
    lattice neighbours, d0 (L, 3) cm reference vectors ref_b - ref_a, axis (L,)
    int32 lattice axis; partners (N, 6) int32 linked particles (-1 padded).  geometry: the links' rest
    lengths, unit vectors and per-axis counts (kernels.link_geometry), filled by the first solve.Stepper.
    """

    dx: float
    shape: tuple
    ref: np.ndarray
    index: np.ndarray
    la: np.ndarray
    lb: np.ndarray
    d0: np.ndarray
    axis: np.ndarray
    partners: np.ndarray
    geometry: tuple = field(default=None, repr=False, compare=False)

    @property
    def dim(self):
        return 2 if self.shape[2] == 1 else 3

    @property
    def n(self):
        return len(self.ref)


def block(nx, ny, nz, dx, origin=(0.0, 0.0, 0.0)):
    """Block of nx x ny x nz particles (nz = 1: 2D), first centre at origin, all neighbours linked."""
    i, j, k = np.meshgrid(np.arange(nx), np.arange(ny), np.arange(nz), indexing="ij")
    index = np.column_stack([i.ravel(), j.ravel(), k.ravel()])
    ref = np.asarray(origin, float) + dx * index.astype(float)
    flat = np.arange(len(ref)).reshape(nx, ny, nz)
    la, lb, axis = [], [], []
    for u, (a, b) in enumerate([(flat[:-1], flat[1:]), (flat[:, :-1], flat[:, 1:]), (flat[:, :, :-1], flat[:, :, 1:])]):
        la.append(a.ravel())
        lb.append(b.ravel())
        axis.append(np.full(a.size, u))
    la, lb, axis = (np.concatenate(x).astype(np.int32) for x in (la, lb, axis))
    return Block(dx, (nx, ny, nz), ref, index, la, lb, ref[lb] - ref[la], axis, partner_table(len(ref), la, lb))


def partner_table(n, la, lb):
    """(n, 6) int32 linked partners of each particle, -1 padded."""
    out = np.full((n, 6), -1, np.int32)
    count = np.zeros(n, int)
    for a, b in zip(la, lb):
        out[a, count[a]] = b
        out[b, count[b]] = a
        count[a] += 1
        count[b] += 1
    return out


def unlinked(n, dx, dim=2):
    """n particles without links (for contact-only tests)."""
    z = np.zeros(0, np.int32)
    return Block(dx, (n, 1, 1), np.zeros((n, 3)), np.zeros((n, 3), int), z, z.copy(), np.zeros((0, 3)), z.copy(),
                 np.full((n, 6), -1, np.int32))


def select(blk, keep):
    """The sub-block of the particles where keep (N,) bool; links between kept particles only."""
    keep = np.asarray(keep, bool)
    new = np.full(blk.n, -1, np.int64)
    new[keep] = np.arange(keep.sum())
    on = keep[blk.la] & keep[blk.lb]
    la, lb = new[blk.la[on]].astype(np.int32), new[blk.lb[on]].astype(np.int32)
    return Block(blk.dx, blk.shape, blk.ref[keep].copy(), blk.index[keep].copy(), la, lb, blk.d0[on].copy(),
                 blk.axis[on].copy(), partner_table(int(keep.sum()), la, lb))
