"""marko2017's claims measured on the solid runs and the paper's own numbers (isaflow.claims).

``MEASURES = {claim id: measure(ctx, entry) -> claims.Measurement}``: every testable marko2017 row of
config/claims/marko2017.yaml except those measured on SPH runs or on section 2's kernel
(methods.sph.claims).  A measure reads run files through ``ctx.run('solid:<case>_<variant>')``, the
paper's printed numbers from the entry's ``numbers`` and the tolerance from ``entry['tolerance']``; it
returns the numbers it found and whether the registry's test passed.  The verdict is written only by
isaflow.claims.verdict.

Conventions:
- *method result* rows on the solid model are judged on the printed method (variant ``paper``, eqs.
  11-16) where the row's inferred inputs include ``solid_variant``; the project's completions
  (``hooke``, ``objective``) are reported beside it and never decide the verdict;
- *paper inconsistency* rows: ``passed`` is True when the paper's two statements can both hold, False
  when the registry's test finds the inconsistency (so the quoted claim does not stand);
- *input rule* rows: ``passed`` is True when the runs use what the page says.
Units: run files in cm, N, s (stresses N/cm^2); theory.py in SI; text in the units the paper prints.
"""

import functools
from pathlib import Path

import numpy as np

from isaflow import claims as C
from isaflow import claims_registry

from . import kernels as K
from . import theory as T
from .cases import MM, UM, to_pa
from .settings import material_units

MEASURES, claim = C.measure_table()  # {claim id: measure(ctx, entry)}, each measure entered by @claim(id)

# ---------------------------------------------------------------------------------------------- helpers


def num(entry, name):
    """A number of the entry's ``numbers`` (the paper's printed values): float or array."""
    v = C.number(entry, name)
    return np.asarray(v, float) if isinstance(v, list) else float(v)


def tol(entry, k=None):
    """The tolerance value of the entry (k: index of a pair)."""
    v = entry["tolerance"]["value"]
    return float(v if k is None else v[k])


def solid(ctx, rid):
    """Run file of 'solid:<rid>'."""
    return ctx.run(f"solid:{rid}")


def rec(ds, name):
    """First value of a run-file variable (a record)."""
    return float(np.asarray(ds[name].values, float).ravel()[0])


def attr(ds, key, run):
    """A run-file attribute; a run made before it was recorded is missing (the claim is not testable)."""
    if key not in ds.attrs:
        raise C.Missing(f"solid:{run} with attribute {key} (rerun it)")
    return ds.attrs[key]


def status(ds):
    return str(ds.attrs["status"])


BROKEN = ("escaped", "nonfinite")


def run_stability(ctx, rid, limit):
    """(ok, text, move) of one run against the paper's stability standard: no escape or non-finite value and
    no particle moving more than `limit` dx in one step (water particles too, for the vessel)."""
    ds = solid(ctx, rid)
    move = float(attr(ds, "max_step_move_over_dx", rid))
    if "water_max_step_move_over_dx" in ds:
        move = max(move, rec(ds, "water_max_step_move_over_dx"))
    ok = status(ds) not in BROKEN and move <= limit
    return ok, f"{rid}: {status(ds)}, largest step move {move:.3g} dx", move


def fmt_list(xs, f="{:+.1%}"):
    return ", ".join(f.format(x) for x in xs)


@functools.lru_cache(maxsize=1)
def _entries():
    return {c["id"]: c for c in claims_registry.load()}


def entry_of(cid):
    """A registry entry by id (for the rows whose verdict is a function of others)."""
    return _entries()[cid]


def measurement(measured, passed, evidence="", why="", margin="", sensitivity="", sweep=()):
    """sweep: ((input, value, passed), ...) for isaflow.claims.robustness (the readings a measure judges besides
    the kept one)."""
    return C.Measurement(measured, None if passed is None else bool(passed), evidence, why, margin, sensitivity,
                         tuple(sweep))


# ---------------------------------------------------------------------------------- abstract and section 3


@claim("mar-abs-stable")
def abs_stable(ctx, e):
    """mar-abs-stable: every paper-variant run at the paper's settings stays within eq. 27's 10 % standard."""
    lim = tol(e)
    res = [run_stability(ctx, r["id"].split(":", 1)[1], lim) for r in e["runs"]]
    bad = [t for ok, t, _ in res if not ok]
    worst = max(m for *_, m in res)
    return measurement(
        "; ".join(t for _, t, _ in res), not bad,
        evidence="status and max_step_move_over_dx of every listed paper-variant run (results/solid/*_paper.nc)",
        why=("unstable or moving more than " f"{lim:g} dx in a step: " + "; ".join(bad)) if bad else "",
        margin=f"largest step move {worst:.3g} dx against {lim:g} dx; any escape fails regardless")


@claim("mar-abs-all-match")
def abs_all_match(ctx, e):
    """mar-abs-all-match: every row it depends on passes."""
    parts, fails = [], []
    for cid in e["depends_on"]:
        m = MEASURES[cid](ctx, entry_of(cid))
        parts.append(f"{cid}: {'passes' if m.passed else 'fails' if m.passed is False else 'untestable'}")
        if not m.passed:
            fails.append(cid)
    return measurement("; ".join(parts), not fails, evidence="the measures of the listed rows on the paper variant",
                       why=("fails: " + ", ".join(fails)) if fails else "",
                       margin=f"{len(e['depends_on']) - len(fails)} of {len(e['depends_on'])} rows pass")


@claim("mar-abs-tensile-solid")
def abs_tensile_solid(ctx, e):
    """mar-abs-tensile-solid: the bar held in sustained tension keeps every particle within 0.1 dx of its
    affine position, at every strain and step of the sweep present (bar_tension_long*_paper)."""
    lim = tol(e)
    kept = "bar_tension_long_paper"
    ids = [kept] + sorted(k.split(":", 1)[1] for k in ctx.paths
                          if k.startswith("solid:bar_tension_long_e") and k.endswith("_paper") and ctx.has(k))
    rows, fails = [], []
    for rid in ids:
        ds = solid(ctx, rid)
        na = rec(ds, "max_nonaffine_over_dx")
        link = float(np.min(ds["min_link_over_dx_t"].values))
        pair = float(np.min(ds["min_pair_over_dx_t"].values))
        ok = status(ds) not in BROKEN and na <= lim
        rows.append((rid, ds.attrs["strain"], ds.attrs["dt_over_dx_c"], na, link, pair, status(ds)))
        if not ok:
            fails.append(rid)
    k = rows[0]
    return measurement(
        f"strain {k[1]:g}, dt {k[2]:g} dx/c, {int(solid(ctx, kept)['steps'])} steps undamped: largest non-affine "
        f"displacement {k[3]:.3g} dx, smallest linked distance {k[4]:.6f} dx, smallest pair distance {k[5]:.6f} dx "
        f"({k[6]})", not fails,
        evidence="results/solid/bar_tension_long*_paper.nc (nonaffine_over_dx_t, min_link_over_dx_t, min_pair_over_dx_t)",
        why=("clumping or blow-up in " + ", ".join(fails)) if fails else "",
        margin=f"largest non-affine displacement over all runs {max(r[3] for r in rows):.3g} dx against {lim:g} dx",
        sensitivity="tension_test_setup sweep: " + "; ".join(
            f"strain {r[1]:g}, dt {r[2]:g} dx/c: {r[3]:.2g} dx ({r[6]})" for r in rows)
        + ("" if len(rows) > 1 else " (sweep runs absent)"))


@claim("mar-3-eq15-rest-length")
def eq15_rest_length(ctx, e):
    """mar-3-eq15-rest-length: eq. 15 as printed, epsilon_ab = dx_ab / (dx (1 + E_uu)) at dx_ab = dx, E_uu = 0."""
    dx = 1.0
    eps = dx / (dx * (1.0 + 0.0))
    lim = tol(e)
    return measurement(
        f"epsilon_ab = {eps:g} at the rest distance (eq. 12's delta L / L would give 0)", abs(eps) <= lim,
        evidence="eq. 15 with dx_ab = dx ('the length between two particles'), E_uu = 0",
        why="eqs. 15-16 as printed have no rest length: a lattice at its natural spacing is under strain 1; the "
            "project's paper variant reads dx_ab as the change of distance (input solid_variant)" if abs(eps) > lim else "",
        margin=f"|epsilon| = {abs(eps):g} against {lim:g}")


@claim("mar-3-no-poisson")
def no_poisson(ctx, e):
    """mar-3-no-poisson: eq. 14 (the kernels' strain update with the Poisson term off) under uniaxial stress."""
    sig = np.zeros((1, 6))
    sig[0, 1] = 1.0  # sigma_yy, any units
    strain = np.zeros((1, 3))
    E = 1.0
    vir = sig * 2.0  # the kernel reads the virial: sigma = vir / (2 V), V = 1
    K.stresses(vir, np.ones(1), 3, E, 0.3, 0, sig.copy(), strain)
    lat = float(abs(strain[0, 0]))
    lim = tol(e)
    neck = num(e, "necking_um")
    return measurement(
        f"lateral strain {lat:g} under uniaxial stress (axial {strain[0, 1]:g} sigma / E); the paper reports "
        f"{neck:g} um of necking", lat > lim,
        evidence="methods.solid.kernels.stresses with poisson = 0 (eq. 14: E_uu = sigma_uu / E)",
        why=f"eq. 14 sets each strain from its own stress only, so eqs. 11-16 cannot neck; the {neck:g} um of "
            "section 4.1 cannot come from the printed model" if lat <= lim else "",
        margin=f"|E_vv| = {lat:g} against {lim:g}")


