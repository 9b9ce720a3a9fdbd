"""Initial liquid lattice and wall (boundary) particles of a tank (NumPy, setup only).

Units cm.  The liquid fills the first vessel to the tank's depth on a
lattice of nx x ny cells (dx, dy) = (B / nx, depth / ny) over the vessel's
width B, one particle per cell centre inside the vessel's polygon half a cell
from its walls (core.geometry.inside_vessel: in a rectangular vessel every
cell, so the cells tile the liquid exactly), and every particle weighs W / N.
Wall particles continue that lattice behind
each wall (Adami et al. 2012: layers of fixed particles covering the kernel
support), anchored to the liquid lattice's origin so that a straight wall
sees the same lattice on both sides.
"""

import numpy as np

from ...core import fixed_order as FO
from ...core.geometry import inside_vessel
from ...core.neighbours import build_pairs


def lattice_shape(width, depth, particles=None, spacing=None, area=None):
    """(nx, ny): cells across the width and the depth [cm] for a target particle
    count or a target spacing [cm] (cells as close to square as the counts allow);
    area [cm^2]: the liquid's (a polygonal vessel's), width x depth if not given."""
    if spacing is None:
        spacing = np.sqrt((width * depth if area is None else area) / particles)
    return max(1, int(round(width / spacing))), max(1, int(round(depth / spacing)))


def liquid_lattice(x0, floor_y, width, depth, nx, ny, vessel=None, walls=()):
    """(N, 2) cell centres [cm], row by row from the floor; and (dx, dy) [cm].  vessel: the vessel's polygon
    [(x, y)] (tank.vessel_polygon): only the centres inside it half a cell from its edges and the walls (W, 4)
    (core.geometry.inside_vessel); None: all nx ny."""
    dx, dy = width / nx, depth / ny
    gx, gy = np.meshgrid(x0 + (np.arange(nx) + 0.5) * dx, floor_y + (np.arange(ny) + 0.5) * dy)
    pos = np.column_stack([gx.ravel(), gy.ravel()])
    if vessel is not None:
        pos = pos[inside_vessel(pos, vessel, walls, 0.5 * min(dx, dy))]
    return pos, (dx, dy)


def hydrostatic_heights(y, floor_y, depth, rho_ratio):
    """Heights [cm] of liquid at undisturbed heights y once compressed to the
    hydrostatic density: y' = floor + integral_0^(y - floor) dz / r(z), with
    r(z) = rho / rho_ref at depth (depth - z) (rho_ratio: callable of depth [cm])."""
    z = np.linspace(0.0, depth, 2001)
    inv = 1.0 / rho_ratio(depth - z)
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (inv[1:] + inv[:-1]) * np.diff(z))])
    return floor_y + np.interp(y - floor_y, z, cum)


def _closest(px, py, seg):
    """(distance, t in [0, 1], side) of points to a segment; side > 0 on its left (liquid side)."""
    x0, y0, x1, y1 = seg
    ex, ey = x1 - x0, y1 - y0
    L2 = ex * ex + ey * ey
    t = np.clip(((px - x0) * ex + (py - y0) * ey) / L2, 0.0, 1.0)
    d = np.hypot(px - (x0 + t * ex), py - (y0 + t * ey))
    side = ex * (py - y0) - ey * (px - x0)
    return d, t, side


def joints(walls):
    """{(wall, end): other wall} for wall ends shared with another wall (end 0 start, 1 end)."""
    out = {}
    for a, sa in enumerate(walls):
        for b, sb in enumerate(walls):
            if a != b and np.allclose(sa[2:], sb[:2]):
                out[a, 1] = b
                out[b, 0] = a
    return out


def is_solid(px, py, walls):
    """(P,) bool: the point lies behind the walls (not on the liquid side).

    Decided by the nearest wall: behind it if the nearest point is inside the
    segment; at a joint of walls A -> B, behind both (a right turn, the liquid
    wraps round the corner) or behind either (a left turn); at a free wall end
    the point is not solid (no caps round open ends).
    """
    walls = np.asarray(walls, float)
    res = [_closest(px, py, s) for s in walls]
    d = np.array([r[0] for r in res])
    near = np.argmin(d, axis=0)
    jt = joints(walls)
    out = np.zeros(len(px), bool)
    for i in range(len(px)):
        w = near[i]
        t, side = res[w][1][i], res[w][2][i]
        if 0.0 < t < 1.0:
            out[i] = side < 0
            continue
        end = int(t >= 1.0)
        other = jt.get((w, end))
        if other is None:
            continue
        a, b = (w, other) if end == 1 else (other, w)
        ea, eb = walls[a, 2:] - walls[a, :2], walls[b, 2:] - walls[b, :2]
        turn = ea[0] * eb[1] - ea[1] * eb[0]
        sa, sb = res[a][2][i] < 0, res[b][2][i] < 0
        out[i] = (sa and sb) if turn < 0 else (sa or sb)
    return out


