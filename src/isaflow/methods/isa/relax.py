"""The compiled relaxation loop of incremental static analysis (numba).

Update rules (``rule`` argument of :func:`relax`):
- PAPER  : x += du F / max|F|                      (paper section 3.3, literal)
- CAPPED : x += du F / max(max|F|, f_ref)          (variant: the step stops
           growing in force units once max|F| < f_ref)
- FIRE   : FIRE (Bitzek et al., PRL 97, 170201, 2006) with unit masses, each
           move capped at du (variant).
Status codes: RUNNING, CONVERGED (max|F| < f_tol), NONFINITE (a position or
force is NaN or infinite), CROSSED (a step would carry a particle across a
wall; the step is not taken).  :func:`relax_resume` takes and returns the
restart state (list-build positions, moved bound, FIRE dt/alpha/n_pos).
"""

import numpy as np
from numba import njit

from ...core.geometry import crossed_wall, segment_closest
from ...core.neighbours import cell_rows, push_pair
from .forces import pair_push, track_max, wall_push

JIT = dict(cache=True, nogil=True)

PAPER, CAPPED, FIRE = 0, 1, 2
RUNNING, CONVERGED, NONFINITE, CROSSED = 0, 1, 2, 3
# FIRE constants (Bitzek et al. 2006): N_min, f_inc, f_dec, alpha_start, f_alpha
FIRE_N_MIN, FIRE_F_INC, FIRE_F_DEC, FIRE_ALPHA0, FIRE_F_ALPHA = 5, 1.1, 0.5, 0.1, 0.99


@njit(**JIT)
def _near_walls(pos, walls, reach):
    """(particle, wall) int32 pairs, ascending, with the particle closer than reach [cm] to the wall."""
    n = pos.shape[0]
    nw = walls.shape[0]
    r2 = reach * reach
    near_part = np.empty(64, np.int32)
    near_wall = np.empty(64, np.int32)
    c = 0
    for i in range(n):
        for w in range(nw):
            cx, cy = segment_closest(pos[i, 0], pos[i, 1], walls[w, 0], walls[w, 1], walls[w, 2], walls[w, 3])
            dx = pos[i, 0] - cx
            dy = pos[i, 1] - cy
            if dx * dx + dy * dy < r2:
                near_part, near_wall = push_pair(near_part, near_wall, c, i, w)
                c += 1
    return near_part[:c], near_wall[:c]


@njit(**JIT)
def _move_and_wall_forces(pos, direction, scale, move, weight, walls, wall_l_u, wall_r_u, near_part, near_wall, force,
                          wall_p=1.0):
    """If move: pos += scale * direction.  Then force = weight + wall forces at pos (one pass; wall law exponent wall_p).

    Walls are taken from the near-wall list only: the other walls would add
    exact zeros, so force is the same as in forces.forces.
    """
    n = pos.shape[0]
    c = 0
    nc = near_part.shape[0]
    for q in range(n):
        if move:
            pos[q, 0] = pos[q, 0] + scale * direction[q, 0]
            pos[q, 1] = pos[q, 1] + scale * direction[q, 1]
        fx = 0.0
        fy = -weight[q]
        while c < nc and near_part[c] == q:
            w = near_wall[c]
            gx, gy = wall_push(pos[q, 0], pos[q, 1], walls[w, 0], walls[w, 1], walls[w, 2], walls[w, 3],
                               wall_l_u, wall_r_u, wall_p)
            fx += gx
            fy += gy
            c += 1
        force[q, 0] = fx
        force[q, 1] = fy


