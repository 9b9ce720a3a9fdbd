"""Wall panels: how a continuum method (SPH, MPS) reports wall loads as contacts.

Each wall is cut into panels of equal length, their count rounded so that the
length is as close to ``length`` as possible.  A
method integrates the force its wall exerts on the liquid over each panel and
reports one contact per panel, at the panel's centre.  With contacts at panel
centres, theory.contact_theory's tributary lengths are exactly the panels, so
per-panel hydrostatic theory and per-contact theory are the same rule.
"""

import numpy as np


def wall_panels(walls, length):
    """Panels of every wall, about ``length`` cm long.

    walls (W, 4) cm.  Returns (wall (P,) int, centre (P, 2) cm, s0 (P,) cm,
    s1 (P,) cm): the wall of each panel, its centre, and its extent as arc
    length from the wall's start point.
    """
    walls = np.asarray(walls, float)
    wall, centre, s0, s1 = [], [], [], []
    for w, (x0, y0, x1, y1) in enumerate(walls):
        L = np.hypot(x1 - x0, y1 - y0)
        n = max(1, int(round(L / length)))
        edges = np.linspace(0.0, L, n + 1)
        mid = 0.5 * (edges[1:] + edges[:-1])
        t = mid / L
        wall.append(np.full(n, w))
        centre.append(np.column_stack([x0 + t * (x1 - x0), y0 + t * (y1 - y0)]))
        s0.append(edges[:-1])
        s1.append(edges[1:])
    return np.concatenate(wall), np.concatenate(centre), np.concatenate(s0), np.concatenate(s1)


def bin_to_panels(walls, length, wall_idx, points, forces):
    """Sum point forces (C, 2) [N] acting on walls at points (C, 2) [cm] into panels.

    wall_idx (C,) int: the wall each force acts on.  Returns the
    (wall, centre, force (P, 2)) contacts of :func:`wall_panels`, force summed
    over the points that fall in each panel (by arc length along the wall).
    """
    walls = np.asarray(walls, float)
    pw, pc, s0, s1 = wall_panels(walls, length)
    out = np.zeros((len(pw), 2))
    wall_idx = np.asarray(wall_idx, int)
    points = np.asarray(points, float)
    forces = np.asarray(forces, float)
    for w, (x0, y0, x1, y1) in enumerate(walls):
        mine = np.flatnonzero(wall_idx == w)
        if len(mine) == 0:
            continue
        L = np.hypot(x1 - x0, y1 - y0)
        s = ((points[mine, 0] - x0) * (x1 - x0) + (points[mine, 1] - y0) * (y1 - y0)) / L
        panels = np.flatnonzero(pw == w)
        k = np.clip(np.searchsorted(s1[panels], s, side="right"), 0, len(panels) - 1)
        np.add.at(out, panels[k], forces[mine])
    return pw, pc, out
