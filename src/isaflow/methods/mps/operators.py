"""MPS particle operators (numba): Koshizuka & Oka (1996) / Koshizuka, Nobe & Oka (1998), 2D (d = 2).

- weight w(r) = r_e / r - 1 for r < r_e, else 0;
- number density n_i = sum_j w(r_ij);
- gradient <grad phi>_i = d / n0 sum_j (phi_j - phi^_i) r_ij / |r_ij|^2 w(r_ij), phi^_i = min(phi_i, phi_j)
  (K&O 1996's stabilised pressure gradient), or with the corrective matrix (Khayyer & Gotoh 2011), or the
  variational one, C sum_j (phi_i + phi_j) (-w'(r_ij)) r_ij / |r_ij| = sum_k phi_k dn_k/dx_i times C (the
  transpose of the number density's Jacobian: Suzuki, Koshizuka & Oka 2007's Hamiltonian MPS);
- Laplacian <lap phi>_i = 2 d / (lambda n0) sum_j (phi_j - phi_i) w(r_ij);
- divergence <div u>_i = d / n0 sum_j (u_j - u_i) . r_ij / |r_ij|^2 w(r_ij).
r_ij = r_j - r_i.  Particle kinds: FLUID, WALL (in the pressure equation and the gradient), DUMMY (number
density only).

Neighbours are full per-particle lists (CSR: start (N+1,), nbr (M,)), built and used by gathering: every
pass computes particle i's value from its own row in a fixed order, so the loops over particles run in
parallel (numba prange) and give bit-identical results for any thread count.  Visibility across thin walls
(a dividing wall with particles behind both faces, boundary.py): a thin wall's face particles are seen only
from their own side of the wall (and, with walls.thin_line_of_sight, only where the wall stands between), and
no pair sees across a thin wall segment.
Units: cm, s, density N s^2 / cm^4 (2D), pressure N / cm^2.
"""

import numpy as np
from numba import prange, uint64
from numba.core.cpu import ParallelOptions

from ...core.jit import njit

JIT = dict(cache=True, nogil=True)
# explicit prange loops only: numba would also run every array expression (np.zeros, a copy) as a parallel loop of its
# own, a thread hand-off each (about 0.2 us apiece, some 20 per step)
PAR = dict(cache=True, nogil=True, parallel=ParallelOptions(dict(
    comprehension=False, reduction=False, inplace_binop=False, setitem=False, numpy=False, stencil=False, fusion=False,
    prange=True)))
FLUID, WALL, DUMMY = 0, 1, 2
DIM = 2
# pressure gradients (settings name -> id)
GRADIENTS = {"min": 0, "corrected": 1, "symmetric": 2, "cmps": 3, "variational": 4, "variational_dummies": 5}
VARIATIONAL = GRADIENTS["variational"]
# the gradients whose pair terms are antisymmetric (momentum-conserving): their wall pair forces are the momentum the
# walls exchange with the liquid (wall_forces)
PAIRWISE = frozenset({2, 3, 4, 5})
# a squared radius times this is a pair's cut before its distance is taken: a pair cut so has r >= the radius whatever
# the rounding of r, so every test on r itself decides as before
CUT = 1.0 + 1e-9


# glibc's hypot (2.35+, sysdeps/ieee754/dbl-64/e_hypot.c, without FMA: the build numba's np.hypot calls here) takes
# its common case for larger |x| <= 2^511 and smaller >= 2^-459; inside this narrower range pair_distance is its
# arithmetic step for step, outside it calls np.hypot
_HYPOT_LARGE, _HYPOT_TINY, _HYPOT_EPS = 2.0 ** 500, 2.0 ** -400, 2.0 ** -54


@njit(inline="always", **JIT)
def _hypot_kernel(ax, ay):
    """glibc's hypot kernel for ax >= ay > ax 2^-54 (Borges 2019's one correction of sqrt(ax^2 + ay^2))."""
    h = np.sqrt(ax * ax + ay * ay)
    big = h <= 2.0 * ay
    delta = h - ay if big else h - ax
    t1 = ax * (2.0 * delta - ax) if big else 2.0 * delta * (ax - 2.0 * ay)
    t2 = (delta - 2.0 * (ax - ay)) * delta if big else (4.0 * delta - ay) * ay + delta * delta
    return h - (t1 + t2) / (2.0 * h)


