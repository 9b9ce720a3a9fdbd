"""Small rotations of the solid particles from their links (numba; for the objective shear springs)."""

import numpy as np
from ...core.jit import njit

JIT = dict(cache=True, nogil=True)


@njit(**JIT)
def rotations(pos, ref, la, lb, d0, laxis, rot):
    """rot (N, 3, 3): each particle's small rotation W = (grad u - grad u^T) / 2, grad u from the
    displacement differences along its links (mean of both sides; one-sided at a surface; 0 along an
    axis without links)."""
    n = pos.shape[0]
    grad = np.zeros((n, 3, 3))
    cnt = np.zeros((n, 3))
    for k in range(la.shape[0]):
        a = la[k]
        b = lb[k]
        u = laxis[k]
        L0 = np.sqrt(d0[k, 0] ** 2 + d0[k, 1] ** 2 + d0[k, 2] ** 2)
        for i in range(3):
            g = ((pos[b, i] - ref[b, i]) - (pos[a, i] - ref[a, i])) / L0
            grad[a, i, u] += g
            grad[b, i, u] += g
        cnt[a, u] += 1.0
        cnt[b, u] += 1.0
    for a in range(n):
        for j in range(3):
            if cnt[a, j] > 0.0:
                for i in range(3):
                    grad[a, i, j] /= cnt[a, j]
        for i in range(3):
            for j in range(3):
                rot[a, i, j] = 0.5 * (grad[a, i, j] - grad[a, j, i])
