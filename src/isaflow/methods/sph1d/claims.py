"""Measures of the claims of Merino-Alonso et al. (2020)'s abstract (config/claims/merino_alonso2020.yaml) on
the 1D sweep: numbers and whether each row's tolerance test passed, every threshold read from the registry
entry (isaflow.claims turns them into verdicts).

``MEASURES = {claim id: function(ctx, entry) -> isaflow.claims.Measurement}``.  Every measure reads the
sweep (``ctx.run('sph1d:sweep')``, results/sph1d/sweep.nc: relative quadratic error and cond_1(A) per
variant, kernel, h/dx and N).  A row is judged on the sweep's first variant (the kept readings of the
gradient form and the floor); the other variants are reported as its sensitivity.  The behaviour of an
error history (settled, decreasing, divergent, ...) is sweep.behaviour with the numbers of the entry's
``tolerance.parameters`` (the rule: the registry file's header).

Units: errors and condition numbers are dimensionless (errors relative to ||p_exact||_2); h/dx [1];
heights [cm]; rho g [N/cm^3].
"""

import numpy as np
import pandas as pd
from scipy import stats

from ... import claims_registry, derived
from ...claims import Measurement, measure_table
from ...inputs import InputError, load as load_yaml
from . import closed_form, sweep
from .sweep import variant_forms

MEASURES, claim = measure_table()  # {claim id: measure(ctx, entry)}, each measure entered by @claim(id)

SWEEP = "sph1d:sweep"
EXTENDED = "sph1d:sweep_n8192"  # the sweep to N = 8192 (registry input n_window): sensitivity only
SURFACE_TOP = "sph1d:sweep_surface_top"  # the top particle on the surface (registry input surface_placement)
EVIDENCE = "results/sph1d/sweep.nc"
WENDLAND = ("wendland_c2", "wendland_c4", "wendland_c6")
SHORT = {"cubic_spline": "cubic", "wendland_c2": "C2", "wendland_c4": "C4", "wendland_c6": "C6"}
CLASSES = ("settled", "decreasing", "divergent", "undetermined", "exact")


def parameters(entry):
    """The named thresholds of the entry's tolerance ({} if none)."""
    return dict(entry["tolerance"].get("parameters", {}))


def rule(entry):
    """(settle_band, round_off) of the classification rule, from the entry's tolerance.parameters."""
    p = parameters(entry)
    return float(p["settle_band"]), float(p["round_off"])


def cases(ds, entry):
    """sweep.classify of the sweep by the entry's rule, over the sweep's own window (its attribute
    classify_window, config/methods/sph1d.yaml classify.window)."""
    band, round_off = rule(entry)
    return sweep.classify(ds, int(ds.attrs["classify_window"]), band, round_off)


def limits(ds):
    """DataFrame, one row per (variant, kernel, ratio): neighbours, error_limit (error at the largest N) and
    cond_over_n (cond_1(A) / N there); no classification."""
    nmax = int(ds.n.values[-1])
    rows = []
    for var in ds.variant.values:
        for kern in ds.kernel.values:
            e = ds.error.sel(variant=var, kernel=kern).values[:, -1]
            k = ds.cond.sel(variant=var, kernel=kern).values[:, -1]
            rows += [dict(variant=str(var), kernel=str(kern), ratio=float(r), neighbours=int(nb), error_limit=e[i],
                          cond_over_n=k[i] / nmax)
                     for i, (r, nb) in enumerate(zip(ds.ratio.values, ds.neighbours.values))]
    return pd.DataFrame(rows)


