"""Claims table and report fragment of the 1D study, generated from the case table (sweep.classify).

Verdict rules (fixed before the sweep was run; thresholds in config/methods/sph1d.yaml):
1. one neighbour: residue |kappa - 1| > small_error for most one-neighbour ratios of every kernel;
2. two and three neighbours: most (kernel, ratio) cases settle to a limit in [EXACT, small_error);
3. Wendland C2 with two neighbours has divergent ratios, and they are ill-conditioned;
4. Wendland C2 has the largest median error among the Wendland kernels for most neighbour counts.
"""

import numpy as np
import pandas as pd

from .sweep import EXACT

PAPER = "Merino-Alonso et al. 2020"
WENDLAND = ("wendland_c2", "wendland_c4", "wendland_c6")
CLAIMS = (
    "the problem in which each particle has one single neighbor at each side is studied [...] "
    "the error converges to a residue, which is in general large compared to the norm of the exact solution",
    "When two and three neighbors are involved it is found that the error tends in most cases to a small "
    "limiting value, different from zero",
    "divergent solutions are also found in the case of two neighbors with the Wendland Kernel C 2",
    "In general, the Wendland Kernel C 2 turns out to be the worst choice",
)
SHORT = {"cubic_spline": "cubic", "wendland_c2": "C2", "wendland_c4": "C4", "wendland_c6": "C6"}


def _claim1(c, small):
    one = c[c.neighbours == 1]
    share = one.groupby("kernel", sort=False).residue.apply(lambda r: float((r > small).mean()))
    med = one.groupby("kernel", sort=False).residue.median()
    ok = bool((share > 0.5).all())
    txt = "median residue abs(kappa-1) over h/dx in (0.5, 1]: " + ", ".join(
        f"{SHORT[k]} {med[k]:.3g} ({100 * share[k]:.0f}% of ratios > {small:g})" for k in med.index)
    return ok, txt


def _claim2(c, small):
    two3 = c[c.neighbours.isin([2, 3])]
    good = (two3.behaviour == "settled") & (two3.error_limit >= EXACT) & (two3.error_limit < small)
    med = two3.groupby(["neighbours", "kernel"], sort=False).error_limit.median()
    txt = (f"{100 * good.mean():.0f}% of (kernel, h/dx) cases settle to a limit in [{EXACT:g}, {small:g}); "
           "median limit " + "; ".join(
               f"{nb} nb: " + ", ".join(f"{SHORT[k]} {med[nb, k]:.2g}" for k in med[nb].index) for nb in (2, 3)))
    return bool(good.mean() > 0.5), txt


def _claim3(c):
    c2 = c[(c.kernel == "wendland_c2") & (c.neighbours == 2)]
    div = c2[c2.behaviour == "divergent"]
    ok = len(div) > 0 and bool(div.ill_conditioned.all())
    txt = (f"Wendland C2, two neighbours: {len(div)} divergent of {len(c2)} ratios, "
           f"max cond_1/N {c2.cond_over_n.max():.3g}")
    others = c[(c.behaviour == "divergent")]
    if len(others):
        g = others.groupby(["kernel", "neighbours"], sort=False)
        txt += "; divergent elsewhere: " + "; ".join(
            f"{SHORT[k]} {nb} nb at h/dx {grp.ratio.min():.2f}-{grp.ratio.max():.2f} ({len(grp)} ratios, "
            f"cond_1/N up to {grp.cond_over_n.max():.3g})" for (k, nb), grp in g)
    return ok, txt


def _claim4(c):
    w = c[c.kernel.isin(WENDLAND)]
    worst = {}
    for nb, g in w.groupby("neighbours"):
        med = g[g.behaviour != "divergent"].groupby("kernel").error_limit.median()
        ndiv = g.groupby("kernel").behaviour.apply(lambda b: int((b == "divergent").sum()))
        worst[nb] = max(med.index, key=lambda k: (ndiv[k], med[k]))
    share = np.mean([k == "wendland_c2" for k in worst.values()])
    txt = "worst Wendland kernel (most divergent ratios, then largest median error) per neighbour count: " + \
        ", ".join(f"{nb} nb {SHORT[k]}" for nb, k in worst.items()) + \
        "; the abstract's reason (divergence, ill-conditioning) is claim 3"
    return bool(share > 0.5), txt


