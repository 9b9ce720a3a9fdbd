"""Weakly compressible SPH (issues 10, 19, 20): physics of the kernels and of coarse runs on the project's tanks.

Tolerances are derived from the discretisation (cell dx x dy, smoothing length h, sound
speed c0, the rest criterion of isaflow.rest), stated next to each check, and fixed before
the runs.  The weakly compressible column at rest is shorter than the tank's H by
g H^2 / (2 c0^2) and loads its side walls with gamma H^2 / 2 (1 - (2/3) g H / c0^2)
(the same weight, its centroid lower): that is the expected value, not an error.
"""

import math
from pathlib import Path

import numba
import numpy as np
import pytest

from isaflow import rest
from isaflow.core import smoothing
from isaflow.core.units import G
from isaflow.methods.sph import kernels as K
from isaflow.methods.sph import pairs as PR
from isaflow.methods.sph import particles as P
from isaflow.methods.sph import settings as S
from isaflow.methods.sph import solver
from isaflow.inputs import InputError as SceneError
from isaflow.tank import load as load_tank

ROOT = Path(__file__).resolve().parents[1]
SINGLE = load_tank(ROOT / "config" / "tanks" / "single.yaml")
FLOW = load_tank(ROOT / "config" / "tanks" / "flow_step50.yaml")
SAME = load_tank(ROOT / "config" / "tanks" / "flow_samefloor.yaml")
GAMMA_W = SINGLE.weight / (100.0 * SINGLE.depth)  # specific weight rho g, N/cm^3
H = SINGLE.depth
QUIET = dict(log=lambda *a: None)
TWO = numba.config.NUMBA_NUM_THREADS >= 2


def _cloud(n=200, seed=3):
    """Random liquid cloud without walls: (x, v, par, pair list) for the pair passes."""
    rng = np.random.default_rng(seed)
    x = rng.uniform(0, 20, (n, 2))
    v = rng.normal(0, 30, (n, 2))
    s = S.resolve(S.read_file(), "wcsph")
    h = 2.0
    par = solver.pack(s, h, 1e-3, 1e-3 * solver.lattice_density_sum(0, h, 1.5, 1.5), 500.0, 1e-4, 0)
    box = np.array([-1.0, -1.0, 21.0, 21.0])
    return x, v, par, K.list_pairs(x, n, box, 2 * h, np.zeros((0, 4)))


def test_kernels_normalised_and_branch_free_shape():
    # 2D integral of W on a fine grid: quadrature error O(spacing^2) ~ 1e-4 for spacing h/50
    h, d = 1.0, 0.02
    g = np.arange(-2.0, 2.0 + d / 2, d)
    r = np.hypot(*np.meshgrid(g, g))
    for name in ("cubic_spline", "wendland_c2"):
        assert abs(smoothing.W(name, r.ravel(), h, 2).sum() * d * d - 1.0) < 1e-3
    # the passes' branch-free shapes are core.smoothing's to round-off (a few ulp of values of order 1)
    for kind in (smoothing.CUBIC, smoothing.WC2):
        for q in np.linspace(0.0, 2.5, 251):
            f, df = K.shape(kind, q)
            assert f == pytest.approx(smoothing.w(kind, q), abs=1e-14)
            assert df == pytest.approx(smoothing.dw(kind, q), abs=1e-14)


@pytest.mark.parametrize("density", ["summation", "continuity"])
def test_pair_forces_conserve_momentum(density):
    x, v, par, lst = _cloud()
    par[K.SUMMATION] = density == "summation"
    n = len(x)
    rho = np.full(n, par[K.RHO0] * 1.01)
    p, acc = np.zeros(n), np.zeros((n, 2))
    wk, fk = np.zeros(len(lst[0])), np.zeros(len(lst[0]))
    K.evaluate(x, v, rho, p, n, np.zeros((0, 4)), par, lst, wk, fk, acc, np.zeros((0, 2)), np.zeros(0, np.int64),
               np.zeros(0, np.int64), np.zeros((0, 2)), 1)
    # every pair force enters both particles with opposite signs: beside gravity the sum vanishes to round-off
    pair = acc - [0.0, -G]
    total = par[K.MASS] * pair.sum(0)
    scale = par[K.MASS] * np.abs(pair).sum()
    assert scale > 0 and np.all(np.abs(total) <= 1e-12 * scale)


