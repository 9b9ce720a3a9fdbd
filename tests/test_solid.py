"""Hooke's-law solid particles (marko2017 section 3-4): link law, contacts, conservation, section-4 cases.

Tolerances are stated with their derivation.  Strains are ~1e-5, so the
second-order factors of eqs. 15-16 ((1 + E_v)(1 + E_w) / (1 + E_u)) change
forces by O(strain) relative; the rest criterion (tol = 1e-6 of the largest
link force) leaves a stress error of at most n_links x 1e-6.
"""

from pathlib import Path

import numpy as np
import pytest

from isaflow import driver
from isaflow.methods.solid import cases as C
from isaflow.methods.solid import lattice, settings, solve, theory
from isaflow.inputs import InputError as SceneError

CFG_PATH = Path(__file__).parents[1] / "config/methods/solid.yaml"
CFG = settings.checked_values(CFG_PATH)
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
        settings.checked_values(bad)


def test_claims_table(tmp_path):
    """The solid claims table (methods.solid.report): the registry's marko2017 rows whose checks read the solid's
    runs, judged by the one judge on the paper's version (the printed model; the vessel with the paper's
    stop-at-the-boundary coupling) with the kept runs beside; rows whose runs were not made are untestable, never
    given a verdict."""
    from isaflow import claims as verdicts
    from isaflow import claims_registry
    from isaflow.methods.solid import outputs, report

    for case in ["bar_tension", "bar_compression", "shear", "hertz", "hertz_dt15ns", "hertz_dt56ns"]:
        for v in ["paper", "hooke"]:
            outputs.write_run(CFG_PATH, case, v, tmp_path / f"{case}_{v}.nc")
    # 4.4 and the elastic floor on a cheaper copy of the settings: a 40 cm plate, a 900 us history
    cfg = tmp_path / "solid.yaml"
    cfg.write_text(CFG_PATH.read_text().replace("span_cm: {value: 100.0", "span_cm: {value: 40.0")
                   .replace("history_us: {value: 2000.0", "history_us: {value: 900.0"))
    outputs.write_run(cfg, "vessel", "pressure_load", tmp_path / "vessel_pressure_load.nc")
    outputs.write_run(cfg, "vessel", "water_particles", tmp_path / "vessel_water_particles.nc")
    outputs.write_run(cfg, "vessel_water_stop", "paper", tmp_path / "vessel_water_stop_paper.nc")
    outputs.write_run(cfg, "floor_uniform", "uniform_load", tmp_path / "floor_uniform_uniform_load.nc")
    rigid = rigid_floor_run(tmp_path / "rigid" / "single.nc", span=40.0, panels=4, weight=3600.0) \
        if (tmp_path / "rigid").mkdir() is None else None
    outputs.write_run(cfg, "floor_sph", "oneway", tmp_path / "floor_sph_oneway.nc", loads=rigid)
    runs = sorted(tmp_path.glob("*.nc"))
    table = tmp_path / "marko2017.csv"
    entries = [c for c in claims_registry.load() if c["paper"] == "marko2017"]
    df = verdicts.judge(verdicts.Context({f"solid:{p.stem}": str(p) for p in runs}), entries)
    df.to_csv(table, index=False)  # as the claims rule writes it
    report.report(runs, table, [tmp_path / "65_solid.md", tmp_path / "timing.md"])
    assert list(df.columns) == verdicts.COLUMNS
    by = {r["id"]: r for r in df.fillna("").to_dict("records")}
    solid = set(report.measured_here(table)["id"])
    assert len(solid) >= 35 and {"mar-4.1-tension-hooke", "mar-4.4-settle", "prj-floor-beam"} <= solid
    assert "mar-4.3-pmax-arith" not in solid  # paper arithmetic reads no run
    s44 = {k: by[k] for k in ("mar-4.4-settle", "mar-4.4-outward", "mar-4.4-inputs", "mar-3-coupling")}
    assert all(verdicts.verdict_class(r["verdict"]) != "not testable here" for r in s44.values())
    assert all(r["judged_on"] == "the paper's version: vessel_water_stop_paper for vessel_water_particles"
               for r in s44.values())
    assert "t_paper 58.7 us" in by["mar-4.4-settle"]["measured"] and by["mar-3-coupling"]["verdict"] == "reproduced"
    assert "mirror_pressure" in by["mar-3-coupling"]["kept_measured"]
    assert verdicts.verdict_class(by["mar-4.3-scale-match"]["verdict"]) == "not testable here"  # its runs not made
    assert "solid:floor_isa_oneway" in by["prj-floor-beam"]["measured"]  # the floor under ISA's loads not made
    text = (tmp_path / "65_solid.md").read_text()
    assert "solid_vessel.png" in text and "solid_floor.png" in text and "| vessel | water_particles |" in text
    assert all(r["verdict"] and verdicts.verdict_class(r["verdict"]) in verdicts.VERDICTS for r in by.values())


