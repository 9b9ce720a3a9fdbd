"""Free surface and hydrostatic theory of the wall loads, shared by every method.

Units: length cm, force N, pressure N/cm (2D: force per unit wall length).
A hydrostatic liquid of specific weight gamma [N/cm^2] with its free surface
at ``level`` loads a wall with gamma (level - y)_+ per unit length.  The
tank's theory (:func:`rest_levels`) fixes gamma = rho g and the levels at rest
from the tank's liquid alone; a method's own theory takes the weight it holds
and the depth of its own free surface (metrics.load_errors).
"""

import numpy as np


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
    k = np.polyfit(x, top, 1)[0]
    return float(np.degrees(np.arctan(k))), float(top.max() - top.min())


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
    """Hydrostatic force magnitude [N] on a whole wall segment (x0, y0, x1, y1)."""
    L = np.hypot(wall[2] - wall[0], wall[3] - wall[1])
    return _pressure_integral(wall, 0.0, L, gamma, level)


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
