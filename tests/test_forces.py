"""Force kernels against hand-computed values, Newton's third law, cell list vs brute force."""

import numpy as np
import pytest

from isaflow.core import geometry as GEO
from isaflow.core import neighbours as NB
from isaflow.methods.isa import forces as F
from isaflow.methods.isa import relax as R

from conftest import L_B, L_P, R_B, R_P




def test_single_pair_force_by_hand():
    # distance 5 cm: R = 3535.5339 (1 - 5 / 7.0710678) = 1035.53 N, along +x on i
    fx, fy = F.pair_push(5.0, 0.0, L_P, R_P)
    assert fx == pytest.approx(1035.534, abs=1e-3) and fy == 0.0
    # diagonal separation (3, 4): same magnitude, along (0.6, 0.8)
    fx, fy = F.pair_push(3.0, 4.0, L_P, R_P)
    assert (fx, fy) == pytest.approx((0.6 * 1035.534, 0.8 * 1035.534), abs=1e-3)
    assert F.pair_push(7.08, 0.0, L_P, R_P) == (0.0, 0.0)


def test_wall_force_interior_and_segment_end_by_hand():
    # above the interior of floor (0,0)-(10,0) at height 1 cm: 10000 (1 - 1/5) = 8000 N up
    assert F.wall_push(4.0, 1.0, 0, 0, 10, 0, L_B, R_B) == pytest.approx((0.0, 8000.0))
    # beyond the end: closest point is (10, 0); d = sqrt(2^2 + 3^2) = 3.6056 cm
    d = np.hypot(2.0, 3.0)
    mag = R_B * (1 - d / L_B)
    assert F.wall_push(12.0, 3.0, 0, 0, 10, 0, L_B, R_B) == pytest.approx((mag * 2 / d, mag * 3 / d))
    # out of reach of the end
    assert F.wall_push(14.0, 4.0, 0, 0, 10, 0, L_B, R_B) == (0.0, 0.0)


def test_particle_exactly_on_wall_is_pushed_to_the_liquid_side():
    # floor oriented left->right has the liquid on its left (+y)
    assert F.wall_push(5.0, 0.0, 0, 0, 10, 0, L_B, R_B) == pytest.approx((0.0, R_B))


def random_cloud(n, seed, size=60.0):
    rng = np.random.default_rng(seed)
    return rng.uniform(0, size, (n, 2))


def brute_forces(pos, weight, walls):
    f = np.zeros_like(pos)
    f[:, 1] -= weight
    for i in range(len(pos)):
        for w in walls:
            f[i] += F.wall_push(pos[i, 0], pos[i, 1], *w, L_B, R_B)
        for j in range(len(pos)):
            if i != j:
                f[i] += F.pair_push(*(pos[i] - pos[j]), L_P, R_P)
    return f


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_cell_list_forces_equal_brute_force(seed):
    pos = random_cloud(300, seed)
    walls = np.array([[0, 60, 0, 0], [0, 0, 60, 0], [60, 0, 60, 30]], float)  # right wall ends at y=30
    weight = np.full(len(pos), 50.0)
    box = np.array([0.0, 0.0, 60.0, 60.0])
    pi, pj, m = NB.build_pairs(pos, box, L_P + 1.0)
    f = np.zeros_like(pos)
    fmax = F.forces(pos, weight, walls, L_B, R_B, L_P, R_P, pi, pj, m, f)
    ref = brute_forces(pos, weight, walls)
    np.testing.assert_allclose(f, ref, rtol=1e-10, atol=1e-8)
    assert fmax == pytest.approx(np.abs(ref).max())


@pytest.mark.parametrize("seed", [3, 4])
def test_neighbour_list_holds_exactly_the_close_pairs(seed):
    pos = random_cloud(500, seed)
    rc = 8.0
    pi, pj, m = NB.build_pairs(pos, np.array([0.0, 0.0, 60.0, 60.0]), rc)
    got = {tuple(sorted(p)) for p in zip(pi[:m], pj[:m])}
    d = np.hypot(*(pos[:, None, :] - pos[None, :, :]).transpose(2, 0, 1))
    want = {(i, j) for i, j in zip(*np.nonzero(np.triu(d < rc, 1)))}
    assert got == want and m == len(want)


def test_pair_forces_obey_newtons_third_law():
    pos = random_cloud(400, 5)
    pi, pj, m = NB.build_pairs(pos, np.array([0.0, 0.0, 60.0, 60.0]), L_P)
    f = np.zeros_like(pos)
    F.forces(pos, np.zeros(len(pos)), np.zeros((0, 4)), L_B, R_B, L_P, R_P, pi, pj, m, f)
    assert np.abs(f).max() > 1000.0  # the cloud does overlap
    np.testing.assert_allclose(f.sum(0), 0.0, atol=1e-8)


def test_move_across_a_wall_is_refused_and_reported():
    # one particle 0.05 cm above the floor, du 0.1 cm straight down with a weak wall
    pos = np.array([[50.0, 0.05]])
    walls = np.array([[0, 0, 100, 0]], float)
    f = np.zeros_like(pos)
    hist = np.zeros(10)
    steps, status, info = R.relax(pos, np.zeros_like(pos), np.array([1e6]), walls, np.array([0, -1, 100, 10.0]),
                                  L_B, 1.0, L_P, R_P, R.PAPER, 0.1, 1.0, 1.0, 0.1, 10, 1.0, f, hist)
    assert status == R.CROSSED and info == 0 and steps == 0  # particle 0, wall 0
    assert pos[0, 1] == 0.05  # the step was not taken


def test_move_past_an_opening_edge_is_refused():
    # wall from (100, 20) up; a particle at (99.9, 20.05) pushed hard to +x would cross it
    walls = np.array([[100, 20, 100, 100]], float)
    assert GEO.crossed_wall(99.9, 20.05, 100.1, 20.05, walls) == 0
    # below the wall's end the opening is free
    assert GEO.crossed_wall(99.9, 19.0, 100.1, 19.0, walls) == -1