# ---- section 4.4 pressure vessel (variant pressure_load) and the elastic floor ----

from isaflow.methods.solid import floor as F  # noqa: E402
from isaflow.methods.solid import vessel as V  # noqa: E402


def test_vessel_ring_is_symmetric_and_loaded_by_p_times_perimeter():
    # the wetted faces' loads cancel (the ring keeps the lattice's symmetry) and each quadrant's load
    # is p times the projected inner diameter, 2 a p per half ring (the staircase projects exactly)
    v = CFG["vessel"]
    st, inner = V.pressure_state(CFG)
    dx, a, b = V.geometry(v)
    assert np.abs(st.fext.sum(0)).max() < 1e-9 * np.abs(st.fext).max()
    up = st.fext[st.block.ref[:, 1] > 0, 1].sum()
    # lattice sites with r < a along a row: 2 floor(sqrt(a^2 - y^2)) + 1 per row; the load on the upper half is
    # p dx x (count of wetted top faces) = p x (projected width of the water in the upper half)
    assert up == pytest.approx(v["pressure_Pa"] * 1e-4 * 2 * a, rel=dx / a)
    area = st.block.n * dx**2 / (np.pi * (b**2 - a**2))
    assert area == pytest.approx(1.0, abs=0.02)  # Gauss circle: count error ~ perimeter / dx points, < 2 %


@pytest.fixture(scope="module")
def vessel_settled():
    st, inner, status, msg, resid = V.settle(CFG)
    return st, inner, status


@pytest.mark.xfail(strict=True, reason="measured +14.2 % (settled 1.173 um against Lame 1.026 um at the inner "
                                       "particles' radii): a first-order surface-layer error of the 5-particle "
                                       "lattice ring, +6.6 % at dx / 2, +2.8 % at dx / 4")
def test_vessel_pressure_load_settles_to_lame(vessel_settled):
    """Settled inner-wall displacement against Lame at the inner particles' own radii, tolerance 5 %.

    Derived before the run: (1) the ring's particle count differs from the annulus area by the Gauss-circle
    error, ~ (perimeter / dx) / N ~ 1.5 %, which changes the wall's effective thickness and u by about as much;
    (2) the staircase surfaces perturb the stresses over one particle layer of five, a second-order effect in
    the mean, (dx / (b - a))^2 = 4 %; sum about 5 %.  The solid model is 'objective' (G gamma in every lattice
    orientation; the 'hooke' shear springs give G gamma / 2 at 45 deg and +59 % here)."""
    st, inner, status = vessel_settled
    assert status == "converged"
    r = np.hypot(*st.block.ref[inner, :2].T)
    assert V.radial(st, inner).mean() == pytest.approx(V.lame(CFG, r).mean(), rel=0.05)


def test_vessel_pushed_outwards_and_error_shrinks_with_dx(vessel_settled):
    # the paper's observation (all steel particles pushed outwards), and the Lame error falls under
    # refinement: at dx / 2 (ring 10 particles thick) below 0.6 of the error at dx (first order: 0.5;
    # the 0.6 was set after measuring 14.2 % -> 6.6 %)
    st, inner, _ = vessel_settled
    assert (V.radial(st, np.ones(st.block.n, bool)) > 0).all()
    v = CFG["vessel"]
    err = V.radial(st, inner).mean() / V.lame(CFG, np.hypot(*st.block.ref[inner, :2].T)).mean() - 1
    fine = {**CFG, "vessel": {**v, "dx_mm": v["dx_mm"] / 2, "ring_particles": 2 * v["ring_particles"],
                              "water_radius_particles": 2 * v["water_radius_particles"]}}
    stf, innf, status, *_ = V.settle(fine)
    err_f = V.radial(stf, innf).mean() / V.lame(fine, np.hypot(*stf.block.ref[innf, :2].T)).mean() - 1
    assert status == "converged" and 0 < err_f < 0.6 * err