@njit(inline="always", **JIT)
def pair_distance(dx, dy):
    """|(dx, dy)| [cm] of a pair, bit for bit numba's np.hypot (glibc's hypot: its common case inlined, the rest by the
    call; tests/test_mps.py compares them over 3.5e6 pairs and the edge cases, 2.8e8 when written). The call itself cost
    22 ns a list entry against 2.7 for sqrt(dx^2 + dy^2), but sqrt's last-bit differences decide MPS outcomes
    (2026-12-03, a full run with sqrt): the flow flow_mixed_dx3.45 escaped (step 2,376: a particle thrown over the wall
    top at 1,570 cm/s), the standard column at l0 = 5.56 cm settled at a pressure slope 1.031 rho0 g (1.022 with
    np.hypot; bound +-3 %) and the V tank of tests/test_compare.py was not at rest by its 8 s (at rest at 6.37 s with
    np.hypot). The escape was no wall's: a spray pair whose pressure only the compressibility term fixed
    (clusters.anchor_clusters, since which 18 of 18 single and flow runs run without an escape with either distance).
    The other two remain with sqrt: both columns' top rows are compressed to n* = 0.98-0.99 n0 with no neighbour above,
    so they sit at the surface test's threshold; the V tank's top-row particles changed surface state 148 times after 5
    s (9 with np.hypot), and the column came to rest with its top two rows 20 / 16 particles (18 / 18 with np.hypot):
    outcomes that hang on the last bit of a distance, which this function keeps as np.hypot has it."""
    x, y = abs(dx), abs(dy)
    ax = y if x < y else x
    ay = x if x < y else y
    if ax <= _HYPOT_LARGE and (ay >= _HYPOT_TINY or ay == 0.0):
        return ax + ay if ay <= ax * _HYPOT_EPS else _hypot_kernel(ax, ay)
    return np.hypot(dx, dy)


@njit(inline="always", **JIT)
def row_span(start, i):
    """(first, end) of row i's list entries, unsigned: numba then indexes with them (and with unsigned neighbour
    indices) without the negative-index test, 28 % of a pass's inner loop."""
    return uint64(start[i]), uint64(start[i + 1])


@njit(inline="always", **JIT)
def weight(r, re):
    """MPS weight r_e / r - 1 (r clamped at 1e-6 r_e so coincident particles stay finite)."""
    if r >= re:
        return 0.0
    return re / max(r, 1e-6 * re) - 1.0


def _lattice_radii(re_over_l0):
    """Distances [l0] of the square lattice's points j != 0 closer than re_over_l0."""
    k = int(np.ceil(re_over_l0)) + 1
    g = np.arange(-k, k + 1, dtype=float)
    x, y = np.meshgrid(g, g)
    r = np.hypot(x, y).ravel()
    return r[(r > 0) & (r < re_over_l0)]


def lattice_constants(re_over_l0, l0=1.0):
    """(n0, lambda [cm^2]) of a full square lattice of spacing l0 for radius r_e = re_over_l0 l0.

    n0 = sum_j w(|r_j|), lambda = sum_j |r_j|^2 w / sum_j w over the lattice
    points j != 0 (Koshizuka & Oka 1996).  n0 does not depend on l0.
    """
    r = _lattice_radii(re_over_l0)
    wts = re_over_l0 / r - 1.0
    return float(wts.sum()), float((r**2 * wts).sum() / wts.sum() * l0**2)


def gradient_norm(mode, re_over_l0):
    """The lattice sum n_g that normalises the gradient of mode (GRADIENTS), d / n_g its constant: the number
    density n0 = sum_j w(r_j) for the Koshizuka-Oka forms (sum_j r_j r_j^T / r_j^2 w = n0 / d I), and
    sum_j r_e / r_j for the variational one (its weight -w'(r) r = r_e / r: sum_j r_e r_j r_j^T / r_j^3 =
    (1/d) sum_j r_e / r_j I), so that each is exact for a linear field on the lattice.  Does not depend on l0."""
    if mode >= GRADIENTS["variational"]:
        return float((re_over_l0 / _lattice_radii(re_over_l0)).sum())
    return lattice_constants(re_over_l0)[0]


