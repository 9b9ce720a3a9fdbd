"""The overdamped variant (not the paper's): the ISA particles as a damped dynamical system (numba).

The same particles, weights and force laws as the paper's update, given masses m = w / g and a
viscous drag on their absolute velocity:

    m x'' = F(x) - c x',   c = 2 zeta sqrt(m lambda_max),

F the out-of-balance force of the paper (weight + wall + pair laws, section 3), lambda_max [N/cm] the
stiffest mode of the equilibrium and zeta its damping ratio (every softer mode is more than critically
damped for zeta >= 1).  This is "dynamic behavior with strong damping" made explicit, so the paper's
update (a static analysis said to approximate it, abstract and section 7) can be compared with it on a
common normalised time axis.

Integration (per step of dt [s]): v <- (v + dt F / m) / (1 + dt c / m) (the drag implicit, so a large
zeta cannot destabilise it), x <- x + dt v; linearly stable on a mode of frequency w iff
(dt w)^2 < 4 + 4 z dt w (settings.overdamped_dt takes half that limit on the Gershgorin bound).

The stop: max|F| < f_tol (the paper's equilibrium criterion on the same forces) while the liquid is at
rest by the project's one criterion (config/rest.yaml, isaflow.rest): e = KE / (W h) below
``e_limit`` at every step of the last ``window`` seconds.

The step loop reuses relax.py's kernels (its start, list rebuilds and write-back, cell-ordered pair
rows, near-wall lists, the wall-crossing test), so forces are evaluated exactly as for the other update
rules.  Units: cm, N, s; mass N s^2/cm.
"""

import numpy as np
from ...core.jit import njit

from .relax import (CONVERGED, CROSSED, NONFINITE, RUNNING, _evaluate, _finish, _first_crossing, _move_and_rebuild,
                    _start)

JIT = dict(cache=True, nogil=True)

OVERDAMPED = 3  # settings.RULE_IDS["overdamped"]


@njit(**JIT)
def _kinetic(rank, weight_c, vel_c, g):
    """Kinetic energy [N cm] of the particles (cell order, masses weight_c / g), summed in the caller's order."""
    ke = 0.0
    for i in range(rank.shape[0]):
        q = rank[i]
        ke += 0.5 * weight_c[q] / g * (vel_c[q, 0] ** 2 + vel_c[q, 1] ** 2)
    return ke


