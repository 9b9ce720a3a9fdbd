"""Free surface and hydrostatic theory of the wall loads, shared by every method.

Units: length cm, force N, pressure N/cm (2D: force per unit wall length).
A hydrostatic liquid of specific weight gamma [N/cm^2] with its free surface
at ``level`` loads a wall with gamma (level - y)_+ per unit length, normal to
the wall whatever its slope (:func:`wall_total`, :func:`wall_force`: a plane
wall of slope theta wetted to depth h carries gamma h^2 / (2 sin theta)).  The
tank's theory (:func:`rest_level`) fixes gamma = rho g and the levels at rest
from the tank's liquid alone, over the vessels' polygons (tank.vessel_polygon);
a method's own theory takes the weight it holds and the depth of its own free
surface (metrics.load_errors).
"""

import math

import numpy as np

from . import tank as T
from .core import fixed_order as FO


def surface_profile(pos, a, x_range):
    """Free surface as the highest particle of each vertical strip of width ``a``.

    pos (N, 2) cm; a strip width cm (the particle spacing); x_range (xmin, xmax)
    is the vessel: strips start at xmin, particles outside are ignored, strips
    holding no particle are skipped.  Returns (x (S,) cm strip centres, top (S,) cm).
    """
    pos = np.asarray(pos)
    pos = pos[(pos[:, 0] >= x_range[0]) & (pos[:, 0] < x_range[1])]
    strip = np.floor((pos[:, 0] - x_range[0]) / a).astype(int)
    ids = np.unique(strip)
    return x_range[0] + (ids + 0.5) * a, np.array([pos[strip == s, 1].max() for s in ids])


def free_surface_level(pos, a, x_range):
    """Free-surface level [cm]: mean of :func:`surface_profile` (the line one reads off
    the paper's figures); NaN if the vessel is empty."""
    _, top = surface_profile(pos, a, x_range)
    return float(np.mean(top)) if len(top) else float("nan")


def surface_slope(x, top):
    """(slope in degrees of the least-squares line through the profile, max - min [cm]);
    a liquid at rest has both about 0.  NaN for fewer than two strips."""
    if len(x) < 2:
        return float("nan"), float("nan")
    k, _ = FO.line(x, top)
    return math.degrees(math.atan(k)), float(top.max() - top.min())


def specific_weight(total_weight, width, level, floor_y=0.0):
    """gamma [N/cm^2] of liquid of ``total_weight`` N filling width x (level - floor_y)."""
    return total_weight / (width * (level - floor_y))


def _pressure_integral(wall, s0, s1, gamma, level):
    """Integral of gamma (level - y)_+ ds over wall parameter [s0, s1] (arc length, cm)."""
    x0, y0, x1, y1 = wall
    L = np.hypot(x1 - x0, y1 - y0)
    ey = (y1 - y0) / L
    if ey == 0.0:
        return gamma * max(level - y0, 0.0) * (s1 - s0)
    s_star = (level - y0) / ey  # where the wall crosses the free surface
    lo, hi = (s0, min(s1, s_star)) if ey > 0 else (max(s0, s_star), s1)
    if hi <= lo:
        return 0.0
    mid = 0.5 * (lo + hi)
    return gamma * (level - (y0 + mid * ey)) * (hi - lo)


def wall_total(wall, gamma, level):
    """Hydrostatic force magnitude [N] on a whole wall segment (x0, y0, x1, y1): the pressure integrated along it,
    normal to it (a plane wall of slope theta from the horizontal wetted to depth h: gamma h^2 / (2 sin theta))."""
    L = np.hypot(wall[2] - wall[0], wall[3] - wall[1])
    return _pressure_integral(wall, 0.0, L, gamma, level)


def wall_force(wall, gamma, level):
    """(2,) hydrostatic force [N] of the liquid on a wall segment (x0, y0, x1, y1), oriented with the liquid on
    its left: wall_total along the wall's right-hand normal (into the wall).  Its horizontal part is gamma h^2 / 2
    on any plane wall wetted to depth h, its vertical part the weight of the liquid above the wall."""
    x0, y0, x1, y1 = (float(c) for c in wall)
    L = np.hypot(x1 - x0, y1 - y0)
    return wall_total(wall, gamma, level) * np.array([(y1 - y0) / L, -(x1 - x0) / L])