# --- neighbour lists ------------------------------------------------------------------------------------


@njit(inline="always", **JIT)
def side_of(x, y, seg):
    """+1 if (x, y) is on the left (the given orientation's liquid side) of segment seg (4,) or on it, else -1."""
    c = (seg[2] - seg[0]) * (y - seg[1]) - (seg[3] - seg[1]) * (x - seg[0])
    return 1 if c >= 0.0 else -1


@njit(inline="always", **JIT)
def segments_cross(x0, y0, x1, y1, seg):
    """True if segment (x0, y0)-(x1, y1) meets segment seg (4,) (touching counts)."""
    ex = seg[2] - seg[0]
    ey = seg[3] - seg[1]
    s0 = ex * (y0 - seg[1]) - ey * (x0 - seg[0])
    s1 = ex * (y1 - seg[1]) - ey * (x1 - seg[0])
    if s0 * s1 > 0.0:
        return False
    mx = x1 - x0
    my = y1 - y0
    t0 = mx * (seg[1] - y0) - my * (seg[0] - x0)
    t1 = mx * (seg[3] - y0) - my * (seg[2] - x0)
    return t0 * t1 <= 0.0


@njit(**JIT)
def visible(i, j, pos, tw, tside, near, thin, behind=False):
    """Whether particles i and j see each other across the thin walls thin (T, 4).

    tw (N,) the thin wall a face particle belongs to (-1: none), tside (N,) its face (+1 / -1);
    near (N,) int64 bit t set when the particle is within reach of thin wall t.  A face particle of
    thin wall t is seen only by particles on its face's side of t (face particles: their face);
    any other pair is cut when the segment between them meets t.  behind: a face particle is seen only
    from where the wall hides it, i.e. when the segment to it also meets t (walls.thin_line_of_sight).
    """
    if tw[i] < 0 and tw[j] < 0 and (near[i] & near[j]) == 0:
        return True
    for t in range(thin.shape[0]):
        if tw[i] == t or tw[j] == t:
            si = tside[i] if tw[i] == t else side_of(pos[i, 0], pos[i, 1], thin[t])
            sj = tside[j] if tw[j] == t else side_of(pos[j, 0], pos[j, 1], thin[t])
            if si != sj:
                return False
            if behind and tw[i] != tw[j] and not segments_cross(pos[i, 0], pos[i, 1], pos[j, 0], pos[j, 1], thin[t]):
                return False
        elif (near[i] >> t) & 1 and (near[j] >> t) & 1:
            if segments_cross(pos[i, 0], pos[i, 1], pos[j, 0], pos[j, 1], thin[t]):
                return False
    return True


@njit(inline="always", **JIT)
def plain_row(i, tw, near, thin):
    """Particle i sees every particle but thin walls' face particles (visible's first test for any j): no thin walls,
    or i is no face particle and within reach of none."""
    return thin.shape[0] == 0 or (tw[i] < 0 and near[i] == 0)


@njit(inline="always", **JIT)
def sees(i, j, pos, tw, tside, near, thin, behind, plain):
    """visible(i, j, ...), plain = plain_row(i, ...): a plain row's non-face neighbours are seen without more tests
    (visible itself is a call, not inlined: the passes' inner loops stay small)."""
    if plain and (thin.shape[0] == 0 or tw[j] < 0):
        return True
    return visible(i, j, pos, tw, tside, near, thin, behind)


