"""Small rotations of the solid particles from their links (numba; for the objective shear springs)."""

from ...core.jit import njit

JIT = dict(cache=True, nogil=True)


@njit(**JIT)
def rotations(pos, ref, la, lb, L0, laxis, cnt, grad, rot):
    """Each particle's small rotation W = (grad u - grad u^T) / 2, grad u from the displacement differences
    along its links (mean of both sides; one-sided at a surface; 0 along an axis without links).

    L0 (L,) link rest lengths, cnt (N, 3) links per particle and axis (kernels.link_geometry); grad is work
    space.  3D layout (pos (N, 3)): grad, rot (N, 9), W row-major.  2D layout (pos (N, 2), links along x and
    y): grad (N, 2) the sums of d u_y / d x and d u_x / d y, rot (N, 1) W_yx (W_xy = -W_yx); the same
    arithmetic as the 3D layout's (each sum has at most two terms, so the link order does not matter)."""
    n = pos.shape[0]
    d = pos.shape[1]
    grad[:, :] = 0.0
    for k in range(la.shape[0]):
        a = la[k]
        b = lb[k]
        u = laxis[k]
        if d == 2:  # along x the y displacement's gradient, along y the x displacement's
            i = 1 - u
            g = ((pos[b, i] - ref[b, i]) - (pos[a, i] - ref[a, i])) / L0[k]
            grad[a, u] += g
            grad[b, u] += g
            continue
        for i in range(3):
            g = ((pos[b, i] - ref[b, i]) - (pos[a, i] - ref[a, i])) / L0[k]
            grad[a, 3 * i + u] += g
            grad[b, 3 * i + u] += g
    for a in range(n):
        if d == 2:
            gyx = grad[a, 0] / cnt[a, 0] if cnt[a, 0] > 0.0 else grad[a, 0]
            gxy = grad[a, 1] / cnt[a, 1] if cnt[a, 1] > 0.0 else grad[a, 1]
            rot[a, 0] = 0.5 * (gyx - gxy)
            continue
        for j in range(3):
            if cnt[a, j] > 0.0:
                for i in range(3):
                    grad[a, 3 * i + j] /= cnt[a, j]
        for i in range(3):
            for j in range(3):
                rot[a, 3 * i + j] = 0.5 * (grad[a, 3 * i + j] - grad[a, 3 * j + i])