def lattice_shear_modulus(E, nu, gamma=1e-6, n=4):
    """Shear modulus [units of E] of the printed model's cubic lattice (normal springs between linked
    nearest neighbours, methods.solid.kernels.link_forces with shear = 0): the virial shear stress of the
    centre particles of an n^3 block under simple shear u_x = gamma y, over gamma."""
    from .lattice import block

    b = block(n, n, n, 1.0)
    pos = b.ref.copy()
    pos[:, 0] += gamma * b.ref[:, 1]
    frc, vir = np.zeros((b.n, 3)), np.zeros((b.n, 6))
    sig, strain, rot = np.zeros((b.n, 6)), np.zeros((b.n, 3)), np.zeros((b.n, 3, 3))
    K.link_forces(pos, b.la, b.lb, b.d0, b.axis, sig, strain, E, nu, E / (2 * (1 + nu)), 1.0, 0, 0, rot, frc, vir)
    inner = np.all((b.index > 0) & (b.index < n - 1), axis=1)
    return float(np.abs(vir[inner, 3] / 2.0).max() / gamma)


@claim("mar-3-shear-mechanism")
def shear_mechanism(ctx, e):
    """mar-3-shear-mechanism: the printed lattice's shear modulus against G."""
    E, nu = num(e, "E_GPa"), num(e, "nu")
    G = E / (2 * (1 + nu))
    g_lat = lattice_shear_modulus(E, nu)
    lim = tol(e)
    return measurement(
        f"shear modulus of the printed cubic lattice {g_lat / G:.3g} G (G = {G:.4f} GPa); the paper reports "
        f"{num(e, 'tau_num_MPa'):g} MPa, close to G gamma", g_lat / G > lim,
        evidence="simple shear gamma = 1e-6 of a 4^3 block through methods.solid.kernels.link_forces (normal "
                 "springs only): virial shear stress of the interior particles / gamma",
        why="nearest-neighbour central springs on a cubic lattice carry no shear to first order: a zero-energy "
            f"mode, so the printed model cannot give {num(e, 'tau_num_MPa'):g} MPa" if g_lat / G <= lim else "",
        margin=f"{g_lat / G:.3g} G against {lim:g} G")


STOP = "vessel_water_stop_paper"  # the vessel with the paper's stop-at-the-boundary coupling (printed ring)


@claim("mar-3-coupling")
def coupling(ctx, e):
    """mar-3-coupling, a project deviation judged on the paper's version: the coupling of the run with the stated
    stop-at-the-boundary force (vessel_water_stop_paper) and what that run gives; the project's kept coupling of
    vessel_water_particles reported beside it."""
    ds = solid(ctx, STOP)
    kind = attr(ds, "coupling", STOP)
    ok, text, _ = run_stability(ctx, STOP, 0.1)
    gives = (f"{text}; ring inner wall {rec(ds, 'u_paper_end') / UM:.3g} um at 400 steps, "
             f"{rec(ds, 'u_inner_mean_cycles') / UM:.3g} um over whole cycles; smallest ring u_r at 400 steps "
             f"{np.nanmin(ds['u_radial_paper_end'].values) / UM:.3g} um; mean water pressure "
             f"{float(ds['p_water_t'].values.min()) * 1e4 / 1e3:.0f} to {float(ds['p_water_t'].values.max()) * 1e4 / 1e3:.0f} kPa; "
             f"{int(ds.attrs.get('stop_contacts', 0)):,} stopping contacts")
    kept = solid(ctx, "vessel_water_particles") if ctx.has("solid:vessel_water_particles") else None
    kept_text = (f"; the project's kept coupling (vessel_water_particles): '{kept.attrs.get('coupling', '?')}', ring "
                 f"{rec(kept, 'u_inner_mean_cycles') / UM:.3g} um over whole cycles") if kept is not None else ""
    return measurement(
        f"paper's version ({STOP}): coupling '{kind}': {ds.attrs.get('coupling_description', '')}; it gives {gives}"
        f"{kept_text}", kind == "stop_at_boundary",
        evidence=f"results/solid/{STOP}.nc attributes coupling, stop_contacts; results/solid/vessel_water_particles.nc",
        why="" if kind == "stop_at_boundary" else "the run does not use the stated coupling",
        margin="a rule in kind: followed or not")


# ---------------------------------------------------------------------------------- 4.1 tension, compression


def bar_geometry(ds):
    """(nx, ny, nz, dx cm) of a bar run from its lattice indices."""
    idx = ds["lattice_index"].values
    nx, ny, nz = (int(idx[:, k].max()) + 1 for k in range(3))
    return nx, ny, nz, float(ds.attrs["dx_cm"])


@claim("mar-4.1-bar-inputs")
def bar_inputs(ctx, e):
    """mar-4.1-bar-inputs: the bar run's E, nu, dx, block, pull against the page (the same unit conversions)."""
    ds = solid(ctx, "bar_tension_paper")
    E, nu, _ = material_units({"E_GPa": num(e, "E_GPa"), "nu": num(e, "nu"), "rho_kg_m3": 1.0})
    page = {"E [N/cm^2]": E, "nu": nu, "dx [cm]": num(e, "dx_mm") * MM, "pull [cm]": num(e, "pull_um") * UM}
    nx, ny, nz, dx = bar_geometry(ds)
    ours = {"E [N/cm^2]": ds.attrs["E_N_cm2"], "nu": ds.attrs["nu"], "dx [cm]": dx, "pull [cm]": ds.attrs["pull_cm"]}
    lim = tol(e)
    dev = {k: abs(ours[k] / page[k] - 1) for k in page}
    shape_ok = [nx, ny, nz] == [int(x) for x in num(e, "particles")]
    ok = all(d <= lim for d in dev.values()) and shape_ok
    return measurement(
        "; ".join(f"{k} {ours[k]:.6g} (page {page[k]:.6g})" for k in page) + f"; block {nx} x {ny} x {nz} "
        f"(page {' x '.join(str(int(x)) for x in num(e, 'particles'))}); every nearest-neighbour pair linked "
        "(methods.solid.lattice.block links them all)", ok,
        evidence="results/solid/bar_tension_paper.nc attributes and lattice indices",
        why="" if ok else "differs: " + ", ".join(k for k, d in dev.items() if d > lim) + ("" if shape_ok else " block"),
        margin=f"largest relative difference {max(dev.values()):.2g} against {lim:g}")


@claim("mar-4.1-bar-length")
def bar_length(ctx, e):
    """mar-4.1-bar-length: 11 x 23.4 mm against 25 cm."""
    L = num(e, "particles_y") * num(e, "dx_mm") / 10.0
    d = abs(L - num(e, "length_cm"))
    return measurement(f"{num(e, 'particles_y'):g} x {num(e, 'dx_mm'):g} mm = {L:.2f} cm against {num(e, 'length_cm'):g} cm "
                       f"(difference {d:.2f} cm)", d <= tol(e),
                       evidence="arithmetic on the page's numbers",
                       why="" if d <= tol(e) else (f"{num(e, 'particles_y'):g} particles of {num(e, 'dx_mm'):g} mm are "
                                                   f"{L:.2f} cm long, not {num(e, 'length_cm'):g} cm; one dx less, "
                                                   f"{L - num(e, 'dx_mm') / 10:.2f} cm, is the held-layer distance"),
                       margin=f"|difference| {d:.2f} cm against {tol(e):g} cm")


def bar_lengths(dx_cm, ny, stated_cm):
    """The bar_length readings [cm]: held layers (ny - 1) dx (kept), extent ny dx, the stated length."""
    return {f"{ny - 1} dx (held layers)": (ny - 1) * dx_cm, f"{ny} dx (extent)": ny * dx_cm, "stated": stated_cm}


@claim("mar-4.1-stress-vs-hooke")
def stress_vs_hooke(ctx, e):
    """mar-4.1-stress-vs-hooke: 1.4758 MPa against E delta / L for every length the text gives."""
    E = num(e, "E_GPa") * 1e9
    delta = num(e, "pull_um") * 1e-6
    sig = num(e, "sigma_MPa") * 1e6
    ny = int(num(e, "particles_y"))
    Ls = bar_lengths(num(e, "dx_mm") / 10.0, ny, num(e, "length_cm"))
    err = {k: sig / T.hooke_stress(E, delta, L / 100.0) - 1 for k, L in Ls.items()}
    lim = tol(e)
    ok = any(abs(x) <= lim for x in err.values())
    return measurement(
        "E delta / L: " + "; ".join(f"L = {k} {L:.4g} cm: {T.hooke_stress(E, delta, L / 100) / 1e6:.4f} MPa "
                                    f"({err[k]:+.2%})" for k, L in Ls.items())
        + f"; {sig / 1e6:g} MPa needs L = {T.implied_length(E, delta, sig) * 100:.2f} cm", ok,
        evidence="Hooke's law with the page's E, pull and lengths",
        why="" if ok else f"no length the text gives turns {num(e, 'pull_um'):g} um into {num(e, 'sigma_MPa'):g} MPa",
        margin=f"smallest |error| {min(abs(x) for x in err.values()):.2%} against {lim:.1e}")