@njit(**JIT)
def cell_sort(pos, box, rc):
    """Counting sort of the particles into square-ish cells >= rc over box (4,) cm (outside: clamped).

    Returns (order (N,) particles cell by cell, ascending within a cell; cstart (C + 1,); cell (N,);
    ncx, ncy)."""
    n = pos.shape[0]
    ncx = max(1, int((box[2] - box[0]) / rc))
    ncy = max(1, int((box[3] - box[1]) / rc))
    csx = (box[2] - box[0]) / ncx
    csy = (box[3] - box[1]) / ncy
    cell = np.empty(n, np.int64)
    cstart = np.zeros(ncx * ncy + 1, np.int64)
    for i in range(n):
        cx = min(ncx - 1, max(0, int((pos[i, 0] - box[0]) / csx)))
        cy = min(ncy - 1, max(0, int((pos[i, 1] - box[1]) / csy)))
        cell[i] = cy * ncx + cx
        cstart[cell[i] + 1] += 1
    for c in range(ncx * ncy):
        cstart[c + 1] += cstart[c]
    fill = cstart[:-1].copy()
    order = np.empty(n, np.int64)
    for i in range(n):
        order[fill[cell[i]]] = i
        fill[cell[i]] += 1
    return order, cstart, cell, ncx, ncy


@njit(**PAR)
def near_thin(pos, thin, reach):
    """(N,) int64: bit t set when the particle is closer than reach [cm] to thin wall t (4,)."""
    n = pos.shape[0]
    out = np.zeros(n, np.int64)
    if thin.shape[0] == 0:  # no thin walls: no parallel loop to start
        return out
    for i in prange(n):
        m = 0
        for t in range(thin.shape[0]):
            ax, ay = thin[t, 0], thin[t, 1]
            ex, ey = thin[t, 2] - ax, thin[t, 3] - ay
            u = ((pos[i, 0] - ax) * ex + (pos[i, 1] - ay) * ey) / (ex * ex + ey * ey)
            u = min(1.0, max(0.0, u))
            dx = pos[i, 0] - ax - u * ex
            dy = pos[i, 1] - ay - u * ey
            if dx * dx + dy * dy < reach * reach:
                m |= np.int64(1) << t
        out[i] = m
    return out


@njit(inline="always", **JIT)
def _row(i, pos, order, cstart, cell, ncx, ncy, rc2, tw, tside, near, thin, store, nbr, k):
    """The neighbours of particle i (:func:`neighbour_list`'s order), stored at nbr[k:] if store (a literal:
    the counting pass compiles without the stores); returns their count."""
    c = cell[i]
    cx, cy = c % ncx, c // ncx
    m = 0
    for yy in range(max(0, cy - 1), min(ncy, cy + 2)):
        for xx in range(max(0, cx - 1), min(ncx, cx + 2)):
            cc = yy * ncx + xx
            for q in range(cstart[cc], cstart[cc + 1]):
                j = order[q]
                dx = pos[j, 0] - pos[i, 0]
                dy = pos[j, 1] - pos[i, 1]
                if j != i and dx * dx + dy * dy < rc2 and visible(i, j, pos, tw, tside, near, thin):
                    if store:
                        nbr[k + m] = j
                    m += 1
    return m


@njit(**PAR)
def neighbour_list(pos, kind, box, rc, tw, tside, thin):
    """Full neighbour lists: every visible j != i closer than rc [cm] (dummy particles get empty rows: no
    operator is evaluated at them).

    Row i lists its neighbours cell by cell (the 3 x 3 cells around i's, rows of cells from the bottom,
    left to right) in ascending particle order: a fixed order whatever the thread count.
    Returns (start (N + 1,) int64, nbr (M,) int32)."""
    n = pos.shape[0]
    order, cstart, cell, ncx, ncy = cell_sort(pos, box, rc)
    near = near_thin(pos, thin, rc)
    rc2 = rc * rc
    count = np.zeros(n + 1, np.int64)
    none = np.empty(0, np.int32)
    for i in prange(n):  # count the rows, then fill them
        if kind[i] != DUMMY:
            count[i + 1] = _row(i, pos, order, cstart, cell, ncx, ncy, rc2, tw, tside, near, thin, False, none, 0)
    for i in range(n):
        count[i + 1] += count[i]
    nbr = np.empty(count[n], np.int32)
    for i in prange(n):
        if kind[i] != DUMMY:
            _row(i, pos, order, cstart, cell, ncx, ncy, rc2, tw, tside, near, thin, True, nbr, count[i])
    return count, nbr


