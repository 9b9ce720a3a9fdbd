"""Hydrostatic theory, free-surface level, cycle detection and the step-stability floor."""

import numpy as np
import pytest

from isaflow import theory
from isaflow.methods.isa import solver
from isaflow.methods.isa.scene import rhombic_lattice

from conftest import box_walls
from isaflow.methods.isa import forces as F
from isaflow.core import neighbours as NB
from isaflow.methods.isa import theory as isa_theory


def test_wall_totals_are_the_hydrostatic_integrals():
    walls = box_walls()
    W, B, h = 9000.0, 100.0, 72.5
    g = theory.specific_weight(W, B, h)
    assert g == pytest.approx(W / (B * h))
    assert theory.wall_total(walls[1], g, h) == pytest.approx(W)  # floor carries the weight
    side = 0.5 * g * h**2
    assert theory.wall_total(walls[0], g, h) == pytest.approx(side)  # downward-oriented wall
    assert theory.wall_total(walls[2], g, h) == pytest.approx(side)  # upward-oriented wall
    assert theory.implied_level(side, W, B) == pytest.approx(h)


def test_contact_theory_partitions_each_wall_total():
    walls = box_walls()
    g, h = 1.2, 70.0
    ys = np.arange(5.0, 100.0, 5.0)
    xs = np.arange(10.0, 91.0, 10.0)
    cw = np.concatenate([np.zeros(len(ys), int), np.ones(len(xs), int), np.full(len(ys), 2)])
    cp = np.concatenate([np.column_stack([np.zeros_like(ys), ys]), np.column_stack([xs, np.zeros_like(xs)]),
                         np.column_stack([np.full_like(ys, 100.0), ys])])
    th = theory.contact_theory(walls, cw, cp, g, h)
    for w in range(3):
        assert th[cw == w].sum() == pytest.approx(theory.wall_total(walls[w], g, h))
    # floor contacts in the middle carry gamma h times their 10 cm tributary width
    assert th[len(ys) + 4] == pytest.approx(g * h * 10.0)
    # a side contact above the surface carries nothing
    assert th[np.flatnonzero((cw == 0) & (cp[:, 1] > h + 2.5))].max() == 0.0


def test_resultant_height_of_a_triangle_is_a_third():
    y = np.linspace(0, 60, 6001)
    assert theory.resultant_height(y, 60 - y) == pytest.approx(20.0, abs=0.01)


def test_free_surface_level_of_the_initial_coarse_lattice():
    pos = rhombic_lattice(10.0, 19, [9, 10], 50.0, 5.0)
    # strips [0, 10), [10, 20), ...: the top row of 9 (y = 95) reaches all strips but
    # the first, which holds only x = 5 of the rows of 10 (top at y = 90)
    assert theory.free_surface_level(pos, 10.0, (0.0, 100.0)) == pytest.approx((90 + 9 * 95) / 10)
    assert theory.free_surface_level(pos, 10.0, (0.0, 20.0)) == pytest.approx(92.5)
    assert np.isnan(theory.free_surface_level(pos, 10.0, (200.0, 300.0)))


def test_detect_cycle():
    rng = np.random.default_rng(0)
    assert solver.detect_cycle(np.tile([8.0, 23.6], 400)) == 2
    assert solver.detect_cycle(np.tile([1.0, 2.0, 3.0], 300)) == 3
    assert solver.detect_cycle(np.full(800, 50.0)) == 0  # constant max|F| (free fall) is no cycle
    assert solver.detect_cycle(rng.uniform(1, 2, 800)) == 0
    assert solver.detect_cycle(np.tile([8.0, 23.6], 100)) == 0  # too short to tell


def test_stiffness_matrix_of_one_particle_on_the_floor():
    walls = box_walls()
    lam, floor = isa_theory.step_floor(np.array([[50.0, 4.0]]), walls, 5.0, 10000.0, 7.07, 3535.5, 0.01)
    assert lam == pytest.approx(2000.0)  # k_b = 10000 / 5 N/cm, vertical only
    assert floor == pytest.approx(10.0)


def test_stiffness_matrix_is_the_force_jacobian():
    pos = rhombic_lattice(10.0, 5, [3, 4], 20.0, 4.0) + np.random.default_rng(1).normal(0, 0.3, (17, 2))
    walls = box_walls(40.0, 40.0)
    args = (walls, 5.0, 10000.0, 7.0710678, 3535.5339)
    H = isa_theory.stiffness_matrix(pos, *args).toarray()

    def force(p):
        
        f = np.zeros_like(p)
        pi, pj, m = NB.build_pairs(p, np.array([0, 0, 40.0, 40.0]), 8.0)
        F.forces(p, np.zeros(len(p)), walls, *args[1:], pi, pj, m, f)
        return f.ravel()

    eps = 1e-6
    J = np.empty_like(H)
    for k in range(H.shape[0]):
        d = np.zeros(H.shape[0])
        d[k] = eps
        J[:, k] = -(force(pos + d.reshape(-1, 2)) - force(pos - d.reshape(-1, 2))) / (2 * eps)
    np.testing.assert_allclose(H, J, atol=1e-3 * np.abs(H).max())


