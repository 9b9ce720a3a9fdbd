"""The optimised relax() against plain references: brute-force forces, fresh full pair lists, the plain loop.

relax() keeps its state in cell order, evaluates wall forces and the crossing
test only near the walls and fuses passes; these tests pin that it still
computes exactly what the straightforward algorithm computes.  Units cm, N.
"""

import numpy as np
import pytest

from isaflow.methods.isa.scene import rhombic_lattice
from isaflow.methods.isa import forces as F
from isaflow.core import geometry as GEO
from isaflow.core import neighbours as NB
from isaflow.methods.isa import relax as R

A = 10.0
L_P, R_P = A / np.sqrt(2.0), 500.0 * A / np.sqrt(2.0)  # pair law: cm, N
L_B, R_B = 5.0, 10000.0  # wall law: cm, N
WALLS = np.array([
    [0, 60, 0, 0],  # left
    [0, 0, 60, 0],  # floor
    [60, 0, 60, 30],  # right wall ends at y = 30 (opening above)
    [20, 45, 35, 38],  # a free-standing tilted baffle with two ends inside the cloud
], float)
BOX = np.array([0.0, 0.0, 60.0, 60.0])


def brute_forces(pos, weight, walls, wl_u, wr_u, pl_u, pr_u):
    """Out-of-balance forces [N] by an O(N^2) double loop written in plain NumPy."""
    f = np.zeros_like(pos)
    f[:, 1] = -weight
    for x0, y0, x1, y1 in walls:
        ex, ey = x1 - x0, y1 - y0
        L2 = ex * ex + ey * ey
        t = np.clip(((pos[:, 0] - x0) * ex + (pos[:, 1] - y0) * ey) / L2, 0.0, 1.0)
        dx = pos[:, 0] - (x0 + t * ex)
        dy = pos[:, 1] - (y0 + t * ey)
        d = np.hypot(dx, dy)
        hit = d < wl_u
        on = hit & (d == 0)
        s = np.where(hit & ~on, wr_u * (1.0 / np.where(on | ~hit, 1.0, d) - 1.0 / wl_u), 0.0)
        f[:, 0] += s * dx + np.where(on, -wr_u * ey / np.sqrt(L2), 0.0)
        f[:, 1] += s * dy + np.where(on, wr_u * ex / np.sqrt(L2), 0.0)
    dx = pos[:, None, 0] - pos[None, :, 0]
    dy = pos[:, None, 1] - pos[None, :, 1]
    d = np.hypot(dx, dy)
    off = ~np.eye(len(pos), dtype=bool)
    hit = off & (d < pl_u)
    zero = hit & (d == 0)
    s = np.where(hit & ~zero, pr_u * (1.0 / np.where(hit & ~zero, d, 1.0) - 1.0 / pl_u), 0.0)
    f[:, 0] += (s * dx).sum(1)
    f[:, 1] += (s * dy).sum(1)
    # coincident particles: the lower-numbered one is pushed along +x
    upper = np.triu(zero, 1)
    f[:, 0] += pr_u * upper.sum(1) - pr_u * upper.sum(0)
    return f


def random_configuration(seed, n=400):
    rng = np.random.default_rng(seed)
    pos = rng.uniform(0.5, 59.5, (n, 2))
    # particles close to the wall ends (within l_u of an end point), including
    # beyond the free ends of the right wall and of the baffle
    ends = np.array([[60, 30], [20, 45], [35, 38], [0, 0], [60, 0]], float)
    k = 60
    ang = rng.uniform(0, 2 * np.pi, k)
    rad = rng.uniform(0.0, 1.2 * L_B, k)
    pos[:k] = ends[rng.integers(0, len(ends), k)] + np.column_stack([rad * np.cos(ang), rad * np.sin(ang)])
    pos[k] = [30.0, 0.0]  # exactly on the floor: pushed along its left normal
    pos[k + 1] = [61.5, 10.0]  # outside the box (clamped into the edge cells)
    pos[k + 2] = pos[k + 3] = [40.0, 20.0]  # coincident pair
    return pos


def relax_forces(pos, weight, walls, skin, wl_u=L_B, wr_u=R_B, pl_u=L_P, pr_u=R_P):
    """(f, max|F|) as computed inside relax() (a step-0 stop returns them)."""
    f = np.zeros_like(pos)
    hist = np.zeros(1)
    p = pos.copy()
    steps, status, _ = R.relax(p, np.zeros_like(p), weight, walls, BOX, wl_u, wr_u, pl_u, pr_u, R.PAPER,
                               0.01, 1.0, 0.1, np.inf, 1, skin, f, hist)
    assert (steps, status) == (0, R.CONVERGED)
    np.testing.assert_array_equal(p, pos)
    return f, hist[0]


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("skin", [0.0, 0.3 * L_P, 4.0])
def test_relax_forces_equal_brute_force(seed, skin):
    pos = random_configuration(seed)
    weight = np.random.default_rng(seed).uniform(10.0, 60.0, len(pos))
    f, fmax = relax_forces(pos, weight, WALLS, skin)
    ref = brute_forces(pos, weight, WALLS, L_B, R_B, L_P, R_P)
    scale = np.abs(ref).max()
    np.testing.assert_allclose(f, ref, rtol=1e-9, atol=1e-9 * scale)
    assert fmax == pytest.approx(scale, rel=1e-12)
    # the public forces() with build_pairs' list agrees too
    pi, pj, m = NB.build_pairs(pos, BOX, L_P + skin)
    f2 = np.zeros_like(pos)
    F.forces(pos, weight, WALLS, L_B, R_B, L_P, R_P, pi, pj, m, f2)
    np.testing.assert_array_equal(f, f2)


