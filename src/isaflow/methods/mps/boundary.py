"""Wall and dummy particles of a tank, the initial liquid block, and wall loads on panels.

Walls (W, 4) cm, each oriented with the liquid on its left.  A wall has one
*face* (its liquid side) or, if it is *thin* (liquid space on both sides: a
dividing wall such as flow tanks' ``right1``), two faces.  Every face gets
``layers`` rows of particles behind it at (k + 1/2) l0 (k < pressure_layers:
WALL particles in the pressure equation and the gradient; further rows: DUMMY
particles for the number density only, as MPS-Basic's generators), so that the
liquid's cells [0, l0]^2 tile the vessel exactly and a first-row particle faces
l0 of wall.  Rows are extended past an end joined to another wall (corners);
candidates of a one-faced wall on the liquid side of another wall are dropped.
A thin wall's two sets of rows lie in each other's liquid space: the particles
of a face are seen only by particles on that face's side (operators.visible) and,
with walls.thin_line_of_sight, only where the wall hides them (not round its free
end, where the other vessel's liquid is seen in their place).
"""

import numpy as np
from scipy.spatial import cKDTree

from isaflow.core import fixed_order as FO
from isaflow.core.geometry import inside_vessel
from isaflow.core.panels import wall_panels

from .operators import DUMMY, FLUID, WALL

BACK_OFFSET = 1e-3  # cm: a thin wall's back-face panel centres lie this far behind the wall line (see load_map)


def _frames(walls):
    """Start points (W, 2), lengths (W,), unit tangents (W, 2), liquid-side normals (W, 2)."""
    a = walls[:, :2]
    e = walls[:, 2:] - a
    L = np.hypot(e[:, 0], e[:, 1])
    t = e / L[:, None]
    return a, L, t, np.column_stack([-t[:, 1], t[:, 0]])


def thin_walls(walls, vessels, eps=1e-6):
    """(W,) bool: the wall has liquid space behind it too (a dividing wall between two vessels).

    Liquid space: inside a vessel's [xmin, xmax), above that vessel's floor (the highest horizontal wall
    spanning it with its liquid side up).  Tested at a point ``eps`` cm behind the wall's midpoint.  vessels [(name, (xmin, xmax))].
    """
    walls = np.asarray(walls, float)
    a, L, t, nrm = _frames(walls)
    out = np.zeros(len(walls), bool)
    horiz = np.isclose(walls[:, 1], walls[:, 3]) & (nrm[:, 1] > 0)
    for w in range(len(walls)):
        p = a[w] + 0.5 * L[w] * t[w] - eps * nrm[w]
        for _, (x0, x1) in vessels:
            if not (x0 <= p[0] < x1):
                continue
            span = (np.minimum(np.maximum(walls[:, 0], walls[:, 2]), x1) - np.maximum(np.minimum(walls[:, 0], walls[:, 2]), x0)) > 0
            floors = walls[horiz & span, 1]
            if len(floors) and p[1] > floors.max():
                out[w] = True
    return out


