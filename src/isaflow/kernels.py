"""Compiled physics kernels: forces, neighbour lists and the relaxation loop.

Unit system (whole package): length cm, force N, stiffness N/cm.
Arrays: ``pos`` (N, 2) float64 [cm]; ``weight`` (N,) float64 [N];
``walls`` (W, 4) float64 rows ``x0, y0, x1, y1`` [cm].

Force laws are linear and repulsive (paper Fig. 1c, 1d):
``R(l) = r_u * (1 - l / l_u)`` for ``l < l_u``, else 0, so the stiffness is
``r_u / l_u``.  Kernels take scalars and arrays only: no config, no I/O.
"""

import numpy as np
from numba import njit

JIT = dict(cache=True, nogil=True)

# update rules (``variant`` argument of :func:`relax`)
PAPER, CAPPED, FIRE = 0, 1, 2

# status codes returned by :func:`relax`
RUNNING, CONVERGED, NONFINITE, CROSSED = 0, 1, 2, 3


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
def wall_push(px, py, x0, y0, x1, y1, l_u, r_u):
    """Force (fx, fy) [N] of wall segment on a particle at (px, py).

    Uses the true point-to-segment distance, so near a segment end the force
    is radial from that end.  A particle exactly on the wall is pushed along
    the wall's left normal (walls are oriented with the liquid on their left).
    """
    cx, cy = segment_closest(px, py, x0, y0, x1, y1)
    dx = px - cx
    dy = py - cy
    d2 = dx * dx + dy * dy
    if d2 >= l_u * l_u:
        return 0.0, 0.0
    d = np.sqrt(d2)
    if d > 0.0:
        s = r_u * (1.0 / d - 1.0 / l_u)  # R(d) / d
        return s * dx, s * dy
    ex = x1 - x0
    ey = y1 - y0
    L = np.sqrt(ex * ex + ey * ey)
    return -r_u * ey / L, r_u * ex / L


@njit(**JIT)
def pair_push(dx, dy, l_u, r_u):
    """Force (fx, fy) [N] on particle i from j, with (dx, dy) = x_i - x_j.

    Coincident particles are pushed apart along +x (i) / -x (j).
    """
    d2 = dx * dx + dy * dy
    if d2 >= l_u * l_u:
        return 0.0, 0.0
    d = np.sqrt(d2)
    if d > 0.0:
        s = r_u * (1.0 / d - 1.0 / l_u)
        return s * dx, s * dy
    return r_u, 0.0


@njit(**JIT)
def build_pairs(pos, box, rc):
    """Half neighbour list of all pairs closer than ``rc`` via a cell list.

    box: (4,) ``xmin, ymin, xmax, ymax`` [cm] of the cell grid (particles
    outside are clamped into edge cells, which stays correct, only slower).
    Returns (pi, pj, m): int32 arrays whose first m entries are the pairs.
    O(N) for bounded density.
    """
    n = pos.shape[0]
    ncx = max(1, int((box[2] - box[0]) / rc))
    ncy = max(1, int((box[3] - box[1]) / rc))
    csx = (box[2] - box[0]) / ncx
    csy = (box[3] - box[1]) / ncy
    head = np.full(ncx * ncy, -1, np.int64)
    nxt = np.empty(n, np.int64)
    for i in range(n - 1, -1, -1):
        cx = min(ncx - 1, max(0, int((pos[i, 0] - box[0]) / csx)))
        cy = min(ncy - 1, max(0, int((pos[i, 1] - box[1]) / csy)))
        c = cy * ncx + cx
        nxt[i] = head[c]
        head[c] = i
    cap = 8 * n + 16
    pi = np.empty(cap, np.int32)
    pj = np.empty(cap, np.int32)
    rc2 = rc * rc
    m = 0
    for cy in range(ncy):
        for cx in range(ncx):
            i = head[cy * ncx + cx]
            while i >= 0:
                xi = pos[i, 0]
                yi = pos[i, 1]
                # half stencil: own cell (later entries), E, NW, N, NE
                for k in range(5):
                    if k == 0:
                        j = nxt[i]
                    else:
                        ox = (1, -1, 0, 1)[k - 1]
                        nx_ = cx + ox
                        ny_ = cy + (0, 1, 1, 1)[k - 1]
                        if nx_ < 0 or nx_ >= ncx or ny_ >= ncy:
                            continue
                        j = head[ny_ * ncx + nx_]
                    while j >= 0:
                        dx = xi - pos[j, 0]
                        dy = yi - pos[j, 1]
                        if dx * dx + dy * dy < rc2:
                            if m == cap:
                                cap *= 2
                                pi2 = np.empty(cap, np.int32)
                                pj2 = np.empty(cap, np.int32)
                                pi2[:m] = pi[:m]
                                pj2[:m] = pj[:m]
                                pi = pi2
                                pj = pj2
                            pi[m] = i
                            pj[m] = j
                            m += 1
                        j = nxt[j]
                i = nxt[i]
    return pi, pj, m


