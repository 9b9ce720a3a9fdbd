"""The design floor of the ISA step (paper's update), timed against the project's by bench_step.py
(a module of its own so that bench_step.py's compile probe still times isaflow's import).

Below it, a scatter-free step (each particle's force gathered from a full list, every pair's law evaluated twice)
was tried on bench_step's relaxed wide vessels (commit aab66c3, benchmarks/isa_scatter_free.py, removed after: its
step loop repeated this one's): no form of it was faster.  1 thread, medians of interleaved calls, load 0.3-0.6,
ns per particle-step at N = 997 / 9,450 / 30,240 / 100,170: project 13.12 / 11.21 / 11.38 / 12.18, this floor
11.50 / 11.15 / 11.41 / 12.17, the best gather (sliced ELLPACK, vectorised across particles) 13.58 / 12.66 /
13.02 / 13.85.  Gathering halves a pair-law entry's cost (1.45 against 2.9 ns with the scatter) but doubles the
entries (5.6-6.8 against 2.8 per particle): the law's sqrt and division bound the step, not the scatter."""

import numpy as np

from isaflow.core.geometry import crossed_wall
from isaflow.core.jit import njit
from isaflow.methods.isa import relax as R
from isaflow.methods.isa.forces import wall_push


@njit(cache=True, nogil=True, error_model="numpy")
def floor_relax(pos, weight, walls, box, wall_l_u, wall_r_u, pair_l_u, pair_r_u, du, n_steps, skin, force, fmax_hist):
    """The design floor of n_steps steps of the paper's update (linear laws, one thread), in place on pos (N, 2) cm;
    force (N, 2) [N] and fmax_hist (n_steps,) [N] as relax.relax.  Returns the status (relax's codes).

    Includes, per step: the crossing test of the near-wall rows (the whole vessel when the rows may not
    suffice, as relax), the move x += du F / max|F|, the weights, the wall rows' forces in their own pass, then
    one sweep over the half pair list in cell order (relax's rows: every partner after its row), each pair's
    linear-law force within l_u added to its row and subtracted from its partner, max|F| taken as each row
    completes, and one finite check of the step (a sum of x - x terms; coincident particles, which relax
    pushes apart along x, fail it).  State: SoA x, y, fx, fy in cell order.
    The list builds are relax's own (relax._start, relax._cell_lists at the same steps: moved > skin / 2), with
    the build's write-back to the caller's order and a gather into x, y; so floor and project pay the same builds,
    and the ratio is the step's own overhead.  Sums in relax's order: the same bits.  Unlike relax, the pair law
    is evaluated row by row in the sweep (scalar, a branch at l_u), not branch-free over a block's pairs."""
    n = pos.shape[0]
    rc = pair_l_u + skin
    reach = wall_l_u + skin
    lu2 = pair_l_u * pair_l_u
    inv = 1.0 / pair_l_u
    vel = np.zeros_like(pos)
    pos_build = np.empty_like(pos)
    (order, rank, row_start, near_start, pos_c, _, vel_c, _, _, w, halo, nbr, cstart, owner, gx, gy, near_part,
     near_wall) = R._start(pos, vel, weight, pos_build, False, box, rc, walls, reach, 1)
    x = np.empty(n)
    y = np.empty(n)
    fx = np.empty(n)
    fy = np.empty(n)
    for q in range(n):
        x[q] = pos_c[q, 0]
        y[q] = pos_c[q, 1]
    moved = 0.0
    scale = 0.0
    move = False
    status = R.RUNNING
    step = -1
    while True:
        if move:
            for q in range(n):
                x[q] += scale * fx[q]
                y[q] += scale * fy[q]
        for q in range(n):
            fx[q] = 0.0
            fy[q] = -w[q]
        for c in range(near_part.shape[0]):
            q = near_part[c]
            k = near_wall[c]
            ax, ay = wall_push(x[q], y[q], walls[k, 0], walls[k, 1], walls[k, 2], walls[k, 3], wall_l_u, wall_r_u)
            fx[q] += ax
            fy[q] += ay
        fmax = 0.0
        chk = 0.0
        for q in range(n):
            xi = x[q]
            yi = y[q]
            sx = fx[q]
            sy = fy[q]
            for k in range(row_start[q], row_start[q + 1]):
                j = nbr[k]
                dx = xi - x[j]
                dy = yi - y[j]
                d2 = dx * dx + dy * dy
                if d2 < lu2:
                    s = pair_r_u * (1.0 / np.sqrt(d2) - inv)
                    ax = s * dx
                    ay = s * dy
                    sx += ax
                    sy += ay
                    fx[j] -= ax
                    fy[j] -= ay
            fx[q] = sx
            fy[q] = sy
            fmax = max(fmax, abs(sx), abs(sy))
            chk += (xi - xi) + (yi - yi) + (sx - sx) + (sy - sy)  # 0 unless something is not finite
        step += 1
        if chk != 0.0:
            fmax = np.nan
        if step < n_steps:
            fmax_hist[step] = fmax
        if chk != 0.0:
            status = R.NONFINITE
            break
        if step == n_steps:
            break
        scale = du / fmax
        max_move = np.sqrt(2.0) * (scale * fmax)
        if moved + max_move < reach:
            for c in range(near_part.shape[0]):
                q = near_part[c]
                k = near_wall[c]
                if crossed_wall(x[q], y[q], x[q] + scale * fx[q], y[q] + scale * fy[q], walls[k:k + 1]) >= 0:
                    status = R.CROSSED
        else:
            for q in range(n):
                if crossed_wall(x[q], y[q], x[q] + scale * fx[q], y[q] + scale * fy[q], walls) >= 0:
                    status = R.CROSSED
        if status == R.CROSSED:
            break
        moved += max_move
        move = True
        if moved > 0.5 * skin:
            for q in range(n):
                i = order[q]
                pos[i, 0] = x[q] + scale * fx[q]
                pos[i, 1] = y[q] + scale * fy[q]
            pos_build[:, :] = pos
            nbr, cstart, owner, gx, gy, near_part, near_wall = R._cell_lists(
                pos, vel, weight, box, rc, walls, reach, 1, 1.25 * row_start[n] / max(n, 1) + 2.0, order, cstart,
                row_start, nbr, rank, pos_c, vel_c, w, owner, gx, gy, halo, near_start)
            for q in range(n):
                x[q] = pos_c[q, 0]
                y[q] = pos_c[q, 1]
            moved = 0.0
            move = False
    for q in range(n):
        i = order[q]
        pos[i, 0] = x[q]
        pos[i, 1] = y[q]
        force[i, 0] = fx[q]
        force[i, 1] = fy[q]
    return status
