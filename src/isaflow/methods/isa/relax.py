"""The compiled relaxation loop of incremental static analysis (numba), serial or parallel.

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

Threads: the per-step passes run in ``threads`` blocks (argument; the
solver passes the solve's thread count and sets numba's to it with
``numba.set_num_threads``; reading numba's count inside compiled code would
stop numba from caching the loop).  Every pass
writes per-particle or per-pair results that do not depend on how the
particles are split between threads, and its only reductions are a maximum
and a first index (exact in any order), so 1 and 2 threads give the same
bits.  The sums of pair forces are formed per particle by gathering (see
:func:`_sum_range`) in the order of the serial scatter they replaced, so the
results are also those of the plain loop "move; rebuild with build_pairs if
due; forces.forces" to the last bit (tests/test_kernels_perf_equivalence.py).
FIRE's power and norms are sums over all particles in the caller's order:
they stay one serial loop (a split sum would round differently).
"""

import numpy as np
from numba import prange

from ...core.jit import njit

from ...core.geometry import crossed_wall, segment_closest
from ...core.neighbours import cell_rows_par
from .forces import pair_push, track_max, wall_push

JIT = dict(cache=True, nogil=True)
NO_TRAIL = np.empty((0, 0, 2))  # relax_resume's trail when no step's positions are kept
PJIT = dict(cache=True, nogil=True, parallel=True)
# no division-by-zero check (numpy's error model): lets LLVM vectorise the pair forces; every division in
# these functions either has a non-zero divisor or its result is discarded
NJIT = dict(cache=True, nogil=True, error_model="numpy")

PAPER, CAPPED, FIRE = 0, 1, 2
RUNNING, CONVERGED, NONFINITE, CROSSED = 0, 1, 2, 3
# FIRE constants (Bitzek et al. 2006): N_min, f_inc, f_dec, alpha_start, f_alpha
FIRE_N_MIN, FIRE_F_INC, FIRE_F_DEC, FIRE_ALPHA0, FIRE_F_ALPHA = 5, 1.1, 0.5, 0.1, 0.99
# particles per thread below which a step runs serially: a parallel pass costs a fork and a join
# (a few microseconds), more than it saves on fewer particles (benchmarks/bench_step.py)
PAR_MIN_PER_THREAD = 2000
CHUNK_ROWS = 128  # rows whose pair forces are computed together (vectorised) before the sweep adds them


@njit(**NJIT)
def _pair_forces_vec(gx, gy, l_u, r_u, p):
    """In place: (gx[k], gy[k]) = separation x_i - x_j [cm] on entry, forces.pair_push's force [N] on i
    on exit (law exponent p), by the same operations without branches, so that they vectorise (the
    division by a zero distance is computed and discarded, hence numpy's error model).  Pass views
    gx[k0:k1]: indices from 0 need no negative-index wraparound, which would stop the vectoriser."""
    inv = 1.0 / l_u
    lu2 = l_u * l_u
    if p != 1.0:  # forces.law_over_d's other shapes, in its arithmetic
        for k in range(gx.shape[0]):
            dx = gx[k]
            dy = gy[k]
            d2 = dx * dx + dy * dy
            d = np.sqrt(d2)
            s = r_u * (1.0 - d / l_u) ** p / d
            far = d2 >= lu2
            zero = not d > 0.0
            gx[k] = 0.0 if far else (r_u if zero else s * dx)
            gy[k] = 0.0 if far else (0.0 if zero else s * dy)
        return
    for k in range(gx.shape[0]):
        dx = gx[k]
        dy = gy[k]
        d2 = dx * dx + dy * dy
        d = np.sqrt(d2)
        s = r_u * (1.0 / d - inv)
        far = d2 >= lu2
        zero = not d > 0.0
        gx[k] = 0.0 if far else (r_u if zero else s * dx)
        gy[k] = 0.0 if far else (0.0 if zero else s * dy)