def test_pair_list_is_the_brute_force_list_with_visibility():
    # every pair within rc once, liquid first; across a wall only liquid-wall pairs, along it only liquid ones
    dx = dy = 5.0
    wpos, owner, face = P.wall_particles(FLOW.walls, dx, dy, 2 * 1.3 * dx,
                                         two_faced=P.wet_back(FLOW.walls, FLOW.vessels))
    rng = np.random.default_rng(1)
    liquid = np.concatenate([rng.uniform([1, 1], [99, 99], (300, 2)), rng.uniform([101, -49], [299, 99], (300, 2))])
    x = np.concatenate([liquid, wpos])
    nf, rc = len(liquid), 2 * 1.3 * dx
    pi, pj, m, col, wrow, wpair, close, dwall = K.list_pairs(x, nf, np.array([-20.0, -70, 320, 120]), rc, FLOW.walls)
    got = {(min(int(a), int(b)), max(int(a), int(b))) for a, b in zip(pi[:m], pj[:m])}
    assert len(got) == m and (pi[:m] < nf).all()
    want = set()
    for a in range(nf):
        for b in range(a + 1, len(x)):
            if np.hypot(*(x[a] - x[b])) < rc:
                meets = PR.segment_meets_wall(*x[a], *x[b], FLOW.walls, b < nf)
                if meets == (b >= nf):
                    want.add((a, b))
    assert got == want
    # columns partition the list; the wall rows list each wall particle's pairs
    assert col[0] == 0 and col[-1] == m and (np.diff(col) >= 0).all()
    assert sorted(wpair) == sorted(np.flatnonzero(pj[:m] >= nf))


def test_wall_particles_cover_both_faces_of_the_dividing_wall():
    dx = dy = 2.5
    h = 1.3 * dx
    two = P.wet_back(FLOW.walls, FLOW.vessels)
    assert [n for n, t in zip(FLOW.wall_names, two) if t] == ["right1"]  # left2's back is under floor1
    assert not P.wet_back(SAME.walls, SAME.vessels)[[0, 1, 3, 4]].any()
    wpos, owner, face = P.wall_particles(FLOW.walls, dx, dy, 2 * h, two_faced=two)
    r1 = owner == 2
    # right1 (x = 100, y 20..100): layers on both sides covering the support 2h, from its tip to its top
    for f, side in ((0, 1.0), (1, -1.0)):
        on = r1 & (face == f)
        assert (np.sign(wpos[on, 0] - 100.0) == side).all()
        assert np.abs(wpos[on, 0] - 100.0).max() >= 2 * h - dx / 2
        assert wpos[on, 1].min() == pytest.approx(20.0) and wpos[on, 1].max() >= 100.0 - dy / 2
    assert (face[owner != 2] == 0).all()
    # a liquid particle half a cell above the floor sees wall particles over its whole support below the floor
    below = (np.abs(wpos[:, 0] - 51.25) < 2 * h) & (wpos[:, 1] < 0) & (wpos[:, 1] > -2 * h)
    assert below.sum() >= int(2 * h / dy) * int(2 * (2 * h) / dx) - 2


def _column(n, variant="wcsph"):
    return solver.solve(SINGLE, variant, {"particles": n}, **QUIET)


@pytest.fixture(scope="module", params=[180, 684])
def column(request):
    """The single vessel at the paper's counts (180 and 684 requested), wcsph, run to rest."""
    return _column(request.param)


def _top_row(r):
    nx = int(round(100.0 / r.params["cell_dx"]))
    return np.argsort(r.pos[:, 1], kind="stable")[-nx:]