@njit(**JIT)
def forces(pos, weight, walls, wl_u, wr_u, pl_u, pr_u, pi, pj, m, f):
    """Out-of-balance forces f (N, 2) [N] = weight + wall + pair forces.

    Pairs are taken from the first m entries of the neighbour list (pi, pj).
    Returns max|F| = max over particles of max(|Fx|, |Fy|) (paper §3.3);
    NaN if any force is non-finite.
    """
    n = pos.shape[0]
    for i in range(n):
        fx = 0.0
        fy = -weight[i]
        px = pos[i, 0]
        py = pos[i, 1]
        for w in range(walls.shape[0]):
            gx, gy = wall_push(px, py, walls[w, 0], walls[w, 1], walls[w, 2], walls[w, 3], wl_u, wr_u)
            fx += gx
            fy += gy
        f[i, 0] = fx
        f[i, 1] = fy
    for k in range(m):
        i = pi[k]
        j = pj[k]
        gx, gy = pair_push(pos[i, 0] - pos[j, 0], pos[i, 1] - pos[j, 1], pl_u, pr_u)
        f[i, 0] += gx
        f[i, 1] += gy
        f[j, 0] -= gx
        f[j, 1] -= gy
    fmax = 0.0
    check = 0.0
    for i in range(n):
        a = abs(f[i, 0])
        b = abs(f[i, 1])
        check += a + b
        if a > fmax:
            fmax = a
        if b > fmax:
            fmax = b
    if not np.isfinite(check):
        return np.nan
    return fmax


@njit(**JIT)
def crossed_wall(x0, y0, x1, y1, walls):
    """Index of the first wall the move (x0, y0) -> (x1, y1) crosses, or -1."""
    for w in range(walls.shape[0]):
        ax = walls[w, 0]
        ay = walls[w, 1]
        ex = walls[w, 2] - ax
        ey = walls[w, 3] - ay
        s0 = ex * (y0 - ay) - ey * (x0 - ax)
        s1 = ex * (y1 - ay) - ey * (x1 - ax)
        if s0 * s1 < 0.0:
            # sides of the wall's end points relative to the move
            mx = x1 - x0
            my = y1 - y0
            t0 = mx * (ay - y0) - my * (ax - x0)
            t1 = mx * (walls[w, 3] - y0) - my * (walls[w, 2] - x0)
            if t0 * t1 <= 0.0:
                return w
    return -1