@claim("mar-4.1-tension-hooke")
def tension_hooke(ctx, e):
    """mar-4.1-tension-hooke: sigma_peak of the paper-variant bar over E delta / L (L = held layers, kept)."""
    lim = tol(e)

    def err(rid):
        ds = solid(ctx, rid)
        nx, ny, nz, dx = bar_geometry(ds)
        Ls = bar_lengths(dx, ny, num(e, "length_cm"))
        s_pk, s_c = rec(ds, "sigma_peak"), rec(ds, "sigma_centre")
        hooke = {k: ds.attrs["E_N_cm2"] * ds.attrs["pull_cm"] / L for k, L in Ls.items()}
        return {k: s_pk / h - 1 for k, h in hooke.items()}, to_pa(s_pk), to_pa(s_c), status(ds), to_pa(hooke[next(iter(hooke))])

    p, s_pk, s_c, st, h0 = err("bar_tension_paper")
    kept = next(iter(p))
    hk, sh, _, sth, _ = err("bar_tension_hooke")
    ok = st not in BROKEN and abs(p[kept]) <= lim
    return measurement(
        f"paper variant: peak {s_pk / 1e6:.5f} MPa (centre {s_c / 1e6:.5f}), E delta / ({kept}) {h0 / 1e6:.5f} MPa: "
        f"{p[kept]:+.2e} ({st}); hooke (completion): {sh / 1e6:.5f} MPa, {hk[kept]:+.2%}", ok,
        evidence="results/solid/bar_tension_{paper,hooke}.nc sigma_peak, sigma_centre",
        why="" if ok else f"peak stress differs from E delta / L by {p[kept]:+.2e}",
        margin=f"|error| {abs(p[kept]):.2e} against {lim:.1e}",
        sensitivity="bar_length: " + "; ".join(f"{k}: {x:+.2%}" for k, x in p.items())
        + " (the paper's own stress: mar-4.1-stress-vs-hooke); bar_grips: the printed model has no lateral coupling, so "
        "sliding grips give the same axial stress (only clamped grips were run)",
        sweep=[("bar_length", k, st not in BROKEN and abs(x) <= lim) for k, x in p.items()])


def width_change_um(ds):
    """Per-side width change at mid-length [um], contraction positive (mean of x and z)."""
    return -0.5 * (rec(ds, "width_change_x") + rec(ds, "width_change_z")) / UM


def necking_readings(dx_cm, nx, ny, pull_cm):
    """{reading: (per-side factor, half-width d [cm], strain)} of input necking_reading (kept first)."""
    return {"per side / 2.5 dx / strain over 11 dx": (1.0, nx / 2 * dx_cm, pull_cm / (ny * dx_cm)),
            "per side / 2 dx / strain over 10 dx": (1.0, (nx - 1) / 2 * dx_cm, pull_cm / ((ny - 1) * dx_cm)),
            "total / 5 dx / strain over 11 dx": (2.0, nx * dx_cm, pull_cm / (ny * dx_cm))}


@claim("mar-4.1-necking-value")
def necking_value(ctx, e):
    """mar-4.1-necking-value: lateral contraction per side at mid-length against 0.1329 um."""
    paper = num(e, "necking_um")
    lim = tol(e)
    dp = width_change_um(solid(ctx, "bar_tension_paper"))
    dh = width_change_um(solid(ctx, "bar_tension_hooke"))
    err = dp / paper - 1
    return measurement(
        f"paper variant {dp:.4f} um per side ({err:+.1%} of {paper:g} um); hooke (completion) {dh:.4f} um "
        f"({dh / paper - 1:+.1%})", abs(err) <= lim,
        evidence="results/solid/bar_tension_{paper,hooke}.nc width_change_x, width_change_z",
        why="" if abs(err) <= lim else "the printed model has no Poisson coupling (mar-3-no-poisson): no necking",
        margin=f"|error| {abs(err):.1%} against {lim:.0%}; the hooke completion at {abs(dh / paper - 1):.1%}",
        sensitivity="bar_grips: the printed model has no lateral coupling, so no grip makes it neck (only clamped grips "
                    "were run; for the hooke completion sliding grips free the ends' contraction); necking_reading does "
                    "not enter (the per-side change is compared)")


@claim("mar-4.1-poisson-arith")
def poisson_arith(ctx, e):
    """mar-4.1-poisson-arith: eq. 17 inverted with the paper's 0.1329 um, per reading."""
    nx, ny, _ = (int(x) for x in num(e, "particles"))
    dx = num(e, "dx_mm") / 10.0
    reads = necking_readings(dx, nx, ny, num(e, "pull_um") * UM)
    dd = num(e, "necking_um") * UM
    nus = {k: T.poisson_from_necking(f * dd, d, s) for k, (f, d, s) in reads.items()}
    kept = next(iter(nus))
    err = nus[kept] / num(e, "nu_eq") - 1
    lim = tol(e)
    return measurement(
        f"nu = {nus[kept]:.5f} ({kept}) against {num(e, 'nu_eq'):g}: {err:+.1e}", abs(err) <= lim,
        evidence="eq. 17 inverted (theory.poisson_from_necking) on the page's numbers",
        why="" if abs(err) <= lim else "no reading of d and L gives the printed nu",
        margin=f"|error| {abs(err):.1e} against {lim:.1e}",
        sensitivity="necking_reading: " + "; ".join(f"{k}: {v:.4f}" for k, v in nus.items()),
        sweep=[("necking_reading", k, abs(v / num(e, "nu_eq") - 1) <= lim) for k, v in nus.items()])


@claim("mar-4.1-poisson-error-claim")
def poisson_error_claim(ctx, e):
    """mar-4.1-poisson-error-claim: 0.34125 against 0.3 within the 5 x 5 cross-section's 20 %."""
    err = num(e, "nu_eq") / num(e, "nu") - 1
    lim = tol(e)
    return measurement(f"{num(e, 'nu_eq'):g} / {num(e, 'nu'):g} - 1 = {err:+.2%}", abs(err) <= lim,
                       evidence="arithmetic on the page's numbers",
                       why="" if abs(err) <= lim else "outside the cross-section's discretisation error",
                       margin=f"|error| {abs(err):.2%} against {lim:.0%}")


@claim("mar-4.1-poisson-method")
def poisson_method(ctx, e):
    """mar-4.1-poisson-method: the run's equivalent nu (eq. 17, kept reading) against its input nu."""
    lim = tol(e)
    out = {}
    for v in ("paper", "hooke"):
        ds = solid(ctx, f"bar_tension_{v}")
        nx, ny, nz, dx = bar_geometry(ds)
        reads = necking_readings(dx, nx, ny, ds.attrs["pull_cm"])
        dd = width_change_um(ds) * UM
        out[v] = {k: T.poisson_from_necking(f * dd, d, s) for k, (f, d, s) in reads.items()}
        nu = float(ds.attrs["nu"])
    kept = next(iter(out["paper"]))
    err = out["paper"][kept] / nu - 1
    return measurement(
        f"paper variant nu_eq = {out['paper'][kept]:.4f} against nu = {nu:g} ({err:+.1%}); hooke (completion) "
        f"{out['hooke'][kept]:.4f} ({out['hooke'][kept] / nu - 1:+.1%})", abs(err) <= lim,
        evidence="results/solid/bar_tension_{paper,hooke}.nc width changes, eq. 17 inverted",
        why="" if abs(err) <= lim else "no necking in the printed model (no Poisson term), so nu_eq = 0",
        margin=f"|error| {abs(err):.1%} against {lim:.0%}",
        sensitivity="necking_reading (paper / hooke): " + "; ".join(
            f"{k}: {out['paper'][k]:.3f} / {out['hooke'][k]:.3f}" for k in out["paper"])
        + "; bar_grips: no grip makes the printed model neck (only clamped grips were run)")


@claim("mar-4.1-compression-symmetric")
def compression_symmetric(ctx, e):
    """mar-4.1-compression-symmetric: |sigma_peak compression / tension| = 1."""
    lim = tol(e)
    r = {v: abs(rec(solid(ctx, f"bar_compression_{v}"), "sigma_peak") / rec(solid(ctx, f"bar_tension_{v}"), "sigma_peak"))
         for v in ("paper", "hooke")}
    err = r["paper"] - 1
    return measurement(f"paper variant |compression / tension| = {r['paper']:.7f}; hooke (completion) {r['hooke']:.7f}",
                       abs(err) <= lim, evidence="results/solid/bar_{tension,compression}_{paper,hooke}.nc sigma_peak",
                       why="" if abs(err) <= lim else f"the two stresses differ by {err:+.1e}",
                       margin=f"|ratio - 1| {abs(err):.1e} against {lim:.1e}")


def lateral_pair(ctx, v, e):
    """(tension contraction um, compression change um, Poisson value nu delta d / L um) of variant v."""
    t, c = solid(ctx, f"bar_tension_{v}"), solid(ctx, f"bar_compression_{v}")
    nx, ny, nz, dx = bar_geometry(t)
    _, d, strain = next(iter(necking_readings(dx, nx, ny, t.attrs["pull_cm"]).values()))
    return width_change_um(t), width_change_um(c), float(t.attrs["nu"]) * strain * d / UM