def _compressed(r):
    """(surface [cm], side load [N]) of the weakly compressible column at rest (module docstring)."""
    gh_c2 = G * H / r.params["sound_speed"] ** 2
    return H * (1 - gh_c2 / 2), GAMMA_W * H**2 / 2 * (1 - 2 / 3 * gh_c2)


def test_column_comes_to_rest_without_losing_particles(column):
    r = column
    cfg = rest.load()
    assert r.status == "converged", r.message
    assert r.params["rest_energy_ratio"] == cfg["energy_ratio"] and r.params["rest_window"] == cfg["window"]
    assert r.params["final_energy_ratio"] < cfg["energy_ratio"] and np.isfinite(r.measures["time_to_rest"][1])
    assert r.weight.sum() == pytest.approx(SINGLE.weight, rel=1e-12)
    assert np.isfinite(r.pos).all()
    assert not P.is_solid(r.pos[:, 0], r.pos[:, 1], SINGLE.walls).any()
    # the contract's tank-difference attributes
    assert r.params["layer_pitch"] == r.params["cell_dy"] and r.params["held_weight"] == pytest.approx(9000.0)
    # the top half cell is not compressed in the reading: within dy g H / c0^2 of the compressed column's H
    tol = r.params["cell_dy"] * G * H / r.params["sound_speed"] ** 2
    assert r.params["initial_depth"] == pytest.approx(_compressed(r)[0], abs=tol) and r.params["tank_difference"]
    assert r.params["threads"] == 1 and r.start_step == 0 and r.steps > 0


def test_column_surface_at_the_tank_depth(column):
    # surface = top particle centres + dy / 2 against the compressed column's H (1 - g H / (2 c0^2)); at the
    # rest criterion e = KE / (W H) a sloshing mode holding all the kinetic energy has an amplitude up to
    # sqrt(4 KE / (gamma B)) = 2 H sqrt(e): the surface is known to that
    r = column
    surface = r.pos[_top_row(r), 1].mean() + r.params["cell_dy"] / 2
    assert abs(surface - _compressed(r)[0]) < 2 * H * math.sqrt(r.params["rest_energy_ratio"])


def test_column_top_layer_and_interior_pressure(column):
    r = column
    dy, h = r.params["cell_dy"], r.params["smoothing_length"]
    p = r.fields["pressure"][1]
    top = _top_row(r)
    surface = r.pos[top, 1].mean() + dy / 2
    # the top layer's centres lie dy/2 below the surface: its pressure gamma dy / 2, known to half a layer's head
    assert abs(p[top].mean() - GAMMA_W * dy / 2) < GAMMA_W * dy / 2
    assert (p[top] > 0).all()
    # below the kernel's reach of the surface: a particle's pressure is a kernel average over radius 2h,
    # its head known to +- h
    deep = r.pos[:, 1] < surface - 2 * h
    err = p[deep] - GAMMA_W * (surface - r.pos[deep, 1])
    assert np.sqrt(np.mean(err**2)) < GAMMA_W * h


def test_column_wall_loads(column):
    r = column
    per = np.zeros((3, 2))
    np.add.at(per, r.contact_wall, r.contact_force)
    # vertical balance over the averaging window: |d(momentum)/dt| <= M 2 v_rest / window, v_rest the rms
    # speed of the rest criterion
    v_rest = rest.speed_at(r.params["rest_energy_ratio"], H)
    tol = SINGLE.weight / G * 2 * v_rest / r.params["load_window"]
    assert abs(per[1, 1] - SINGLE.weight) < tol
    # side walls: the compressed column's gamma H^2 / 2 (1 - 2/3 g H / c0^2); the pressure near the surface
    # is known to half a layer's head gamma dy / 2 over the band 2h the kernel feels the surface in:
    # dF = gamma dy h
    expected = _compressed(r)[1]
    for w, sign in ((0, 1), (2, -1)):
        assert abs(sign * per[w, 0] - expected) < GAMMA_W * r.params["cell_dy"] * r.params["smoothing_length"]