def test_vessel_time_step_rule():
    # eq. 26: dt <= dx / (4 c) for the history run; the paper's 146.8 ns is below it (1.135 us for 23.4 mm steel)
    st, _ = V.pressure_state(CFG)
    assert CFG["vessel"]["dt_ns"] * 1e-9 < st.dt_max
    assert st.dt_max == pytest.approx(2.34 / (4 * np.sqrt(207e9 / 7800) * 100), rel=1e-9)
    with pytest.raises(ValueError, match="above the step rule"):
        V.history(CFG, 1.01 * st.dt_max)


def test_vessel_undamped_history_starts_at_rest_and_overshoots():
    # sudden pressure on an undamped elastic ring: u(t) rises from 0 and overshoots its static value
    # (a suddenly applied load peaks at twice the static response); short history to stay fast
    cfg = {**CFG, "vessel": {**CFG["vessel"], "history_us": 400.0}}
    t, ui, uo, st = V.history(cfg, CFG["vessel"]["dt_ns"] * 1e-9)
    assert ui[0] == 0.0 and ui[1] > 0.0
    assert ui.max() > 1.5 * V.lame(CFG, V.geometry(CFG["vessel"])[1])


def test_nodal_loads_keep_force_and_moment():
    rng = np.random.default_rng(3)
    x, f = rng.uniform(0, 100, 50), rng.uniform(-10, 0, 50)
    P = F.nodal(x, f, 1.0, 101)
    assert P.sum() == pytest.approx(f.sum(), rel=1e-12)
    assert (P * np.arange(101)).sum() == pytest.approx((f * x).sum(), rel=1e-12)


@pytest.fixture(scope="module")
def floor_uniform():
    return F.run_floor(CFG, "uniform_load")


@pytest.mark.xfail(strict=True, reason="measured -16.7 %: the 5-layer lattice plate is stiffer than beam theory "
                                       "(0.408 mm against 0.490 mm at mid-span), -4.8 % with 10 layers of 0.5 cm "
                                       "(second order in dx); in pure bending the lattice is +6.7 % stiff at 5 "
                                       "layers, +2.3 % at 9, +0.7 % at 17")
def test_floor_uniform_load_beam_theory(floor_uniform):
    """Mid-span deflection of the 5 x 1 cm steel plate under W / span against Euler-Bernoulli (plane strain)
    under the same nodal loads, tolerance 5 %.

    Derived before the run: the lattice's second moment sum(y_i^2) dx = 10 dx^4 against t^3 / 12 = 10.4 dx^4
    (-4 % stiffness), Timoshenko shear deflection 0.8 (E / kappa G) (t / L)^2 = +0.6 %, support and load
    transfer over one particle of 100 (~1 %): about 5 %."""
    r = floor_uniform
    assert r.status == "converged"
    assert r.history["load_total"][1][0] == pytest.approx(CFG["floor"]["weight_N"], rel=1e-12)
    assert r.history["w_centre"][1][0] == pytest.approx(r.history["w_centre_actual"][1][0], rel=0.05)


def test_floor_deflection_in_the_asked_range(floor_uniform):
    # the settings aim at 0.1-1 % of the span under W / span (issue 13); check the plate itself
    w = floor_uniform.history["w_centre"][1][0] / CFG["floor"]["span_cm"]
    assert 1e-3 < w < 1e-2