@njit(**PAR)
def distances(pos, start, nbr):
    """(M,) distance [cm] of every list entry at positions pos."""
    n = pos.shape[0]
    d = np.empty(nbr.shape[0])
    for i in prange(n):
        for k in range(start[i], start[i + 1]):
            j = nbr[k]
            d[k] = pair_distance(pos[j, 0] - pos[i, 0], pos[j, 1] - pos[i, 1])
    return d


@njit(**PAR)
def visible_distances(pos, start, nbr, tw, tside, thin, reach, behind=False):
    """(M,) distance [cm] of every list entry at positions pos, inf for a pair that does not see each other
    across the thin walls thin (T, 4) at pos (visible; reach [cm]: the lists' radius).  Every operator skips
    a pair at r >= its radius, so visibility is that of the positions the operators are evaluated at, not
    of the lists' build (a particle that grazes a thin wall's line changes side between builds)."""
    n = pos.shape[0]
    near = near_thin(pos, thin, reach)
    d = np.empty(nbr.shape[0])
    for i in prange(n):
        for k in range(start[i], start[i + 1]):
            j = nbr[k]
            if visible(i, j, pos, tw, tside, near, thin, behind):
                d[k] = pair_distance(pos[j, 0] - pos[i, 0], pos[j, 1] - pos[i, 1])
            else:
                d[k] = np.inf
    return d


# --- operators (gathers over the lists) ---------------------------------------------------------------------


@njit(**PAR)
def number_density(start, nbr, dist, re):
    """(N,) number density sum_j w(r_ij) over every listed neighbour (fluid, wall, dummy)."""
    n = start.shape[0] - 1
    out = np.zeros(n)
    for i in prange(n):
        s = 0.0
        for k in range(start[i], start[i + 1]):
            s += weight(dist[k], re)
        out[i] = s
    return out


@njit(inline="always", **JIT)
def divergence_term(hs, i, j, pos, vel, r, re):
    """Pair (i, j)'s term of particle i's divergence sum at distance r: the K&O model's (u_ij . r_ij) / r^2 w(r), or
    (hs) Khayyer & Gotoh 2009's (u_ij . r_ij) r_e / r^3 (0 from r_e on)."""
    if hs:
        if r >= re:
            return 0.0
        rr = max(r, 1e-6 * re)
        return ((vel[j, 0] - vel[i, 0]) * (pos[j, 0] - pos[i, 0]) + (vel[j, 1] - vel[i, 1]) * (pos[j, 1] - pos[i, 1])) \
            * re / (rr * rr * rr)
    wt = weight(r, re)
    if wt == 0.0:
        return 0.0
    return ((vel[j, 0] - vel[i, 0]) * (pos[j, 0] - pos[i, 0]) + (vel[j, 1] - vel[i, 1]) * (pos[j, 1] - pos[i, 1])) \
        / (r * r) * wt


@njit(inline="always", **JIT)
def divergence_value(hs, s, n0):
    """Particle i's divergence [1/s] from its sum of divergence_term: d / n0 times it, or (hs) 1 / n0."""
    return s / n0 if hs else s * (DIM / n0)


@njit(**PAR)
def _divergence(pos, vel, start, nbr, dist, re, n0, hs):
    n = pos.shape[0]
    out = np.zeros(n)
    for i in prange(n):
        s = 0.0
        for k in range(start[i], start[i + 1]):
            if dist[k] < re:
                s += divergence_term(hs, i, nbr[k], pos, vel, dist[k], re)
        out[i] = divergence_value(hs, s, n0)
    return out


@njit(**JIT)
def divergence(pos, vel, start, nbr, dist, re, n0):
    """(N,) MPS divergence of vel [1/s] (all neighbours; wall particles' velocity is theirs, 0)."""
    return _divergence(pos, vel, start, nbr, dist, re, n0, False)


@njit(**JIT)
def divergence_hs(pos, vel, start, nbr, dist, re, n0):
    """(N,) divergence as the higher-order source term of Khayyer & Gotoh 2009 (Appl. Ocean Res. 31, 111):
    -(1/n0) Dn/Dt with the analytic rate of the number density, Dn/Dt = -sum_j r_e / r^3 (r_ij . u_ij) [1/s]
    (all neighbours within re; wall particles' velocity is theirs, 0)."""
    return _divergence(pos, vel, start, nbr, dist, re, n0, True)