def _judged(ctx, judge, table, entry):
    """Measurement of judge(rows of one variant, entry) -> (passed, text, margin, why) on the sweep's first
    variant; the sensitivity (``sweep``, one value of a registry input each): the other variants (gradient_form,
    floor_treatment), the same sweep judged by the max norm (error_norm), and the first variant of the sweeps with
    the top particle on the surface (SURFACE_TOP, surface_placement) and extended to N = 8192 (EXTENDED, n_window)
    when the workflow made them.  table(ds, entry) -> the rows of every variant."""
    ds = ctx.run(SWEEP)
    rows = table(ds, entry)
    variants = [str(v) for v in ds.variant.values]
    per = {v: judge(rows[rows.variant == v], entry) for v in variants}
    ok, text, margin, why = per[variants[0]]
    notes = []
    forms = variant_forms(ds)
    g0, f0 = forms[variants[0]]
    sweep = [("gradient_form", f"{g0} (kept)", bool(ok)), ("floor_treatment", f"{f0} (kept)", bool(ok))]
    if len(variants) > 1:
        notes.append("readings of gradient_form and floor_treatment: " + "; ".join(
            f"{v}: the test {'passes' if per[v][0] else 'fails'} ({per[v][1]})" for v in variants[1:]))
        for v in variants[1:]:  # a variant changes one reading of the kept pair
            g, f = forms[v]
            sweep += [("gradient_form", g, bool(per[v][0]))] if g != g0 else []
            sweep += [("floor_treatment", f, bool(per[v][0]))] if f != f0 else []

    def first(other):  # (passed, text) of the first variant of another sweep
        r = table(other, entry)
        res = judge(r[r.variant == str(other.variant.values[0])], entry)
        return bool(res[0]), res[1]

    m_ok, m_text = first(ds.assign(error=ds.error_max))
    notes.append(f"error_norm (relative max norm): {variants[0]}: the test {'passes' if m_ok else 'fails'} ({m_text})")
    sweep += [("error_norm", "relative L2 (kept)", bool(ok)), ("error_norm", "relative max norm", m_ok)]
    for key, name, kept, label in (
            (SURFACE_TOP, "surface_placement", "dx / 2 (kept)", "0 (top particle on the surface)"),
            (EXTENDED, "n_window", f"N up to {int(ds.n.values[-1])} (kept)", None)):
        if not ctx.has(key):
            notes.append(f"{name}: {key} not made")
            continue
        other = ctx.run(key)
        o_ok, o_text = first(other)
        label = label or f"N up to {int(other.n.values[-1])}"
        notes.append(f"{name} ({key}, {_window_text(other)}): {other.variant.values[0]}: the test "
                     f"{'passes' if o_ok else 'fails'} ({o_text})")
        sweep += [(name, kept, bool(ok)), (name, label, o_ok)]
    return Measurement(measured=f"{variants[0]}, {_window_text(ds)}: {text}", passed=bool(ok), evidence=EVIDENCE,
                       why="" if ok else why, margin=margin, sensitivity="; ".join(notes), sweep=tuple(sweep))


def _window_text(ds):
    w = int(ds.attrs["classify_window"])
    return f"N = {int(ds.n.values[-w])}-{int(ds.n.values[-1])}"


# --- the sweep's design and the linear system --------------------------------------------------------------


@claim("mer-abs-setup")
def measure_setup(ctx, entry):
    ds = ctx.run(SWEEP)
    n = ds.n.values
    refined = len(n) >= 2 and bool(np.all(np.diff(n) > 0))
    doubling = bool(np.all(n[1:] == 2 * n[:-1]))
    missing = int(np.isnan(ds.error.values).sum())
    ok = refined and missing == 0 and ds.error.dims == ("variant", "kernel", "ratio", "n")
    r = ds.ratio.values
    return Measurement(
        measured=f"1D column H = {float(ds.attrs['height_cm']):g} cm; N = {', '.join(str(int(x)) for x in n)} "
                 f"({'doublings' if doubling else 'not doublings'}) at each fixed h/dx of {len(r)} in "
                 f"[{r.min():.2f}, {r.max():.2f}] x {ds.sizes['kernel']} kernels x {ds.sizes['variant']} variants; "
                 f"{missing} (case, N) without a solve",
        passed=ok, evidence=EVIDENCE,
        why="" if ok else "some case is not solved at every N, or N is not refined",
        margin="exact rule (no threshold)")


@claim("mer-abs-linear")
def measure_linear(ctx, entry):
    tol = entry["tolerance"]["value"]
    lin = ctx.run(entry["runs"][1]["id"])  # the registry's derived linearity of the sweep (sweep.linearity)
    worst = float(lin.rel_diff.max())
    parts = [f"{SHORT[str(k)]} h/dx {float(lin.ratio.sel(kernel=k)):.2f}: {float(lin.rel_diff.sel(kernel=k)):.3g}"
             for k in lin.kernel.values]
    ok = worst <= tol
    return Measurement(
        measured=f"{lin.attrs['variant']}, N = {int(lin.attrs['n'])}, the best-conditioned h/dx of each kernel: max "
                 f"|p(2 rho g) - 2 p(rho g)| / max |2 p(rho g)| = " + "; ".join(parts),
        passed=ok, evidence=f"isaflow.methods.sph1d.sweep.linearity ({derived.path(entry['runs'][1]['id'])}: A p = b, "
                            "b linear in rho g)",
        why="" if ok else f"a relative difference {worst:.3g} > {tol:g}",
        margin=f"largest difference {worst:.3g} against {tol:g}")


# --- one neighbour per side ---------------------------------------------------------------------------------


