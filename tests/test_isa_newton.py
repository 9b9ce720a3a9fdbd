"""The equilibrium solver (variant ``newton_lm``, methods/isa/newton.py; not the paper's update):
its energy, forces and Hessian against the force laws and finite differences, and its runs
against the capped update's on the paper's scenes.  Units cm, N.

Tolerances: the final states are compared with the report's own measures and tolerances
(metrics.load_errors against the top-centre level, methods.isa.metrics.tolerances: level a / 4,
side load (a / 4) / h); finite differences use steps whose truncation and rounding errors are
stated at each test.  Runs go through isaflow.run (tests/conftest.py run_isa, run_declared).
"""

import numpy as np
import pytest

from isaflow import metrics, runfile
from isaflow.core import neighbours as NB
from isaflow.methods.isa import dynamics as D
from isaflow.methods.isa import forces as F
from isaflow.methods.isa import metrics as IM
from isaflow.methods.isa import newton as NW
from isaflow.methods.isa import relax as R
from isaflow.methods.isa import settings as ST

from conftest import run_declared, run_isa

A = 10.0
L_P, R_P = A / np.sqrt(2.0), 500.0 * A / np.sqrt(2.0)  # pair law: cm, N
L_B, R_B = 5.0, 10000.0  # wall law: cm, N
WALLS = np.array([[0, 60, 0, 0], [0, 0, 60, 0], [60, 0, 60, 30], [20, 45, 35, 38]], float)  # a free-standing baffle
BOX = np.array([0.0, 0.0, 60.0, 60.0])


def cloud(seed, n=300):
    """Particles in the box, many in contact with each other, the walls and the baffle's ends."""
    rng = np.random.default_rng(seed)
    pos = rng.uniform(1.0, 59.0, (n, 2))
    ends = np.array([[60, 30], [20, 45], [35, 38]], float)
    ang = rng.uniform(0, 2 * np.pi, 30)
    pos[:30] = ends[rng.integers(0, 3, 30)] + 3.0 * np.column_stack([np.cos(ang), np.sin(ang)])
    return pos


def evaluate(pos, weight):
    pi, pj, m = NB.build_pairs(pos, BOX, L_P + 1.0)
    f = np.zeros_like(pos)
    e, fmax, bad = NW.energy_forces(pos, weight, WALLS, L_B, R_B, L_P, R_P, pi, pj, m, 0.0, f)
    return e, f, fmax, bad, (pi, pj, m)


@pytest.mark.parametrize("seed", [0, 1])
def test_forces_are_those_of_forces_forces_bit_for_bit(seed):
    pos = cloud(seed)
    weight = np.random.default_rng(seed).uniform(10, 60, len(pos))
    e, f, fmax, bad, (pi, pj, m) = evaluate(pos, weight)
    ref = np.zeros_like(pos)
    assert fmax == F.forces(pos, weight, WALLS, L_B, R_B, L_P, R_P, pi, pj, m, ref) and bad == -1
    assert np.array_equal(f, ref)


@pytest.mark.parametrize("seed", [0, 1])
def test_forces_are_minus_the_energy_gradient(seed):
    """Central difference of E along a random unit direction v with h = 1e-5 cm: truncation
    ~ h^2 |E'''| (k / l_u ~ 1e2 N/cm^2: 1e-8 N) and rounding ~ 1e-16 |E| / h (|E| ~ 1e5 N cm:
    1e-6 N) against |F.v| ~ 1e3 N; a contact opening inside the interval adds at most
    k h ~ 5e-3 N (E is C1).  Tolerance 1e-2 N."""
    pos = cloud(seed)
    weight = np.full(len(pos), 50.0)
    v = np.random.default_rng(seed + 10).normal(size=pos.shape)
    v /= np.linalg.norm(v)
    h = 1e-5
    _, f, _, _, _ = evaluate(pos, weight)
    ep = evaluate(pos + h * v, weight)[0]
    em = evaluate(pos - h * v, weight)[0]
    assert abs(np.sum(f * v)) > 100.0
    assert (ep - em) / (2 * h) == pytest.approx(-np.sum(f * v), abs=1e-2)