@njit(**JIT)
def _pair_forces(pos, pair_l_u, pair_r_u, row_start, nbr, force, pair_p=1.0):
    """Add the pair forces of the row list to force (pair law exponent pair_p); returns (max|F| as forces.forces
    does, bad).

    bad: the first particle (cell order) whose position or force is NaN or
    infinite (then max|F| is NaN), else -1.  Positions are checked too: the
    force laws return finite forces for NaN distances (their "coincident"
    branch), so a force check alone would miss them.

    Row q holds particle q's pairs (q, nbr[k]) for row_start[q] <= k <
    row_start[q + 1], in the order of core.neighbours.build_pairs, so every
    force component receives the same additions in the same order as in
    forces.forces.  A row's particle is complete after its row (the rows that
    reach it come from its own cell, earlier entries, and from the cells W,
    SW, S, SE, which all come first), so max|F| is taken on the fly.
    """
    fmax = 0.0
    bad = -1
    for q in range(pos.shape[0]):
        xi = pos[q, 0]
        yi = pos[q, 1]
        fx = force[q, 0]
        fy = force[q, 1]
        for k in range(row_start[q], row_start[q + 1]):
            j = nbr[k]
            gx, gy = pair_push(xi - pos[j, 0], yi - pos[j, 1], pair_l_u, pair_r_u, pair_p)
            fx += gx
            fy += gy
            force[j, 0] -= gx
            force[j, 1] -= gy
        force[q, 0] = fx
        force[q, 1] = fy
        fmax, finite = track_max(fx, fy, fmax, (abs(xi) < np.inf) & (abs(yi) < np.inf))
        if not finite and bad < 0:
            bad = q
    if bad >= 0:
        return np.nan, bad
    return fmax, bad


@njit(**JIT)
def _first_crossing(pos, direction, scale, walls, order, near_part, test_all):
    """(particle, wall) of the lowest-numbered particle whose move pos += scale * direction
    crosses a wall, or (-1, -1).  Only near-wall particles are tested unless
    test_all; particle numbers are the caller's (order[q])."""
    best = -1
    best_wall = -1
    last = -1
    for c in range(pos.shape[0] if test_all else near_part.shape[0]):
        q = c if test_all else near_part[c]
        if q == last:
            continue
        last = q
        i = order[q]
        if best >= 0 and i > best:
            continue
        w = crossed_wall(pos[q, 0], pos[q, 1], pos[q, 0] + scale * direction[q, 0],
                         pos[q, 1] + scale * direction[q, 1], walls)
        if w >= 0:
            best = i
            best_wall = w
    return best, best_wall


@njit(**JIT)
def _to_cell_order(pos, vel, weight, order, nbr, m, rank, pos_c, vel_c, weight_c):
    """Gather the state into cell order (pos_c, vel_c, weight_c) and renumber nbr[:m] to it."""
    for q in range(pos.shape[0]):
        i = order[q]
        rank[i] = q
        pos_c[q, 0] = pos[i, 0]
        pos_c[q, 1] = pos[i, 1]
        vel_c[q, 0] = vel[i, 0]
        vel_c[q, 1] = vel[i, 1]
        weight_c[q] = weight[i]
    for k in range(m):
        nbr[k] = rank[nbr[k]]


@njit(**JIT)
def _to_caller_order(order, src, dst):
    """dst[order[q]] = src[q]."""
    for q in range(src.shape[0]):
        i = order[q]
        dst[i, 0] = src[q, 0]
        dst[i, 1] = src[q, 1]


@njit(**JIT)
def _fire_velocities(vel, force, rank, dt, dt_max, alpha, n_pos):
    """One FIRE velocity update (Bitzek et al. 2006) in place; returns (dt, alpha, n_pos).

    Power and norms are summed in the caller's particle order (rank maps it to
    cell order), as in a plain loop over particles.
    """
    n = vel.shape[0]
    power = 0.0
    vnorm2 = 0.0
    fnorm2 = 0.0
    for i in range(n):
        q = rank[i]
        power += vel[q, 0] * force[q, 0] + vel[q, 1] * force[q, 1]
        vnorm2 += vel[q, 0] ** 2 + vel[q, 1] ** 2
        fnorm2 += force[q, 0] ** 2 + force[q, 1] ** 2
    if power > 0.0:
        c = alpha * np.sqrt(vnorm2 / fnorm2)
        for q in range(n):
            vel[q, 0] = (1.0 - alpha) * vel[q, 0] + c * force[q, 0]
            vel[q, 1] = (1.0 - alpha) * vel[q, 1] + c * force[q, 1]
        n_pos += 1
        if n_pos > FIRE_N_MIN:
            dt = min(FIRE_F_INC * dt, dt_max)
            alpha *= FIRE_F_ALPHA
    else:
        n_pos = 0
        dt *= FIRE_F_DEC
        alpha = FIRE_ALPHA0
        vel[:, :] = 0.0
    return dt, alpha, n_pos