@njit(**JIT)
def _near_range(lo, hi, pos, walls, r2, part, wall, c):
    """Store (particle, wall) of particles lo <= i < hi within sqrt(r2) [cm] of a wall at part[c:],
    wall[c:] (if part is long enough); returns the count of such pairs."""
    nw = walls.shape[0]
    reach = np.sqrt(r2)
    count = 0
    for i in range(lo, hi):
        for w in range(nw):
            # outside the wall's bounding box grown by reach: too far (a cheap test first)
            if (pos[i, 0] < min(walls[w, 0], walls[w, 2]) - reach or pos[i, 0] > max(walls[w, 0], walls[w, 2]) + reach
                    or pos[i, 1] < min(walls[w, 1], walls[w, 3]) - reach
                    or pos[i, 1] > max(walls[w, 1], walls[w, 3]) + reach):
                continue
            cx, cy = segment_closest(pos[i, 0], pos[i, 1], walls[w, 0], walls[w, 1], walls[w, 2], walls[w, 3])
            dx = pos[i, 0] - cx
            dy = pos[i, 1] - cy
            if dx * dx + dy * dy < r2:
                if c + count < part.shape[0]:
                    part[c + count] = i
                    wall[c + count] = w
                count += 1
    return count


@njit(**JIT)
def _near_walls(pos, walls, reach):
    """(particle, wall) int32 pairs, ascending, with the particle closer than reach [cm] to the wall
    (counted, then stored)."""
    n = pos.shape[0]
    r2 = reach * reach
    c = _near_range(0, n, pos, walls, r2, np.empty(0, np.int32), np.empty(0, np.int32), 0)
    part = np.empty(c, np.int32)
    wall = np.empty(c, np.int32)
    _near_range(0, n, pos, walls, r2, part, wall, 0)
    return part, wall


@njit(**JIT)
def _row_starts(keys, n, start):
    """start (n + 1,) int32 of ascending keys (C,): entries start[q] <= c < start[q + 1] have keys[c] == q."""
    start[:] = 0
    for c in range(keys.shape[0]):
        start[keys[c] + 1] += 1
    for q in range(n):
        start[q + 1] += start[q]