def rigid_floor_run(path, span=100.0, panels=10, weight=9000.0, method="sph", variant="wcsph"):
    """A synthetic rigid-floor run file: hydrostatic floor contacts (W / panels at each panel centre),
    the tank's three walls, the liquid's weight; what floor.floor_contacts reads."""
    import xarray as xr

    x = (np.arange(panels) + 0.5) * span / panels
    ds = xr.Dataset(
        {"wall_segment": (("wall", "end"), [[0, span, 0, 0], [0, 0, span, 0], [span, 0, span, span]]),
         "contact_wall": (("contact",), np.ones(panels, np.int32)),
         "contact_point": (("contact", "xy"), np.column_stack([x, np.zeros(panels)])),
         "contact_force": (("contact", "xy"), np.column_stack([np.zeros(panels), np.full(panels, weight / panels)])),
         "weight": (("particle",), np.full(180, weight / 180)), "wall_time": ((), 1.5)},
        coords={"wall": ["left", "floor", "right"], "xy": ["x", "y"]},
        attrs={"method": method, "variant": variant})
    ds.to_netcdf(path, engine="netcdf4")
    return path


def test_floor_oneway_reads_the_floor_contacts(tmp_path):
    # a short plate (span 40 cm) so the test settles in a second; loads: the synthetic hydrostatic contacts
    cfg = {**CFG, "floor": {**CFG["floor"], "span_cm": 40.0}}
    run = rigid_floor_run(tmp_path / "rigid.nc", span=40.0, panels=4, weight=3600.0)
    r = F.run_floor(cfg, "oneway", loads=run, case="floor_sph")
    assert r.status == "converged" and r.variant == "oneway" and r.params["load_method"] == "sph"
    assert r.history["load_total"][1][0] == pytest.approx(3600.0, rel=1e-12)
    assert r.history["nodal_load"][1].sum() == pytest.approx(3600.0)
    # the panel centres (5, 15, 25, 35 cm) are particle centres: the theory under the applied loads is the
    # beam under the four panel point loads exactly
    h = r.history
    th = theory.beam_point_deflection(h["x_mid"][1], [5.0, 15.0, 25.0, 35.0], np.full(4, 900.0), 40.0,
                                      F.stiffness(cfg))
    assert h["w_theory_actual"][1] == pytest.approx(th, rel=1e-9, abs=1e-15)
    bad = rigid_floor_run(tmp_path / "rigid50.nc", span=50.0)
    with pytest.raises(ValueError, match="floor length"):
        F.run_floor(cfg, "oneway", loads=bad)


def test_water_particles_at_rest_balance_and_load_the_ring():
    # variant water_particles: at rest at p0 every water particle has a full lattice support (water + ring,
    # the ring 5 dx > 2 h thick), so its pressure forces cancel to round-off; the ring takes the reaction,
    # whose radial total is the pressure on the inner wall, p0 2 pi a (1 % check: measured 0.1 %, the 1 % was
    # set after measuring, a consistency check); forces are pairwise, so water + ring forces sum to zero
    from isaflow.core import smoothing as SM
    from isaflow.methods.solid import water as Wt

    v = CFG["vessel"]
    dx, a, _ = V.geometry(v)
    st, _ = V.pressure_state(CFG)
    xw = Wt.water_sites(v["water_radius_particles"], dx)
    nw = len(xw)
    rho0, K, p0 = v["rho_water_kg_m3"] * 1e-8, v["K_GPa"] * 1e5, v["pressure_Pa"] * 1e-4
    h = v["water_h_over_dx"] * dx
    kind = SM.kernel_id(v["water_kernel"])
    pos = np.vstack([xw, st.pos[:, :2]])
    fw, fs, drho = np.zeros((nw, 2)), np.zeros((st.block.n, 2)), np.zeros(nw)
    Wt.water_forces(pos, np.zeros_like(pos), np.full(nw, rho0), nw, rho0 * dx**2, h, kind, SM.NORM[kind, 2] / h**2,
                    K, rho0, p0, v["water_alpha"], np.sqrt(K / rho0), fw, fs, drho)
    assert np.abs(fw).max() < 1e-9 * p0 * dx
    assert np.abs(fw.sum(0) + fs.sum(0)).max() < 1e-9 * p0 * dx
    ref = st.block.ref[:, :2]
    radial_total = (fs * ref / np.hypot(*ref.T)[:, None]).sum()
    assert radial_total == pytest.approx(p0 * 2 * np.pi * a, rel=0.01)