@njit(**PAR)
def laplacian(f, kind, start, nbr, dist, re, n0, lam):
    """(N, C) MPS Laplacian of f (N, C) at the fluid particles over fluid and wall neighbours (0 elsewhere)."""
    n = f.shape[0]
    out = np.zeros_like(f)
    c = 2.0 * DIM / (lam * n0)
    for i in prange(n):
        if kind[i] != FLUID:
            continue
        for k in range(start[i], start[i + 1]):
            j = nbr[k]
            if kind[j] == DUMMY:
                continue
            wt = weight(dist[k], re)
            for q in range(f.shape[1]):
                out[i, q] += (f[j, q] - f[i, q]) * wt
        for q in range(f.shape[1]):
            out[i, q] *= c
    return out


@njit(inline="always", **JIT)
def in_gradient(mode, kind_j):
    """Whether a neighbour of this kind enters the gradient: fluid and wall particles (the pressure-carrying ones);
    dummy particles too in variational_dummies (mode 5, with their P = 0: they are in the number density)."""
    return kind_j != DUMMY or mode == 5


@njit(**PAR)
def neighbourhood_min(p, kind, start, nbr, dist, re):
    """(N,) p^_i: the minimum of p_i and its fluid and wall neighbours' p within re (K&O 1996's gradient)."""
    pmin = p.copy()
    for i in prange(p.shape[0]):
        if kind[i] == DUMMY:
            continue
        m = p[i]
        for k in range(start[i], start[i + 1]):
            j = nbr[k]
            if kind[j] != DUMMY and dist[k] < re:
                m = min(m, p[j])
        pmin[i] = m
    return pmin


@njit(inline="always", **JIT)
def pair_coefficient(mode, pi, pj, mi, mj, r, re):
    """q of pair (i, j) at distance r < re in the gradient sum sum_j q r_ij (before the constant d / n_g):
    0, 1 (p_j - p^_i) w / r^2; 2 (p_i + p_j) w / r^2; 3 ((p_i - p^_i) + (p_j - p^_j)) w / r^2;
    4, 5 (p_i + p_j) r_e / r^3 (-w'(r) / r, the variational forms).  mi, mj: p^_i, p^_j."""
    if mode >= 4:
        rr = max(r, 1e-6 * re)
        return (pi + pj) * re / (rr * rr * rr)
    wt = weight(r, re)
    if mode <= 1:
        return (pj - mi) / (r * r) * wt
    if mode == 2:
        return (pj + pi) / (r * r) * wt
    return ((pj - mj) + (pi - mi)) / (r * r) * wt


@njit(**PAR)
def gradient(pos, p, kind, start, nbr, dist, re, n0, mode):
    """(N, 2) MPS pressure gradient [N/cm^3] at the fluid particles (0 elsewhere), over fluid and wall
    neighbours (not dummies, but for mode 5).  n0: the lattice sum that normalises the mode (gradient_norm).
    mode (GRADIENTS): 0 K&O 1996, sum (p_j - p^_i), p^_i the minimum of p_i and its neighbours' (MPS-Basic's
    calPressureGradient); 1 the same with the corrective matrix C_i = (d/n0 sum_j w r_ij r_ij^T / r^2)^-1
    (Khayyer & Gotoh 2011; the plain sum where det C_i^-1 < 0.01); 2 sum (p_i + p_j) (pairwise antisymmetric:
    momentum-conserving); 3 CMPS (Khayyer & Gotoh 2008, Coastal Eng. J. 50, 179), sum [(p_i + p_j) - (p^_i +
    p^_j)]: momentum-conserving and, both shifted pressures being >= 0, repulsive for every pair; 4 variational
    (Suzuki, Koshizuka & Oka 2007): C sum_j (p_i + p_j) r_e r_ij / r^3 over fluid and wall neighbours = C sum_k
    p_k dn'_k/dx_i, n' the number density over fluid and wall particles (the full one but for the dummies'
    share, a fixed function of x_i for a fluid particle within r_e of a dummy row), C = d / sum_lattice r_e / r:
    antisymmetric pair terms, and its power on the liquid is -C / rho0 sum_k p_k dn'_k/dt (pressure works only
    by changing number densities); 5 the same over every neighbour, dummies (P = 0) included: C sum_k p_k
    dn_k/dx_i with n the full number density of the source term.
    """
    n = pos.shape[0]
    pmin = neighbourhood_min(p, kind, start, nbr, dist, re) if mode in (0, 1, 3) else p
    out = np.zeros((n, 2))
    a = DIM / n0
    for i in prange(n):
        if kind[i] != FLUID:
            continue
        out[i, 0], out[i, 1], _ = gradient_row(i, pos, p, pmin, kind, start, nbr, dist, re, a, mode, False, nbr, p)
    return out


