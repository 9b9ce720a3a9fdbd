"""MPS (isaflow.methods.mps): operators, the eq. (1)-(5) identity, the pressure equation, source terms, settings.

Coarse cases only (l0 = 5 cm in the 100 cm tank, under 0.3 s of physical time).
"""

import numpy as np
import pytest

from isaflow import runfile
from isaflow.core import units
from isaflow.methods import registry
from isaflow.methods.mps import boundary, model, pressure, settings, solver
from isaflow.inputs import InputError as SceneError
from isaflow.tank import load as load_tank

ROOT = __import__("pathlib").Path(__file__).resolve().parents[1]
TANK = ROOT / "config" / "tanks" / "single.yaml"
CFG = ROOT / "config" / "methods" / "mps.yaml"


def lattice(n=21, l0=1.0):
    g = (np.arange(n) - n // 2) * l0
    X, Y = np.meshgrid(g, g)
    return np.column_stack([X.ravel(), Y.ravel()])


def pairs(pos, rc):
    box = np.array([pos[:, 0].min() - 1, pos[:, 1].min() - 1, pos[:, 0].max() + 1, pos[:, 1].max() + 1])
    return model.build_pairs(pos, box, rc)


def interior(pos, margin):
    return np.all(np.abs(pos) <= np.abs(pos).max() - margin, axis=1)


# --- operators on a regular lattice ---------------------------------------------


def test_number_density_and_lambda_of_the_lattice():
    """n of an interior lattice particle is n0 exactly; lambda is the weighted mean of r^2 (K&O 1996)."""
    pos = lattice(l0=2.0)
    n0, lam = model.lattice_constants(2.1, 2.0)
    pi, pj, m = pairs(pos, 4.2)
    n = model.number_density(pos, pi, pj, m, 4.2)
    inner = interior(pos, 6.0)
    assert np.allclose(n[inner], n0, rtol=1e-12)
    # r_e = 2.1 l0: 4 neighbours at l0, 4 at sqrt(2) l0, 4 at 2 l0
    w1, w2, w3 = 2.1 - 1, 2.1 / np.sqrt(2) - 1, 2.1 / 2 - 1
    assert n0 == pytest.approx(4 * (w1 + w2 + w3), rel=1e-12)
    assert lam == pytest.approx(4.0 * 4 * (w1 + 2 * w2 + 4 * w3) / n0, rel=1e-12)


@pytest.mark.parametrize("re", [2.1, 3.1, 4.0])
def test_laplacian_exact_for_quadratics_on_the_lattice(re):
    """The MPS Laplacian 2d/(lambda n0) sum (f_j - f_i) w is exact for x^2 + 3 y^2 (= 8) away from the edge:
    sum r^2 w = lambda n0 and the square lattice's symmetry cancels the odd terms (tolerance: round-off)."""
    l0 = 1.5
    pos = lattice(l0=l0)
    n0, lam = model.lattice_constants(re, l0)
    pi, pj, m = pairs(pos, re * l0)
    kind = np.zeros(len(pos), np.int64)
    f = (pos[:, 0] ** 2 + 3 * pos[:, 1] ** 2)[:, None] + 5.0
    lap = model.laplacian(pos, f, kind, pi, pj, m, re * l0, n0, lam)[:, 0]
    inner = interior(pos, re * l0)
    assert np.allclose(lap[inner], 8.0, rtol=1e-10)


def test_gradient_and_divergence_exact_for_linear_fields():
    """Gradient of 2 x - 3 y + 1 is (2, -3) and the divergence of (2 x, -5 y) is -3 away from the edge:
    sum r r^T / r^2 w = n0 / d I on the square lattice (tolerance: round-off)."""
    l0 = 2.0
    pos = lattice(l0=l0)
    n0, _ = model.lattice_constants(2.1, l0)
    pi, pj, m = pairs(pos, 2.1 * l0)
    kind = np.zeros(len(pos), np.int64)
    p = 2 * pos[:, 0] - 3 * pos[:, 1] + 1 + 100.0
    g = model.gradient(pos, p, kind, pi, pj, m, 2.1 * l0, n0)
    inner = interior(pos, 2.1 * l0)
    # p^_i = min over neighbours shifts every term by (p_i - p^_i) sum r/r^2 w = 0 in the interior
    assert np.allclose(g[inner], [2.0, -3.0], rtol=1e-10)
    vel = np.column_stack([2 * pos[:, 0], -5 * pos[:, 1]])
    div = model.divergence(pos, vel, pi, pj, m, 2.1 * l0, n0)
    assert np.allclose(div[inner], -3.0, rtol=1e-10)


# --- the seed's checkable statement ---------------------------------------------


def manual_step(l0=5.0, seed=0, dt=1e-3, nu=7.0):
    """One MPS step of a disturbed liquid block in the single tank, every stage kept.

    nu = 7 cm^2/s: a viscosity large enough that the viscous term shows in the balance."""
    tank = load_tank(TANK)
    cfg = settings.load(CFG)
    rng = np.random.default_rng(seed)
    fluid = boundary.liquid_block((0.0, 100.0), 0.0, 50.0, l0)
    fluid = fluid + rng.normal(0, 0.05 * l0, fluid.shape)
    s = solver.State(tank, cfg, l0, fluid, rng.normal(0, 5.0, fluid.shape))
    pos_n, vel_n = s.pos.copy(), s.vel.copy()
    pi, pj, m = model.build_pairs(pos_n, s.grid_box, s.re_l)
    lap = model.laplacian(pos_n, vel_n, s.kind, pi, pj, m, s.re_l, s.n0_l, s.lam)
    ps, vs, n_star, div, dirichlet, qi, qj, qm, system = model.predict(
        pos_n, vel_n, s.kind, s.grid_box, dt, 0.0, -units.G, nu, s.re_n, s.re_g, s.re_l, s.n0_n, s.n0_g, s.n0_l, s.lam,
        0.97, s.rho0, 0, 0.0, cfg["model.relaxation"], cfg["model.sound_speed"], 0.0, 0.2)
    row, indptr, indices, data, rhs = system
    x, resid, _ = pressure.solve(pressure.csr(indptr, indices, data), rhs, "direct")
    p = np.zeros(len(s.pos))
    p[row >= 0] = x[row[row >= 0]]
    p = np.maximum(p, 0.0)
    pos1, vel1, grad, bad, _ = model.correct(pos_n, ps, vs, p, s.kind, qi, qj, qm, s.re_g, s.n0_g, s.rho0, dt,
                                             s.walls, s.escape_box, s.graze_depth)
    return dict(s=s, dt=dt, nu=nu, pos_n=pos_n, vel_n=vel_n, lap=lap, p=p, pos1=pos1, vel1=vel1, grad=grad,
                bad=bad, resid=resid)


def test_eqs_3_and_5_add_up_to_the_discrete_navier_stokes_eqs_1_2():
    """Hattori et al.: adding (3) and (5) gives back (1)-(2).  On a disturbed state, one MPS step satisfies
    (V[n+1] - V[n]) / dt = nu lap V[n] + g - grad P / rho0 and (U[n+1] - U[n]) / dt = V[n+1] to round-off
    (relative 1e-9), with grad P the MPS gradient at U* and rho0 for Rho[n+1] (the MPS reading of eq. 1)."""
    st = manual_step()
    s, dt = st["s"], st["dt"]
    f = slice(0, s.nf)
    assert st["bad"][0] == 0 and st["resid"] < 1e-10
    accel = st["nu"] * st["lap"][f] + np.array([0.0, -units.G]) - st["grad"][f] / s.rho0
    scale = np.abs(accel).max()
    assert np.abs((st["vel1"][f] - st["vel_n"][f]) / dt - accel).max() < 1e-9 * scale
    assert np.abs((st["pos1"][f] - st["pos_n"][f]) / dt - st["vel1"][f]).max() < 1e-9 * np.abs(st["vel1"][f]).max()
    assert np.abs(st["grad"][f]).max() > 0.1 * s.rho0 * units.G  # the pressure term is really there


@pytest.mark.xfail(strict=True, reason="MPS evaluates grad P at U*, eq. (1) at U[n+1] (dU = dt^2 grad P / rho0): "
                                       "the two gradients differ beyond round-off")
def test_pressure_gradient_at_new_positions_equals_the_one_used():
    st = manual_step()
    s = st["s"]
    pi, pj, m = model.build_pairs(st["pos1"], s.grid_box, s.re_l)
    g_new = model.gradient(st["pos1"], st["p"], s.kind, pi, pj, m, s.re_g, s.n0_g)
    f = slice(0, s.nf)
    assert np.abs(g_new[f] - st["grad"][f]).max() < 1e-9 * np.abs(st["grad"][f]).max()


# --- source terms -----------------------------------------------------------------


def test_source_terms():
    """standard = relax rho0/dt^2 (n0-n*)/n0; hattori adds (rho0 - Rho*)/dt div V* to the unrelaxed density term;
    mixed = rho0/dt div + gamma (unrelaxed standard)."""
    n0, rho, dt, gam, relax = 10.0, 2.0, 0.01, 0.05, 0.2
    std = model.source_term(9.9, 3.0, n0, rho, dt, 0, gam, 1.0)
    assert std == pytest.approx(rho / dt**2 * 0.01)
    assert model.source_term(9.9, 3.0, n0, rho, dt, 0, gam, relax) == pytest.approx(relax * std)
    assert model.source_term(9.9, 3.0, n0, rho, dt, 1, gam, relax) == pytest.approx(std + rho * 0.01 / dt * 3.0)
    assert model.source_term(9.9, 3.0, n0, rho, dt, 2, gam, relax) == pytest.approx(rho / dt * 3.0 + gam * std)
    # at rest (div V* = 0) hattori reduces to the unrelaxed standard source
    assert model.source_term(9.9, 0.0, n0, rho, dt, 1, gam, relax) == std


def test_compressibility_term_makes_a_pressure_equation_without_free_surface_definite():
    """A block whose particles are all 'inner' (no Dirichlet particle: the pure-Neumann block that made SuperLU
    report 'exactly singular') has a singular Laplacian; the compressibility term c of MPS-Basic lifts every
    eigenvalue by c (Laplacian rows are diagonally dominant, so the smallest eigenvalue is >= c up to round-off)."""
    pos = lattice(n=9, l0=1.0)
    n0, lam = model.lattice_constants(3.1)
    pi, pj, m = pairs(pos, 3.1)
    kind = np.zeros(len(pos), np.int64)
    none = np.zeros(len(pos), np.bool_)
    b = np.ones(len(pos))
    for extra, singular in ((0.0, True), (0.01, False)):
        row, indptr, indices, data, rhs = model.assemble(pos, kind, none, b, pi, pj, m, 3.1, n0, lam, extra)
        ev = np.linalg.eigvalsh(pressure.csr(indptr, indices, data).toarray())
        assert ev.min() < 1e-9 if singular else ev.min() >= extra * (1 - 1e-9)


def test_failed_pressure_solve_is_reported_with_its_residual():
    """One CG iteration cannot reach rtol 1e-12: the run stops as solver_failed, naming the residual."""
    tank = load_tank(TANK)
    cfg = settings.load(CFG).with_overrides(**{"pressure.maxiter": 1, "pressure.solver": "amg", "pressure.rtol": 1e-12})
    r = solver.solve(tank, cfg, "standard", 10.0, 0.01, cfg["runs.probes_single"])
    assert r.status == "solver_failed" and "residual" in r.message and r.steps <= 2


# --- the tank at rest -------------------------------------------------------------


@pytest.fixture(scope="module")
def column_runs():
    tank = load_tank(TANK)
    cfg = settings.load(CFG).with_overrides(**{"time.average_window": 0.1})
    return {v: solver.solve(tank, cfg, v, 5.0, 0.25, cfg["runs.probes_single"]) for v in ("standard", "hattori", "mixed")}


@pytest.mark.parametrize("variant", ["standard", "hattori", "mixed"])
def test_time_averaged_pressure_of_a_column_is_hydrostatic(column_runs, variant):
    """Probe pressures averaged over the last 0.1 s vs rho g (y_s - y), y_s the top row's centre (P = 0 there).
    Tolerance rho g l0: the surface sits within l0/2 of y_s and the Laplacian's boundary error adds up to
    another l0/2 of head (derived from the spacing, l0 = 5 cm)."""
    r = column_runs[variant]
    h = r.history
    win = h["in_window"][1].astype(bool)
    mean = h["hist_probe_pressure"][1][win].mean(0)
    probes = h["probe_point"][1]
    rho_g = r.params["rho0_N_s2_cm4"] * units.G
    y_s = r.pos0[:, 1].max()
    assert np.all(np.abs(mean - rho_g * (y_s - probes[:, 1])) < rho_g * 5.0)


def test_mass_momentum_and_recorded_variant(column_runs, tmp_path):
    """Mass is the particle count times the particle weight (never changes); total weight = the tank's W;
    the floor carries the weight within the hydrostatic tolerance rho g l0 B; the run file records the variant."""
    tank = load_tank(TANK)
    rho_g = column_runs["standard"].params["rho0_N_s2_cm4"] * units.G
    for v, r in column_runs.items():
        assert r.weight.sum() == pytest.approx(tank.weight, rel=1e-12)
        assert r.status in ("converged", "step_limit")
        assert r.history["hist_vessel_count"][1][:, 0].min() == len(r.pos)
        ds = runfile.to_dataset(r, tank, {"command": "test"}, runfile.now(), runfile.now(), 5.0)
        runfile.write(ds, tmp_path / f"{v}.nc")
        back = runfile.read(tmp_path / f"{v}.nc")
        assert back.attrs["variant"] == v and back.attrs["source_term"] == v
        assert back.attrs["variant_label"] == registry()["mps"].variants[v].label
        assert back["pressure"].attrs["units"] == "N cm-2"
        floor = r.contact_force[r.contact_wall == 1, 1].sum()
        assert abs(floor - tank.weight) < rho_g * 5.0 * 100.0, v


def test_wall_particles_and_panels():
    """Four rows behind every wall (two WALL, two DUMMY), at least l0/2 apart; each wall's first row faces
    exactly its length; P = 1 on every wall particle loads each 10 cm panel with 10 N/cm x 1 cm."""
    tank = load_tank(ROOT / "config" / "tanks" / "flow_step50.yaml")
    b = boundary.wall_particles(tank.walls, 5.0, 4, 2)
    assert set(np.unique(b["kind"])) == {model.WALL, model.DUMMY}
    L = np.hypot(*(tank.walls[:, 2:] - tank.walls[:, :2]).T)
    for w in range(len(L)):
        assert b["face_ds"][b["face_wall"] == w].sum() == pytest.approx(L[w])
    d = np.sort(np.hypot(*(b["pos"][:, None] - b["pos"][None]).T), axis=1)[:, 1]
    assert d.min() > 0.5 * 5.0 - 1e-9
    pw, pc, M = boundary.load_map(tank.walls, b, 10.0)
    unit = (M @ np.ones(len(b["pos"]))).reshape(-1, 2)  # P = 1: force = panel length x normal
    assert np.allclose(np.hypot(*unit.T), 10.0)


def test_bad_settings_name_file_and_field(tmp_path):
    bad = tmp_path / "mps.yaml"
    text = CFG.read_text().replace("beta:", "betta:")
    bad.write_text(text)
    with pytest.raises(SceneError, match=r"mps.yaml: field '\(top level\)'|mps.yaml: field 'model'"):
        settings.load(bad)
    with pytest.raises(SceneError, match="model.beta"):
        settings.load(CFG, ["model.beta=1.5"])
    with pytest.raises(SceneError, match="no field"):
        settings.load(CFG, ["model.nope=1"])


def test_stiff_cases_change_only_their_setting():
    """Each stiff case overrides exactly the settings it names (large time step, small radii, no relaxation);
    on_wall keeps the settings and asks for a particle on the floor line."""
    from isaflow.methods.mps import outputs

    cfg = settings.load(CFG)
    changed = {}
    for case in outputs.STIFF_CASES:
        new, start = outputs.stiff_settings(cfg, case)
        changed[case] = sorted(k for k in cfg if new[k] != cfg[k])
        assert (start == "on_wall") == (case == "on_wall")
    assert changed == {"large_dt": ["time.courant"], "small_re": ["model.re_density", "model.re_gradient", "model.re_laplacian"],
                       "no_relaxation": ["model.relaxation"], "on_wall": []}
    assert outputs.stiff_settings(cfg, "large_dt")[0]["time.courant"] == cfg["stiff.courant_large"] > cfg["time.courant"]


@pytest.mark.parametrize("begin, end, escaped", [
    ((99.5, 0.3), (100.05, -0.05), False),  # cuts the opening's convex corner (crosses floor1 at x = 99.97), ends
                                            # 0.07 cm from floor1's end, in front of left2
    ((99.9, 0.3), (99.9, -0.05), False),    # 0.05 cm past floor1's line: the half cell before the first wall row
    ((99.9, 0.3), (99.0, -2.0), True),      # 2 cm past floor1's line: through the first wall row (l0/2 = 1.67 cm)
])
def test_a_wall_crossing_is_an_escape_only_past_the_first_wall_particle_row(begin, end, escaped):
    """model.correct: a move across a wall line ending within graze = l0/2 of the wall segment is a graze
    (returned, the run goes on), farther is an escape (bad[0] == 2) naming the particle and the wall."""
    walls = load_tank(ROOT / "config" / "tanks" / "flow_step50.yaml").walls
    l0 = 10.0 / 3.0
    start, stop = np.array([begin]), np.array([end])
    no_pairs = np.zeros(0, np.int64)
    _, _, _, bad, deepest = model.correct(start, stop, np.zeros((1, 2)), np.zeros(1), np.array([model.FLUID]),
                                          no_pairs, no_pairs, 0, 1.0, 1.0, 1.0, 1e-3, walls,
                                          np.array([-1e3, -1e3, 1e3, 1e3]), 0.5 * l0)
    if escaped:
        assert bad[0] == 2 and bad[1] == 0 and bad[2] == 1  # wall 1 is floor1
    else:
        assert bad[0] == 0 and 0.0 < deepest <= 0.5 * l0