def wall_particles(walls, l0, layers=4, pressure_layers=2, thin=None):
    """Boundary particles of the walls.

    layers: rows in all, pressure_layers of them WALL; thin (W,) bool: walls with two faces
    (default none).  Returns dict: pos (M, 2) cm, kind (M,) WALL/DUMMY, wall (M,) wall index,
    side (M,) +1 for particles of a wall's own face, -1 for those of a thin wall's back face;
    and the stretches of wall the first rows face: face_particle (F,) the particle, face_wall (F,),
    face_side (F,) +-1, face_arc (F,) cm centre along the wall, face_ds (F,) cm length (a corner
    particle can face two walls).
    """
    walls = np.asarray(walls, float)
    thin = np.zeros(len(walls), bool) if thin is None else np.asarray(thin, bool)
    a, L, t, nrm = _frames(walls)
    ends = np.concatenate([walls[:, :2], walls[:, 2:]])
    cand = []  # (x, y, kind, wall, side, arc, ds)
    for k in range(layers):
        for w in range(len(walls)):
            for side in ((1, -1) if thin[w] else (1,)):
                n = max(1, int(round(L[w] / l0)))
                ds = L[w] / n
                s = (np.arange(n) + 0.5) * ds
                faces = np.full(n, ds if k == 0 else 0.0)
                joined = [np.sum(np.hypot(*(ends - p).T) < 1e-9) > 1 for p in (walls[w, :2], walls[w, 2:])]
                ext = (np.arange(layers) + 0.5) * l0
                if joined[0]:
                    s, faces = np.concatenate([-ext[::-1], s]), np.concatenate([np.zeros(layers), faces])
                if joined[1]:
                    s, faces = np.concatenate([s, L[w] + ext]), np.concatenate([faces, np.zeros(layers)])
                p = a[w] + s[:, None] * t[w] - side * (k + 0.5) * l0 * nrm[w]
                for q, sq, f in zip(p, s, faces):
                    cand.append((q[0], q[1], WALL if k < pressure_layers else DUMMY, w, side, sq, f))
    cand = np.array(cand)
    cw = cand[:, 3].astype(np.int64)
    keep = np.ones(len(cand), bool)
    reach = layers * l0
    own_thin = thin[cw]
    for w in range(len(walls)):  # drop one-faced walls' candidates in front of another wall
        if thin[w]:
            continue
        rel = cand[:, :2] - a[w]
        s = FO.dot2(rel, t[w])
        d = FO.dot2(rel, nrm[w])
        keep &= ~((d > 1e-9) & (d < reach) & (s > -1e-9) & (s < L[w] + 1e-9) & (cw != w) & ~own_thin)
    cand = cand[keep]
    cand_w, cand_side, cand_s, cand_ds = cand[:, 3].astype(np.int64), cand[:, 4].astype(np.int64), cand[:, 5], cand[:, 6]
    group = np.where(thin[cand_w], 2 * cand_w + (cand_side < 0), -1)  # thin faces never merge with other particles
    drop = np.zeros(len(cand), bool)
    tree = cKDTree(cand[:, :2])
    for i, j in sorted(tree.query_pairs(0.5 * l0)):  # keep the earlier (lower layer) candidate
        if group[i] == group[j] and not drop[i]:
            drop[j] = True
    kept = np.flatnonzero(~drop)
    # kind by depth behind the walls (a corner's row extensions reach deeper behind the other wall than their
    # own row): WALL within pressure_layers l0 of the nearest wall segment (a thin face's: its own wall), else DUMMY
    depth = np.full(len(cand), np.inf)
    for w in range(len(walls)):
        rel = cand[:, :2] - a[w]
        u = np.clip(FO.dot2(rel, t[w]), 0.0, L[w])
        d = np.hypot(*(rel - u[:, None] * t[w]).T)
        mine = np.where(thin[cand_w], cand_w == w, ~thin[w])
        depth = np.where(mine, np.minimum(depth, d), depth)
    cand[:, 2] = np.where(depth < pressure_layers * l0, WALL, DUMMY)
    # a dropped first-row candidate's stretch of wall is faced by the kept particle of its group that replaced it
    owner = np.empty(len(cand), np.int64)
    for g in np.unique(group):
        mine = np.flatnonzero(group == g)
        mine_kept = np.flatnonzero(group[kept] == g)
        owner[mine] = mine_kept[cKDTree(cand[kept[mine_kept], :2]).query(cand[mine, :2])[1]]
    faces = np.flatnonzero(cand[:, 6] > 0)
    c = cand[kept]
    return dict(pos=c[:, :2].copy(), kind=c[:, 2].astype(np.int64), wall=c[:, 3].astype(np.int64),
                side=c[:, 4].astype(np.int64), face_particle=owner[faces], face_wall=cand_w[faces],
                face_side=cand_side[faces], face_arc=cand_s[faces], face_ds=cand_ds[faces])


def liquid_block(x_range, floor_y, depth, l0, vessel=None, walls=()):
    """(N, 2) cm square lattice filling [x0, x1] x [floor_y, floor_y + rows l0], rows = round(depth / l0); vessel:
    the vessel's polygon [(x, y)] (tank.vessel_polygon): only the cells whose centres lie inside it half a cell
    from its edges and the walls (W, 4) (core.geometry.inside_vessel: in a rectangular vessel, every cell)."""
    cols = int(round((x_range[1] - x_range[0]) / l0))
    rows = max(1, int(round(depth / l0)))
    dx = (x_range[1] - x_range[0]) / cols
    x = x_range[0] + (np.arange(cols) + 0.5) * dx
    y = floor_y + (np.arange(rows) + 0.5) * l0
    X, Y = np.meshgrid(x, y)
    pos = np.column_stack([X.ravel(), Y.ravel()])
    if vessel is not None:
        pos = pos[inside_vessel(pos, vessel, walls, 0.5 * min(dx, l0))]
    return pos