EQ6 = {180: "176 particles: surface 69.83 cm (72.39 expected; 2.6 cm low, the tolerance 0.46 cm), top layer "
             "0.57 gamma dy",
       684: "682 particles: top layer P = 0 (clamped; 0.5 gamma dy = 2.05 N/cm^2 expected), surface 72.28 cm"}


@pytest.mark.parametrize("n", [pytest.param(n, marks=pytest.mark.xfail(strict=True, reason=(
    "marko2017 eq. 6 literally (variant wcsph_eq6): the summed density is deficient within 2h of the surface and "
    "P >= 0 zeroes the surface band's pressure; measured at " + EQ6[n]))) for n in EQ6])
def test_eq6_top_layer(n):
    r = _column(n, "wcsph_eq6")
    dy = r.params["cell_dy"]
    top = _top_row(r)
    assert abs(r.fields["pressure"][1][top].mean() - GAMMA_W * dy / 2) < GAMMA_W * dy / 2
    assert abs(r.pos[top, 1].mean() + dy / 2 - _compressed(r)[0]) < 2 * H * math.sqrt(r.params["rest_energy_ratio"])


@pytest.fixture(scope="module")
def start180():
    return _column(180)


def test_split_run_equals_straight_run_bit_for_bit(start180):
    # the flow from the column at rest, straight for 2k steps and split k + k (second half on 2 threads when
    # the machine has them): positions, velocities and densities agree bit for bit; clock and steps chain on
    st = solver.start_dataset(start180)
    dt = start180.params["dt"]
    k = 600
    straight = solver.solve(FLOW, "wcsph", start=st, t_max=2 * k * dt, **QUIET)
    first = solver.solve(FLOW, "wcsph", start=st, t_max=k * dt, **QUIET)
    second = solver.solve(FLOW, "wcsph", start=solver.start_dataset(first), t_max=k * dt, threads=2 if TWO else 1,
                          **QUIET)
    assert straight.status == first.status == second.status == "step_limit"
    for name in ("velocity", "density", "list_pos"):
        assert np.array_equal(second.fields[name][1], straight.fields[name][1]), name
    assert np.array_equal(second.pos, straight.pos)
    assert first.start_step == start180.steps and second.start_step == first.steps
    assert second.steps == straight.steps == start180.steps + 2 * k
    assert second.sim_time == pytest.approx(straight.sim_time, rel=1e-14)
    assert straight.params["start_time"] == start180.sim_time
    assert np.abs(straight.pos - st["pos"].values).max() > 1.0  # the liquid moved: the flow has started


@pytest.mark.skipif(not TWO, reason="needs 2 numba threads")
def test_two_threads_bit_identical_to_one(start180):
    st = solver.start_dataset(start180)
    a = solver.solve(SAME, "wcsph", start=st, t_max=0.15, threads=1, **QUIET)
    b = solver.solve(SAME, "wcsph", start=st, t_max=0.15, threads=2, **QUIET)
    assert b.params["threads"] == 2
    for name in ("velocity", "density", "pressure"):
        assert np.array_equal(a.fields[name][1], b.fields[name][1]), name
    assert np.array_equal(a.pos, b.pos) and np.array_equal(a.contact_force, b.contact_force)


V_IMPACT = math.sqrt(2 * G * 122.5)  # free fall over the largest drop, 72.5 + 50 cm


def _blob(centre, direction, d=2.5, n=3):
    """Start Dataset: n x n liquid particles (cell d, at the reference density) at V_IMPACT along direction."""
    import xarray as xr

    g = (np.arange(n) - (n - 1) / 2) * d
    pos = np.asarray(centre, float) + np.column_stack([a.ravel() for a in np.meshgrid(g, g)])
    w = GAMMA_W * d * d
    u = np.asarray(direction, float) / np.hypot(*direction)
    return xr.Dataset({"pos": (("particle", "xy"), pos), "velocity": (("particle", "xy"), np.tile(V_IMPACT * u, (len(pos), 1))),
                       "density": (("particle",), np.full(len(pos), w / G / (d * d))), "weight": (("particle",), np.full(len(pos), w))},
                      attrs={"cell_dx": d, "cell_dy": d}), u