@njit(**JIT)
def overdamped_resume(pos, vel, weight, walls, box, wall_l_u, wall_r_u, pair_l_u, pair_r_u, dt, zeta, lambda_max,
                      g, f_tol, e_limit, e_norm, window, n_steps, skin, force, fmax_hist, ke_hist, pos_build, state,
                      resume, wall_p=1.0, pair_p=1.0):
    """Run up to n_steps time steps of the overdamped dynamics in place (module docstring).

    pos (N, 2) cm, vel (N, 2) cm/s, weight (N,) N (masses weight / g, g in cm/s^2), walls (W, 4) cm, box (4,)
    cm of the cell grid; dt s; zeta, lambda_max N/cm set the drag c = 2 zeta sqrt(m lambda_max) N s/cm of each
    particle; f_tol N; the rest test e = KE / e_norm < e_limit over window s (e_norm = W h, N cm).
    force (N, 2) receives the final out-of-balance forces [N] (no drag); fmax_hist[k] and ke_hist[k] the max|F|
    [N] and kinetic energy [N cm] *before* step k.

    Restart state (in and out): pos_build (N, 2) cm, the positions at the last list build, and state (5,) =
    (moved bound since that build [cm], simulated time t [s], start of the current quiet stretch [s] (-1: none),
    unused, largest displacement component of any particle in any step of this call [cm]).  resume=False builds
    the list from pos and sets moved = 0; t and the quiet stretch always continue from state.

    Returns (steps_done, status, crossing) as relax.relax_resume.
    """
    n = pos.shape[0]
    nw = walls.shape[0]
    rc = pair_l_u + skin
    reach = wall_l_u + skin
    serial = np.int64(1)  # one block, typed int64 as relax_resume passes it (a literal 1 compiles a second overload)
    # the serial pass's block scratch (relax._evaluate, _first_crossing with nb = 1)
    one_b, one_w, one_bad, fmax_b, none = (np.empty(1, np.int64), np.empty(1, np.int64), np.empty(1, np.int64),
                                           np.empty(1), np.empty(0))
    (order, rank, row_start, near_start, pos_c, new_c, vel_c, force_c, force_n, weight_c, halo, nbr, cstart, owner,
     gx, gy, near_part, near_wall) = _start(pos, vel, weight, pos_build, resume, box, rc, walls, reach, serial)
    moved = state[0] if resume else 0.0
    t = state[1]
    quiet = state[2]
    move = n < 0  # False, computed (relax_resume's one specialisation of _evaluate)
    fire = move  # no FIRE sums: False, computed for the same reason
    ke = _kinetic(rank, weight_c, vel_c, g)
    status = RUNNING
    crossing = -1
    done = n_steps
    step_move = 0.0
    step = -1
    while True:  # evaluate at the new positions, then test and step
        fmax, bad = _evaluate(serial, halo, pos_c, new_c, vel_c, dt, move, weight_c, walls, wall_l_u, wall_r_u, near_start,
                              near_part, near_wall, pair_l_u, pair_r_u, wall_p, pair_p, row_start, nbr, owner, gx, gy,
                              force_n, fire, order, vel_c, none, none, none, fmax_b, one_bad)
        pos_c, new_c = new_c, pos_c
        force_c, force_n = force_n, force_c
        step += 1
        if step < n_steps:
            fmax_hist[step] = fmax
            ke_hist[step] = ke
        if bad >= 0:
            status = NONFINITE
            crossing = order[bad]
            done = step
            break
        if step == n_steps:
            break
        if fmax < f_tol and quiet >= 0.0 and t - quiet >= window - 1e-12:
            status = CONVERGED
            done = step
            break
        vmax = 0.0
        for q in range(n):
            inv_m = g / weight_c[q]
            damp = 1.0 + dt * 2.0 * zeta * np.sqrt(lambda_max * inv_m)  # 1 + dt c / m
            vel_c[q, 0] = (vel_c[q, 0] + dt * inv_m * force_c[q, 0]) / damp
            vel_c[q, 1] = (vel_c[q, 1] + dt * inv_m * force_c[q, 1]) / damp
            vmax = max(vmax, abs(vel_c[q, 0]), abs(vel_c[q, 1]))
        max_move = np.sqrt(2.0) * dt * vmax
        step_move = max(step_move, dt * vmax)
        i, w = _first_crossing(serial, pos_c, vel_c, dt, walls, order, near_part, near_wall,
                               not (moved + max_move < reach), one_b, one_w)
        if i >= 0:  # tested before any particle moved: the step is not taken
            status = CROSSED
            crossing = i * nw + w
            done = step
            break
        moved += max_move
        move = True
        t += dt
        ke = _kinetic(rank, weight_c, vel_c, g)  # the step's (velocities are set before the move)
        if ke / e_norm < e_limit:
            if quiet < 0.0:
                quiet = t
        else:
            quiet = -1.0
        if moved > 0.5 * skin:
            nbr, cstart, owner, gx, gy, near_part, near_wall = _move_and_rebuild(
                pos_c, dt, vel_c, pos, vel, weight, pos_build, box, rc, walls, reach, serial, order, cstart, row_start,
                nbr, rank, vel_c, weight_c, owner, gx, gy, halo, near_start)
            moved = 0.0
            move = False
    _finish(order, pos_c, vel_c, force_c, pos, vel, force, state, step_move)
    state[0], state[1], state[2] = moved, t, quiet
    return done, status, crossing