@claim("mar-4.1-bulging-symmetric")
def bulging_symmetric(ctx, e):
    """mar-4.1-bulging-symmetric: compression widens by the same distance as tension narrows."""
    floor, lim = tol(e, 0), tol(e, 1)
    out = {}
    for v in ("paper", "hooke"):
        dt, dc, ref = lateral_pair(ctx, v, e)
        nonzero = abs(dt) > floor * ref and abs(dc) > floor * ref
        ratio = -dc / dt if dt != 0 else np.nan
        out[v] = (dt, dc, ref, nonzero, ratio, nonzero and dt * dc < 0 and abs(ratio - 1) <= lim)
    dt, dc, ref, nz_, ratio, ok = out["paper"]
    h = out["hooke"]
    return measurement(
        f"paper variant: tension {dt:+.3g} um, compression {dc:+.3g} um (Poisson value {ref:.4f} um); hooke "
        f"(completion): {h[0]:+.4f} / {h[1]:+.4f} um, ratio {h[4]:.6f}", ok,
        evidence="results/solid/bar_{tension,compression}_{paper,hooke}.nc width changes",
        why="" if ok else ("the printed model does not change the width at all" if not nz_ else
                           f"ratio {ratio:.6f}"),
        margin=(f"|width change| {max(abs(dt), abs(dc)):.2g} um against the floor {floor * ref:.2g} um" if not nz_
                else f"|ratio - 1| {abs(ratio - 1):.1e} against {lim:.1e}"))


@claim("mar-4.1-neck-bulge")
def neck_bulge(ctx, e):
    """mar-4.1-neck-bulge: tension narrows, compression widens (beyond the round-off floor)."""
    floor = tol(e)
    dt, dc, ref = lateral_pair(ctx, "paper", e)
    ht, hc, _ = lateral_pair(ctx, "hooke", e)
    ok = dt > floor * ref and -dc > floor * ref
    return measurement(
        f"paper variant: contraction in tension {dt:+.3g} um, in compression {dc:+.3g} um; hooke (completion) "
        f"{ht:+.4f} / {hc:+.4f} um", ok,
        evidence="results/solid/bar_{tension,compression}_{paper,hooke}.nc width changes",
        why="" if ok else "no lateral change in the printed model (no Poisson coupling)",
        margin=f"floor {floor * ref:.2g} um (1e-6 of the Poisson value {ref:.4f} um)")


# ---------------------------------------------------------------------------------- 4.2 shear


@claim("mar-4.2-shear-inputs")
def shear_inputs(ctx, e):
    """mar-4.2-shear-inputs: the shear run's free block, particle size and deflection against the page."""
    ds = solid(ctx, "shear_paper")
    idx = ds["lattice_index"].values
    g = int(ds.attrs["grip_layers"])
    shape = [int(idx[:, 0].max()) + 1, int(idx[:, 1].max()) + 1 - 2 * g, int(idx[:, 2].max()) + 1]
    page_shape = [int(x) for x in num(e, "particles")]
    dx_ok = abs(float(ds.attrs["dx_cm"]) / (num(e, "dx_mm") * MM) - 1) <= tol(e)
    d_ok = abs(float(ds.attrs["deflection_cm"]) / (num(e, "deflection_um") * UM) - 1) <= tol(e)
    ok = shape == page_shape and dx_ok and d_ok
    return measurement(
        f"free block {' x '.join(map(str, shape))} (page {' x '.join(map(str, page_shape))}), dx {ds.attrs['dx_cm']:g} cm, "
        f"deflection {ds.attrs['deflection_cm'] / UM:g} um in x; plus {g} held and {g} moved layer(s) (input "
        "shear_height)", ok, evidence="results/solid/shear_paper.nc attributes and lattice indices",
        why="" if ok else "the run differs from the page", margin="copied inputs: equal or not")


@claim("mar-4.2-height-arith")
def height_arith(ctx, e):
    """mar-4.2-height-arith: 3 x 23.4 mm against 9.3619 cm."""
    H = num(e, "particles_y") * num(e, "dx_mm") / 10.0
    d = abs(H - num(e, "height_cm"))
    return measurement(f"{num(e, 'particles_y'):g} x {num(e, 'dx_mm'):g} mm = {H:.4f} cm against {num(e, 'height_cm'):g} cm; "
                       f"{num(e, 'height_cm'):g} cm = {num(e, 'height_cm') * 10 / num(e, 'dx_mm'):.4f} particle widths",
                       d <= tol(e), evidence="arithmetic on the page's numbers",
                       why="" if d <= tol(e) else "the stated height is four particle widths, not the 3-particle block's",
                       margin=f"|difference| {d:.4f} cm against {tol(e):g} cm")


@claim("mar-4.2-g-arith")
def g_arith(ctx, e):
    """mar-4.2-g-arith: eq. 18."""
    G = T.shear_modulus(num(e, "E_GPa"), num(e, "nu"))
    d = abs(G - num(e, "G_GPa"))
    return measurement(f"207 / 2.6 = {G:.7f} GPa against {num(e, 'G_GPa'):g}", d <= tol(e),
                       evidence="theory.shear_modulus on the page's E and nu",
                       why="" if d <= tol(e) else "the printed value is not eq. 18's",
                       margin=f"|difference| {d:.1e} GPa against {tol(e):g} GPa")


@claim("mar-4.2-gamma-arith")
def gamma_arith(ctx, e):
    """mar-4.2-gamma-arith: the printed quotient."""
    g = num(e, "deflection_m") / num(e, "height_m")
    d = abs(g - num(e, "gamma"))
    return measurement(f"{g:.7e} against {num(e, 'gamma'):g}", d <= tol(e), evidence="the printed operands",
                       why="" if d <= tol(e) else "the printed quotient is off",
                       margin=f"|difference| {d:.1e} against {tol(e):g}")


@claim("mar-4.2-tau-arith")
def tau_arith(ctx, e):
    """mar-4.2-tau-arith: the printed product."""
    t = num(e, "G_Pa") * num(e, "gamma")
    d = abs(t - num(e, "tau_Pa"))
    exact = T.shear_stress(T.shear_modulus(num(e, "E_GPa") * 1e9, num(e, "nu")), num(e, "deflection_m"), num(e, "height_m"))
    return measurement(f"{num(e, 'G_Pa'):g} x {num(e, 'gamma'):g} = {t:.1f} Pa against {num(e, 'tau_Pa'):.1f} Pa", d <= tol(e),
                       evidence="the printed operands",
                       why="" if d <= tol(e) else (f"the expression as printed evaluates to {t / 1e6:.5f}e6; the printed "
                                                   f"{num(e, 'tau_Pa') / 1e6:g}e6 is the product of the unrounded G and gamma "
                                                   f"({exact / 1e6:.5f}e6)"),
                       margin=f"|difference| {d:.0f} Pa against {tol(e):g} Pa",
                       sensitivity=f"unrounded operands (E / (2 (1 + nu)) x {num(e, 'deflection_m'):g} / "
                                   f"{num(e, 'height_m'):g}): {exact:.1f} Pa, "
                                   f"|difference| {abs(exact - num(e, 'tau_Pa')):.0f} Pa")


@claim("mar-4.2-error-arith")
def error_arith(ctx, e):
    """mar-4.2-error-arith: 15.8993 / 15.5992 - 1 < 2 %."""
    err = num(e, "tau_num_MPa") / num(e, "tau_MPa") - 1
    return measurement(f"{err:+.3%}", err < tol(e), evidence="the printed numbers",
                       why="" if err < tol(e) else "the error is not below the paper's bound",
                       margin=f"{err:.3%} against {tol(e):.0%}")


@claim("mar-4.2-shear-num")
def shear_num(ctx, e):
    """mar-4.2-shear-num: tau_peak of the paper-variant block over G delta / H (H of the run: held to moved)."""
    lim = tol(e)
    out = {}
    for v in ("paper", "hooke"):
        ds = solid(ctx, f"shear_{v}")
        E, nu = float(ds.attrs["E_N_cm2"]), float(ds.attrs["nu"])
        tau_th = T.shear_stress(T.shear_modulus(E, nu), float(ds.attrs["deflection_cm"]), rec(ds, "height"))
        out[v] = (to_pa(rec(ds, "tau_peak")), to_pa(tau_th), rec(ds, "tau_peak") / tau_th - 1, status(ds),
                  rec(ds, "height"))
    tp, th, err, st, H = out["paper"]
    ok = st not in BROKEN and abs(err) < lim
    return measurement(
        f"paper variant: tau_peak {tp / 1e6:.4f} MPa against G delta / H = {th / 1e6:.4f} MPa at H = {H:.2f} cm "
        f"({err:+.1%}, {st}); hooke (completion): {out['hooke'][0] / 1e6:.4f} MPa ({out['hooke'][2]:+.2%})", ok,
        evidence="results/solid/shear_{paper,hooke}.nc tau_peak, height",
        why="" if ok else "the printed lattice has no shear stiffness (mar-3-shear-mechanism): it carries no shear stress",
        margin=f"|error| {abs(err):.1%} against {lim:.0%}",
        sensitivity="shear_height: the paper variant carries no shear stress at any H, so no reading changes the "
                    "verdict; the hooke completion matches G delta / H for the H its geometry has")