def load_map(walls, bnd, panel_length):
    """Linear map from first-row wall-particle pressures to panel forces.

    Each face of a wall has its own panels (a thin wall: two sets, the back face's centres BACK_OFFSET cm
    behind the wall line, on the liquid side they load, so that metrics.contact_in_vessel gives them to
    that vessel).  Each WALL particle carries its pressure over the wall length it faces (arc +- ds / 2),
    split between panels by overlap; the force on the liquid is P x length along the face's liquid-side
    normal.  Returns (panel_wall (P,), panel_centre (P, 2) cm, panel_side (P,) +-1, M (2P, Nb), share (P, Nb))
    with force = (M @ P_bnd).reshape(P, 2) in N when P is in N/cm^2 (2D: per cm of thickness); share: how the
    force of every boundary particle (wall, dummy, a corner's row extension) is split between the panels of its
    own wall and face, by the overlap of the stretch it stands for (its projection on the wall line +- half its
    row's spacing, moved inside the wall's ends) with each panel (each column sums to 1): the panels of the
    pair-force reading (operators.wall_forces).
    """
    walls = np.asarray(walls, float)
    a, L, t, nrm = _frames(walls)
    pw, pc, s0, s1 = wall_panels(walls, panel_length)
    sides = sorted({(int(w), int(sd)) for w, sd in zip(bnd["face_wall"], bnd["face_side"])})
    back = np.array([w for w, sd in sides if sd < 0], int)
    bq = np.flatnonzero(np.isin(pw, back))
    panel_wall = np.concatenate([pw, pw[bq]])
    panel_centre = np.concatenate([pc, pc[bq] - BACK_OFFSET * nrm[pw[bq]]])
    panel_side = np.concatenate([np.ones(len(pw), np.int64), -np.ones(len(bq), np.int64)])
    s0, s1 = np.concatenate([s0, s0[bq]]), np.concatenate([s1, s1[bq]])
    M = np.zeros((2 * len(panel_wall), len(bnd["pos"])))
    for b, w, sd, arc, ds in zip(bnd["face_particle"], bnd["face_wall"], bnd["face_side"], bnd["face_arc"], bnd["face_ds"]):
        lo, hi = arc - ds / 2, arc + ds / 2
        for q in np.flatnonzero((panel_wall == w) & (panel_side == sd)):
            overlap = min(hi, s1[q]) - max(lo, s0[q])
            if overlap > 0:
                M[2 * q:2 * q + 2, b] += overlap * sd * nrm[w]
    bw, bs = bnd["wall"], bnd["side"]
    pitch = np.zeros(len(walls))  # the rows' spacing along each wall (its first row's stretches)
    pitch[bnd["face_wall"]] = bnd["face_ds"]
    half = 0.5 * pitch[bw]
    mid = np.clip(FO.dot2(bnd["pos"] - a[bw], t[bw]), half, L[bw] - half)
    share = np.zeros((len(panel_wall), len(bw)))
    for q in range(len(panel_wall)):
        on = (bw == panel_wall[q]) & (bs == panel_side[q])
        share[q, on] = np.clip(np.minimum(mid[on] + half[on], s1[q]) - np.maximum(mid[on] - half[on], s0[q]), 0.0, None)
    share /= share.sum(0)
    return panel_wall, panel_centre, panel_side, M, share


def assemble_particles(fluid_pos, walls, l0, layers=4, pressure_layers=2, thin=None):
    """All particles: fluid first, then the boundary.  Returns (pos, kind, bnd dict)."""
    bnd = wall_particles(walls, l0, layers, pressure_layers, thin)
    pos = np.concatenate([fluid_pos, bnd["pos"]])
    kind = np.concatenate([np.full(len(fluid_pos), FLUID, np.int64), bnd["kind"]])
    return pos, kind, bnd