@pytest.mark.parametrize("seed", [0, 1])
def test_exact_hessian_product_matches_finite_differences_of_the_forces(seed):
    """(F(x - h v) - F(x + h v)) / 2h = H v with the exact Hessian (theta = 1) of the contacts in
    range.  h = 1e-6 cm: rounding ~ 1e-16 |F| / h ~ 1e-7 N/cm, truncation ~ h^2 k / l_u^2 ~ 1e-10;
    no distance may lie within 1e-5 cm of l_u (checked): the ACTIVE_TOL band is 7e-6 cm wide and
    a distance moves by at most 2 sqrt(2) h, so the active set is the same at x +- h v.
    Near a wall end at distance d the third derivative grows like k_b l_bu / d^3: relative
    truncation (h / d)^2 <= 1e-7 for d >= 3e-3 cm (checked).  Tolerance 1e-4 N/cm + 1e-7 |H v|
    (|H v| ~ 1e3 - 1e5 N/cm)."""
    pos = cloud(seed)
    close = np.triu(np.hypot(*(pos[:, None] - pos[None]).transpose(2, 0, 1)) < 0.1, 1).any(0)
    pos = pos[~close]  # no pair closer than 0.1 cm: its third derivative k_p l_pu / d^2 stays small
    weight = np.full(len(pos), 50.0)
    v = np.random.default_rng(seed + 20).normal(size=pos.shape)
    v /= np.abs(v).max()
    h = 1e-6
    _, _, _, _, (pi, pj, m) = evaluate(pos, weight)
    d = np.hypot(*(pos[pi[:m]] - pos[pj[:m]]).T)
    assert np.abs(d - L_P).min() > 1e-5 and (d < L_P).sum() > 300
    for w in WALLS:  # and no wall distance near l_bu
        e = w[2:] - w[:2]
        t = np.clip(((pos - w[:2]) @ e) / (e @ e), 0, 1)
        assert np.abs(np.hypot(*(pos - w[:2] - t[:, None] * e).T) - L_B).min() > 1e-5
        assert min(np.hypot(*(pos - w[:2]).T).min(), np.hypot(*(pos - w[2:]).T).min()) > 3e-3
    diag, blk, hv = np.zeros((len(pos), 3)), np.zeros((m, 3)), np.zeros_like(pos)
    NW.assemble(pos, WALLS, L_B, R_B, L_P, R_P, pi, pj, m, 1.0, diag, blk)
    NW.hess_vec(diag, blk, pi, pj, m, 0.0, v, hv)
    fd = (evaluate(pos - h * v, weight)[1] - evaluate(pos + h * v, weight)[1]) / (2 * h)
    assert np.abs(hv).max() > 1e3
    np.testing.assert_allclose(hv, fd, rtol=1e-7, atol=1e-4)


def test_cg_solves_a_positive_definite_system():
    pos = cloud(3)
    _, _, _, _, (pi, pj, m) = evaluate(pos, np.full(len(pos), 50.0))
    diag, blk = np.zeros((len(pos), 3)), np.zeros((m, 3))
    NW.assemble(pos, WALLS, L_B, R_B, L_P, R_P, pi, pj, m, 0.0, diag, blk)  # Gauss-Newton: PSD, + mu I is PD
    b = np.random.default_rng(3).normal(size=pos.shape) * 100
    x, scratch = np.zeros_like(b), [np.zeros_like(b) for _ in range(4)]
    its, ok = NW.pcg(diag, blk, pi, pj, m, 10.0, b, x, 1e-9, 10000, *scratch)
    y = np.zeros_like(b)
    NW.hess_vec(diag, blk, pi, pj, m, 10.0, x, y)
    assert ok and 0 < its < 10000
    assert np.abs(y - b).max() <= 1e-9
    # the exact Hessian of compressed contacts is indefinite: CG says so instead of returning a step
    NW.assemble(pos, WALLS, L_B, R_B, L_P, R_P, pi, pj, m, 1.0, diag, blk)
    assert not NW.pcg(diag, blk, pi, pj, m, 0.0, b, x, 1e-9, 10000, *scratch)[1]


def test_rule_codes_are_the_kernels_own():
    """settings.RULE_IDS (the variant -> rule code table) against the codes the kernels test."""
    assert ST.RULE_IDS == {"paper": R.PAPER, "capped": R.CAPPED, "fire": R.FIRE, "overdamped": D.OVERDAMPED,
                           "newton_lm": NW.NEWTON}
    assert len(set(ST.RULE_IDS.values())) == len(ST.RULE_IDS)


@pytest.fixture(scope="module")
def singles(tmp_path_factory):
    """Both paper lattices (tank single, resolutions coarse and refined) with the capped update and newton."""
    tmp = tmp_path_factory.mktemp("newton")
    out = {}
    for lat in ("coarse", "refined"):
        for v in ("capped", "newton_lm"):
            path = tmp / f"{lat}_{v}.nc"
            assert run_isa(path, "single", lat, v) == 0
            out[lat, v] = runfile.read(path)
    return out


def state_differences(a, b, vessel=None):
    """(differences, tolerances) of level [cm] and side load (relative) of run b against run a."""
    ea, eb = metrics.load_errors(a, vessel, "level"), metrics.load_errors(b, vessel, "level")
    view = metrics.vessel_view(a, vessel)
    tol = IM.tolerances(dict(depth=ea["depth"], weight=ea["weight"]), float(a.attrs["spacing"]),
                        int(view["inside"].sum()), float(a.attrs["solver.f_tol"]))
    diff = dict(level=eb["level"] - ea["level"], side=eb["side_err"] - ea["side_err"],
                floor=eb["floor_err"] - ea["floor_err"])
    return diff, {k: tol[k][0] for k in diff}