@claim("mer-abs-one-nb-explicit")
def measure_one_nb_explicit(ctx, entry):
    tol = entry["tolerance"]["value"]
    ds = ctx.run(SWEEP)
    one = ds.neighbours.values == 1
    ratios = ds.ratio.values[one]
    worst, worst_abs, largest, where, checked = 0.0, 0.0, 0.0, "", []
    for var, (grad, floor) in variant_forms(ds).items():
        if grad != "symmetric" or floor not in ("mirror_hydrostatic", "mirror_equal"):
            continue  # the closed form is that of the symmetric form with a mirrored floor
        checked.append(var)
        for kern in ds.kernel.values:
            solver_e = ds.error.sel(variant=var, kernel=kern).values[one]
            for k, n in enumerate(ds.n.values):
                closed = closed_form.error(int(n), ratios, str(kern), floor)
                d = np.abs(solver_e[:, k] - closed)
                worst_abs, largest = max(worst_abs, float(d.max())), max(largest, float(closed.max()))
                scaled = d / (1.0 + closed)  # the solve's round-off is relative to ||p|| <= (1 + E) ||p_exact||
                if scaled.max() > worst:
                    i = int(np.argmax(scaled))
                    worst, where = float(scaled.max()), f"{var}, {SHORT[str(kern)]}, h/dx {ratios[i]:.2f}, N {int(n)}"
    ok = bool(checked) and worst <= tol
    return Measurement(
        measured=f"closed-form error E = sqrt((kappa - 1)^2 + [6 (kappa - 1)(kappa - beta) + 3 (kappa - beta)^2] / "
                 f"(4 N^2 - 1)) against the solver over {one.sum()} one-neighbour h/dx x {ds.sizes['kernel']} kernels x "
                 f"{ds.sizes['n']} N, variants {', '.join(checked) or 'none'}: max |E_solver - E_closed| / (1 + E_closed) "
                 f"= {worst:.3g}" + (f" ({where})" if where else "") + f"; max |E_solver - E_closed| = {worst_abs:.3g} "
                 f"(E_closed up to {largest:.3g})",
        passed=ok, evidence=f"{EVIDENCE}; isaflow.methods.sph1d.closed_form.error; docs/sph1d.md",
        why="" if ok else ("no variant has the symmetric gradient with a mirrored floor" if not checked
                           else f"the closed form and the solver differ by {worst:.3g} > {tol:g}"),
        margin=f"largest scaled difference {worst:.3g} against {tol:g}")


def _one_nb(c):
    return c[c.neighbours == 1]


def _judge_no_convergence(c, entry):
    share_min = entry["tolerance"]["value"]
    _, round_off = rule(entry)
    one = _one_nb(c)
    nonconv = (one.residue > round_off) & (one.behaviour != "decreasing")
    share = nonconv.groupby(one.kernel, sort=False).mean()
    count = nonconv.groupby(one.kernel, sort=False).sum()
    size = one.groupby(one.kernel, sort=False).size()
    ok = bool((share >= share_min).all())
    text = "one-neighbour ratios with residue |kappa - 1| > {:g} and error not decreasing: ".format(round_off) + \
        ", ".join(f"{SHORT[k]} {int(count[k])} of {int(size[k])}" for k in share.index)
    worst = share.idxmin()
    return (ok, text, f"smallest share {share.min():.3f} ({SHORT[worst]}) against {share_min:g}",
            f"{SHORT[worst]}: only {int(count[worst])} of {int(size[worst])} ratios do not converge")


@claim("mer-abs-one-nb-no-convergence")
def measure_one_nb_no_convergence(ctx, entry):
    return _judged(ctx, _judge_no_convergence, cases, entry)