def liquid_area(polygon, floor_y, depth):
    """Area [cm^2] of a vessel's polygon [(x, y)] below floor_y + depth (tank.liquid_area: width x depth in a
    rectangular vessel)."""
    return T.liquid_area(polygon, floor_y, depth)


def contact_theory(walls, contact_wall, contact_point, gamma, level, wall_mask=None):
    """Theoretical hydrostatic force magnitude [N] on each wall contact.

    Each contact carries the pressure over its tributary length: from the wall
    start (or midway to the previous contact along the wall) to midway to the
    next contact (or the wall end).  contact_wall (C,) int, contact_point (C, 2)
    cm.  Contacts on walls not in wall_mask (W,) bool get NaN.
    """
    walls = np.asarray(walls, float)
    out = np.full(len(contact_wall), np.nan)
    for w, seg in enumerate(walls):
        if wall_mask is not None and not wall_mask[w]:
            continue
        idx = np.flatnonzero(contact_wall == w)
        if len(idx) == 0:
            continue
        L = np.hypot(seg[2] - seg[0], seg[3] - seg[1])
        s = np.hypot(contact_point[idx, 0] - seg[0], contact_point[idx, 1] - seg[1])
        order = np.argsort(s)
        ss = s[order]
        bounds = np.concatenate([[0.0], 0.5 * (ss[1:] + ss[:-1]), [L]])
        for k, c in enumerate(idx[order]):
            out[c] = _pressure_integral(seg, bounds[k], bounds[k + 1], gamma, level)
    return out


def resultant_height(contact_point_y, magnitude):
    """Height [cm] of the resultant of parallel contact loads (sum F y / sum F)."""
    tot = np.sum(magnitude)
    return float(np.sum(magnitude * contact_point_y) / tot) if tot > 0 else float("nan")


def implied_level(side_load, total_weight, width):
    """Level [cm] implied by a side-wall load: F = gamma h^2 / 2 with gamma = W / (B h)."""
    return 2.0 * width * side_load / total_weight


def rest_levels(floors, widths, weight, rho_g):
    """Free-surface level [cm] of a liquid at rest in communicating vessels.

    floors, widths (V,) cm of the vessels (they communicate through openings
    at their floors, as in every tank here); weight N; rho_g N/cm^2.  The
    level H solves sum_v B_v (H - floor_v)_+ = W / rho_g; a vessel whose floor
    is above H holds no liquid.  Returns H.
    """
    floors, widths = np.asarray(floors, float), np.asarray(widths, float)
    area = weight / rho_g
    order = np.argsort(floors)
    f, b = floors[order], widths[order]
    for k in range(len(f)):
        wsum = b[: k + 1].sum()
        held = np.sum(b[: k + 1] * (f[k] - f[: k + 1]))  # area below floor k in the deeper vessels
        h = f[k] + (area - held) / wsum
        if k == len(f) - 1 or h <= f[k + 1]:
            return float(h)
    return float("nan")


def rest_level(polygons, floors, weight, rho_g):
    """Free-surface level [cm] of a liquid at rest in communicating vessels of any polygonal shape.

    polygons: each vessel's polygon [(x, y)] (tank.vessel_polygon), floors (V,) cm their floors; the level H
    solves sum_v A_v(H) = W / rho_g, A_v the vessel's polygon below H (liquid_area).  Vessels that are all
    rectangles take the closed form (rest_levels); any other by bisection to round-off (the areas grow with H).
    NaN if the vessels cannot hold the liquid below their tops."""
    boxes = [T.is_box(p) for p in polygons]
    if all(boxes):
        widths = [max(x for x, _ in p) - min(x for x, _ in p) for p in polygons]
        return rest_levels(floors, widths, weight, rho_g)
    target = weight / rho_g

    def held(H):
        return sum(liquid_area(p, f, H - f) for p, f in zip(polygons, floors) if H > f)

    lo, hi = float(min(floors)), float(max(y for p in polygons for _, y in p))
    if held(hi) < target:
        return float("nan")
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        lo, hi = (mid, hi) if held(mid) < target else (lo, mid)
    return float(hi)