@pytest.mark.parametrize("lat", ["coarse", "refined"])
def test_newton_converges_in_under_a_fiftieth_of_the_capped_evaluations(singles, lat):
    capped, newton = singles[lat, "capped"], singles[lat, "newton_lm"]
    for ds in (capped, newton):
        assert ds.attrs["status"] == "converged" and np.abs(ds["force"].values).max() < float(ds.attrs["solver.f_tol"])
    assert newton.attrs["variant"] == "newton_lm" and int(newton["force_evals"]) == int(newton["steps"]) + 1
    assert int(newton.attrs["hessian_assemblies"]) >= int(newton["steps"]) and int(newton.attrs["cg_iterations"]) > 0
    # measured: coarse 101 against 9,964; refined 167 against 20,053
    assert 50 * int(newton["force_evals"]) < int(capped["force_evals"])


@pytest.mark.xfail(strict=True, reason="issue 20 target <= 100 force evaluations: newton needs 101 (coarse) and "
                   "167 (refined); a Levenberg-Marquardt step per evaluation cannot cross the lattice's mechanism "
                   "phase faster (benchmarks/results/newton_evals.csv)")
@pytest.mark.parametrize("lat", ["coarse", "refined"])
def test_newton_needs_at_most_100_evaluations(singles, lat):
    assert int(singles[lat, "newton_lm"]["force_evals"]) <= 100


@pytest.mark.parametrize("lat", ["coarse", "refined"])
def test_newton_level_is_the_capped_level_within_a_quarter_spacing(singles, lat):
    diff, tol = state_differences(singles[lat, "capped"], singles[lat, "newton_lm"])
    assert abs(diff["level"]) < tol["level"]  # measured: coarse -0.003 cm of 2.5; refined -0.74 cm of 1.25
    assert abs(diff["floor"]) < tol["floor"]


def test_newton_coarse_state_is_the_capped_state(singles):
    diff, tol = state_differences(singles["coarse", "capped"], singles["coarse", "newton_lm"])
    assert abs(diff["side"]) < tol["side"]  # measured 0.0008 of 0.034


@pytest.mark.xfail(strict=True, reason="refined: newton ends in another local minimum (energy 352,145 against "
                   "capped's 351,927 N cm): side walls loaded 23 % more (side_err +0.018 against -0.179, tolerance "
                   "0.0167); the end state is path-dependent")
def test_newton_refined_side_loads_are_the_capped_ones(singles):
    diff, tol = state_differences(singles["refined", "capped"], singles["refined", "newton_lm"])
    assert abs(diff["side"]) < tol["side"]


@pytest.fixture(scope="module")
def flows(tmp_path_factory):
    """Application 1 -> 3 (paper's update; runs single_coarse, flow_incomplete of config/methods/isa.yaml)
    -> 4 (run flow_complete_capped: to step 300,000, flow records) with capped and with newton."""
    tmp = tmp_path_factory.mktemp("newton_flow")
    paths = {k: tmp / f"{k}.nc" for k in ("app1", "app3", "capped", "newton")}
    assert run_declared(paths["app1"], "single_coarse") == 0
    assert run_declared(paths["app3"], "flow_incomplete", start=paths["app1"]) == 0
    for v, name in (("capped", "capped"), ("newton_lm", "newton")):
        assert run_declared(paths[name], "flow_complete_capped", start=paths["app3"], variant=v) == 0
    return tuple(runfile.read(paths[k]) for k in ("app3", "capped", "newton"))


def test_newton_completes_the_flow_in_under_one_percent_of_the_capped_evaluations(flows):
    app3, capped, newton = flows
    assert newton.attrs["status"] == capped.attrs["status"] == "converged"
    assert newton.attrs["restart"].startswith("positions only")
    assert int(newton["start_step"]) == int(app3["steps"]) == 100000
    # measured: 356 against 46,724 (0.76 %)
    assert 100 * int(newton["force_evals"]) <= int(capped["force_evals"])


def test_newton_flow_ends_in_the_capped_state(flows):
    _, capped, newton = flows
    fc, fn = metrics.flow_measures(capped), metrics.flow_measures(newton)
    assert fn["particles_first"] == fc["particles_first"] and fn["mass_conserved"]
    diff, tol = state_differences(capped, newton, "second")
    for k in ("level", "side", "floor"):
        assert abs(diff[k]) < tol[k], k  # measured: level -0.001 cm, side -0.002, floor +0.0002