@njit(**JIT)
def relax(pos, vel, weight, walls, box, wall_l_u, wall_r_u, pair_l_u, pair_r_u, rule, du, f_ref,
          dt_max, f_tol, n_steps, skin, force, fmax_hist, wall_p=1.0, pair_p=1.0):
    """One chunk from a fresh start (neighbour list built from pos, FIRE reset); see :func:`relax_resume`.

    Returns (steps_done, status, crossing).
    """
    state = np.zeros(5)
    return relax_resume(pos, vel, weight, walls, box, wall_l_u, wall_r_u, pair_l_u, pair_r_u, rule, du, f_ref,
                        dt_max, f_tol, n_steps, skin, force, fmax_hist, np.empty_like(pos), state, False, wall_p,
                        pair_p)


@njit(**JIT)
def relax_resume(pos, vel, weight, walls, box, wall_l_u, wall_r_u, pair_l_u, pair_r_u, rule, du, f_ref,
                 dt_max, f_tol, n_steps, skin, force, fmax_hist, pos_build, state, resume, wall_p=1.0, pair_p=1.0):
    """Run up to n_steps relaxation steps in place; the whole loop is compiled.

    pos (N, 2) cm, vel (N, 2) (FIRE velocities), weight (N,) N, walls (W, 4) cm,
    box (4,) cm of the cell grid.  force (N, 2) receives the final
    out-of-balance forces [N]; fmax_hist[k] the max|F| [N] *before* step k.
    A neighbour list with cutoff pair_l_u + skin is rebuilt whenever particles
    may have moved skin / 2 since the last build.  Returns (steps_done,
    status, crossing): crossing = particle * W + wall for CROSSED, the first
    non-finite particle for NONFINITE, else -1.

    Restart state (in and out): pos_build (N, 2) cm, the positions at the
    last list build, and state (4,) = (moved bound since that build [cm],
    FIRE dt [s], alpha, n_pos); a fifth entry, if state has one, receives the
    largest displacement component [cm] of any particle in any step of this
    call (not restart state).  wall_p, pair_p: the force laws' exponents
    (forces.law_over_d; 1 = linear).  resume=False is a fresh start: the list is
    built from pos, moved = 0 and FIRE is reset (dt = dt_max / 10).
    resume=True rebuilds the list from pos_build and continues with the
    given state, so a run split anywhere repeats the unsplit run bit for bit.

    Implementation (results identical, to the last bit, to the plain loop
    "move; rebuild with build_pairs if due; forces.forces"): the pair list is
    build_pairs' list in the same order, stored by rows (core.neighbours.
    cell_rows), and the state is kept in that cell order between builds, so
    the passes stream through memory; the caller's arrays are written back on
    return.  The move and the weight + wall forces share one pass; wall
    forces and the crossing test only visit particles that were within
    wall_l_u + skin of a wall at the last build (no other particle can come
    within wall_l_u of a wall, or reach one, before the next build; if one
    step could reach farther, every particle is tested).
    """
    n = pos.shape[0]
    nw = walls.shape[0]
    rc = pair_l_u + skin
    reach = wall_l_u + skin
    order = np.empty(n, np.int32)  # order[q]: caller's index of the q-th particle in cell order
    rank = np.empty(n, np.int32)  # inverse of order
    row_start = np.empty(n + 1, np.int32)
    pos_c = np.empty((n, 2))
    vel_c = np.empty((n, 2))
    force_c = np.empty((n, 2))
    weight_c = np.empty(n)
    if not resume:
        pos_build[:, :] = pos
    nbr, cstart = cell_rows(pos_build, box, rc, order, np.empty(1, np.int32), row_start,
                            np.empty(4 * n + 16, np.int32))
    _to_cell_order(pos_build, vel, weight, order, nbr, row_start[n], rank, pos_c, vel_c, weight_c)
    near_part, near_wall = _near_walls(pos_c, walls, reach)
    if resume:
        for q in range(n):
            pos_c[q, 0] = pos[order[q], 0]
            pos_c[q, 1] = pos[order[q], 1]
        moved, dt, alpha, n_pos = state[0], state[1], state[2], int(state[3])
    else:
        moved, dt, alpha, n_pos = 0.0, 0.1 * dt_max, FIRE_ALPHA0, 0  # moved: bound on any displacement, cm
    _move_and_wall_forces(pos_c, force_c, 0.0, False, weight_c, walls, wall_l_u, wall_r_u, near_part, near_wall,
                          force_c, wall_p)
    fmax, bad = _pair_forces(pos_c, pair_l_u, pair_r_u, row_start, nbr, force_c, pair_p)
    status = RUNNING
    step_move = 0.0
    crossing = -1
    done = n_steps
    for step in range(n_steps + 1):
        if step < n_steps:
            fmax_hist[step] = fmax
        if bad >= 0:
            status = NONFINITE
            crossing = order[bad]
            done = step
            break
        if step == n_steps:
            break
        if fmax < f_tol:
            status = CONVERGED
            done = step
            break
        if rule == FIRE:
            dt, alpha, n_pos = _fire_velocities(vel_c, force_c, rank, dt, dt_max, alpha, n_pos)
            # semi-implicit Euler with the step capped at du
            vmax = 0.0
            for q in range(n):
                vel_c[q, 0] += dt * force_c[q, 0]
                vel_c[q, 1] += dt * force_c[q, 1]
                vmax = max(vmax, abs(vel_c[q, 0]), abs(vel_c[q, 1]))
            scale = dt
            if vmax * dt > du:
                scale = du / vmax
            direction = vel_c
            max_move = np.sqrt(2.0) * scale * vmax
            step_move = max(step_move, scale * vmax)
        else:
            scale = du / fmax if rule == PAPER else du / max(fmax, f_ref)
            direction = force_c
            max_move = np.sqrt(2.0) * (scale * fmax)
            step_move = max(step_move, scale * fmax)
        # refuse any move across a wall
        i, w = _first_crossing(pos_c, direction, scale, walls, order, near_part, not (moved + max_move < reach))
        if i >= 0:  # tested before any particle moved: the step is not taken
            status = CROSSED
            crossing = i * nw + w
            done = step
            break
        moved += max_move
        if moved > 0.5 * skin:
            for q in range(n):
                pos_c[q, 0] = pos_c[q, 0] + scale * direction[q, 0]
                pos_c[q, 1] = pos_c[q, 1] + scale * direction[q, 1]
            _to_caller_order(order, pos_c, pos)
            _to_caller_order(order, vel_c, vel)
            pos_build[:, :] = pos
            nbr, cstart = cell_rows(pos, box, rc, order, cstart, row_start, nbr)
            _to_cell_order(pos, vel, weight, order, nbr, row_start[n], rank, pos_c, vel_c, weight_c)
            near_part, near_wall = _near_walls(pos_c, walls, reach)
            moved = 0.0
            _move_and_wall_forces(pos_c, direction, scale, False, weight_c, walls, wall_l_u, wall_r_u, near_part,
                                  near_wall, force_c, wall_p)
        else:
            _move_and_wall_forces(pos_c, direction, scale, True, weight_c, walls, wall_l_u, wall_r_u, near_part,
                                  near_wall, force_c, wall_p)
        fmax, bad = _pair_forces(pos_c, pair_l_u, pair_r_u, row_start, nbr, force_c, pair_p)
    _to_caller_order(order, pos_c, pos)
    _to_caller_order(order, vel_c, vel)
    _to_caller_order(order, force_c, force)
    state[0], state[1], state[2], state[3] = moved, dt, alpha, n_pos
    if state.shape[0] > 4:
        state[4] = step_move
    return done, status, crossing