def wet_back(walls, vessels):
    """(W,) bool: walls whose back (right-hand) face the liquid can wet too (thin dividing walls).

    A wall's back is wettable when the point a hair behind its middle lies inside a vessel,
    between its x bounds and above its floor (the lowest horizontal wall over it).
    vessels: [(name, (xmin, xmax) cm)]."""
    walls = np.asarray(walls, float)
    horiz = np.isclose(walls[:, 1], walls[:, 3])
    out = np.zeros(len(walls), bool)
    for w, (x0, y0, x1, y1) in enumerate(walls):
        L = np.hypot(x1 - x0, y1 - y0)
        px = 0.5 * (x0 + x1) + 1e-6 * (y1 - y0) / L
        py = 0.5 * (y0 + y1) - 1e-6 * (x1 - x0) / L
        for _, (a, b) in vessels:
            over = horiz & (np.minimum(walls[:, [0, 2]].max(1), b) - np.maximum(walls[:, [0, 2]].min(1), a) > 1e-9)
            if a < px < b and over.any() and py > walls[over, 1].min():
                out[w] = True
    return out


def wall_particles(walls, dx, dy, support, origin=(0.0, 0.0), two_faced=None):
    """Wall particles behind every wall face, covering `support` [cm] (the kernel's 2 h).

    Each wall gets layers (k - 1/2) d_n behind it (d_n = dy for horizontal,
    dx for vertical walls, sqrt(dx dy) otherwise), points d_t apart along it in
    the phase of the lattice through `origin`; at joints the layers run on
    past the end to fill the corner, kept where behind the walls (is_solid); at a
    free end a column stands at the very tip.  Walls flagged in two_faced (W,) bool
    (thin dividing walls, see wet_back) get the same layers in front too (face 1),
    for the liquid on their back; the pair list's visibility rule (pairs) lets each
    liquid particle see only the layers across the wall from it.
    Points closer than half a spacing to an earlier one are dropped.
    Returns (pos (P, 2) cm, wall (P,) int: the wall each belongs to, face (P,) int:
    0 behind the wall (serving its front, the liquid side), 1 in front (serving its back)).
    """
    walls = np.asarray(walls, float)
    two_faced = np.zeros(len(walls), bool) if two_faced is None else np.asarray(two_faced, bool)
    jt = joints(walls)
    pts, owner, extra, faces = [], [], [], []
    for w, (x0, y0, x1, y1) in enumerate(walls):
        ex, ey = x1 - x0, y1 - y0
        L = np.hypot(ex, ey)
        tx, ty = ex / L, ey / L
        nx_, ny_ = ty, -tx  # back (right-hand) normal
        if abs(ty) < 1e-12:
            d_t, d_n = dx, dy
        elif abs(tx) < 1e-12:
            d_t, d_n = dy, dx
        else:
            d_t = d_n = np.sqrt(dx * dy)
        layers = int(np.ceil(support / d_n))
        s_org = (origin[0] - x0) * tx + (origin[1] - y0) * ty  # lattice phase along the wall
        n_ext = int(np.ceil(support / d_t))
        tips = [e for e, free in ((0.0, (w, 0) not in jt), (L, (w, 1) not in jt)) if free]
        for face in ((0, 1) if two_faced[w] else (0,)):
            # face 0, past a joint: fill the corner; at a free end (and on face 1): up to the tip column
            lo = -n_ext * d_t if (w, 0) in jt and face == 0 else 0.0
            hi = L + n_ext * d_t if (w, 1) in jt and face == 0 else L
            j = np.arange(np.floor((lo - s_org) / d_t) - 1, np.ceil((hi - s_org) / d_t) + 1)
            s = s_org + (j + 0.5) * d_t
            s = s[(s >= lo) & (s <= hi)]
            s = np.concatenate([tips, s])  # free ends: a column at the very tip (later duplicates dropped)
            sign = 1.0 if face == 0 else -1.0
            for k in range(1, layers + 1):
                off = sign * (k - 0.5) * d_n
                px, py = x0 + s * tx + off * nx_, y0 + s * ty + off * ny_
                pts.append(np.column_stack([px, py]))
                owner.append(np.full(len(s), w))
                faces.append(np.full(len(s), face))
                extra.append(((s < 0) & ((w, 0) in jt)) | ((s > L) & ((w, 1) in jt)))
    pos, owner, extra = np.concatenate(pts), np.concatenate(owner), np.concatenate(extra)
    faces = np.concatenate(faces)
    keep = ~extra | is_solid(pos[:, 0], pos[:, 1], walls)
    # layer points first, then corner points; keep(fewer than half a spacing apart: drop the later)
    order = np.flatnonzero(keep)[np.argsort(extra[keep], kind="stable")]
    pos, owner, faces = pos[order], owner[order], faces[order]
    lo, hi = pos.min(0) - 1.0, pos.max(0) + 1.0
    pi, pj, m = build_pairs(pos, np.array([lo[0], lo[1], hi[0], hi[1]]), 0.5 * min(dx, dy))
    drop = np.zeros(len(pos), bool)
    for a, b in sorted(zip(np.minimum(pi[:m], pj[:m]), np.maximum(pi[:m], pj[:m]))):
        if not drop[a]:
            drop[b] = True
    return pos[~drop], owner[~drop], faces[~drop]