DROPS = [(FLOW, "left", (5, 50), (-1, 0)), (FLOW, "floor1", (50, 5), (0, -1)), (FLOW, "right1", (95, 60), (1, 0)),
         (FLOW, "right1 back", (105, 60), (-1, 0)), (FLOW, "right1 tip", (100, 12), (0, 1)),
         (FLOW, "left2", (105, -25), (-1, 0)), (FLOW, "floor2", (200, -45), (0, -1)), (FLOW, "right2", (295, 0), (1, 0)),
         (SAME, "left", (5, 50), (-1, 0)), (SAME, "floor1", (50, 5), (0, -1)), (SAME, "right1", (95, 60), (1, 0)),
         (SAME, "right1 back", (105, 60), (-1, 0)), (SAME, "right1 tip", (100, 12), (0, 1)),
         (SAME, "floor2", (200, 5), (0, -1)), (SAME, "right2", (295, 50), (1, 0))]


@pytest.mark.parametrize("tank, wall, centre, direction", DROPS, ids=[f"{t.name}-{w}" for t, w, _, _ in DROPS])
def test_drop_at_impact_speed_does_not_cross_the_wall(tank, wall, centre, direction):
    # a 3 x 3 blob (2.5 cm cells) starting 1.5 cells off the wall face at sqrt(2 g 122.5) = 490 cm/s:
    # 40 ms carry it 20 cm if nothing stops it; the run stops (escaped) before any move across a wall
    st, u = _blob(centre, direction)
    r = solver.solve(tank, "wcsph", start=st, t_max=0.04, **QUIET)
    assert r.status == "step_limit", r.message
    if "tip" not in wall:  # the wall stopped it and threw it back; at the tip it splits round the free end
        assert r.fields["velocity"][1].mean(0) @ u < 0
        name = wall.split()[0]
        seg = tank.walls[tank.wall_names.index(name)]
        e = seg[2:] - seg[:2]
        side = np.sign(e[0] * (r.pos[:, 1] - seg[1]) - e[1] * (r.pos[:, 0] - seg[0]))
        assert (side == (-1 if "back" in wall else 1)).all()


@pytest.fixture(scope="module")
def flows(start180):
    """Both flow tanks from the 176-particle column at rest, to rest or the 40 s limit."""
    st = solver.start_dataset(start180)
    return {t.name: solver.solve(t, "wcsph", start=st, **QUIET) for t in (FLOW, SAME)}


def test_flows_come_to_rest_inside_the_walls(flows):
    for name, f in flows.items():
        assert f.status == "converged", f"{name}: {f.message}"  # at rest by isaflow.rest, no particle escaped
        assert f.sim_time - f.params["start_time"] <= f.params["t_max"] + 1e-9 and f.params["t_max"] >= 40.0
        count = f.history["sample_vessel_count"][1]
        assert (count.sum(1) == len(f.pos)).all()  # every particle in some vessel at every sample
        assert f.params["particles_left"] == np.count_nonzero(f.pos[:, 0] < 100.0)
        assert f.params["two_faced_walls"] == "right1"


def test_flow_levels(flows):
    from isaflow.theory import free_surface_level

    for name, f in flows.items():
        dx, dy = f.params["cell_dx"], f.params["cell_dy"]
        in2 = f.pos[:, 0] >= 100.0
        floor2 = -50.0 if name == FLOW.name else 0.0
        expected = floor2 + f.weight[in2].sum() / (GAMMA_W * 200.0)  # flat surface of the liquid the vessel holds
        level = free_surface_level(f.pos, np.sqrt(dx * dy), (100.0, 300.0)) + dy / 2  # centres -> surface
        # the surface is a layer of particles: read to within half a cell
        assert abs(level - expected) < dy / 2, name
    # same floor: the two vessels communicate below right1, so their surfaces meet at the same level
    same = flows[SAME.name]
    dy = same.params["cell_dy"]
    levels = [free_surface_level(same.pos, dy, xr) for xr in ((0.0, 100.0), (100.0, 300.0))]
    assert abs(levels[0] - levels[1]) < dy