@claim("mer-abs-one-nb-residue")
def measure_one_nb_residue(ctx, entry):
    large = entry["tolerance"]["value"]
    most = parameters(entry)["most"]
    ds = ctx.run(SWEEP)
    one = ds.neighbours.values == 1
    parts, flips, ok = [], {}, True
    for kern in ds.kernel.values:
        res = np.sort(ds.residue.sel(kernel=kern).values[one])[::-1]
        share = float(np.mean(res >= large))
        ok = ok and share > most
        # largest threshold t at which more than 'most' of the ratios still have residue >= t
        need = int(np.floor(most * len(res))) + 1
        flips[str(kern)] = float(res[need - 1])
        parts.append(f"{SHORT[str(kern)]} median {np.median(res):.3g}, {100 * share:.0f} % >= {large:g}")
    k_min = min(flips, key=flips.get)
    # the other gradient form (no closed form here): the solver's error at the largest N stands for its residue
    forms = variant_forms(ds)
    v0 = str(ds.variant.values[0])
    sweep = [("gradient_form", f"{forms[v0][0]} (kept)", bool(ok))]
    other = []
    for v, (g, f) in forms.items():
        if g != forms[v0][0]:
            lim = ds.error.sel(variant=v).values[:, one, -1]
            shares = np.mean(lim >= large, axis=1)
            sweep.append(("gradient_form", g, bool(np.all(shares > most))))
            other.append(f"{v} (solver's error at N = {int(ds.n.values[-1])}): " + ", ".join(
                f"{SHORT[str(k)]} {100 * s:.0f} %" for k, s in zip(ds.kernel.values, shares)) + f" >= {large:g}")
    return Measurement(
        sweep=tuple(sweep),
        measured=f"residue |kappa - 1| (closed form, the solver's limit) over the {one.sum()} one-neighbour h/dx: "
                 + "; ".join(parts),
        passed=bool(ok), evidence=f"{EVIDENCE} (residue); figures/sph1d_maps.png",
        why="" if ok else f"for {SHORT[k_min]} at most half of the ratios have a residue >= {large:g}",
        margin=f"the test holds for any 'large' threshold up to {flips[k_min]:.3g} ({SHORT[k_min]}; "
               + ", ".join(f"{SHORT[k]} {v:.3g}" for k, v in flips.items()) + f"), here {large:g}",
        sensitivity="the residue is the closed form of the symmetric gradient with a mirrored floor (both floors: the "
                    "same limit); " + "; ".join(other))


# --- two and three neighbours, conditioning, Wendland C2 ------------------------------------------------------


def _judge_cond_association(c, entry):
    """'The kernel influences the accuracy ... through modifying the condition number': at each two-neighbour
    h/dx the kernels are ranked by cond_1/N and by the error; the kernel ranking must agree (Spearman over the
    kernels > 0) at significantly more ratios than it disagrees (one-sided sign test at alpha).  The pooled
    correlation over every (kernel, h/dx), which h/dx alone can drive, is reported."""
    alpha = entry["tolerance"]["value"]
    two = c[(c.neighbours == 2) & np.isfinite(c.cond_over_n) & np.isfinite(c.error_limit)]
    rho, p = stats.spearmanr(two.cond_over_n, two.error_limit, alternative="greater")
    rho, p = float(rho), float(p)
    per = []
    for _, g in two.groupby("ratio"):
        if len(g) >= 3 and g.cond_over_n.nunique() > 1 and g.error_limit.nunique() > 1:
            per.append(float(stats.spearmanr(g.cond_over_n, g.error_limit)[0]))
    up, down = sum(r > 0 for r in per), sum(r < 0 for r in per)
    p_sign = float(stats.binomtest(up, up + down, 0.5, alternative="greater").pvalue) if up + down else 1.0
    ok = up > down and p_sign < alpha
    med = two.groupby("kernel", sort=False)[["cond_over_n", "error_limit"]].median()
    text = (f"kernels ranked by cond_1/N and by error at each of {len(per)} two-neighbour h/dx: agree at {up}, disagree "
            f"at {down} (median Spearman over the kernels {np.median(per) if per else np.nan:.2f}; sign test one-sided p "
            f"{p_sign:.2g}); reported, not judged: pooled Spearman rho {rho:.3f} (p {p:.2g}) over {len(two)} (kernel, "
            "h/dx) cases; median cond_1/N and error by kernel: " + ", ".join(
                f"{SHORT[k]} {r.cond_over_n:.3g} / {r.error_limit:.3g}" for k, r in med.iterrows()))
    return ok, text, f"sign test p {p_sign:.2g} against {alpha:g} ({up} agree, {down} disagree)", \
        "at a fixed h/dx the kernel with the larger condition number is not the one with the larger error more " \
        "often than chance"


@claim("mer-abs-cond-association")
def measure_cond_association(ctx, entry):
    return _judged(ctx, _judge_cond_association, lambda ds, entry: limits(ds), entry)


def _judge_two_three_small(c, entry):
    most = entry["tolerance"]["value"]
    p = parameters(entry)
    small, round_off = p["small"], p["round_off"]
    t = c[c.neighbours.isin([2, 3])]
    settled = t.behaviour == "settled"
    inside = (t.error_limit >= round_off) & (t.error_limit < small)
    good = settled & inside
    share = float(good.mean())
    counts = t.behaviour.value_counts()
    text = (f"{int(good.sum())} of {len(t)} two- and three-neighbour cases ({100 * share:.0f} %) settle to a limit in "
            f"[{round_off:g}, {small:g}); limit in that range {int(inside.sum())}, settled {int(settled.sum())}; "
            "behaviour " + ", ".join(f"{k} {int(counts.get(k, 0))}" for k in CLASSES))
    return (share > most, text, f"share {share:.3f} against {most:g}",
            f"only {100 * share:.0f} % of the cases settle to a small non-zero limit")


