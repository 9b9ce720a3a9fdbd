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


@njit(inline="always", **JIT)
def track_max(fx, fy, fmax, finite):
    """Running max|F| = max(|Fx|, |Fy|) [N] and all-finite flag after one particle."""
    a = abs(fx)
    b = abs(fy)
    return max(fmax, a, b), finite & (a < np.inf) & (b < np.inf)  # False for NaN and inf


@njit(**JIT)
def push_pair(a, b, m, x, y):
    """Store (x, y) at index m of the int32 arrays (a, b), doubling them when full.
    Returns the (possibly new) arrays."""
    if m == a.shape[0]:
        a2 = np.empty(2 * m + 16, np.int32)
        b2 = np.empty(2 * m + 16, np.int32)
        a2[:m] = a[:m]
        b2[:m] = b[:m]
        a, b = a2, b2
    a[m] = x
    b[m] = y
    return a, b


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
                            pi, pj = push_pair(pi, pj, m, i, j)
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
    finite = True
    for i in range(n):
        fmax, finite = track_max(f[i, 0], f[i, 1], fmax, finite)
    if not finite:
        return np.nan
    return fmax


@njit(**JIT)
def crossed_wall(x0, y0, x1, y1, walls):
    """Index of the first wall the move (x0, y0) -> (x1, y1) crosses, or -1.

    A move crosses a wall when it passes from one side to the other, when it
    ends exactly on the wall (the wall's push has no side there), or when it
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


@njit(**JIT)
def _cell_rows(pos, box, rc, cpart, cstart, start, nbr):
    """The pair list of :func:`build_pairs`, in the same order, stored by rows.

    The particles are counting-sorted into the same cells; cpart (N,) int32
    receives them cell by cell (ascending within a cell, i.e. the order in
    which :func:`build_pairs` visits them), cstart (ncx ncy + 1,) int32 the
    cell boundaries in cpart.  Row q holds the pairs (cpart[q], nbr[k]) for
    start[q] <= k < start[q + 1], in :func:`build_pairs`' order.  nbr (cap,)
    int32 is reused and returned (grown when full); cstart is returned too
    (reallocated if the grid changed size).
    """
    n = pos.shape[0]
    ncx = max(1, int((box[2] - box[0]) / rc))
    ncy = max(1, int((box[3] - box[1]) / rc))
    csx = (box[2] - box[0]) / ncx
    csy = (box[3] - box[1]) / ncy
    nc = ncx * ncy
    if cstart.shape[0] != nc + 1:
        cstart = np.empty(nc + 1, np.int32)
    cstart[:] = 0
    cell = start[:n]  # scratch: start is rewritten below, after the cells are used
    for i in range(n):
        cx = min(ncx - 1, max(0, int((pos[i, 0] - box[0]) / csx)))
        cy = min(ncy - 1, max(0, int((pos[i, 1] - box[1]) / csy)))
        c = cy * ncx + cx
        cell[i] = c
        cstart[c + 1] += 1
    for c in range(nc):
        cstart[c + 1] += cstart[c]
    # stable fill: ascending particles within each cell
    for i in range(n):
        c = cell[i]
        cpart[cstart[c]] = i
        cstart[c] += 1
    for c in range(nc, 0, -1):
        cstart[c] = cstart[c - 1]
    cstart[0] = 0
    rc2 = rc * rc
    m = 0
    for cy in range(ncy):
        for cx in range(ncx):
            c = cy * ncx + cx
            for q in range(cstart[c], cstart[c + 1]):
                i = cpart[q]
                start[q] = m
                xi = pos[i, 0]
                yi = pos[i, 1]
                # half stencil: own cell (later entries), E, NW, N, NE
                for k in range(5):
                    if k == 0:
                        a = q + 1
                        b = cstart[c + 1]
                    else:
                        nx_ = cx + (1, -1, 0, 1)[k - 1]
                        ny_ = cy + (0, 1, 1, 1)[k - 1]
                        if nx_ < 0 or nx_ >= ncx or ny_ >= ncy:
                            continue
                        a = cstart[ny_ * ncx + nx_]
                        b = cstart[ny_ * ncx + nx_ + 1]
                    for r in range(a, b):
                        j = cpart[r]
                        dx = xi - pos[j, 0]
                        dy = yi - pos[j, 1]
                        if dx * dx + dy * dy < rc2:
                            if m == nbr.shape[0]:
                                grown = np.empty(2 * m + 16, np.int32)
                                grown[:m] = nbr[:m]
                                nbr = grown
                            nbr[m] = j
                            m += 1
    start[n] = m
    return nbr, cstart


@njit(**JIT)
def _wall_candidates(pos, walls, reach):
    """(particle, wall) int32 pairs, ascending, with the particle closer than reach to the wall."""
    n = pos.shape[0]
    nw = walls.shape[0]
    r2 = reach * reach
    ci = np.empty(64, np.int32)
    cw = np.empty(64, np.int32)
    c = 0
    for i in range(n):
        for w in range(nw):
            cx, cy = segment_closest(pos[i, 0], pos[i, 1], walls[w, 0], walls[w, 1], walls[w, 2], walls[w, 3])
            dx = pos[i, 0] - cx
            dy = pos[i, 1] - cy
            if dx * dx + dy * dy < r2:
                ci, cw = push_pair(ci, cw, c, i, w)
                c += 1
    return ci[:c], cw[:c]


@njit(**JIT)
def _move_init(ps, gs, scale, move, ws, walls, wl_u, wr_u, ci, cw, fs):
    """If move: ps += scale * gs.  Then fs = weight + wall forces at ps (one pass).

    Walls are taken from the candidate list (ci, cw) only: the other walls
    would add exact zeros, so fs is the same as in :func:`forces`.
    """
    n = ps.shape[0]
    c = 0
    nc = ci.shape[0]
    for q in range(n):
        if move:
            ps[q, 0] = ps[q, 0] + scale * gs[q, 0]
            ps[q, 1] = ps[q, 1] + scale * gs[q, 1]
        fx = 0.0
        fy = -ws[q]
        while c < nc and ci[c] == q:
            w = cw[c]
            gx, gy = wall_push(ps[q, 0], ps[q, 1], walls[w, 0], walls[w, 1], walls[w, 2], walls[w, 3], wl_u, wr_u)
            fx += gx
            fy += gy
            c += 1
        fs[q, 0] = fx
        fs[q, 1] = fy


@njit(**JIT)
def _pair_pass(ps, pl_u, pr_u, start, nbr, fs):
    """Add the pair forces of the row list to fs; returns max|F| as :func:`forces` does.

    Arrays are in list (cell) order: row q belongs to particle q.  Rows are
    visited in list order and each row's pairs in order, so every force
    component receives the same additions in the same order as in
    :func:`forces` with :func:`build_pairs`' list.  A row's particle is
    complete after its row (the rows that reach it come from its own cell,
    earlier entries, and from the cells W, SW, S, SE, which all come first),
    so max|F| is taken on the fly.
    """
    fmax = 0.0
    finite = True
    for q in range(ps.shape[0]):
        xi = ps[q, 0]
        yi = ps[q, 1]
        fx = fs[q, 0]
        fy = fs[q, 1]
        for k in range(start[q], start[q + 1]):
            j = nbr[k]
            gx, gy = pair_push(xi - ps[j, 0], yi - ps[j, 1], pl_u, pr_u)
            fx += gx
            fy += gy
            fs[j, 0] -= gx
            fs[j, 1] -= gy
        fs[q, 0] = fx
        fs[q, 1] = fy
        fmax, finite = track_max(fx, fy, fmax, finite)
    if not finite:
        return np.nan
    return fmax


@njit(**JIT)
def _first_crossing(ps, gs, scale, walls, cpart, ci, use_all):
    """(particle, wall) of the lowest-numbered particle whose move ps += scale * gs
    crosses a wall, or (-1, -1).  Only the candidates ci (list order) are
    tested unless use_all; particle numbers are the caller's (cpart[q])."""
    best = -1
    bw = -1
    last = -1
    for c in range(ps.shape[0] if use_all else ci.shape[0]):
        q = c if use_all else ci[c]
        if q == last:
            continue
        last = q
        i = cpart[q]
        if best >= 0 and i > best:
            continue
        w = crossed_wall(ps[q, 0], ps[q, 1], ps[q, 0] + scale * gs[q, 0], ps[q, 1] + scale * gs[q, 1], walls)
        if w >= 0:
            best = i
            bw = w
    return best, bw