# ---------------------------------------------------------------------------------- 4.3 Hertz


@claim("mar-4.3-plate-dims")
def plate_dims(ctx, e):
    """mar-4.3-plate-dims: 51 x 159 um and 10 x 159 um against 8 mm and 1.5 mm."""
    n = num(e, "plate")
    size = n * num(e, "dx_um") / 1000.0
    want = num(e, "size_mm")
    d = np.abs(size - want)
    lims = np.array([tol(e, 0), tol(e, 1)])
    ok = bool(np.all(d <= lims))
    return measurement(f"{size[0]:.3f} mm by {size[1]:.3f} mm against {want[0]:g} by {want[1]:g} mm", ok,
                       evidence="arithmetic on the page's numbers",
                       why="" if ok else (f"{n[1]:g} x {num(e, 'dx_um'):g} um = {size[1]:.2f} mm is outside "
                                          f"{want[1]:g} +- {lims[1]:g} mm"),
                       margin=f"differences {d[0]:.3f}, {d[1]:.3f} mm against {lims[0]:g}, {lims[1]:g} mm")


@claim("mar-4.3-inputs")
def hertz_inputs(ctx, e):
    """mar-4.3-inputs: the Hertz run's disk, increments, plate and supports against the page."""
    ds = solid(ctx, "hertz_paper")
    idx = ds["lattice_index"].values
    shape = [int(idx[:, 0].max()) + 1, int(idx[:, 1].max()) + 1]
    depths = ds["depth"].values
    bottom = idx[:, 1] == 0
    held = bool(np.all(ds["pos"].values[bottom] == ds["pos0"].values[bottom]))
    moved = bool(np.any(ds["pos"].values[~bottom] != ds["pos0"].values[~bottom]))
    checks = {
        "radius": float(ds.attrs["radius_cm"]) == num(e, "radius_mm") * MM,
        "first and last depth": len(depths) > 0 and depths[0] == num(e, "depths_um")[0] * UM
        and depths[-1] == num(e, "depths_um")[-1] * UM,
        "increments": len(depths) == int(num(e, "increments")),
        "plate": shape == [int(x) for x in num(e, "plate")],
        "particle size": float(ds.attrs["dx_cm"]) == num(e, "dx_um") * UM,
        "bottom row fixed, the rest free": held and moved,
    }
    ok = all(checks.values())
    return measurement(
        f"disk radius {ds.attrs['radius_cm'] / MM:g} mm (rigid, exact circle: input hertz_disk), depths "
        f"{', '.join(f'{d / UM:g}' for d in depths)} um, plate {shape[0]} x {shape[1]} of {ds.attrs['dx_cm'] / UM:g} um, "
        f"bottom row held: {held}", ok, evidence="results/solid/hertz_paper.nc",
        why="" if ok else "differs: " + ", ".join(k for k, v in checks.items() if not v),
        margin="copied inputs: equal or not", sensitivity="hertz_increments: the interior depths are inferred (equal steps)")


@claim("mar-4.3-ered-arith")
def ered_arith(ctx, e):
    """mar-4.3-ered-arith: eq. 22."""
    Er = T.reduced_modulus(num(e, "E_GPa"), num(e, "nu"))
    d = abs(Er - num(e, "ered"))
    return measurement(f"207 / 0.91 = {Er:.7f} against {num(e, 'ered'):g}", d <= tol(e), evidence="theory.reduced_modulus",
                       why="" if d <= tol(e) else "the printed value is not eq. 22's",
                       margin=f"|difference| {d:.1e} against {tol(e):g}")


@claim("mar-4.3-ered-unit")
def ered_unit(ctx, e):
    """mar-4.3-ered-unit: 207 GPa / 0.91 in MPa against the printed 227.4725 'MPa'."""
    Er = T.reduced_modulus(num(e, "E_GPa") * 1e9, num(e, "nu"))  # Pa
    ratio = Er / (num(e, "ered_MPa") * 1e6)
    ok = abs(ratio - 1) <= tol(e)
    return measurement(f"E / (1 - nu^2) = {Er / 1e6:.1f} MPa = {ratio:.6g} x the printed {num(e, 'ered_MPa'):g} MPa", ok,
                       evidence="unit arithmetic",
                       why="" if ok else f"{num(e, 'ered_MPa'):g} is in GPa, not MPa (a factor {ratio:.0f})",
                       margin=f"|ratio - 1| {abs(ratio - 1):.3g} against {tol(e):g}")


@claim("mar-4.3-chord-not-hertz")
def chord_not_hertz(ctx, e):
    """mar-4.3-chord-not-hertz: eq. 24's chord against Hertz's sphere half-width sqrt(R delta)."""
    R = num(e, "radius_mm") * 1e-3
    d = num(e, "depths_um") * 1e-6
    ratio = T.chord_half_width(R, d) / np.sqrt(R * d)
    ok = bool(np.all(np.abs(ratio - 1) <= tol(e)))
    return measurement(f"a_eq24 / a_Hertz,sphere = {fmt_list(ratio, '{:.5f}')} at {fmt_list(d * 1e6, '{:g}')} um", ok,
                       evidence="theory.chord_half_width against sqrt(R delta)",
                       why="" if ok else "the chord of the undeformed bodies is sqrt(2) wider than Hertz's contact: "
                                         "eq. 24 is geometry, not a Hertz relation",
                       margin=f"|ratio - 1| {np.abs(ratio - 1).min():.3f} against {tol(e):g}")


@claim("mar-4.3-pmax-arith")
def pmax_arith(ctx, e):
    """mar-4.3-pmax-arith: eqs. 24-25 at 26 and 49 um."""
    R = num(e, "radius_mm") * 1e-3
    d = num(e, "depths_um") * 1e-6
    p = T.hertz_pmax(R, d, num(e, "ered_GPa") * 1e9) / 1e9
    want = num(e, "pmax_GPa")
    diff = np.abs(p - want)
    lims = np.array([tol(e, 0), tol(e, 1)])
    ok = bool(np.all(diff <= lims))
    return measurement(f"eq. 25: {p[0]:.3f} and {p[1]:.3f} GPa against {want[0]:g} and {want[1]:g} GPa", ok,
                       evidence=f"theory.hertz_pmax with the printed E' = {num(e, 'ered_GPa'):g} GPa",
                       why="" if ok else "eq. 25 does not give the printed range",
                       margin=f"differences {diff[0]:.3f}, {diff[1]:.3f} GPa against {lims[0]:g}, {lims[1]:g} GPa")


def load_exponents(R, d):
    """{reading: exponent n of P ~ delta^n between the two depths d} of the Hertz loads of input
    hertz_load_reading (line contact per metre and times a thickness share one exponent)."""
    a2 = T.chord_half_width(R, d) ** 2  # line contact P' = pi a p_max / 2 ~ a^2
    n_line = float(np.log(a2[1] / a2[0]) / np.log(d[1] / d[0]))
    return {"line contact x 159 um": n_line, "line contact per metre": n_line, "rigid sphere": 1.5}


@claim("mar-4.3-load-arith")
def load_arith(ctx, e):
    """mar-4.3-load-arith: the exponent of the paper's loads against the Hertz loads' exponents."""
    P, d = num(e, "loads_kN"), num(e, "depths_um") * 1e-6
    n_paper = float(np.log(P[1] / P[0]) / np.log(d[1] / d[0]))
    lo, hi = tol(e, 0), tol(e, 1)
    ns = load_exponents(num(e, "radius_mm") * 1e-3, d)
    inside = {k: lo <= n <= hi for k, n in ns.items()}
    ok = any(inside.values())
    return measurement(
        f"paper n = {n_paper:.3f}; Hertz: " + ", ".join(f"{k} {n:.3f}" for k, n in ns.items()), ok,
        evidence="ln(P2 / P1) / ln(delta2 / delta1) on the printed loads and depths; the Hertz loads' exponents "
                 "need no prefactor or thickness",
        why="" if ok else f"no Hertz load grows as delta^{n_paper:.2f}: the printed loads follow no Hertz formula",
        margin=f"Hertz exponents {', '.join(f'{n:.3f}' for n in sorted(set(ns.values())))} against [{lo:g}, {hi:g}]",
        sensitivity="hertz_load_reading: " + ", ".join(f"{k}: {'inside' if v else 'outside'}" for k, v in inside.items()))


def hertz_errors(ds):
    """Per depth of a Hertz run: (depth um, peak-pressure error, load error) against eq. 25 and the line contact
    P' = pi a p_max / 2 (plane strain, E' = E / (1 - nu^2)), and the readings' load errors (dict)."""
    E, nu = to_pa(ds.attrs["E_N_cm2"]), float(ds.attrs["nu"])
    R = float(ds.attrs["radius_cm"]) / 100.0
    d = ds["depth"].values / 100.0
    t = float(ds.attrs["dx_cm"]) / 100.0  # one plate particle, m (input hertz_load_reading)
    out = {}
    for plane, Er in (("plane strain", T.reduced_modulus(E, nu)), ("plane stress", E)):
        p_th = T.hertz_pmax(R, d, Er)
        line = np.pi * T.chord_half_width(R, d) * p_th / 2.0  # N/m
        load = ds["load"].values * 100.0  # N/cm -> N/m
        sphere = 4.0 / 3.0 * Er * np.sqrt(R) * d**1.5  # N
        out[plane] = dict(p=to_pa(ds["pmax"].values) / p_th - 1, line=load / line - 1, sphere=load * t / sphere - 1)
    return d * 1e6, out


