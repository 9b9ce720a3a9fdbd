"""Wall geometry shared by every method (numba).

``walls`` (W, 4) float64 rows ``x0, y0, x1, y1`` [cm], each oriented with the
liquid on its left.
"""

import numpy as np
from .jit import njit

JIT = dict(cache=True, nogil=True)


@njit(**JIT)
def segment_closest(px, py, x0, y0, x1, y1):
    """Closest point (cx, cy) on segment (x0, y0)-(x1, y1) to point (px, py)."""
    ex = x1 - x0
    ey = y1 - y0
    L2 = ex * ex + ey * ey
    t = 0.0
    if L2 > 0.0:
        t = ((px - x0) * ex + (py - y0) * ey) / L2
        t = min(1.0, max(0.0, t))
    return x0 + t * ex, y0 + t * ey


@njit(**JIT)
def crossed_wall(x0, y0, x1, y1, walls):
    """Index of the first wall the move (x0, y0) -> (x1, y1) crosses, or -1.

    A move crosses a wall when it passes from one side to the other, when it
    ends exactly on the wall (a wall's push has no side there), or when it
    starts on the wall and goes to the back (right-hand) side.
    """
    for w in range(walls.shape[0]):
        ax = walls[w, 0]
        ay = walls[w, 1]
        ex = walls[w, 2] - ax
        ey = walls[w, 3] - ay
        s0 = ex * (y0 - ay) - ey * (x0 - ax)  # > 0: left (liquid) side
        s1 = ex * (y1 - ay) - ey * (x1 - ax)
        if s1 == 0.0:
            t = ((x1 - ax) * ex + (y1 - ay) * ey) / (ex * ex + ey * ey)
            if 0.0 <= t <= 1.0 and (x1 != x0 or y1 != y0):
                return w
            continue
        if s0 * s1 < 0.0 or (s0 == 0.0 and s1 < 0.0):
            # sides of the wall's end points relative to the move
            mx = x1 - x0
            my = y1 - y0
            t0 = mx * (ay - y0) - my * (ax - x0)
            t1 = mx * (walls[w, 3] - y0) - my * (walls[w, 2] - x0)
            if t0 * t1 <= 0.0:
                return w
    return -1


def bounding_box(walls):
    """(4,) ``xmin, ymin, xmax, ymax`` [cm] of the wall end points."""
    pts = np.asarray(walls, float).reshape(-1, 2)
    lo, hi = pts.min(0), pts.max(0)
    return np.array([lo[0], lo[1], hi[0], hi[1]])


def outside_box(pos, box, eps=1e-9):
    """(N,) bool: particle outside the box, or with a non-finite coordinate (NaN counts as outside)."""
    pos = np.asarray(pos, float)
    inside = ((pos[:, 0] >= box[0] - eps) & (pos[:, 0] <= box[2] + eps)
              & (pos[:, 1] >= box[1] - eps) & (pos[:, 1] <= box[3] + eps))
    return ~inside