def test_water_particles_pressure_drops_as_ring_expands_and_step_rule():
    from isaflow.methods.solid import water as Wt

    dt = CFG["vessel"]["dt_ns"] * 1e-9
    t, ui, pw, st, inner, rho = Wt.coupled_history(CFG, dt, 400, 100)
    assert (np.diff(ui) > 0).all() and (np.diff(pw) < 0).all()  # the paper's 400 steps: still expanding
    with pytest.raises(ValueError, match="above the step rule"):
        Wt.coupled_history(CFG, 1.01 * st.dt_max, 1, 1)


# ---- the runs the claims registry asks for: eq. 27 stepping, sustained tension, other disk radii ----


def test_eq27_step_from_the_particle_speed_and_the_move_recorded():
    """Eq. 27: dt = 0.1 dx / V_max with V_max the particle's speed (3-4-5 velocity: |v| = 5 cm/s), capped by
    eq. 26 (dx / (4 c)); a force-free particle then moves exactly 0.1 dx, which the state records."""
    b = lattice.unlinked(1, 1.0)
    st = solve.State(b, solve.Material(1.0, 0.3, 1.0), "paper", np.ones((1, 3)), push=0)  # c = 1 cm/s
    st.vel[0] = [3.0, 4.0, 0.0]
    solve.relax(st, 0.0, 1, min_steps=1)
    assert st.clock[3] == pytest.approx(0.1 / 5.0, rel=1e-12) and st.clock[6] == pytest.approx(0.1, rel=1e-12)
    # clock[3] is the largest step so far (the steps grow below): 0.1 dx / 0.5 = 0.2 s < dx / (4 c) = 0.25 s; at
    # 0.05 cm/s the cap acts
    st.vel[0] = [0.3, 0.4, 0.0]
    solve.relax(st, 0.0, 1, min_steps=1)
    assert st.clock[3] == pytest.approx(0.2, rel=1e-12)
    st.vel[0] = [0.03, 0.04, 0.0]
    solve.relax(st, 0.0, 1, min_steps=1)
    assert st.clock[3] == pytest.approx(0.25, rel=1e-12)
    st.vel[0] = 0.0  # eq. 27 alone at rest: the speed floor sets the step
    solve.relax(st, 0.0, 1, min_steps=1, cap=False, vfloor=1e-3)
    assert st.clock[3] == pytest.approx(100.0, rel=1e-12)
    with pytest.raises(ValueError, match="speed floor"):
        solve.relax(st, 0.0, 1, cap=False)


def test_long_bar_starts_in_equilibrium_and_stays_affine():
    """The bar held at 1 % strain, started on its affine positions plus 1e-6 dx: an equilibrium of the printed
    model (no clumping: the registry's test is 0.1 dx), 2,000 undamped steps here (10^5 in the run)."""
    cfg = {**CFG, "bar_long": {**CFG["bar_long"], "steps": 2000, "record_every": 500}}
    r = C.run_bar_long(cfg, "paper", 0.01, 0.25)
    assert r.status == "step_limit"
    assert r.history["max_nonaffine_over_dx"][1][0] < 1e-3
    assert min(r.history["min_link_over_dx_t"][1]) > 0.999
    assert C.long_bar_case(CFG, "bar_tension_long_e5_dt0.1") == (0.05, 0.1)
    with pytest.raises(ValueError, match="outside bar_long"):
        C.long_bar_case(CFG, "bar_tension_long_e2_dt0.1")


def test_scale_radii_come_from_the_settings():
    assert C.scale_radius_mm(CFG, "hertz_R50.8mm") == 50.8 and C.scale_radius_mm(CFG, "hertz_R20m") == 20000.0
    with pytest.raises(ValueError, match="scale_radii_mm"):
        C.scale_radius_mm(CFG, "hertz_R3m")