@njit(**JIT)
def _pair_scratch(row_start, n, owner, gx, gy):
    """(owner, gx, gy) for the row list row_start: owner[k] = the row of pair k (int32), gx, gy
    scratch of the pair forces [N]; the arrays given are reused unless too small."""
    m = row_start[n]
    if owner.shape[0] < m:
        owner = np.empty(m + m // 4 + 16, np.int32)
        gx = np.empty(owner.shape[0])
        gy = np.empty(owner.shape[0])
    for q in range(n):
        for k in range(row_start[q], row_start[q + 1]):
            owner[k] = q
    return owner, gx, gy


@njit(**JIT)
def _halo_rows(row_start, nbr, n, nb, halo):
    """halo (nb,) int64: the first row (cell order) with a pair whose partner lies in block b
    (particles b n / nb <= j < (b + 1) n / nb) while the row itself lies before the block;
    the block's first particle if there is none.  Rows reach at most `span` particles ahead
    (the largest nbr[k] - q of the list), so only the rows within span before a block are read."""
    span = 0
    for q in range(n):
        for k in range(row_start[q], row_start[q + 1]):
            span = max(span, nbr[k] - q)
    for b in range(nb):
        lo = b * n // nb
        hi = (b + 1) * n // nb
        halo[b] = lo
        for q in range(max(0, lo - span), lo):
            for k in range(row_start[q], row_start[q + 1]):
                if nbr[k] >= lo and nbr[k] < hi:
                    halo[b] = q
                    break
            if halo[b] < lo:
                break


@njit(**NJIT)
def _forces_range(lo, hi, h, pos, new, direction, scale, move, weight, walls, wall_l_u, wall_r_u, near_start,
                  near_part, near_wall, pair_l_u, pair_r_u, wall_p, pair_p, row_start, nbr, owner, gx, gy, force, fire, order, vel,
                  power, vnorm2, fnorm2):
    """Move particles lo <= q < hi (cell order) and evaluate their forces; returns (max|F|, bad) of the range.

    new[q] = pos[q] + scale direction[q] if move else pos[q] (cm); force[q] =
    weight + wall forces at new[q] (walls of the near-wall rows only: the
    others add exact zeros) + pair forces [N], summed in the serial order:
    q's wall forces, then every pair (q', q) of an earlier row q' < q (rows in
    order), then q's own row -- the order of the one-block sweep, where row q
    adds its pairs to q and subtracts them from their partners.

    Parallel blocks: a block's particles receive pairs from earlier rows that
    belong to other blocks (rows h <= q' < lo, see :func:`_halo_rows`); the
    block evaluates those pairs itself first, then sweeps its own rows,
    subtracting only from partners inside the block.  A particle of another
    block is placed by the same expression pos + scale direction, so it equals
    that block's new[j] bit for bit without waiting for it (pos, direction are
    read-only during the pass; force must not be direction).  bad: the first
    particle of the range whose position or force is not finite (then max|F|
    is NaN), else -1.  fire: also store FIRE's per-particle terms v.F, |v|^2,
    |F|^2 at the caller's index order[q] (summed in that order by
    :func:`_fire_step`).
    """
    # move, and the weights (two plain loops that vectorise); then the walls of the near-wall rows,
    # in their order (ascending particle, then wall): the additions forces.forces makes
    if move:
        for i in range(lo, hi):
            q = np.uint64(i)  # unsigned: no negative-index wraparound
            new[q, 0] = pos[q, 0] + scale * direction[q, 0]
            new[q, 1] = pos[q, 1] + scale * direction[q, 1]
    else:
        for i in range(lo, hi):
            q = np.uint64(i)
            new[q, 0] = pos[q, 0]
            new[q, 1] = pos[q, 1]
    for i in range(lo, hi):
        q = np.uint64(i)
        force[q, 0] = 0.0
        force[q, 1] = -weight[q]
    for c in range(near_start[lo], near_start[hi]):
        q = near_part[c]
        w = near_wall[c]
        ax, ay = wall_push(new[q, 0], new[q, 1], walls[w, 0], walls[w, 1], walls[w, 2], walls[w, 3], wall_l_u,
                           wall_r_u, wall_p)
        force[q, 0] += ax
        force[q, 1] += ay
    for q in range(h, lo):  # pairs of earlier blocks' rows with partners in this block
        xi = pos[q, 0]
        yi = pos[q, 1]
        if move:
            xi = xi + scale * direction[q, 0]
            yi = yi + scale * direction[q, 1]
        for k in range(row_start[q], row_start[q + 1]):
            j = nbr[k]
            if j >= lo and j < hi:
                ax, ay = pair_push(xi - new[j, 0], yi - new[j, 1], pair_l_u, pair_r_u, pair_p)
                force[j, 0] -= ax
                force[j, 1] -= ay
    # the block's pairs: views from 0 and unsigned particle numbers need no negative-index wraparound
    k0 = row_start[lo]
    k1 = row_start[hi]
    own = owner[k0:k1]
    par = nbr[k0:k1]
    bx = gx[k0:k1]
    by = gy[k0:k1]
    uhi = np.uint32(hi)
    for k in range(own.shape[0]):  # separations
        q = np.uint32(own[k])
        j = np.uint32(par[k])
        if j < uhi:
            xj = new[j, 0]
            yj = new[j, 1]
        else:
            xj = pos[j, 0]
            yj = pos[j, 1]
            if move:
                xj = xj + scale * direction[j, 0]
                yj = yj + scale * direction[j, 1]
        bx[k] = new[q, 0] - xj
        by[k] = new[q, 1] - yj
    _pair_forces_vec(bx, by, pair_l_u, pair_r_u, pair_p)
    for k in range(own.shape[0]):  # the sweep: in pair order, each row adds to its particle, subtracts from partners
        q = np.uint32(own[k])
        j = np.uint32(par[k])
        ax = bx[k]
        ay = by[k]
        force[q, 0] += ax
        force[q, 1] += ay
        if j < uhi:
            force[j, 0] -= ax
            force[j, 1] -= ay
    fmax = 0.0
    bad = -1
    for i in range(lo, hi):
        q = np.uint64(i)
        fx = force[q, 0]
        fy = force[q, 1]
        fmax, finite = track_max(fx, fy, fmax, (abs(new[q, 0]) < np.inf) & (abs(new[q, 1]) < np.inf))
        if not finite and bad < 0:
            bad = i
        if fire:
            ic = order[q]
            power[ic] = vel[q, 0] * fx + vel[q, 1] * fy
            vnorm2[ic] = vel[q, 0] ** 2 + vel[q, 1] ** 2
            fnorm2[ic] = fx ** 2 + fy ** 2
    if bad >= 0:
        return np.nan, bad
    return fmax, bad


@njit(**PJIT)
def _forces_par(nb, halo, pos, new, direction, scale, move, weight, walls, wall_l_u, wall_r_u, near_start,
                near_part, near_wall, pair_l_u, pair_r_u, wall_p, pair_p, row_start, nbr, owner, gx, gy, force, fire, order, vel, power,
                vnorm2, fnorm2, fmax_b, bad_b):
    """:func:`_forces_range` over nb blocks in parallel; (max|F|, bad) of block b in fmax_b[b], bad_b[b]."""
    n = pos.shape[0]
    for b in prange(nb):
        fmax_b[b], bad_b[b] = _forces_range(b * n // nb, (b + 1) * n // nb, halo[b], pos, new, direction, scale,
                                            move, weight, walls, wall_l_u, wall_r_u, near_start, near_part,
                                            near_wall,
                                            pair_l_u, pair_r_u, wall_p, pair_p, row_start, nbr, owner, gx, gy, force, fire, order,
                                            vel, power, vnorm2, fnorm2)


@njit(**JIT)
def _evaluate(nb, halo, pos, new, direction, scale, move, weight, walls, wall_l_u, wall_r_u, near_start,
              near_part, near_wall,
              pair_l_u, pair_r_u, wall_p, pair_p, row_start, nbr, owner, gx, gy, force, fire, order, vel, power, vnorm2, fnorm2,
              fmax_b, bad_b):
    """Move (if move) into new and evaluate force there: returns (max|F| [N], bad) as forces.forces.

    nb blocks of particles (nb <= 1: one serial pass).  The blocks' maxima
    and first bad particles combine exactly, whatever nb.
    """
    n = pos.shape[0]
    if nb <= 1:
        zero = n - n  # not a literal 0: the same specialisation of _forces_range as the parallel blocks'
        return _forces_range(zero, n, zero, pos, new, direction, scale, move, weight, walls, wall_l_u, wall_r_u,
                             near_start, near_part, near_wall, pair_l_u, pair_r_u, wall_p, pair_p, row_start, nbr, owner, gx, gy,
                             force, fire, order, vel, power, vnorm2, fnorm2)
    _forces_par(nb, halo, pos, new, direction, scale, move, weight, walls, wall_l_u, wall_r_u, near_start,
                near_part, near_wall,
                pair_l_u, pair_r_u, wall_p, pair_p, row_start, nbr, owner, gx, gy, force, fire, order, vel, power, vnorm2, fnorm2,
                fmax_b, bad_b)
    fmax = 0.0
    for b in range(nb):
        if bad_b[b] >= 0:
            return np.nan, bad_b[b]
        fmax = max(fmax, fmax_b[b])
    return fmax, -1


@njit(**JIT)
def _crossing_range(lo, hi, pos, direction, scale, walls, order, near_part, test_all):
    """(particle, wall) of the lowest-numbered particle (caller's numbers, order[q]) among the
    entries lo <= c < hi (particles if test_all, else near-wall rows) whose move pos +=
    scale * direction crosses a wall, or (-1, -1)."""
    best = -1
    best_wall = -1
    last = -1
    for c in range(lo, hi):
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
def _crossing_near(lo, hi, pos, direction, scale, walls, order, near_part, near_wall):
    """(particle, wall), smallest as a pair (caller's particle number order[q], then wall), among the
    near-wall rows lo <= c < hi whose particle's move pos += scale * direction crosses the row's wall;
    (-1, -1) if none.  A particle's rows are in ascending wall order, and no other wall can be
    reached before the next list build, so for the lowest-numbered crossing particle this is the
    wall core.geometry.crossed_wall returns (the first one the move crosses)."""
    best = -1
    best_wall = -1
    for c in range(lo, hi):
        q = near_part[c]
        i = order[q]
        if best >= 0 and i >= best:  # a lower particle, or a lower wall of this one, already crosses
            continue
        w = near_wall[c]
        if crossed_wall(pos[q, 0], pos[q, 1], pos[q, 0] + scale * direction[q, 0],
                        pos[q, 1] + scale * direction[q, 1], walls[w:w + 1]) >= 0:
            best = i
            best_wall = w
    return best, best_wall


@njit(**PJIT)
def _crossing_par(nb, pos, direction, scale, walls, order, near_part, near_wall, best_b, wall_b):
    """:func:`_crossing_near` over nb blocks of the near-wall rows in parallel."""
    m = near_part.shape[0]
    for b in prange(nb):
        best_b[b], wall_b[b] = _crossing_near(b * m // nb, (b + 1) * m // nb, pos, direction, scale, walls, order,
                                              near_part, near_wall)


@njit(**JIT)
def _first_crossing(nb, pos, direction, scale, walls, order, near_part, near_wall, test_all, best_b, wall_b):
    """(particle, wall) of the lowest-numbered particle whose move pos += scale * direction
    crosses a wall, and the first wall it crosses, or (-1, -1).  Only near-wall rows are
    tested unless test_all (then every particle against every wall); the rows in nb parallel
    blocks when there are enough of them (:func:`blocks`); the result is the same."""
    if test_all:
        return _crossing_range(0, pos.shape[0], pos, direction, scale, walls, order, near_part, True)
    nbc = blocks(near_part.shape[0], nb)
    if nbc <= 1:
        zero = nb - nb  # not a literal 0 (one specialisation)
        return _crossing_near(zero, near_part.shape[0], pos, direction, scale, walls, order, near_part, near_wall)
    _crossing_par(nbc, pos, direction, scale, walls, order, near_part, near_wall, best_b, wall_b)
    best = -1
    best_wall = -1
    for b in range(nbc):
        i = best_b[b]
        if i >= 0 and (best < 0 or i < best or (i == best and wall_b[b] < best_wall)):
            best = i
            best_wall = wall_b[b]
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
def _cell_lists(pos, vel, weight, box, rc, walls, reach, nb, hint, order, cstart, row_start, nbr, rank, pos_c, vel_c,
                weight_c, owner, gx, gy, halo, near_start):
    """The lists of a build at pos (N, 2) cm (caller order): the pair rows within rc [cm]
    (core.neighbours.cell_rows_par in nb blocks, hint pairs per particle), the state gathered into their
    cell order (pos_c, vel_c, weight_c), the pair scratch, the halo rows (nb > 1) and the near-wall rows
    within reach [cm].  Returns (nbr, cstart, owner, gx, gy, near_part, near_wall)."""
    n = pos.shape[0]
    nbr, cstart = cell_rows_par(pos, box, rc, order, cstart, row_start, nbr, nb, hint)
    _to_cell_order(pos, vel, weight, order, nbr, row_start[n], rank, pos_c, vel_c, weight_c)
    owner, gx, gy = _pair_scratch(row_start, n, owner, gx, gy)
    if nb > 1:
        _halo_rows(row_start, nbr, n, nb, halo)
    near_part, near_wall = _near_walls(pos_c, walls, reach)
    _row_starts(near_part, n, near_start)
    return nbr, cstart, owner, gx, gy, near_part, near_wall


@njit(**JIT)
def _start(pos, vel, weight, pos_build, resume, box, rc, walls, reach, nb):
    """A step loop's buffers and first lists (:func:`_cell_lists`), built at pos_build (set to pos unless
    resume), with pos_c at pos.  Returns (order, rank, row_start, near_start, pos_c, new_c, vel_c, force_c,
    force_n, weight_c, halo, nbr, cstart, owner, gx, gy, near_part, near_wall): order[q] the caller's index of
    the q-th particle in cell order, rank its inverse; new_c and force_n the next step's positions and forces
    (double buffers)."""
    n = pos.shape[0]
    order = np.empty(n, np.int32)
    rank = np.empty(n, np.int32)
    row_start = np.empty(n + 1, np.int32)
    near_start = np.empty(n + 1, np.int32)
    pos_c = np.empty((n, 2))
    new_c = np.empty((n, 2))
    vel_c = np.empty((n, 2))
    force_c = np.empty((n, 2))
    force_n = np.empty((n, 2))
    weight_c = np.empty(n)
    halo = np.empty(nb, np.int64)
    if not resume:
        pos_build[:, :] = pos
    nbr, cstart, owner, gx, gy, near_part, near_wall = _cell_lists(
        pos_build, vel, weight, box, rc, walls, reach, nb, 4.0, order, np.empty(1, np.int32), row_start,
        np.empty(4 * n + 16, np.int32), rank, pos_c, vel_c, weight_c, np.empty(0, np.int32), np.empty(0),
        np.empty(0), halo, near_start)
    if resume:
        for q in range(n):
            pos_c[q, 0] = pos[order[q], 0]
            pos_c[q, 1] = pos[order[q], 1]
    return (order, rank, row_start, near_start, pos_c, new_c, vel_c, force_c, force_n, weight_c, halo, nbr, cstart,
            owner, gx, gy, near_part, near_wall)


@njit(**JIT)
def _move_and_rebuild(pos_c, scale, direction, pos, vel, weight, pos_build, box, rc, walls, reach, nb, order,
                      cstart, row_start, nbr, rank, vel_c, weight_c, owner, gx, gy, halo, near_start):
    """Take the step pos_c += scale direction, write positions and velocities back in the caller's order
    (pos, vel, and pos_build: the new build's positions) and rebuild the lists there (:func:`_cell_lists`,
    sized by the last build's pairs per particle).  Returns what :func:`_cell_lists` returns."""
    n = pos.shape[0]
    for q in range(n):
        pos_c[q, 0] = pos_c[q, 0] + scale * direction[q, 0]
        pos_c[q, 1] = pos_c[q, 1] + scale * direction[q, 1]
    _to_caller_order(order, pos_c, pos)
    _to_caller_order(order, vel_c, vel)
    pos_build[:, :] = pos
    return _cell_lists(pos, vel, weight, box, rc, walls, reach, nb, 1.25 * row_start[n] / max(n, 1) + 2.0, order,
                       cstart, row_start, nbr, rank, pos_c, vel_c, weight_c, owner, gx, gy, halo, near_start)


@njit(**JIT)
def _finish(order, pos_c, vel_c, force_c, pos, vel, force, state, step_move):
    """Write positions, velocities and forces back in the caller's order; state[4] (if state has it) =
    step_move, the largest displacement component [cm] of the call."""
    _to_caller_order(order, pos_c, pos)
    _to_caller_order(order, vel_c, vel)
    _to_caller_order(order, force_c, force)
    if state.shape[0] > 4:
        state[4] = step_move


@njit(**JIT)
def _fire_range(lo, hi, vel, force, mix, one_minus_alpha, c, dt):
    """FIRE's velocity update of particles lo <= q < hi: v = (1 - alpha) v + c F if mix, else
    v = 0; then v += dt F (semi-implicit Euler).  Returns max(|vx|, |vy|) over the range."""
    vmax = 0.0
    for q in range(lo, hi):
        if mix:
            vel[q, 0] = one_minus_alpha * vel[q, 0] + c * force[q, 0]
            vel[q, 1] = one_minus_alpha * vel[q, 1] + c * force[q, 1]
        else:
            vel[q, 0] = 0.0
            vel[q, 1] = 0.0
        vel[q, 0] += dt * force[q, 0]
        vel[q, 1] += dt * force[q, 1]
        vmax = max(vmax, abs(vel[q, 0]), abs(vel[q, 1]))
    return vmax


@njit(**JIT)
def _fire_step(vel, force, power_i, vnorm2_i, fnorm2_i, dt, dt_max, alpha, n_pos):
    """One FIRE velocity update (Bitzek et al. 2006) followed by v += dt F, in place.

    Returns (dt, alpha, n_pos, vmax).  Power and norms are summed over the
    per-particle terms of :func:`_sum_range`, stored in the caller's particle
    order, in that order (as a plain loop over particles), serially.
    """
    power = 0.0
    vnorm2 = 0.0
    fnorm2 = 0.0
    for i in range(power_i.shape[0]):
        power += power_i[i]
        vnorm2 += vnorm2_i[i]
        fnorm2 += fnorm2_i[i]
    mix = power > 0.0
    one_minus_alpha = 1.0 - alpha
    c = 0.0
    if mix:
        c = alpha * np.sqrt(vnorm2 / fnorm2)
        n_pos += 1
        if n_pos > FIRE_N_MIN:
            dt = min(FIRE_F_INC * dt, dt_max)
            alpha *= FIRE_F_ALPHA
    else:
        n_pos = 0
        dt *= FIRE_F_DEC
        alpha = FIRE_ALPHA0
    vmax = _fire_range(0, vel.shape[0], vel, force, mix, one_minus_alpha, c, dt)
    return dt, alpha, n_pos, vmax


@njit(**PJIT)
def start_threads(out):
    """Touch numba's thread pool (out (T,) receives the block numbers): the first parallel call
    starts the threads, which :func:`isaflow.methods.isa.solver.warm_up` keeps out of timings."""
    for b in prange(out.shape[0]):
        out[b] = b


@njit(**JIT)
def blocks(n, threads):
    """Blocks of particles a step is split into: 1 (serial) unless every thread gets at least
    PAR_MIN_PER_THREAD particles; then one per thread."""
    if threads <= 1 or n < threads * PAR_MIN_PER_THREAD:
        return 1
    return threads


def relax(pos, vel, weight, walls, box, wall_l_u, wall_r_u, pair_l_u, pair_r_u, rule, du, f_ref,
          dt_max, f_tol, n_steps, skin, force, fmax_hist, threads=1, wall_p=1.0, pair_p=1.0):
    """One chunk from a fresh start (neighbour list built from pos, FIRE reset); see :func:`relax_resume`.

    Returns (steps_done, status, crossing).  A Python function: it calls the
    compiled relax_resume with the argument types the solver passes, so that
    there is one compiled specialisation (a compiled caller passing a literal
    False would compile the whole loop a second time).
    """
    return relax_resume(pos, vel, weight, walls, box, float(wall_l_u), float(wall_r_u), float(pair_l_u),
                        float(pair_r_u), int(rule), float(du), float(f_ref), float(dt_max), float(f_tol), int(n_steps),
                        float(skin), force, fmax_hist, np.empty_like(pos), np.zeros(4), False, int(threads),
                        float(wall_p), float(pair_p), NO_TRAIL)


@njit(**JIT)
def relax_resume(pos, vel, weight, walls, box, wall_l_u, wall_r_u, pair_l_u, pair_r_u, rule, du, f_ref,
                 dt_max, f_tol, n_steps, skin, force, fmax_hist, pos_build, state, resume, threads, wall_p,
                 pair_p, trail):
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
    threads: how many blocks the passes may run in (:func:`blocks`; the
    results do not depend on it).  trail (K, N, 2) cm: trail[k] receives the
    positions after k steps of this call, for k < K (K = 0: none; the replay,
    replay.py, reads every step of a chunk from it).

    Implementation (results identical, to the last bit, to the plain loop
    "move; rebuild with build_pairs if due; forces.forces", for any number of
    threads): the pair list is build_pairs' list in the same order, stored by
    rows (core.neighbours.cell_rows), and the state is kept in that cell order
    between builds, so the passes stream through memory; the caller's arrays
    are written back on return.  A step is one pass over the particles
    (:func:`_evaluate`): move, weight and wall forces, then the rows' pair
    forces; positions and forces are double-buffered so that parallel blocks
    read the previous step's only (:func:`_forces_range`).  Wall forces and
    the crossing test only visit particles that were within wall_l_u + skin
    of a wall at the last build (no other particle can
    come within wall_l_u of a wall, or reach one, before the next build; if
    one step could reach farther, every particle is tested).  The passes run
    in parallel blocks, one per thread (:func:`blocks`).
    """
    n = pos.shape[0]
    nw = walls.shape[0]
    nb = blocks(n, threads)
    fire = rule == FIRE
    rc = pair_l_u + skin
    reach = wall_l_u + skin
    nf = n if fire else 0
    power_i = np.empty(nf)
    vnorm2_i = np.empty(nf)
    fnorm2_i = np.empty(nf)
    fmax_b = np.empty(nb)
    best_b = np.empty(nb, np.int64)
    wall_b = np.empty(nb, np.int64)
    bad_b = np.empty(nb, np.int64)
    # state in cell order between builds: order[q] the caller's index of the q-th particle; force_n the next
    # forces (force_c is the move direction of the paper/capped rules)
    (order, rank, row_start, near_start, pos_c, new_c, vel_c, force_c, force_n, weight_c, halo, nbr, cstart, owner,
     gx, gy, near_part, near_wall) = _start(pos, vel, weight, pos_build, resume, box, rc, walls, reach, nb)
    if resume:
        moved, dt, alpha, n_pos = state[0], state[1], state[2], int(state[3])
    else:
        moved, dt, alpha, n_pos = 0.0, 0.1 * dt_max, FIRE_ALPHA0, 0  # moved: bound on any displacement, cm
    status = RUNNING
    step_move = 0.0
    crossing = -1
    done = n_steps
    direction = force_c
    scale = 0.0
    move = n < 0  # False (the first evaluation is at pos), computed: a literal False would be a second specialisation
    step = -1
    while True:  # one call site of _evaluate (one compiled specialisation)
        fmax, bad = _evaluate(nb, halo, pos_c, new_c, direction, scale, move, weight_c, walls, wall_l_u, wall_r_u,
                              near_start, near_part, near_wall, pair_l_u, pair_r_u, wall_p, pair_p, row_start, nbr, owner, gx, gy,
                              force_n, fire, order, vel_c, power_i, vnorm2_i, fnorm2_i, fmax_b, bad_b)
        pos_c, new_c = new_c, pos_c
        force_c, force_n = force_n, force_c
        step += 1
        if step < n_steps:
            fmax_hist[step] = fmax
        if step < trail.shape[0]:
            _to_caller_order(order, pos_c, trail[step])
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
        if fire:
            dt, alpha, n_pos, vmax = _fire_step(vel_c, force_c, power_i, vnorm2_i, fnorm2_i, dt, dt_max, alpha, n_pos)
            # semi-implicit Euler with the step capped at du
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
        i, w = _first_crossing(nb, pos_c, direction, scale, walls, order, near_part, near_wall,
                               not (moved + max_move < reach), best_b, wall_b)
        if i >= 0:  # tested before any particle moved: the step is not taken
            status = CROSSED
            crossing = i * nw + w
            done = step
            break
        moved += max_move
        move = True
        if moved > 0.5 * skin:
            nbr, cstart, owner, gx, gy, near_part, near_wall = _move_and_rebuild(
                pos_c, scale, direction, pos, vel, weight, pos_build, box, rc, walls, reach, nb, order, cstart,
                row_start, nbr, rank, vel_c, weight_c, owner, gx, gy, halo, near_start)
            moved = 0.0
            move = False
    _finish(order, pos_c, vel_c, force_c, pos, vel, force, state, step_move)
    state[0], state[1], state[2], state[3] = moved, dt, alpha, n_pos
    return done, status, crossing