def small_lattice():
    """The paper's coarse lattice (180 particles, a = 10 cm) in its 100 cm vessel."""
    pos = rhombic_lattice(A, 19, [9, 10], 50.0, 5.0)
    walls = np.array([[0, 100, 0, 0], [0, 0, 100, 0], [100, 0, 100, 100]], float)
    return pos, walls, np.array([0.0, 0.0, 100.0, 100.0])


def test_relax_history_equals_fresh_full_pair_list_each_step():
    pos0, walls, box = small_lattice()
    n, n_steps, du = len(pos0), 500, 0.01
    weight = np.full(n, 50.0)
    pos = pos0.copy()
    f = np.zeros_like(pos)
    hist = np.zeros(n_steps)
    steps, status, _ = R.relax(pos, np.zeros_like(pos), weight, walls, box, L_B, R_B, L_P, R_P, R.PAPER, du,
                               1.0, 0.1, 1e-30, n_steps, 0.3 * L_P, f, hist)
    assert (steps, status) == (n_steps, R.RUNNING)
    # reference: every pair i < j, rebuilt from scratch before every force evaluation
    p = pos0.copy()
    g = np.zeros_like(p)
    ref = np.zeros(n_steps)
    for k in range(n_steps + 1):
        pi, pj = (a.astype(np.int32) for a in np.triu_indices(n, 1))
        fmax = F.forces(p, weight, walls, L_B, R_B, L_P, R_P, pi, pj, len(pi), g)
        if k == n_steps:
            break
        ref[k] = fmax
        p += (du / fmax) * g
    np.testing.assert_allclose(hist, ref, rtol=1e-9)
    np.testing.assert_allclose(pos, p, rtol=0, atol=1e-9)
    np.testing.assert_allclose(f, g, rtol=1e-9, atol=1e-9 * np.abs(g).max())


def plain_relax(pos, weight, walls, box, variant, du, f_ref, n_steps, skin):
    """The straightforward loop: move (refusing wall crossings), rebuild with build_pairs when due, forces()."""
    pos = pos.copy()
    f = np.zeros_like(pos)
    rc = L_P + skin
    pi, pj, m = NB.build_pairs(pos, box, rc)
    moved = 0.0
    fmax = F.forces(pos, weight, walls, L_B, R_B, L_P, R_P, pi, pj, m, f)
    hist = []
    for step in range(n_steps):
        hist.append(fmax)
        scale = du / fmax if variant == R.PAPER else du / max(fmax, f_ref)
        for i in range(len(pos)):
            x1, y1 = pos[i, 0] + scale * f[i, 0], pos[i, 1] + scale * f[i, 1]
            w = GEO.crossed_wall(pos[i, 0], pos[i, 1], x1, y1, walls)
            if w >= 0:
                for k in range(i):
                    pos[k, 0] -= scale * f[k, 0]
                    pos[k, 1] -= scale * f[k, 1]
                return pos, f, np.array(hist), (step, R.CROSSED, i * len(walls) + w)
            pos[i] = x1, y1
        moved += np.sqrt(2.0) * (scale * fmax)
        if moved > 0.5 * skin:
            pi, pj, m = NB.build_pairs(pos, box, rc)
            moved = 0.0
        fmax = F.forces(pos, weight, walls, L_B, R_B, L_P, R_P, pi, pj, m, f)
    return pos, f, np.array(hist), (n_steps, R.RUNNING, -1)


@pytest.mark.parametrize("variant", [R.PAPER, R.CAPPED])
def test_relax_is_bit_identical_to_the_plain_loop(variant):
    pos0, walls, box = small_lattice()
    weight = np.full(len(pos0), 50.0)
    n_steps, skin = 400, 0.3 * L_P
    ref_pos, ref_f, ref_hist, ref_ret = plain_relax(pos0, weight, walls, box, variant, 0.01, 50.0, n_steps, skin)
    pos = pos0.copy()
    f = np.zeros_like(pos)
    hist = np.zeros(n_steps)
    ret = R.relax(pos, np.zeros_like(pos), weight, walls, box, L_B, R_B, L_P, R_P, variant, 0.01, 50.0, 0.1,
                  1e-30, n_steps, skin, f, hist)
    assert tuple(ret) == ref_ret
    np.testing.assert_array_equal(hist, ref_hist)
    np.testing.assert_array_equal(pos, ref_pos)
    np.testing.assert_array_equal(f, ref_f)


def test_far_particle_with_a_huge_step_is_still_caught_crossing():
    # the crossing test normally visits only particles near a wall; a step
    # longer than wl_u + skin must make it test everyone (particle 2 here)
    pos = np.array([[30.0, 40.0], [45.0, 40.0], [10.0, 20.0], [50.0, 50.0]])
    walls = np.array([[0, 0, 60, 0]], float)
    weight = np.array([1.0, 1.0, 1e4, 1.0])  # particle 2 carries max|F|: it moves du straight down
    box = np.array([0.0, -30.0, 60.0, 60.0])
    ref = plain_relax(pos, weight, walls, box, R.PAPER, 25.0, 1.0, 3, 1.0)
    p = pos.copy()
    f = np.zeros_like(p)
    ret = R.relax(p, np.zeros_like(p), weight, walls, box, L_B, R_B, L_P, R_P, R.PAPER, 25.0, 1.0, 0.1, 1e-30, 3,
                  1.0, f, np.zeros(3))
    assert tuple(ret) == ref[3] == (0, R.CROSSED, 2)
    np.testing.assert_array_equal(p, ref[0])  # particles 0, 1 moved and moved back exactly as in the plain loop