def hertz_row(ctx, rid, n_depths):
    """(depths um, errors dict, status, converged increments) of a Hertz run; depths it did not reach count as NaN."""
    ds = solid(ctx, rid)
    d, errs = hertz_errors(ds)
    pad = lambda x: np.concatenate([x, np.full(n_depths - len(x), np.nan)])  # noqa: E731
    errs = {pl: {k: pad(v) for k, v in r.items()} for pl, r in errs.items()}
    return d, errs, status(ds), int(np.sum(ds["increment_converged"].values)) if "increment_converged" in ds else None


N_DEPTHS = 5  # the page's 'five discrete increments' (mar-4.3-inputs checks the runs against it)


def worst(x):
    """Largest |x| (NaN, a depth not reached, counts as infinite)."""
    x = np.asarray(x, float)
    return float(np.inf if np.isnan(x).any() else np.abs(x).max())


def hertz_judged(ctx, e, key):
    """The Hertz paper-variant run judged on one error (key 'p': peak pressure, 'line': load; hertz_errors) in plane
    strain: (tolerance, depths um, paper variant's errors, hooke's, paper's status, its increments at rest, the
    judged errors, all within the tolerance)."""
    lim = tol(e)
    d, ep, st, conv = hertz_row(ctx, "hertz_paper", N_DEPTHS)
    eh = hertz_row(ctx, "hertz_hooke", N_DEPTHS)[1]
    err = ep["plane strain"][key]
    return lim, d, ep, eh, st, conv, err, worst(err) <= lim


@claim("mar-4.3-pmax-error")
def pmax_error(ctx, e):
    """mar-4.3-pmax-error: peak contact pressure against eq. 25 at every depth, paper variant."""
    lim, d, ep, eh, st, conv, err, ok = hertz_judged(ctx, e, "p")
    return measurement(
        f"paper variant: {fmt_list(err)} at {fmt_list(d, '{:g}')} um ({conv} of {N_DEPTHS} increments at rest, {st}); "
        f"hooke (completion): {fmt_list(eh['plane strain']['p'])}", ok,
        evidence="results/solid/hertz_{paper,hooke}.nc pmax (largest contact force on a top particle / dx), eq. 25",
        why="" if ok else "the printed lattice, a mechanism without shear stiffness, does not hold the disk's load as "
                          "an elastic half-plane (it does not come to rest)",
        margin=f"worst |error| {worst(err):.1%} against {lim:.1%}; hooke {worst(eh['plane strain']['p']):.1%}",
        sensitivity=f"hertz_plane (plane stress): worst {worst(ep['plane stress']['p']):.1%}; hertz_disk, "
                    "hertz_increments: only the exact circle and equal increments were run")


@claim("mar-4.3-load-error")
def load_error(ctx, e):
    """mar-4.3-load-error: the numerically integrated load against the Hertz line contact at every depth."""
    lim, d, ep, eh, st, _, err, ok = hertz_judged(ctx, e, "line")
    return measurement(
        f"paper variant: {fmt_list(err)} at {fmt_list(d, '{:g}')} um ({st}); hooke (completion): "
        f"{fmt_list(eh['plane strain']['line'])}", ok,
        evidence="results/solid/hertz_{paper,hooke}.nc load (force on the disk per unit thickness) against "
                 "P' = pi a p_max / 2 with eq. 24's a; the kept thickness (one plate particle) multiplies both and "
                 "cancels",
        why="" if ok else f"the integrated load misses the Hertz line-contact load by more than the paper's {lim:.1%}",
        margin=f"worst |error| {worst(err):.1%} against {lim:.1%}; hooke {worst(eh['plane strain']['line']):.1%}",
        sensitivity=f"hertz_load_reading: per metre {worst(err):.1%} (same), rigid sphere x one plate particle "
                    f"{worst(ep['plane strain']['sphere']):.1%}; hertz_plane (plane stress) "
                    f"{worst(ep['plane stress']['line']):.1%}")


@claim("mar-4.3-settled")
def settled(ctx, e):
    """mar-4.3-settled: every increment of the paper variant comes to rest."""
    ds = solid(ctx, "hertz_paper")
    c = ds["increment_converged"].values
    steps = ds["increment_steps"].values
    ok = len(c) == N_DEPTHS and bool(np.all(c == 1))
    h = solid(ctx, "hertz_hooke")["increment_converged"].values
    return measurement(
        f"paper variant: {int(c.sum())} of {N_DEPTHS} increments at rest (steps {', '.join(str(int(s)) for s in steps)}); "
        f"hooke (completion): {int(h.sum())} of {N_DEPTHS}", ok,
        evidence="results/solid/hertz_paper.nc increment_converged (rest: max|F_free| < solver.tol of the largest link force)",
        why="" if ok else "the printed lattice's zero-energy shear modes do not settle under kinetic damping within "
                          "the step budget (solver.max_steps_mechanism)",
        margin=f"{int(c.sum())} of {N_DEPTHS}",
        sensitivity="settling: only kinetic damping was run to rest; undamped (the paper's text) never rests "
                    "(see mar-4.3-extremely-stable)")


def eq27_run(ctx, rid, lim):
    """(ok, text, move) of an undamped eq. 27 run."""
    ds = solid(ctx, rid)
    move = float(attr(ds, "max_step_move_over_dx", rid))
    stable = ds["increment_stable"].values
    ok = status(ds) not in BROKEN and move <= lim and len(stable) == N_DEPTHS
    return ok, (f"{rid}: {status(ds)} ({ds.attrs['status_message']}), {int(stable.sum())} of {N_DEPTHS} increments "
                f"stepped without blow-up, largest step move {move:.3g} dx, dt {float(ds.attrs['dt_min_s']):.3g}-"
                f"{float(ds.attrs['dt_max_s']):.3g} s"), move


@claim("mar-4.3-extremely-stable")
def extremely_stable(ctx, e):
    """mar-4.3-extremely-stable: the paper variant stepped by eqs. 26-27 (undamped) stays stable."""
    lim = tol(e)
    ok, text, move = eq27_run(ctx, "hertz_eq27_paper", lim)
    sens = []
    if ctx.has("solid:hertz_eq27_hooke"):
        sens.append("hooke completion, same stepping: " + eq27_run(ctx, "hertz_eq27_hooke", lim)[1])
    sens.append("settling (kinetic damping, hertz_paper): " + run_stability(ctx, "hertz_paper", lim)[1])
    return measurement(text, ok, evidence="results/solid/hertz_eq27_paper.nc",
                       why="" if ok else "the printed plate collapses under the disk (a particle leaves its width): "
                                         "no shear stiffness, nothing to stop the mechanism",
                       margin=f"largest step move {move:.3g} dx against {lim:g} dx; the escape fails regardless",
                       sensitivity="; ".join(sens) + "; sound_speed: eq. 26's cap uses sqrt(E / rho) only")


@claim("mar-4.3-eq27-guarantee")
def eq27_guarantee(ctx, e):
    """mar-4.3-eq27-guarantee: no particle moves more than 0.1 dx in a step under eq. 27 stepping."""
    lim = tol(e)
    ds = solid(ctx, "hertz_eq27_paper")
    move = float(attr(ds, "max_step_move_over_dx", "hertz_eq27_paper"))
    per = ds["increment_max_move_over_dx"].values
    return measurement(
        f"largest step move {move:.4g} dx (per increment {fmt_list(per, '{:.3g}')}) up to the run's end ({status(ds)}, "
        f"step {int(ds['steps'])})", move <= lim,
        evidence="results/solid/hertz_eq27_paper.nc max_step_move_over_dx (dt from the speeds at the step's start)",
        why="" if move <= lim else f"dt is chosen from the speeds before the step's acceleration, so the move can exceed {lim:g} dx",
        margin=f"{move:.3g} dx against {lim:g} dx")


@claim("mar-4.3-eq27-stability")
def eq27_stability(ctx, e):
    """mar-4.3-eq27-stability: eq. 27 alone (no eq. 26 cap) keeps the model stable."""
    lim = tol(e)
    ok, text, move = eq27_run(ctx, "hertz_eq27_uncapped_paper", lim)
    return measurement(text, ok, evidence="results/solid/hertz_eq27_uncapped_paper.nc",
                       why="" if ok else "at rest V_max = 0 and eq. 27 allows any step: the first step after the disk "
                                         "moves is far above the explicit scheme's limit 2 / omega_max",
                       margin=f"largest step move {move:.3g} dx against {lim:g} dx",
                       sensitivity=f"the V_max floor (hertz.eq27_vfloor_m_s) sets the first step; any floor below the "
                                   "plate's speeds gives a step far above dx / (4 c)")


def sound_speeds(E, nu, rho):
    """{name: speed m/s} of input sound_speed: shear, bar, P-wave (SI in)."""
    G = E / (2 * (1 + nu))
    M = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
    return {"shear": np.sqrt(G / rho), "bar": np.sqrt(E / rho), "P-wave": np.sqrt(M / rho)}