def test_the_claims_sweep_cases_come_from_the_settings():
    """The vessel water of claims input vessel_water (vessel.water_h_sweep, water_alpha_sweep), refused outside them;
    the axial-only grips and the other depths of inputs bar_grips and hertz_increments."""
    assert C.water_sweep(CFG, "vessel_water_stop") == {}
    assert C.water_sweep(CFG, "vessel_water_stop_h1.5") == {"water_h_over_dx": 1.5}
    assert C.water_sweep(CFG, "vessel_water_stop_a0") == {"water_alpha": 0.0}
    for bad in ("vessel_water_stop_h2", "vessel_water_stop_x1", "vessel_water_stop_a"):
        with pytest.raises(ValueError, match="water_h_sweep"):
            C.water_sweep(CFG, bad)
    ids = settings.claim_run_ids(CFG_PATH)
    assert {"bar_tension_sliding_paper", "vessel_water_stop_h1.5_paper", "hertz_loadsteps_paper"} <= set(ids)
    r = C.run_case(CFG, "bar_tension_sliding", "paper")
    assert r.params["grips"] == "sliding" and r.params["case"] == "bar_tension_sliding"
    assert CFG["hertz"]["depths_alt_um"][0] == CFG["hertz"]["depths_um"][0]  # the stated end depths kept
    assert CFG["hertz"]["depths_alt_um"][-1] == CFG["hertz"]["depths_um"][-1]


def test_the_papers_stop_at_the_boundary_coupling_stops_an_approaching_particle_only():
    """marko2017 section 3 (run as the case vessel_water_stop, claims deviation mar-3-coupling): a water particle
    touching a ring particle and moving towards it gets m (v_rel . n) / dt, which stops its relative normal motion
    within the step, and the ring particle the opposite force; a particle moving away or out of reach gets none."""
    from isaflow.methods.solid.water import stop_contacts

    m, dt, dx = 2.0, 1e-3, 1.0
    xs = np.array([[0.0, 0.0]])
    vs = np.zeros((1, 2))
    xw = np.array([[0.99, 0.0], [-0.6, 0.6], [0.0, 1.5]])  # touching, touching, out of reach
    vw = np.array([[-3.0, 2.0], [-1.0, 1.0], [0.0, -5.0]])  # towards, away (along the normal), towards but far
    fw, fs = np.zeros((3, 2)), np.zeros((1, 2))
    assert stop_contacts(xw, vw, xs, vs, m, dt, dx, fw, fs) == 1
    v_after = vw[0] + dt * fw[0] / m
    assert v_after[0] == pytest.approx(0.0, abs=1e-12) and v_after[1] == pytest.approx(2.0)  # tangential kept
    assert np.allclose(fw[1:], 0.0) and np.allclose(fs[0], -fw[0])  # action = reaction


# ---- the compiled loop's layouts and the coupled vessel's reused pair list (issue 42) ----


@pytest.mark.parametrize("case", ["hertz_hooke", "floor_objective"])
def test_2d_layout_gives_the_3d_layouts_numbers(case):
    """A 2D run steps in the 2D layout ((N, 2) arrays, 3-component virial, one rotation per particle); the 3D
    layout of the same run (flat=False) must give the same positions, velocities, stresses, strains, forces and
    clock to the bit: the z terms it adds are exact zeros.  Hertz: unlinked pairs and the disk; floor: the
    objective springs' rotations and the Poisson term."""
    if case == "hertz_hooke":
        make = lambda: C.hertz_state(CFG, "hooke")  # noqa: E731
    else:
        def make():
            st, top, _ = F.plate({**CFG, "floor": {**CFG["floor"], "span_cm": 20.0}})
            st.fext[np.flatnonzero(top), 1] = -100.0
            return st
    runs = []
    for flat in (None, False):
        st = make()
        if case == "hertz_hooke":
            C.set_depth(st, CFG["hertz"]["radius_mm"] * 0.1, 26e-4)
        stp = solve.Stepper(st, 0.0, 3000, min_steps=3000, chunk=1000, flat=flat)
        assert stp.flat == (flat is None)
        driver.drive(stp)
        runs.append(st)
    a, b = runs
    assert a.steps == b.steps == 3000
    for k in ("pos", "vel", "sig", "strain", "frc", "clock", "pres"):
        assert np.array_equal(getattr(a, k), getattr(b, k)), k
    assert np.abs(a.pos - a.block.ref).max() > 0  # it moved