@njit(inline="always", **JIT)
def gradient_row(i, pos, p, pmin, kind, start, nbr, dist, re, a, mode, record, wk, wq):
    """(gx, gy, walls) of fluid particle i: its pressure gradient (gradient; a = d / n_g, pmin: p^ or p) and the number
    of its terms that are a boundary particle's (its share of the walls' forces, wall_terms).  record (a constant):
    the boundary terms' list entries k and pair coefficients q are stored at wk, wq[start[i]:] (recorded_wall_terms)."""
    gx = gy = 0.0
    walls = 0
    first, end = row_span(start, i)
    for k in range(first, end):
        j = uint64(nbr[k])
        if dist[k] >= re or not in_gradient(mode, kind[j]):
            continue
        q = pair_coefficient(mode, p[i], p[j], pmin[i], pmin[j], dist[k], re)
        if kind[j] != FLUID:
            if record:
                wk[first + walls] = k
                wq[first + walls] = q
            walls += 1
        gx += q * (pos[j, 0] - pos[i, 0])
        gy += q * (pos[j, 1] - pos[i, 1])
    gx *= a
    gy *= a
    if mode == 1:
        gx, gy = corrected(gx, gy, corrective(i, pos, kind, start, nbr, dist, re, a))
    return gx, gy, walls


@njit(inline="always", **JIT)
def corrective(i, pos, kind, start, nbr, dist, re, a):
    """(mxx, mxy, myy, det): particle i's moment matrix a sum_j w r_ij r_ij^T / r^2 over its fluid and wall neighbours
    and its determinant; corrected applies its inverse, the corrective matrix of Khayyer & Gotoh 2011."""
    mxx = mxy = myy = 0.0
    for k in range(start[i], start[i + 1]):
        if dist[k] >= re or kind[nbr[k]] == DUMMY:
            continue
        j = nbr[k]
        dx = pos[j, 0] - pos[i, 0]
        dy = pos[j, 1] - pos[i, 1]
        wr = weight(dist[k], re) / (dist[k] * dist[k])
        mxx += dx * dx * wr
        mxy += dx * dy * wr
        myy += dy * dy * wr
    mxx *= a
    mxy *= a
    myy *= a
    return mxx, mxy, myy, mxx * myy - mxy * mxy


@njit(inline="always", **JIT)
def corrected(gx, gy, m):
    """(gx, gy) times the inverse of the moment matrix m = corrective(...); unchanged where det <= 0.01 (near
    singular)."""
    mxx, mxy, myy, det = m
    if det > 0.01:
        return (myy * gx - mxy * gy) / det, (mxx * gy - mxy * gx) / det
    return gx, gy


@njit(**JIT)
def wall_forces(pos, p, kind, start, nbr, dist, re, n0, mode, mass_over_rho):
    """(N, 2) force [N] of each boundary particle on the liquid (0 at liquid particles): the terms of the fluid
    particles' pressure gradients (gradient, same arguments) that come from their boundary neighbours, times -m /
    rho0 (mass_over_rho [cm^2], l0^2 in 2D).  For the pairwise antisymmetric forms (PAIRWISE: symmetric, cmps,
    variational) this is the momentum the walls exchange with the liquid, and floor plus side walls carry the
    liquid's weight at rest; for the K&O forms it is the boundary neighbours' share of sums that are not pairwise
    (the liquid's internal terms do not cancel).  Serial (a scatter onto the boundary particles)."""
    pmin = neighbourhood_min(p, kind, start, nbr, dist, re) if mode in (0, 1, 3) else p
    out = np.zeros((pos.shape[0], 2))
    for i in range(pos.shape[0]):
        if kind[i] == FLUID:
            wall_terms(i, out, 0, pos, p, pmin, kind, start, nbr, dist, re, DIM / n0, mode, mass_over_rho)
    return out