@claim("mar-4.3-dt-vs-eq26")
def dt_vs_eq26(ctx, e):
    """mar-4.3-dt-vs-eq26: the stated 15-56 ns against eq. 26's longest permitted step."""
    dx = num(e, "dx_um") * 1e-6
    cs = sound_speeds(num(e, "E_GPa") * 1e9, num(e, "nu"), num(e, "rho_kg_m3"))
    dtmax = {k: dx / (4 * c) * 1e9 for k, c in cs.items()}
    lo = float(num(e, "dt_ns")[0])
    ok = any(lo <= v for v in dtmax.values())
    return measurement(
        "eq. 26 dx / (4 C_s): " + ", ".join(f"{k} {cs[k] / 1e3:.2f} km/s -> {v:.2f} ns" for k, v in dtmax.items())
        + f"; stated {lo:g}-{num(e, 'dt_ns')[1]:g} ns", ok,
        evidence="eq. 26 with the page's dx and the speeds of steel from its E, nu, rho",
        why="" if ok else f"the stated steps exceed eq. 26's 'longest permitted time step' for every sound speed of "
                          f"steel ({lo:g} ns needs C_s <= {dx / (4 * lo * 1e-9) / 1e3:.2f} km/s)",
        margin=f"largest dt_max {max(dtmax.values()):.2f} ns against {lo:g} ns",
        sensitivity="sound_speed: the inconsistency holds for all three speeds")


@claim("mar-4.3-dt-stable")
def dt_stable(ctx, e):
    """mar-4.3-dt-stable: the paper variant at fixed 15 ns and 56 ns (second increment)."""
    lim = tol(e)
    res = {v: [run_stability(ctx, f"hertz_dt{ns}ns_{v}", lim) for ns in ("15", "56")] for v in ("paper", "hooke")}
    ok = all(r[0] for r in res["paper"])
    return measurement(
        "paper variant: " + "; ".join(r[1] for r in res["paper"]) + " | hooke (completion): "
        + "; ".join(r[1] for r in res["hooke"]), ok,
        evidence="results/solid/hertz_dt{15,56}ns_{paper,hooke}.nc",
        why="" if ok else "the stated step is " + ", ".join(
            f"{float(solid(ctx, f'hertz_dt{ns}ns_paper').attrs['dt_over_rule']):.1f}" for ns in ("15", "56"))
        + " x eq. 26's dx / (4 c): above the explicit scheme's limit the step is unstable",
        margin="largest step move " + ", ".join(f"{r[2]:.3g}" for r in res["paper"]) + f" dx against {lim:g} dx")


def scale_radius_runs(e):
    return [r["id"].split(":", 1)[1] for r in e["runs"]]


@claim("mar-4.3-scale-match")
def scale_match(ctx, e):
    """mar-4.3-scale-match: peak pressure and load errors at the other disk radii (same plate)."""
    lp, ll = tol(e, 0), tol(e, 1)
    rows, fails = [], []
    for rid in scale_radius_runs(e):
        ds = solid(ctx, rid)
        d, errs, st, conv = hertz_row(ctx, rid, N_DEPTHS)
        wp, wl = worst(errs["plane strain"]["p"]), worst(errs["plane strain"]["line"])
        rows.append(f"R = {float(ds.attrs['radius_cm']) / 100:g} m: worst pmax {wp:.0%}, load {wl:.0%} ({conv} of "
                    f"{N_DEPTHS} at rest)")
        if not (wp <= lp and wl <= ll):
            fails.append(rid)
    return measurement("; ".join(rows), not fails,
                       evidence="results/solid/hertz_R*_paper.nc against eqs. 24-25 and the line contact",
                       why="" if not fails else "fails at " + ", ".join(fails) + ": the printed plate does not come to "
                       "rest under the disk (a mechanism), and at the metre radii the disk is flatter than the plate is "
                       "wide (mar-4.3-scale-contact-width), so no Hertz contact exists",
                       margin=f"bounds {lp:.1%} (pmax), {ll:.1%} (load)",
                       sensitivity="hertz_scale_reading: only 'same plate' was run (the geometrically scaled model "
                                   "would repeat the kept radius's result by dimensional analysis)")


@claim("mar-4.3-scale-contact-width")
def scale_contact_width(ctx, e):
    """mar-4.3-scale-contact-width: sqrt(2 R delta) at 20 m against the plate's half-width."""
    R = num(e, "radius_m")
    d = num(e, "depth_um") * 1e-6
    a = np.sqrt(2 * R * d) * 1e3
    half = num(e, "plate_x") * num(e, "dx_um") / 2 / 1e3
    ok = bool(a[0] <= half)
    return measurement(f"sqrt(2 R delta) = {fmt_list(a, '{:.1f}')} mm at R = {fmt_list(R, '{:g}')} m, delta = "
                       f"{d * 1e6:g} um, against the plate's half-width {half:.2f} mm", ok,
                       evidence="arithmetic on the page's numbers",
                       why="" if ok else "the disk covers the whole plate: no Hertz contact, whatever the tolerance",
                       margin=f"{a[0]:.1f} mm against {half:.2f} mm",
                       sensitivity="hertz_scale_reading: with the whole model scaled there is no inconsistency",
                       sweep=[("hertz_scale_reading", "same plate, radius varied", ok),
                              ("hertz_scale_reading", "whole model scaled geometrically with the radius", True)])


# ---------------------------------------------------------------------------------- 4.4 pressure vessel


@claim("mar-4.4-inputs")
def vessel_inputs(ctx, e):
    """mar-4.4-inputs: the vessel runs' geometry, materials, initial pressure and step against the page."""
    w = solid(ctx, "vessel_water_particles")
    p = solid(ctx, "vessel_pressure_load")
    dx = float(w.attrs["dx_cm"])
    E, nu, rho = material_units({"E_GPa": num(e, "E_GPa"), "nu": num(e, "nu"), "rho_kg_m3": num(e, "rho_kg_m3")})
    # the radii as methods.solid.vessel.geometry builds them from the page's counts (the same operations)
    a_page = num(e, "water_radius_particles") * (num(e, "dx_mm") * MM)
    pairs = {
        "water radius a [cm]": (w.attrs["a_cm"], a_page),
        "outer radius b [cm]": (w.attrs["b_cm"], a_page + num(e, "ring_particles") * (num(e, "dx_mm") * MM)),
        "dx [cm]": (dx, num(e, "dx_mm") * MM),
        "E [N/cm^2]": (w.attrs["E_N_cm2"], E), "nu": (w.attrs["nu"], nu), "rho [N s^2/cm^4]": (w.attrs["rho_N_s2_cm4"], rho),
        "water rho [N s^2/cm^4]": (attr(w, "rho_water_N_s2_cm4", "vessel_water_particles"), num(e, "rho_water_kg_m3") * 1e-8),
        "K [N/cm^2]": (attr(w, "K_N_cm2", "vessel_water_particles"), num(e, "K_GPa") * 1e5),
        "p0 [N/cm^2]": (w.attrs["pressure_N_cm2"], num(e, "p0_Pa") * 1e-4),
        "steps": (attr(w, "paper_steps", "vessel_water_particles"), num(e, "steps")),
        "dt [s]": (attr(w, "dt_s", "vessel_water_particles"), num(e, "dt_ns") * 1e-9),
        "pressure-load dt [s]": (attr(p, "dt_s", "vessel_pressure_load"), num(e, "dt_ns") * 1e-9),
    }
    dev = {k: abs(float(a) / float(b) - 1) for k, (a, b) in pairs.items()}
    lim = tol(e)
    ok = all(d <= lim for d in dev.values())
    return measurement(f"ring {num(e, 'ring_particles'):g} particles thick, water radius {num(e, 'water_radius_particles'):g} "
                       "particles: " + "; ".join(f"{k} {float(a):.6g} (page {float(b):.6g})" for k, (a, b) in pairs.items()), ok,
                       evidence="results/solid/vessel_{water_particles,pressure_load}.nc attributes",
                       why="" if ok else "differs: " + ", ".join(k for k, d in dev.items() if d > lim),
                       margin=f"largest relative difference {max(dev.values()):.1e} against {lim:g}",
                       sensitivity="vessel_model: the water's kernel, h, viscosity and the coupling are readings "
                                   "(not page text)")


@claim("mar-4.4-atm")
def atm(ctx, e):
    """mar-4.4-atm: 101,135 Pa against 1 atm = 101,325 Pa."""
    d = abs(num(e, "atm_Pa") - num(e, "p0_Pa"))
    return measurement(f"|{num(e, 'atm_Pa'):.0f} - {num(e, 'p0_Pa'):.0f}| = {d:.0f} Pa", d <= tol(e),
                       evidence="the definition of the standard atmosphere",
                       why="" if d <= tol(e) else "1 atm is 101,325 Pa (digits transposed)",
                       margin=f"{d:.0f} Pa against {tol(e):g} Pa")


def breathing_period(t, u):
    """(period [s], how): the mean time between upward crossings of the history's mean; with fewer than two
    crossings, twice the time of the first maximum (an undamped step response from rest peaks at T / 2;
    NaN if the history ends rising)."""
    dev = u - u.mean()
    cross = t[1:][(dev[:-1] < 0) & (dev[1:] >= 0)]
    if cross.size > 1:
        return float(np.diff(cross).mean()), "between upward crossings"
    k = int(np.argmax(u))
    return (2.0 * float(t[k]) if 0 < k < len(u) - 1 else np.nan), "twice the first maximum"


