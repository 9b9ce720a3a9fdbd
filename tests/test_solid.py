"""Hooke's-law solid particles (marko2017 section 3-4): link law, contacts, conservation, section-4 cases.

Tolerances are stated with their derivation.  Strains are ~1e-5, so the
second-order factors of eqs. 15-16 ((1 + E_v)(1 + E_w) / (1 + E_u)) change
forces by O(strain) relative; the rest criterion (tol = 1e-6 of the largest
link force) leaves a stress error of at most n_links x 1e-6.
"""

import csv
from pathlib import Path

import numpy as np
import pytest

from isaflow.methods.solid import cases as C
from isaflow.methods.solid import claims, lattice, settings, solve, theory
from isaflow.scene import SceneError

CFG_PATH = Path(__file__).parents[1] / "config/methods/solid.yaml"
CFG = settings.load(CFG_PATH)
MAT = C._material(CFG)


def _pair(gap, variant="paper", linked=True, push=1):
    """Two 2D particles of size 1 cm, both prescribed, b at distance gap [cm] along x; one force pass."""
    b = lattice.block(2, 1, 1, 1.0) if linked else lattice.unlinked(2, 1.0)
    b.ref[:] = [[0, 0, 0], [1.0, 0, 0]]
    st = solve.State(b, MAT, variant, np.zeros((2, 3)), push=push)
    st.target = b.ref.copy()
    st.target[1, 0] = gap
    st.pos[:] = st.target
    solve.relax(st, 1e-6, 1, min_steps=0)
    return st.frc[1, 0]  # force on b along x (> 0: push away from a)


@pytest.mark.parametrize("strain", [1e-5, -1e-5])
def test_single_link_hooke(strain):
    # eq. 16: f = E A strain with A = dx (2D, per unit thickness); relative tolerance 10 x strain
    # covers the second-order factors (E_u, E_v are O(strain) after the first stress update)
    f = _pair(1.0 + strain)
    assert f == pytest.approx(-MAT.E * 1.0 * strain, rel=10 * abs(strain))


def test_linked_pull_unlinked_only_push():
    assert _pair(1.1, linked=True) < 0  # linked and stretched: pulls b back
    assert _pair(1.1, linked=False) == 0.0  # unlinked and apart: nothing
    push = _pair(0.9, linked=False)
    assert push == pytest.approx(MAT.E * 0.1, rel=1e-12)  # unlinked, overlapping: Hooke push E A (r0 - r) / r0


def test_free_block_conserves_momentum():
    # all forces are pair forces: sum F = 0 to round-off, so a block released from a random
    # deformation keeps its centre of mass (kinetic damping zeroes a zero total momentum)
    rng = np.random.default_rng(1)
    b = lattice.block(4, 3, 3, 1.0)
    st = solve.State(b, MAT, "hooke", np.ones((b.n, 3)))
    st.pos += 1e-4 * rng.standard_normal(st.pos.shape)
    com0 = st.pos.mean(0)
    solve.relax(st, 1e-9, 2000)
    assert np.abs(st.frc.sum(0)).max() < 1e-9 * np.abs(st.frc).max() + 1e-12 * MAT.E * 1e-4
    assert np.abs(st.pos.mean(0) - com0).max() < 1e-12


def test_bar_paper_variant_is_exact_hooke():
    # normal springs in series between the held layers: strain delta / ((ny - 1) dx) everywhere;
    # tolerance 1e-4: rest criterion (10 links x 1e-6) plus O(strain ~ 7e-6) factors of eqs. 15-16
    r = C.run_bar(CFG, "paper", +1)
    b = CFG["bar"]
    L = (b["particles"][1] - 1) * b["dx_mm"] * 0.1
    assert r.status == "converged"
    assert r.history["sigma_centre"][1][0] == pytest.approx(MAT.E * b["pull_um"] * 1e-4 / L, rel=1e-4)
    assert r.history["width_change_x"][1][0] == 0.0  # eqs. 11-16 as printed: no Poisson necking


def test_bar_hooke_poisson_with_sliding_grips():
    # uniaxial stress (grips free laterally): continuum answer nu = 0.3 at mid-length.  Tolerance 5 %:
    # 16 of the 25 particles of the 5 x 5 section are surface particles whose lateral virial has one
    # link instead of two, so their lateral stress (zero in the exact state) feeds the Poisson term
    # with an error of the order of the surface fraction of lateral links, 2 / (2 (n - 1)) = 1/4 of
    # a term that is itself of order nu^2 ~ 0.1 of the axial strain: 2.5 %, doubled for margin.
    cfg = {**CFG, "bar": {**CFG["bar"], "grips": "sliding"}}
    r = C.run_bar(cfg, "hooke", +1)
    b = cfg["bar"]
    dx, ny, nx = b["dx_mm"] * 0.1, b["particles"][1], b["particles"][0]
    strain = b["pull_um"] * 1e-4 / ((ny - 1) * dx)
    nu = -r.history["width_change_x"][1][0] / ((nx - 1) / 2 * dx) / strain
    assert nu == pytest.approx(0.3, rel=0.05)
    assert r.history["sigma_centre"][1][0] == pytest.approx(MAT.E * strain, rel=0.05)