def verdicts(cases, variant, small):
    """[(reproduced?, measured text)] of the four claims for one variant."""
    c = cases[cases.variant == variant]
    return [_claim1(c, small), _claim2(c, small), _claim3(c), _claim4(c)]


def claims_table(cases, variants, small, figures):
    """The claims CSV rows: verdict of the first (default) variant; the others say whether they agree."""
    per = {v: verdicts(cases, v, small) for v in variants}
    default = variants[0]
    rows = []
    for i, claim in enumerate(CLAIMS):
        ok, txt = per[default][i]
        agree = [v for v in variants[1:] if per[v][i][0] == ok]
        differ = [v for v in variants[1:] if per[v][i][0] != ok]
        txt = f"{default}: {txt}" + (f". Same verdict: {', '.join(agree)}" if agree else "") + \
            "".join(f". Other verdict, {v}: {per[v][i][1]}" for v in differ)
        rows.append(dict(paper=PAPER, section="abstract", claim=claim, measured=txt,
                         verdict="reproduced" if ok else "not reproduced", evidence=figures[i]))
    return pd.DataFrame(rows)


def fragment(cases, summary, claims, variants, labels, nmax):
    """Markdown of the report section (results/report/60_sph1d.md)."""
    d = variants[0]
    s = summary[summary.variant == d]
    lines = [
        "## 1D truncated SPH hydrostatic column (Merino-Alonso et al. 2020, abstract only)", "",
        "The SPH momentum balance at rest, grad p = -rho g, at every particle of a liquid column, with the "
        "kernel truncated at the free surface, solved as a banded linear system A p = b (no time stepping). "
        "The abstract states neither the gradient form nor the floor; the discrete equations we chose are "
        "in `docs/sph1d.md`.  Variants: " + "; ".join(f"`{v}`: {labels[v]}" for v in variants) + ".", "",
        f"Sweep: h/dx {cases.ratio.min():.2f} to {cases.ratio.max():.2f}, N up to {nmax}, "
        f"{len(cases)} (variant, kernel, h/dx) cases (solve time in `docs/timing.md`).  Error: relative quadratic "
        "error at the largest N; behaviour over the last four N (settled, decreasing, divergent).", "",
        f"Per kernel and neighbours per side (`{d}`):", "",
        "| kernel | nb | median error | min | max | divergent ratios | max cond_1/N |",
        "|---|---|---|---|---|---|---|",
    ]
    for _, r in s.iterrows():
        lines.append(f"| {r.kernel} | {r.neighbours} | {r.median_error:.3g} | {r.min_error:.3g} | "
                     f"{r.max_error:.3g} | {r.divergent_ratios if r.divergent else '-'} | {r.max_cond_over_n:.3g} |")
    lines += ["", "Verdicts on the abstract's four claims: " + "; ".join(
        f"({k}) **{v}**" for k, v in enumerate(claims.verdict, 1)) + " (measurements in the claims table above).", "", "![error against N](../figures/sph1d_error_vs_n.png)",
              "![error and conditioning maps](../figures/sph1d_maps.png)",
              "![variants](../figures/sph1d_variants.png)", ""]
    return "\n".join(lines)


def timing(cases, nmax, solve_seconds):
    """Markdown for docs/timing.md: the sweep's solve time."""
    return (f"## 1D truncated SPH sweep: solve time\n\n{len(cases)} (variant, kernel, h/dx) cases, N up to {nmax}, "
            f"every N of each case: {solve_seconds:.1f} s of banded solves and condition estimates (one process).\n")