def test_stop_contacts_from_the_list_are_the_brute_force_ones():
    """The stop contacts of the coupled loop come from the water's pair list (the ring candidates of each water
    particle, ascending): the same contacts, in the same order, so the same forces to the bit as the brute-force
    search over every ring particle (written out here), on a random cloud of water around a ring lattice."""
    from isaflow.methods.solid.water import pair_list, stop_rows

    rng = np.random.default_rng(7)
    xs = np.array([[i, j] for i in range(-4, 5) for j in range(-4, 5) if abs(i) == 4 or abs(j) == 4], float)
    xw = rng.uniform(-4.5, 4.5, (300, 2))
    vw, vs = rng.normal(size=(300, 2)), 0.1 * rng.normal(size=(len(xs), 2))
    m, dt, reach = 2.0, 1e-3, 1.0
    fw, fs = np.zeros_like(xw), np.zeros_like(xs)
    lst, start, ring = pair_list(np.vstack([xw, xs]), len(xw), 2.6)  # the coupled loop's cutoff 2 h + skin
    acted = stop_rows(xw, vw, xs, vs, m, dt, reach, start, ring, fw, fs)
    gw, gs, count = np.zeros_like(xw), np.zeros_like(xs), 0
    for a in range(len(xw)):
        v = vw[a].copy()
        for b in range(len(xs)):
            d = xw[a] - xs[b]
            r2 = d[0] * d[0] + d[1] * d[1]
            if r2 >= reach * reach or r2 == 0.0:
                continue
            n = d / np.sqrt(r2)
            vn = (v[0] - vs[b, 0]) * n[0] + (v[1] - vs[b, 1]) * n[1]
            if vn >= 0.0:
                continue
            f = -m * vn / dt
            gw[a] += f * n
            gs[b] -= f * n
            v -= vn * n
            count += 1
    assert acted == count > 20
    assert np.array_equal(fw, gw) and np.array_equal(fs, gs)


def test_coupled_vessel_reuses_one_pair_list():
    """The coupled loop builds the water's pair list (cutoff 2 h + 0.1 dx) once and keeps it while no particle
    has moved half the skin: the water moves ~1e-7 dx in the paper's 400 steps, so one build.  The forces from
    the kept list equal a fresh list's (water_forces) to round-off (the sums in another order; 1e-12 of the
    largest force), and the mean inner displacement at step 400 is main's (per-step lists, 509ae75) to 1e-9:
    the summation order is all that changed, and its round-off grows to ~3e-9 only by the 13,624 steps of the
    full history (measured)."""
    from isaflow.methods.solid import water as Wt

    dt = CFG["vessel"]["dt_ns"] * 1e-9
    out = {}
    t, ui, pw, st, inner, rho = Wt.coupled_history(CFG, dt, 400, 100, out)
    assert out["list_builds"] == 1 and out["status"] == "step_limit" and out["steps"] == 400
    assert ui[-1] == pytest.approx(1.9632524212551335e-05, rel=1e-9)
    c = Wt.Coupled(CFG, dt, 50, 50)
    driver.drive(c)
    m, h, kind, norm, rho0, c0, p0, alpha, skin, dx = c.wpar
    fw, fs, drho = np.zeros_like(c.fw), np.zeros_like(c.fs), np.zeros_like(c.drho)
    Wt.water_forces(c.X, c.V, c.rho, c.nw, m, h, int(kind), norm, rho0 * c0**2, rho0, p0, alpha, c0, fw, fs, drho)
    gw, gs, grho = np.zeros_like(fw), np.zeros_like(fs), np.zeros_like(drho)
    pr2 = np.zeros(c.nw)
    Wt.pressures(c.rho, rho0, c0, p0, pr2)
    Wt.pair_forces(c.lst[0], c.lst[1], c.lst.shape[1], c.X, c.V, c.rho, pr2, c.nw, m, h, int(kind), norm, alpha, c0,
                   True, gw, gs, grho)
    scale = max(np.abs(fw).max(), np.abs(fs).max())
    assert np.abs(gw - fw).max() <= 1e-12 * scale and np.abs(gs - fs).max() <= 1e-12 * scale
    assert np.abs(grho - drho).max() <= 1e-12 * np.abs(drho).max()