@njit(**JIT)
def relax(pos, vel, weight, walls, box, wl_u, wr_u, pl_u, pr_u, variant, du, f_ref,
          dt_max, f_tol, n_steps, skin, f, fmax_hist):
    """Run up to n_steps relaxation steps in place; the whole loop is compiled.

    variant PAPER  : x += du * F / max|F|                      (paper §3.3)
    variant CAPPED : x += du * F / max(max|F|, f_ref)          (step stops
                     growing in force units once max|F| < f_ref)
    variant FIRE   : FIRE (Bitzek et al. 2006) with unit masses; dt_max is its
                     largest pseudo time step, capped so no particle moves
                     more than du per step; vel (N, 2) carries its velocities.
    f (N, 2) receives the final out-of-balance forces [N]; fmax_hist[k] the
    max|F| [N] *before* step k.  A neighbour list with cutoff pl_u + skin is
    rebuilt whenever particles may have moved skin / 2 since the last build.
    Returns (steps_done, status, info): status CONVERGED when max|F| < f_tol,
    NONFINITE on NaN/inf, CROSSED if a step would carry a particle across a
    wall (info = particle * W + wall; the step is not taken); else RUNNING.
    """
    n = pos.shape[0]
    pi, pj, m = build_pairs(pos, box, pl_u + skin)
    moved = 0.0
    fmax = forces(pos, weight, walls, wl_u, wr_u, pl_u, pr_u, pi, pj, m, f)
    # FIRE state (Bitzek et al. 2006 default constants)
    dt = 0.1 * dt_max
    alpha = 0.1
    n_pos = 0
    for step in range(n_steps):
        fmax_hist[step] = fmax
        if not np.isfinite(fmax):
            return step, NONFINITE, -1
        if fmax < f_tol:
            return step, CONVERGED, -1
        if variant == FIRE:
            p = 0.0
            vn = 0.0
            fn = 0.0
            for i in range(n):
                p += vel[i, 0] * f[i, 0] + vel[i, 1] * f[i, 1]
                vn += vel[i, 0] ** 2 + vel[i, 1] ** 2
                fn += f[i, 0] ** 2 + f[i, 1] ** 2
            if p > 0.0:
                c = alpha * np.sqrt(vn / fn)
                for i in range(n):
                    vel[i, 0] = (1.0 - alpha) * vel[i, 0] + c * f[i, 0]
                    vel[i, 1] = (1.0 - alpha) * vel[i, 1] + c * f[i, 1]
                n_pos += 1
                if n_pos > 5:
                    dt = min(1.1 * dt, dt_max)
                    alpha *= 0.99
            else:
                n_pos = 0
                dt *= 0.5
                alpha = 0.1
                vel[:, :] = 0.0
            # semi-implicit Euler with the step capped at du
            vmax = 0.0
            for i in range(n):
                vel[i, 0] += dt * f[i, 0]
                vel[i, 1] += dt * f[i, 1]
                vmax = max(vmax, abs(vel[i, 0]), abs(vel[i, 1]))
            scale = dt
            if vmax * dt > du:
                scale = du / vmax
            sx = 0.0
            sy = 0.0
        else:
            scale = du / fmax if variant == PAPER else du / max(fmax, f_ref)
        # move, refusing any move across a wall
        for i in range(n):
            if variant == FIRE:
                sx = scale * vel[i, 0]
                sy = scale * vel[i, 1]
            else:
                sx = scale * f[i, 0]
                sy = scale * f[i, 1]
            x1 = pos[i, 0] + sx
            y1 = pos[i, 1] + sy
            w = crossed_wall(pos[i, 0], pos[i, 1], x1, y1, walls)
            if w >= 0:
                for k in range(i):  # undo: the step is not taken
                    g = vel if variant == FIRE else f
                    pos[k, 0] -= scale * g[k, 0]
                    pos[k, 1] -= scale * g[k, 1]
                return step, CROSSED, i * walls.shape[0] + w
            pos[i, 0] = x1
            pos[i, 1] = y1
        moved += np.sqrt(2.0) * (du if variant == FIRE else scale * fmax)
        if moved > 0.5 * skin:
            pi, pj, m = build_pairs(pos, box, pl_u + skin)
            moved = 0.0
        fmax = forces(pos, weight, walls, wl_u, wr_u, pl_u, pr_u, pi, pj, m, f)
    return n_steps, RUNNING, -1


@njit(**JIT)
def wall_contacts(pos, walls, l_u, r_u):
    """All wall-particle contacts with a non-zero force.

    Returns (particle (C,) int64, wall (C,) int64, point (C, 2) [cm] closest
    point on the wall, force (C, 2) [N] exerted by the wall on the particle).
    """
    n = pos.shape[0]
    nw = walls.shape[0]
    c = 0
    for i in range(n):
        for w in range(nw):
            gx, gy = wall_push(pos[i, 0], pos[i, 1], walls[w, 0], walls[w, 1], walls[w, 2], walls[w, 3], l_u, r_u)
            if gx != 0.0 or gy != 0.0:
                c += 1
    part = np.empty(c, np.int64)
    wall = np.empty(c, np.int64)
    point = np.empty((c, 2))
    force = np.empty((c, 2))
    c = 0
    for i in range(n):
        for w in range(nw):
            gx, gy = wall_push(pos[i, 0], pos[i, 1], walls[w, 0], walls[w, 1], walls[w, 2], walls[w, 3], l_u, r_u)
            if gx != 0.0 or gy != 0.0:
                cx, cy = segment_closest(pos[i, 0], pos[i, 1], walls[w, 0], walls[w, 1], walls[w, 2], walls[w, 3])
                part[c] = i
                wall[c] = w
                point[c, 0] = cx
                point[c, 1] = cy
                force[c, 0] = gx
                force[c, 1] = gy
                c += 1
    return part, wall, point, force