def test_extreme_time_step_is_classified():
    r = solver.solve(SINGLE, "wcsph", {"particles": 180}, overrides={"cfl": 20.0}, t_max=0.5, **QUIET)
    assert r.status in ("escaped", "nonfinite", "step_limit", "converged")
    assert r.status in ("escaped", "nonfinite") or np.isfinite(r.pos).all()


def test_threads_argument_is_checked():
    with pytest.raises(ValueError, match="threads"):
        solver.set_threads(numba.config.NUMBA_NUM_THREADS + 1)


def test_settings_reject_unknown_keys(tmp_path):
    text = (ROOT / "config" / "methods" / "sph.yaml").read_text().replace("  alpha:", "  alpah:", 1)
    bad = tmp_path / "sph.yaml"
    bad.write_text(text)
    with pytest.raises(SceneError, match=r"sph.yaml: field 'settings'"):
        S.read_file(bad)


# ---- the periodic block (methods.sph.block): the tensile-instability test of marko2017 sections 1-2 ----

from isaflow.methods.sph import block  # noqa: E402


def _block(**kw):
    """Settings of a periodic n180 block: the wcsph variant with the block's settings (kw overrides)."""
    s = S.resolve(S.read_file(), "wcsph")
    s.update(domain="periodic_block", negative_pressure="keep", perturbation=0.0, stretch=0.0, t_max_block=0.05)
    s.update(kw)
    return s


def test_periodic_block_lattice_is_an_equilibrium():
    # a uniform periodic lattice at any uniform pressure is an exact equilibrium: the symmetric pair terms
    # cancel to round-off (1e-12 spacing over the run, far below the 1e-6 perturbation of the claims runs)
    for stretch in (0.0, 0.01):
        r = block.run(SINGLE, _block(stretch=stretch), {"particles": 180})
        assert r.status == "step_limit"
        assert r.history["nonaffine_over_dx_t"][1].max() < 1e-12
        assert abs(r.params["initial_pressure"]) > 0 if stretch else r.params["initial_pressure"] == 0.0
    # total momentum of the periodic block: pair forces are equal and opposite, the mean velocity stays 0
    r = block.run(SINGLE, _block(stretch=0.01, perturbation=1e-3), {"particles": 180})
    v = r.fields["velocity"][1]
    assert np.abs(v).sum() > 0 and np.abs(v.sum(0)).max() < 1e-9 * np.abs(v).sum()


def test_stretched_block_clumps_and_the_wendland_block_under_pressure_does_not():
    """The claim's mechanism at n180 (h = 8.7 cm, h / c0 = 1.8 ms): tension (P < 0) makes particles pair within
    0.4 s (the n684 runs clump at 0.07 s: growth ~ c0 / h); the Wendland C2 block compressed by as much stays
    within the 0.1-spacing clumping threshold (no pairing instability in compression)."""
    r = block.run(SINGLE, _block(stretch=0.01, perturbation=1e-6, t_max_block=0.4), {"particles": 180})
    na = r.history["nonaffine_over_dx_t"][1]
    assert r.params["initial_pressure"] < 0 and na.max() > 0.1
    assert r.history["min_pair_over_dx_t"][1].min() < 0.7
    c = block.run(SINGLE, _block(stretch=-0.01, perturbation=1e-6, t_max_block=0.4, kernel="wendland_c2",
                                 h_factor=1.5), {"particles": 180})
    assert c.params["initial_pressure"] > 0 and c.history["nonaffine_over_dx_t"][1].max() < 0.1


def test_periodic_block_refuses_what_it_does_not_implement():
    with pytest.raises(ValueError, match="density diffusion"):
        block.run(SINGLE, _block(delta=0.1), {"particles": 180})
    with pytest.raises(ValueError, match="3 x 3 cells"):
        block.run(SINGLE, _block(h_factor=8.0), {"particles": 180})