@pytest.mark.parametrize("theta_deg", [30.0, 45.0, 60.0, 75.0, 90.0])
def test_a_sloping_wall_carries_the_closed_form_normal_load(theta_deg):
    """A plane wall of slope theta from the horizontal wetted to depth h carries gamma h^2 / (2 sin theta) normal
    to it per unit thickness; the liquid pushes it outwards by gamma h^2 / 2 and down by gamma h^2 / (2 tan theta)
    (the weight of the liquid above it); its contacts' tributary shares add up to it."""
    gamma, h, length = 1.25, 60.0, 150.0  # every wall reaches above the surface (75 cm at 30 degrees)
    t = np.radians(theta_deg)
    right = np.array([0.0, 0.0, length * np.cos(t), length * np.sin(t)])  # right-hand wall: up, liquid on its left
    left = np.array([-length * np.cos(t), length * np.sin(t), 0.0, 0.0])  # left-hand wall: down to the floor
    closed = gamma * h**2 / (2 * np.sin(t))
    for wall, sign in ((right, 1.0), (left, -1.0)):
        assert theory.wall_total(wall, gamma, h) == pytest.approx(closed, rel=1e-12)
        fx, fy = theory.wall_force(wall, gamma, h)
        assert fx == pytest.approx(sign * gamma * h**2 / 2, rel=1e-12)
        assert fy == pytest.approx(-gamma * h**2 / (2 * np.tan(t)), rel=1e-12, abs=1e-9 * closed)
        assert np.hypot(fx, fy) == pytest.approx(closed, rel=1e-12)
    s = np.linspace(2.5, length - 2.5, 30)  # contacts every 5 cm along the right wall
    cp = np.column_stack([s * np.cos(t), s * np.sin(t)])
    th = theory.contact_theory(right[None], np.zeros(len(s), int), cp, gamma, h)
    assert th.sum() == pytest.approx(closed, rel=1e-12)
    assert th[-1] == 0.0  # above the surface


def test_polygon_areas_and_rest_levels_follow_the_walls():
    """The liquid's area below a level over a vessel's polygon: B h in closed form for a rectangle (the number
    every tank's rho g took before polygons, bit for bit), h^2 / tan(theta) for a V; the level at rest solves the
    area the weight needs: rectangles by the closed form, a V and a trapezoid to round-off."""
    from isaflow import tank as T

    box = T.vessel_polygon([(0, 100, 0, 0), (0, 0, 100, 0), (100, 0, 100, 100)], (0.0, 100.0))
    assert T.is_box(box) and T.liquid_area(box, 0.0, 72.5) == 100.0 * 72.5
    vee = T.vessel_polygon([(-100, 100, 0, 0), (0, 0, 100, 100)], (-100.0, 100.0))
    assert T.liquid_area(vee, 0.0, 60.0) == pytest.approx(3600.0, rel=1e-12)
    assert theory.rest_level([vee], [0.0], 1.25 * 3600.0, 1.25) == pytest.approx(60.0, rel=1e-12)
    assert theory.rest_level([box], [0.0], 9000.0, 9000.0 / 7250.0) == theory.rest_levels([0.0], [100.0], 9000.0,
                                                                                       9000.0 / 7250.0) == 72.5
    # a vessel 150 cm wide at its floor (y = -50) whose right wall leans out by 1/3 cm per cm of height:
    # 150 t + t^2 / 6 = A at depth t
    trap = [(100.0, 100.0), (100.0, -50.0), (250.0, -50.0), (300.0, 100.0)]
    t = (-900 + np.sqrt(900**2 + 4 * 6 * 6720.0)) / 2
    assert theory.rest_level([box, trap], [0.0, -50.0], 8400.0, 1.25) == pytest.approx(t - 50.0, rel=1e-12)
    assert np.isnan(theory.rest_level([vee], [0.0], 1.25 * 3600.0 * 10, 1.25))  # more than the V holds


def test_fixed_order_line_dot_and_solve_match_numpy_to_round_off():
    """core.fixed_order's forms against numpy's BLAS/LAPACK ones: equal to round-off (their point, the same bits on
    every machine, cannot be shown on one)."""
    from isaflow.core import fixed_order as FO

    rng = np.random.default_rng(7)
    x, y = rng.uniform(0, 100, 257), rng.normal(size=257)
    slope, intercept = FO.line(x, y)
    ref = np.polyfit(x, y, 1)
    assert slope == pytest.approx(ref[0], rel=1e-10, abs=1e-14) and intercept == pytest.approx(ref[1], rel=1e-10)
    assert np.abs(FO.residual(x, y) - (y - np.polyval(ref, x))).max() < 1e-12
    flat = FO.line(x, np.full_like(x, 72.39))
    assert abs(flat[0]) < 1e-15 and flat[1] == pytest.approx(72.39, rel=1e-15)
    a, b = rng.normal(size=(50, 2)), rng.normal(size=2)
    assert np.abs(FO.dot2(a, b) - a @ b).max() < 1e-15
    m, f = rng.normal(size=(2, 2)), rng.normal(size=2)
    assert np.allclose(FO.solve2(m, f), np.linalg.solve(m, f), rtol=1e-12)
    assert FO.det2(m) == pytest.approx(np.linalg.det(m), rel=1e-12)
    with pytest.raises(ValueError, match="one x"):
        FO.line([1.0, 1.0], [0.0, 1.0])
