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


def point_segment_distance(pts, segs):
    """(N,) distance [cm] of each point (N, 2) to the nearest of the segments (S, 4) x0, y0, x1, y1 (inf if none)."""
    pts = np.asarray(pts, float).reshape(-1, 2)
    out = np.full(len(pts), np.inf)
    for x0, y0, x1, y1 in np.asarray(segs, float).reshape(-1, 4):
        ex, ey = x1 - x0, y1 - y0
        L2 = ex * ex + ey * ey
        t = np.clip(((pts[:, 0] - x0) * ex + (pts[:, 1] - y0) * ey) / L2, 0.0, 1.0) if L2 > 0 else 0.0
        out = np.minimum(out, np.hypot(pts[:, 0] - (x0 + t * ex), pts[:, 1] - (y0 + t * ey)))
    return out


def inside_polygon(pts, polygon):
    """(N,) bool: the point (N, 2) lies inside the closed polygon [(x, y)] (even-odd rule; a point on an edge may
    fall either way: ask for a clearance, inside_vessel)."""
    pts = np.asarray(pts, float).reshape(-1, 2)
    poly = np.asarray(polygon, float).reshape(-1, 2)
    x, y = pts[:, 0], pts[:, 1]
    inside = np.zeros(len(pts), bool)
    for k in range(len(poly)):
        (ax, ay), (bx, by) = poly[k - 1], poly[k]
        if ay == by:
            continue
        spans = (ay > y) != (by > y)
        xc = ax + (y - ay) * (bx - ax) / (by - ay)
        inside ^= spans & (x < xc)
    return inside


def inside_vessel(pts, polygon, walls, clearance):
    """(N,) bool: the point (N, 2) [cm] lies inside a vessel's polygon (isaflow.tank.vessel_polygon) at least
    ``clearance`` cm from its edges and from every wall (W, 4) (a point at the clearance to round-off counts as
    at it): the one test by which every method's initial liquid fills its vessel.  A lattice of cells (dx, dy)
    from a rectangle's corner, tested at half a cell, keeps every cell: its centres lie half a cell from its sides."""
    pts = np.asarray(pts, float).reshape(-1, 2)
    poly = np.asarray(polygon, float).reshape(-1, 2)
    edges = np.column_stack([np.roll(poly, 1, axis=0), poly])
    segs = np.concatenate([edges, np.asarray(walls, float).reshape(-1, 4)])
    scale = max(1.0, float(np.abs(poly).max()))
    return inside_polygon(pts, poly) & (point_segment_distance(pts, segs) >= clearance * (1 - 1e-9) - 1e-12 * scale)