def reached(ds, t):
    """True when the run's history reaches time t [s]."""
    return float(ds["time"].values[-1]) >= t * (1 - 1e-9)


@claim("mar-4.4-settle")
def settle(ctx, e):
    """mar-4.4-settle: the paper's 400 x 146.8 ns against a quarter of the ring's breathing period."""
    lim = tol(e)
    rows, ratios = [], {}
    for rid, settled_var in (("vessel_water_particles", "u_inner_mean_cycles"), ("vessel_pressure_load", "u_inner_settled")):
        ds = solid(ctx, rid)
        tp = rec(ds, "t_paper")
        T_b = rec(ds, "breathing_period") if "breathing_period" in ds else breathing_period(ds["time"].values,
                                                                                             ds["u_inner_t"].values)[0]
        ratios[rid] = tp / (T_b / 4)
        rows.append(f"{rid}: t_paper {tp * 1e6:.1f} us, breathing period {T_b * 1e6:.0f} us, t_paper / (T / 4) = "
                    f"{ratios[rid]:.3f}, u(t_paper) / settled {rec(ds, 'u_paper_end') / rec(ds, settled_var):.2f}")
    ok = all(r >= lim for r in ratios.values())
    sens, sweep = [], [("vessel_model", "water particles, objective ring (kept)", ok),
                       ("vessel_model", "pressure load", ratios["vessel_pressure_load"] >= lim)]
    for rid, what in (("vessel_water_particles_paper", "the paper solid variant"), (STOP, "the paper's coupling")):
        if ctx.has(f"solid:{rid}"):
            ds = solid(ctx, rid)
            T_b, how = breathing_period(ds["time"].values, ds["u_inner_t"].values)
            r = rec(ds, "t_paper") / (T_b / 4)
            sens.append(f"vessel_model with {what}: {status(ds)}, breathing period {T_b * 1e6:.0f} us ({how}), "
                        f"t_paper / (T / 4) = {r:.3f}")
            sweep.append(("vessel_model", what, bool(r >= lim) if np.isfinite(r) else None))
    sens = "; ".join(sens)
    return measurement("; ".join(rows), ok, evidence="results/solid/vessel_{water_particles,pressure_load}.nc u_inner_t",
                       why="" if ok else "the paper's run is shorter than a quarter of the ring's breathing period: its "
                                         "particles cannot have settled into place",
                       margin="t_paper / (T / 4) " + ", ".join(f"{r:.3f}" for r in ratios.values()) + f" against {lim:g}",
                       sensitivity=sens, sweep=sweep)


@claim("mar-4.4-stable")
def vessel_stable(ctx, e):
    """mar-4.4-stable: the vessel with water, printed solid model: no escape, no move beyond 0.1 dx in a step."""
    lim = tol(e)
    ok, text, move = run_stability(ctx, "vessel_water_particles_paper", lim)
    ds = solid(ctx, "vessel_water_particles_paper")
    ok_o, text_o, _ = run_stability(ctx, "vessel_water_particles", lim)
    sweep = [("vessel_model", "water particles, paper solid variant (judged)", ok),
             ("vessel_model", "water particles, objective ring", ok_o)]
    stop = ""
    if ctx.has(f"solid:{STOP}"):
        ok_s, text_s, _ = run_stability(ctx, STOP, lim)
        stop = f"; the paper's coupling: {text_s}"
        sweep.append(("vessel_model", "the paper's coupling", ok_s))
    return measurement(
        f"paper solid variant: {text} ({ds.attrs['status_message']}); objective completion: {text_o}{stop}", ok,
        evidence="results/solid/vessel_water_particles{_paper,}.nc status, max_step_move_over_dx (ring), "
                 "water_max_step_move_over_dx",
        why="" if ok else "the printed ring, a lattice without shear stiffness, does not hold the water's pressure",
        margin=f"largest step move {move:.3g} dx against {lim:g} dx",
        sensitivity="vessel_model: the water's h and viscosity were not swept", sweep=sweep)


@claim("mar-4.4-outward")
def outward(ctx, e):
    """mar-4.4-outward: every ring particle moves outward, at the paper's end and in the cycle mean."""
    lim = tol(e)
    w = solid(ctx, "vessel_water_particles")
    n = int(attr(w, "paper_steps", "vessel_water_particles"))
    up, um = w["u_radial_paper_end"].values / UM, w["u_radial_mean_cycles"].values / UM
    ok = bool(up.min() > lim and um.min() > lim)
    p = solid(ctx, "vessel_pressure_load")
    pp, ps = p["u_radial_paper_end"].values / UM, p["u_radial_settled"].values / UM
    sens, sweep = [], [("vessel_model", "water particles, objective ring (kept)", ok),
                       ("vessel_model", "pressure load", bool(pp.min() > lim and ps.min() > lim))]
    for rid, what in (("vessel_water_particles_paper", "the paper solid variant"), (STOP, "the paper's coupling")):
        if ctx.has(f"solid:{rid}"):
            q = solid(ctx, rid)
            qp, qm = q["u_radial_paper_end"].values / UM, q["u_radial_mean_cycles"].values / UM
            lo = np.nanmin(qp) if np.isfinite(qp).any() else np.nan
            lm = np.nanmin(qm) if np.isfinite(qm).any() else np.nan
            sens.append(f"vessel_model with {what} ({status(q)}): min u_r at {n} steps {lo:.3g} um, in the cycle mean "
                        f"{lm:.3g} um")
            sweep.append(("vessel_model", what, bool(lo > lim and lm > lim) if np.isfinite(lo) and np.isfinite(lm)
                          else None))
    sens = "; ".join(sens)
    return measurement(
        f"water particles (objective ring): min u_r {up.min():.3g} um at {n} steps (max {up.max():.3g}), "
        f"{um.min():.3g} um in the cycle mean; pressure load: {pp.min():.3g} um at {n} steps, {ps.min():.3g} um settled",
        ok, evidence="results/solid/vessel_{water_particles,pressure_load}.nc u_radial_paper_end, u_radial_mean_cycles, "
                     "u_radial_settled",
        why="" if ok else "some ring particles move inward",
        margin=f"smallest u_r {min(up.min(), um.min()):.3g} um against {lim:g} um", sensitivity=sens, sweep=sweep)


def quarter_halfranges(ds):
    """Half-range [N/cm^2] of the mean water pressure in each quarter of the paper's steps (records in [0, t_paper])."""
    t, p = ds["time"].values, ds["p_water_t"].values
    tp = rec(ds, "t_paper")
    edges = np.linspace(0.0, tp, 5)
    out = []
    for a, b in zip(edges[:-1], edges[1:]):
        sel = (t >= a - 1e-12) & (t <= b + 1e-12)
        out.append(0.5 * (p[sel].max() - p[sel].min()) if sel.any() else np.nan)
    return np.array(out)


@claim("mar-4.4-pressure-stabilises")
def pressure_stabilises(ctx, e):
    """mar-4.4-pressure-stabilises: the water pressure's fluctuation over the paper's 400 steps decays."""
    ds = solid(ctx, "vessel_water_particles")
    q = quarter_halfranges(ds) / 1e-4 / 1e3  # kPa
    ok = bool(q[-1] < q[0])
    sens, sweep = [], [("vessel_model", "water particles, objective ring (kept)", ok)]
    for rid, what in (("vessel_water_particles_paper", "the paper solid variant"), (STOP, "the paper's coupling")):
        if ctx.has(f"solid:{rid}"):
            qp = quarter_halfranges(solid(ctx, rid)) / 1e-4 / 1e3
            sens.append(f"vessel_model with {what}: half-ranges {fmt_list(qp, '{:.2f}')} kPa")
            sweep.append(("vessel_model", what, bool(qp[-1] < qp[0])))
    sens = "; ".join(sens)
    n = int(attr(ds, "paper_steps", "vessel_water_particles"))
    return measurement(f"half-range of the mean water pressure per quarter of {n} steps: {fmt_list(q, '{:.2f}')} kPa", ok,
                       evidence="results/solid/vessel_water_particles.nc p_water_t",
                       why="" if ok else "the fluctuation grows over the paper's run: the water is still being "
                                         "compressed and released by the ring's first swing",
                       margin=f"last / first quarter {q[-1] / q[0]:.2f} against 1", sensitivity=sens, sweep=sweep)


@claim("prj-floor-beam")
def floor_beam(ctx, e):
    """prj-floor-beam: the elastic floor's mid-span deflection against beam theory under the same loads."""
    lim = tol(e)
    rows, errs = [], []
    for r in e["runs"]:
        rid = r["id"].split(":", 1)[1]
        ds = solid(ctx, rid)
        err = rec(ds, "w_centre") / rec(ds, "w_centre_actual") - 1
        errs.append(err)
        rows.append(f"{rid}: {rec(ds, 'w_centre') * 10:.3f} mm ({err:+.1%} of beam theory under its loads)")
    ok = all(abs(x) <= lim for x in errs)
    return measurement("; ".join(rows), ok, evidence="results/solid/floor_*.nc w_centre, w_centre_actual",
                       why="" if ok else "the 5-layer lattice plate is stiffer than Euler-Bernoulli theory (an error "
                                         "of second order in dx, smaller with more layers)",
                       margin=f"worst |error| {max(abs(x) for x in errs):.1%} against {lim:.0%}")