def test_bar_compression_mirrors_tension():
    t, c = C.run_bar(CFG, "hooke", +1), C.run_bar(CFG, "hooke", -1)
    # linear springs: mirror to the rest criterion and the O(strain) second-order factors
    assert c.history["sigma_peak"][1][0] == pytest.approx(-t.history["sigma_peak"][1][0], rel=1e-4)


def test_shear_hooke_matches_G_gamma():
    # simple shear between held and moved layers 4 dx apart: tau = G delta / (4 dx) in the middle.
    # Tolerance 2 %: the free x-ends (5 dx from the centre) perturb the shear over a decay length of
    # the block height (4 dx): exp(-pi 5 / 4) = 2 %.
    r = C.run_shear(CFG, "hooke")
    H = r.history["height"][1][0]
    assert H == pytest.approx(4 * CFG["bar"]["dx_mm"] * 0.1)
    assert r.history["tau_centre"][1][0] == pytest.approx(MAT.G * CFG["shear"]["deflection_um"] * 1e-4 / H, rel=0.02)


@pytest.mark.xfail(strict=True, reason="eqs. 11-16 as printed have no shear term: the 'paper' variant carries no "
                                       "shear stress, so the paper's 15.8993 MPa cannot come from them")
def test_shear_paper_variant_carries_the_papers_stress():
    r = C.run_shear(CFG, "paper")
    assert r.history["tau_peak"][1][0] == pytest.approx(15.8993e6 * 1e-4, rel=0.02)


def test_hertz_eq25_numbers():
    Er = theory.reduced_modulus(207e9, 0.3)
    assert Er / 1e9 == pytest.approx(227.4725, abs=5e-5)  # eq. 22 as printed (GPa)
    p = theory.hertz_pmax(12.7e-3, np.array([26e-6, 49e-6]), Er) / 1e9
    assert p[0] == pytest.approx(7.3, abs=0.05) and p[1] == pytest.approx(10.0, abs=0.05)  # paper's 2 digits


def test_lame_vessel_about_one_micron():
    u = theory.lame_inner_displacement(20 * 0.0234, 25 * 0.0234, 101135.0, 207e9, 0.3)
    assert u == pytest.approx(1.037e-6, rel=1e-3)  # hand evaluation of the plane-strain formula


@pytest.fixture(scope="module")
def hertz_hooke():
    return C.run_hertz(CFG, "hooke")


def test_hertz_hooke_settles_and_rule_step(hertz_hooke):
    r = hertz_hooke
    assert r.status == "converged"
    load, pmax = r.history["load"][1], r.history["pmax"][1]
    assert np.all(np.diff(load) > 0) and np.all(np.diff(pmax) > 0)
    dt_rule = CFG["hertz"]["dx_um"] * 1e-4 / (4 * MAT.c)  # eq. 26
    assert r.params["dt_max_s"] <= dt_rule * (1 + 1e-12)


@pytest.mark.xfail(strict=True, reason="known deviation: our peak pressure errors against eq. 25 reach ~10 % "
                                       "(plate 10 rows on a fixed base, geometric chord a), above the paper's 5.4 %")
def test_hertz_peak_pressure_within_papers_errors(hertz_hooke):
    d = np.asarray(hertz_hooke.history["depth"][1]) * 1e-2
    p = np.asarray(hertz_hooke.history["pmax"][1]) * 1e4
    err = np.abs(p / theory.hertz_pmax(12.7e-3, d, theory.reduced_modulus(207e9, 0.3)) - 1)
    assert err.max() <= 0.054


def test_step_above_rule_is_classified_not_silent():
    r = C.run_hertz_dt(CFG, "hooke", 56.0)  # the paper's largest stated step, 7.3 x eq. 26
    assert r.status == "escaped" and "unstable" in r.message
    ok = C.run_hertz_dt(CFG, "hooke", 15.0)
    assert ok.status == "converged"


def test_settings_reject_unknown_key(tmp_path):
    bad = tmp_path / "solid.yaml"
    bad.write_text(CFG_PATH.read_text().replace("  nu: {value: 0.3,", "  nuu: {value: 0.3,"))
    with pytest.raises(SceneError, match=r"solid.yaml: field 'material'"):
        settings.load(bad)


def test_claims_table(tmp_path):
    from isaflow.methods.solid import outputs

    for case in ["bar_tension", "bar_compression", "shear", "hertz", "hertz_dt15ns", "hertz_dt56ns"]:
        for v in ["paper", "hooke"]:
            outputs.write_run(CFG_PATH, case, v, tmp_path / f"{case}_{v}.nc")
    out = claims.write_claims(CFG_PATH, sorted(tmp_path.glob("*.nc")), tmp_path / "claims.csv")
    rows = list(csv.DictReader(open(out)))
    assert list(rows[0]) == claims.COLUMNS
    ok = ("reproduced", "not reproduced")
    assert all(r["verdict"] in ok or r["verdict"].startswith(("not testable here (", "reproduced only after"))
               for r in rows)
    assert len(rows) >= 15
