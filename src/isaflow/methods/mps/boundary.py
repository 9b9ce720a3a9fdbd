"""Wall and dummy particles of a tank, the initial liquid block, and wall loads on panels.

Walls (W, 4) cm, each oriented with the liquid on its left.  Every wall gets
``layers`` rows of particles behind it at (k + 1/2) l0 (k < pressure_layers:
WALL particles in the pressure equation and the gradient; further rows: DUMMY
particles for the number density only, as MPS-Basic's generators), so
that the liquid's cells [0, l0]^2 tile the vessel exactly and a first-layer
particle faces l0 of wall.  Rows are extended past an end joined to another
wall (corners), and candidates on the liquid side of another wall are dropped.
"""

import numpy as np
from scipy.spatial import cKDTree

from isaflow.core.panels import wall_panels

from .model import DUMMY, FLUID, WALL


def _frames(walls):
    """Start points (W, 2), lengths (W,), unit tangents (W, 2), liquid-side normals (W, 2)."""
    a = walls[:, :2]
    e = walls[:, 2:] - a
    L = np.hypot(e[:, 0], e[:, 1])
    t = e / L[:, None]
    return a, L, t, np.column_stack([-t[:, 1], t[:, 0]])


def wall_particles(walls, l0, layers=3, pressure_layers=1):
    """Boundary particles of the walls.

    layers: rows in all, pressure_layers of them WALL.
    Returns dict: pos (M, 2) cm, kind (M,) WALL/DUMMY, wall (M,) wall index;
    and the stretches of wall the first row faces: face_particle (F,) the
    particle, face_wall (F,), face_arc (F,) cm centre along the wall,
    face_ds (F,) cm length (a corner particle can face two walls).
    """
    walls = np.asarray(walls, float)
    a, L, t, nrm = _frames(walls)
    ends = np.concatenate([walls[:, :2], walls[:, 2:]])
    cand = []  # (x, y, kind, wall, arc, ds)
    for k in range(layers):
        for w in range(len(walls)):
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
            p = a[w] + s[:, None] * t[w] - (k + 0.5) * l0 * nrm[w]
            for q, sq, f in zip(p, s, faces):
                cand.append((q[0], q[1], WALL if k < pressure_layers else DUMMY, w, sq, f))
    cand = np.array(cand)
    keep = np.ones(len(cand), bool)
    reach = layers * l0
    for w in range(len(walls)):  # drop candidates in front of another wall
        rel = cand[:, :2] - a[w]
        s = rel @ t[w]
        d = rel @ nrm[w]
        keep &= ~((d > 1e-9) & (d < reach) & (s > -1e-9) & (s < L[w] + 1e-9) & (cand[:, 3] != w))
    cand = cand[keep]
    cand_w, cand_s, cand_ds = cand[:, 3].astype(np.int64), cand[:, 4], cand[:, 5]
    tree = cKDTree(cand[:, :2])
    drop = np.zeros(len(cand), bool)
    for i, j in sorted(tree.query_pairs(0.5 * l0)):  # keep the earlier (lower layer) candidate
        if not drop[i]:
            drop[j] = True
    kept = np.flatnonzero(~drop)
    # a dropped first-row candidate's stretch of wall is faced by the kept particle that replaced it (corners)
    _, owner = cKDTree(cand[kept, :2]).query(cand[:, :2])
    faces = np.flatnonzero(cand[:, 5] > 0)
    cand = cand[kept]
    return dict(pos=cand[:, :2].copy(), kind=cand[:, 2].astype(np.int64), wall=cand[:, 3].astype(np.int64),
                face_particle=owner[faces], face_wall=cand_w[faces], face_arc=cand_s[faces], face_ds=cand_ds[faces])


def liquid_block(x_range, floor_y, depth, l0):
    """(N, 2) cm square lattice filling [x0, x1] x [floor_y, floor_y + rows l0], rows = round(depth / l0)."""
    cols = int(round((x_range[1] - x_range[0]) / l0))
    rows = max(1, int(round(depth / l0)))
    dx = (x_range[1] - x_range[0]) / cols
    x = x_range[0] + (np.arange(cols) + 0.5) * dx
    y = floor_y + (np.arange(rows) + 0.5) * l0
    X, Y = np.meshgrid(x, y)
    return np.column_stack([X.ravel(), Y.ravel()])


def load_map(walls, bnd, panel_length):
    """Linear map from first-layer wall-particle pressures to panel forces.

    Each WALL particle carries its pressure over the wall length it faces
    (arc +- ds / 2), split between panels by overlap; the force on the liquid
    is P x length along the wall's liquid-side normal.  Returns (panel_wall
    (P,), panel_centre (P, 2) cm, M (2P, Nb) with force = (M @ P_bnd).reshape(P, 2)
    in N when P is in N/cm^2 (2D: per cm of thickness).
    """
    walls = np.asarray(walls, float)
    _, _, _, nrm = _frames(walls)
    pw, pc, s0, s1 = wall_panels(walls, panel_length)
    M = np.zeros((2 * len(pw), len(bnd["pos"])))
    for b, w, arc, ds in zip(bnd["face_particle"], bnd["face_wall"], bnd["face_arc"], bnd["face_ds"]):
        lo, hi = arc - ds / 2, arc + ds / 2
        for q in np.flatnonzero(pw == w):
            overlap = min(hi, s1[q]) - max(lo, s0[q])
            if overlap > 0:
                M[2 * q:2 * q + 2, b] += overlap * nrm[w]
    return pw, pc, M


def assemble_particles(fluid_pos, walls, l0, layers=3, pressure_layers=1):
    """All particles: fluid first, then the boundary.  Returns (pos, kind, bnd dict)."""
    bnd = wall_particles(walls, l0, layers, pressure_layers)
    pos = np.concatenate([fluid_pos, bnd["pos"]])
    kind = np.concatenate([np.full(len(fluid_pos), FLUID, np.int64), bnd["kind"]])
    return pos, kind, bnd