@njit(inline="always", **JIT)
def wall_terms(i, out, first, pos, p, pmin, kind, start, nbr, dist, re, a, mode, mass_over_rho):
    """Add fluid particle i's boundary-neighbour terms of its pressure gradient, times -mass_over_rho, to out[j - first]
    of each boundary neighbour j (wall_forces; a = d / n_g, pmin: p^ or p).  Serial: a scatter."""
    m = (1.0, 0.0, 1.0, 1.0)
    fresh = True
    for k in range(start[i], start[i + 1]):
        j = nbr[k]
        if kind[j] == FLUID or dist[k] >= re or not in_gradient(mode, kind[j]):
            continue
        if mode == 1 and fresh:
            m = corrective(i, pos, kind, start, nbr, dist, re, a)
            fresh = False
        wall_term(i, j, a * pair_coefficient(mode, p[i], p[j], pmin[i], pmin[j], dist[k], re), pos, m, mode, out,
                  first, mass_over_rho)


@njit(inline="always", **JIT)
def recorded_wall_terms(i, out, first, pos, kind, start, nbr, dist, re, a, mode, mass_over_rho, wk, wq, walls):
    """wall_terms from the boundary terms gradient_row recorded (walls of them at wk, wq[start[i]:])."""
    m = corrective(i, pos, kind, start, nbr, dist, re, a) if mode == 1 else (1.0, 0.0, 1.0, 1.0)
    for t in range(start[i], start[i] + walls):
        wall_term(i, nbr[wk[t]], a * wq[t], pos, m, mode, out, first, mass_over_rho)


@njit(inline="always", **JIT)
def wall_term(i, j, q, pos, m, mode, out, first, mass_over_rho):
    """One boundary term of fluid particle i's pressure gradient, q r_ij (q: d / n_g times the pair coefficient; mode 1
    times the inverse of the moment matrix m), times -mass_over_rho, added to out[j - first]."""
    gx = q * (pos[j, 0] - pos[i, 0])
    gy = q * (pos[j, 1] - pos[i, 1])
    if mode == 1:
        gx, gy = corrected(gx, gy, m)
    out[j - first, 0] -= mass_over_rho * gx
    out[j - first, 1] -= mass_over_rho * gy


@njit(**PAR)
def offsets(pos, start, nbr, dist, rc, re):
    """((N, 2) sum_j r_ij [cm] over neighbours closer than rc (MPS-Basic's particle-distribution test),
    (N, 2) sum_j w(r_ij; re) r_ij [cm]: points from a surface particle into the liquid)."""
    n = pos.shape[0]
    s = np.zeros((n, 2))
    sw = np.zeros((n, 2))
    for i in prange(n):
        for k in range(start[i], start[i + 1]):
            j = nbr[k]
            dx = pos[j, 0] - pos[i, 0]
            dy = pos[j, 1] - pos[i, 1]
            if dist[k] < rc:
                s[i, 0] += dx
                s[i, 1] += dy
            wt = weight(dist[k], re)
            sw[i, 0] += wt * dx
            sw[i, 1] += wt * dy
    return s, sw


@njit(**JIT)
def probe_pressure(pos, p, kind, probes, re):
    """(K,) pressure [N/cm^2] at fixed points: MPS-weighted mean of fluid particle pressures (NaN if none in range)."""
    out = np.full(probes.shape[0], np.nan)
    for k in range(probes.shape[0]):
        sw = 0.0
        sp = 0.0
        for i in range(pos.shape[0]):
            if kind[i] != FLUID:
                continue
            wt = weight(pair_distance(pos[i, 0] - probes[k, 0], pos[i, 1] - probes[k, 1]), re)
            sw += wt
            sp += wt * p[i]
        if sw > 0.0:
            out[k] = sp / sw
    return out