def wall_contacts(walls, wpos, owner, force):
    """Split wall-particle forces into (wall, point on the wall, force) contributions.

    A particle behind the inside of its wall gives its whole force to that
    wall at its foot point; one beyond a joint (a corner particle) splits its
    force along the two walls' normals, each part acting at the joint.
    wpos (P, 2) cm, owner (P,) int, force (P, 2) N.  Returns (wall (Q,), point
    (Q, 2), force (Q, 2)).
    """
    walls = np.asarray(walls, float)
    jt = joints(walls)
    ws, pts, fs = [], [], []
    for q, (w, (px, py), f) in enumerate(zip(owner, wpos, force)):
        x0, y0, x1, y1 = walls[w]
        e = np.array([x1 - x0, y1 - y0])
        t = ((px - x0) * e[0] + (py - y0) * e[1]) / FO.dot2(e, e)
        if 0.0 <= t <= 1.0 or (w, int(t > 1.0)) not in jt:
            tc = min(1.0, max(0.0, t))
            ws.append(w)
            pts.append([x0 + tc * e[0], y0 + tc * e[1]])
            fs.append(f)
            continue
        other = jt[w, int(t > 1.0)]
        corner = walls[w, 2:] if t > 1.0 else walls[w, :2]
        n = []
        for k in (w, other):
            ek = walls[k, 2:] - walls[k, :2]
            n.append(np.array([-ek[1], ek[0]]) / np.hypot(*ek))  # liquid-side normal
        A = np.column_stack(n)
        if abs(FO.det2(A)) < 1e-9:
            coef = np.array([0.5, 0.5]) * FO.dot2(f, n[0])
        else:
            coef = FO.solve2(A, f)
        for k, c, nk in zip((w, other), coef, n):
            ws.append(k)
            pts.append(list(corner))
            fs.append(c * nk)
    return np.array(ws, int), np.array(pts, float).reshape(-1, 2), np.array(fs, float).reshape(-1, 2)


def along_spacing(wall, dx, dy):
    """Spacing [cm] of the wall particles along a wall (x0, y0, x1, y1)."""
    ex, ey = wall[2] - wall[0], wall[3] - wall[1]
    if abs(ey) < 1e-12 * abs(ex):
        return dx
    if abs(ex) < 1e-12 * abs(ey):
        return dy
    return float(np.sqrt(dx * dy))


def spread_to_panels(walls, length, cw, cpt, cf, dx, dy):
    """Sum wall-particle contributions into the panels of core.panels.wall_panels, each
    spread uniformly over its tributary length (one along-wall spacing centred on its
    foot point; joint contributions stay points), so that panels holding a different
    number of wall-particle columns are not aliased.  Belongs in core.panels.
    Returns (wall (P,), centre (P, 2) cm, force (P, 2) N)."""
    from ...core.panels import wall_panels

    walls = np.asarray(walls, float)
    pw, pc, s0, s1 = wall_panels(walls, length)
    out = np.zeros((len(pw), 2))
    for w, seg in enumerate(walls):
        mine = np.flatnonzero(cw == w)
        panels = np.flatnonzero(pw == w)
        if len(mine) == 0:
            continue
        L = np.hypot(seg[2] - seg[0], seg[3] - seg[1])
        s = np.hypot(cpt[mine, 0] - seg[0], cpt[mine, 1] - seg[1])
        half = 0.5 * along_spacing(seg, dx, dy)
        point = (s <= 1e-9) | (s >= L - 1e-9)  # joint contributions
        lo, hi = np.clip(s - half, 0, L), np.clip(s + half, 0, L)
        for k, q in enumerate(mine):
            if point[k] or hi[k] <= lo[k]:
                j = panels[min(len(panels) - 1, np.searchsorted(s1[panels], s[k], side="right"))]
                out[j] += cf[q]
                continue
            frac = np.clip(np.minimum(hi[k], s1[panels]) - np.maximum(lo[k], s0[panels]), 0, None) / (hi[k] - lo[k])
            out[panels] += frac[:, None] * cf[q]
    return pw, pc, out