@claim("mer-abs-two-three-small")
def measure_two_three_small(ctx, entry):
    return _judged(ctx, _judge_two_three_small, cases, entry)


def _divergent(c, kernel, neighbours=None):
    k = c[c.kernel == kernel]
    if neighbours is not None:
        k = k[k.neighbours == neighbours]
    return k, k[k.behaviour == "divergent"]


def _elsewhere(c):
    div = c[c.behaviour == "divergent"]
    if not len(div):
        return "no divergent case in the sweep"
    return "divergent cases: " + "; ".join(
        f"{SHORT[k]} {nb} nb h/dx {g.ratio.min():.2f}-{g.ratio.max():.2f} ({len(g)})"
        for (k, nb), g in div.groupby(["kernel", "neighbours"], sort=False))


def _judge_c2_divergent_two(c, entry):
    need = entry["tolerance"]["value"]
    k, div = _divergent(c, "wendland_c2", 2)
    counts = k.behaviour.value_counts()
    text = (f"Wendland C2, two neighbours: {len(div)} divergent of {len(k)} h/dx (behaviour "
            + ", ".join(f"{b} {int(counts.get(b, 0))}" for b in CLASSES) + f", max cond_1/N {k.cond_over_n.max():.3g}); "
            + _elsewhere(c))
    return len(div) >= need, text, f"{len(div)} divergent ratios against {need:g}", \
        "no two-neighbour ratio of Wendland C2 diverges"


@claim("mer-abs-c2-divergent-two")
def measure_c2_divergent_two(ctx, entry):
    return _judged(ctx, _judge_c2_divergent_two, cases, entry)


def _judge_c2_worst(c, entry):
    n = {k: len(_divergent(c, k)[1]) for k in WENDLAND}
    ok = n["wendland_c2"] > n["wendland_c4"] and n["wendland_c2"] > n["wendland_c6"]
    text = "divergent ratios over the sweep: " + ", ".join(f"{SHORT[k]} {v}" for k, v in n.items())
    rival = max(n["wendland_c4"], n["wendland_c6"])
    return ok, text, f"C2 {n['wendland_c2']} against the most of C4 and C6, {rival}", \
        f"C2 has {n['wendland_c2']} divergent ratios, not more than C4 ({n['wendland_c4']}) and C6 ({n['wendland_c6']})"


@claim("mer-abs-c2-worst")
def measure_c2_worst(ctx, entry):
    return _judged(ctx, _judge_c2_worst, cases, entry)


def _judge_c2_illcond(c, entry):
    share_min = entry["tolerance"]["value"]
    k, div = _divergent(c, "wendland_c2")
    ill = int(div.ill_conditioned.sum())
    share = ill / len(div) if len(div) else float("nan")
    ok = len(div) >= 1 and share >= share_min
    text = (f"Wendland C2: {len(div)} divergent h/dx over the sweep, {ill} of them ill-conditioned; "
            f"ill-conditioned C2 ratios in all {int(k.ill_conditioned.sum())}")
    why = "no Wendland C2 ratio diverges" if not len(div) else f"{len(div) - ill} divergent C2 ratios are well conditioned"
    return ok, text, (f"share {share:.3f} against {share_min:g}" if len(div) else "needs one divergent C2 ratio"), why


@claim("mer-abs-c2-illcond")
def measure_c2_illcond(ctx, entry):
    return _judged(ctx, _judge_c2_illcond, cases, entry)


def rule_of_file(path):
    """(settle_band, round_off) of the classification rule of a registry file (config/claims/
    merino_alonso2020.yaml): the same in every row that states it (InputError naming the file otherwise).
    The method's own tables and figures classify with it (pipeline.make_cases), so they agree with the claims."""
    _, spec = load_yaml(path, claims_registry.SCHEMA, "claims registry file")
    found = {rule(c) for c in spec["claims"] if "settle_band" in c.get("tolerance", {}).get("parameters", {})}
    if len(found) != 1:
        raise InputError(f"{path}: the rows state {len(found)} different classification rules "
                         "(tolerance.parameters settle_band, round_off); exactly one is needed")
    return found.pop()