@njit(**JIT)
def _sort_state(pos, vel, weight, cpart, nbr, m, inv, ps, vs, ws):
    """Gather the state into list order (ps, vs, ws) and renumber nbr[:m] to it."""
    for q in range(pos.shape[0]):
        i = cpart[q]
        inv[i] = q
        ps[q, 0] = pos[i, 0]
        ps[q, 1] = pos[i, 1]
        vs[q, 0] = vel[i, 0]
        vs[q, 1] = vel[i, 1]
        ws[q] = weight[i]
    for k in range(m):
        nbr[k] = inv[nbr[k]]


@njit(**JIT)
def _unsort(cpart, src, dst):
    """dst[cpart[q]] = src[q]."""
    for q in range(src.shape[0]):
        i = cpart[q]
        dst[i, 0] = src[q, 0]
        dst[i, 1] = src[q, 1]


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

    Implementation (results identical, to the last bit, to the plain loop
    "move; rebuild with :func:`build_pairs` if due; :func:`forces`"): the
    pair list is that of :func:`build_pairs`, in the same order, stored by
    rows, and the state is kept in that (cell) order between builds, so the
    passes stream through memory; the caller's arrays are written back on
    return.  The move and the weight + wall forces share one pass; wall
    forces and the crossing test only visit particles that were within
    wl_u + skin of a wall at the last build (no other particle can come
    within wl_u of a wall, or reach one, before the next build; if one step
    could reach farther, every particle is tested).
    """
    n = pos.shape[0]
    nw = walls.shape[0]
    rc = pl_u + skin
    reach = wl_u + skin
    cpart = np.empty(n, np.int32)
    inv = np.empty(n, np.int32)
    start = np.empty(n + 1, np.int32)
    ps = np.empty((n, 2))
    vs = np.empty((n, 2))
    fs = np.empty((n, 2))
    ws = np.empty(n)
    nbr, cstart = _cell_rows(pos, box, rc, cpart, np.empty(1, np.int32), start, np.empty(4 * n + 16, np.int32))
    _sort_state(pos, vel, weight, cpart, nbr, start[n], inv, ps, vs, ws)
    ci, cw = _wall_candidates(ps, walls, reach)
    moved = 0.0
    _move_init(ps, fs, 0.0, False, ws, walls, wl_u, wr_u, ci, cw, fs)
    fmax = _pair_pass(ps, pl_u, pr_u, start, nbr, fs)
    # FIRE state (Bitzek et al. 2006 default constants)
    dt = 0.1 * dt_max
    alpha = 0.1
    n_pos = 0
    status = RUNNING
    info = -1
    done = n_steps
    for step in range(n_steps):
        fmax_hist[step] = fmax
        if not np.isfinite(fmax):
            status = NONFINITE
            done = step
            break
        if fmax < f_tol:
            status = CONVERGED
            done = step
            break
        if variant == FIRE:
            # sums in the caller's particle order, as in the plain loop
            p = 0.0
            vn = 0.0
            fn = 0.0
            for i in range(n):
                q = inv[i]
                p += vs[q, 0] * fs[q, 0] + vs[q, 1] * fs[q, 1]
                vn += vs[q, 0] ** 2 + vs[q, 1] ** 2
                fn += fs[q, 0] ** 2 + fs[q, 1] ** 2
            if p > 0.0:
                c = alpha * np.sqrt(vn / fn)
                for q in range(n):
                    vs[q, 0] = (1.0 - alpha) * vs[q, 0] + c * fs[q, 0]
                    vs[q, 1] = (1.0 - alpha) * vs[q, 1] + c * fs[q, 1]
                n_pos += 1
                if n_pos > 5:
                    dt = min(1.1 * dt, dt_max)
                    alpha *= 0.99
            else:
                n_pos = 0
                dt *= 0.5
                alpha = 0.1
                vs[:, :] = 0.0
            # semi-implicit Euler with the step capped at du
            vmax = 0.0
            for q in range(n):
                vs[q, 0] += dt * fs[q, 0]
                vs[q, 1] += dt * fs[q, 1]
                vmax = max(vmax, abs(vs[q, 0]), abs(vs[q, 1]))
            scale = dt
            if vmax * dt > du:
                scale = du / vmax
            gs = vs
            inc = np.sqrt(2.0) * scale * vmax  # largest move this step
        else:
            scale = du / fmax if variant == PAPER else du / max(fmax, f_ref)
            gs = fs
            inc = np.sqrt(2.0) * (scale * fmax)
        # refuse any move across a wall (moved bounds every displacement since the build)
        i, w = _first_crossing(ps, gs, scale, walls, cpart, ci, not (moved + inc < reach))
        if i >= 0:  # tested before any particle moved: the step is not taken
            status = CROSSED
            info = i * nw + w
            done = step
            break
        moved += inc
        if moved > 0.5 * skin:
            for q in range(n):
                ps[q, 0] = ps[q, 0] + scale * gs[q, 0]
                ps[q, 1] = ps[q, 1] + scale * gs[q, 1]
            _unsort(cpart, ps, pos)
            _unsort(cpart, vs, vel)
            nbr, cstart = _cell_rows(pos, box, rc, cpart, cstart, start, nbr)
            _sort_state(pos, vel, weight, cpart, nbr, start[n], inv, ps, vs, ws)
            ci, cw = _wall_candidates(ps, walls, reach)
            moved = 0.0
            _move_init(ps, gs, scale, False, ws, walls, wl_u, wr_u, ci, cw, fs)
        else:
            _move_init(ps, gs, scale, True, ws, walls, wl_u, wr_u, ci, cw, fs)
        fmax = _pair_pass(ps, pl_u, pr_u, start, nbr, fs)
    _unsort(cpart, ps, pos)
    _unsort(cpart, vs, vel)
    _unsort(cpart, fs, f)
    return done, status, info


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

