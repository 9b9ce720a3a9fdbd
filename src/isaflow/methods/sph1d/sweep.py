"""The sweep: N (dx -> 0 at fixed h/dx) x h/dx x kernel x variant, and the behaviour of each case.

run_sweep -> xarray Dataset (dims variant, kernel, ratio, n) of the relative
quadratic and max-norm errors and the 1-norm condition number of A; classify -> one row per
(variant, kernel, ratio): the error at the largest N, its behaviour over the
last ``window`` N and the conditioning there, by the rule of the claims registry
(config/claims/merino_alonso2020.yaml, file header; its numbers are the
registry's, passed in).
"""

import logging
import time

import numpy as np
import pandas as pd
import xarray as xr

from isaflow.core.smoothing import kernel_id

from . import closed_form
from .column import solve_column
from .system import neighbours_per_side

log = logging.getLogger(__name__)
PROGRESS_S = 20.0  # a progress line at least this often


def run_sweep(s):
    """Solve every case of settings s (settings.checked_values); Dataset with units on every variable."""
    variants, kernels, ratios, ns = list(s["variants"]), s["kernels"], s["ratios"], s["n"]
    height, rho_g, gap = s["column"]["height"], s["column"]["rho_g"], float(s["surface"])
    err = np.full((len(variants), len(kernels), len(ratios), len(ns)), np.nan)
    err_max, cond = np.full_like(err, np.nan), np.full_like(err, np.nan)
    t0 = last = time.perf_counter()
    for a, var in enumerate(variants):
        form = s["variants"][var]
        for b, kern in enumerate(kernels):
            kind = kernel_id(kern)
            for c, r in enumerate(ratios):
                for d, n in enumerate(ns):
                    sol = solve_column(n, r, kind, form["gradient"], form["floor"], height, rho_g, gap)
                    err[a, b, c, d], err_max[a, b, c, d], cond[a, b, c, d] = sol.error, sol.error_max, sol.cond
            if time.perf_counter() - last > PROGRESS_S or b == len(kernels) - 1:
                last = time.perf_counter()
                log.info("sph1d sweep: variant %s kernel %s done (%.1f s)", var, kern, last - t0)
    kappa = np.array([closed_form.kappa(k, ratios) for k in kernels])
    one = neighbours_per_side(ratios) == 1
    return xr.Dataset(
        {
            "error": (("variant", "kernel", "ratio", "n"), err,
                      {"units": "1", "long_name": "relative quadratic error ||p - p_exact||_2 / ||p_exact||_2",
                       "missing": "not finite: the solve broke down (a divergent case)"}),
            "error_max": (("variant", "kernel", "ratio", "n"), err_max,
                          {"units": "1", "long_name": "relative max-norm error max|p - p_exact| / max|p_exact|",
                           "missing": "not finite: the solve broke down (a divergent case)"}),
            "cond": (("variant", "kernel", "ratio", "n"), cond,
                     {"units": "1", "long_name": "1-norm condition number of A (Higham's lower-bound estimate)",
                      "missing": "not finite: a singular system"}),
            "neighbours": (("ratio",), neighbours_per_side(ratios),
                           {"units": "1", "long_name": "neighbours per side inside the support 2 h"}),
            "kappa": (("kernel", "ratio"), np.where(one, kappa, np.nan),
                      {"units": "1", "long_name": "one-neighbour slope factor 1 / (2 dx^2 |dW/dr(dx)|)",
                       "missing": "not applicable: more than one neighbour per side"}),
            "residue": (("kernel", "ratio"), np.where(one, np.abs(kappa - 1.0), np.nan),
                        {"units": "1", "long_name": "closed-form limit |kappa - 1| of the relative error",
                         "missing": "not applicable: more than one neighbour per side"}),
        },
        coords={"variant": variants, "kernel": list(kernels),
                "ratio": ("ratio", ratios, {"units": "1", "long_name": "h / dx (kernel support 2 h)"}),
                "n": ("n", np.asarray(ns), {"units": "1", "long_name": "particles N (dx = H / (N - 1/2 + top_gap_dx))"})},
        attrs={"height_cm": height, "rho_g_N_cm3": rho_g, "top_gap_dx": gap, "solve_seconds": time.perf_counter() - t0,
               "method": "sph1d", "settings_file": s["path"], "resolution": s.get("resolution", ""),
               "classify_window": int(s["classify"]["window"]),
               "variant_gradient": " ".join(s["variants"][v]["gradient"] for v in variants),
               "variant_floor": " ".join(s["variants"][v]["floor"] for v in variants)},
    )


def variant_forms(ds):
    """{variant: (gradient form, floor)} of a sweep's variants (its attributes)."""
    grads = str(ds.attrs["variant_gradient"]).split()
    floors = str(ds.attrs["variant_floor"]).split()
    return {str(v): (g, f) for v, g, f in zip(ds.variant.values, grads, floors)}


def linearity(ds):
    """Linearity of the solve in rho g on sweep ds: for its first variant at its largest N and, per kernel, the
    h/dx whose cond_1(A) there is smallest, the columns at rho g and 2 rho g -> Dataset over 'kernel' of that
    ratio and max |p(2 rho g) - 2 p(rho g)| / max |2 p(rho g)| (1)."""
    v0 = str(ds.variant.values[0])
    grad, floor = variant_forms(ds)[v0]
    n = int(ds.n.values[-1])
    height, rho_g = float(ds.attrs["height_cm"]), float(ds.attrs["rho_g_N_cm3"])
    ratios, diffs = [], []
    for kern in ds.kernel.values:
        cond = ds.cond.sel(variant=v0, kernel=kern).values[:, -1]
        ratio = float(ds.ratio.values[int(np.nanargmin(np.where(np.isfinite(cond), cond, np.nan)))])
        p1 = solve_column(n, ratio, str(kern), grad, floor, height, rho_g).p
        p2 = solve_column(n, ratio, str(kern), grad, floor, height, 2.0 * rho_g).p
        ratios.append(ratio)
        diffs.append(float(np.abs(p2 - 2.0 * p1).max() / np.abs(2.0 * p1).max()))
    return xr.Dataset(
        {"ratio": ("kernel", np.array(ratios), {"units": "1", "long_name": "h/dx of the best-conditioned A at N"}),
         "rel_diff": ("kernel", np.array(diffs), {"units": "1",
                                                   "long_name": "max |p(2 rho g) - 2 p(rho g)| / max |2 p(rho g)|"})},
        coords={"kernel": ds.kernel.values}, attrs={"variant": v0, "n": n, "height_cm": height, "rho_g_N_cm3": rho_g})


def behaviour(errors, settle_band, round_off):
    """Class of an error history (window,) at doubling N (1): the rule of config/claims/merino_alonso2020.yaml
    (file header), with its numbers settle_band b and round_off (tolerance.parameters of its rows).

    With r = E(2N) / E(N) (first-order convergence r -> 1/2, a non-zero limit r -> 1):
    'divergent' if some E is not finite; 'exact' if every E < round_off (no ratio is formed);
    'settled' if every r in [b, 1/b]; 'decreasing' if every r < b; 'divergent' if some r > 1/b with
    E(N_max) > E(N_min); 'undetermined' otherwise.
    """
    e = np.asarray(errors, float)
    if not np.all(np.isfinite(e)):
        return "divergent"
    if e.max() < round_off:
        return "exact"
    r = e[1:] / e[:-1]
    if np.all((r >= settle_band) & (r <= 1.0 / settle_band)):
        return "settled"
    if np.all(r < settle_band):
        return "decreasing"
    if np.any(r > 1.0 / settle_band) and e[-1] > e[0]:
        return "divergent"
    return "undetermined"


def ill_conditioned(cond, ns, settle_band):
    """True if cond_1(A) over the window (window,) at N = ns (doublings) grows faster than N by the margin of
    the divergence rule (config/claims/merino_alonso2020.yaml, file header): some cond is not finite, or some
    cond(2N)/cond(N) > 2/b with cond(N_max)/cond(N_min) > N_max/N_min."""
    c, n = np.asarray(cond, float), np.asarray(ns, float)
    if not np.all(np.isfinite(c)):
        return True
    jump = np.any(c[1:] / c[:-1] > (n[1:] / n[:-1]) / settle_band)
    return bool(jump and c[-1] / c[0] > n[-1] / n[0])


def classify(ds, window, settle_band, round_off):
    """DataFrame, one row per (variant, kernel, ratio): neighbours, error_limit (error at the largest N),
    behaviour (over the last ``window`` N), cond_max_n, cond_over_n (cond_1 / N at the largest N),
    ill_conditioned (over the window), residue (one neighbour).  The rule and its numbers: behaviour,
    ill_conditioned."""
    ns = ds.n.values[-window:]
    nmax = int(ns[-1])
    rows = []
    for var in ds.variant.values:
        for kern in ds.kernel.values:
            e = ds.error.sel(variant=var, kernel=kern).values
            k = ds.cond.sel(variant=var, kernel=kern).values
            res = ds.residue.sel(kernel=kern).values
            for i, r in enumerate(ds.ratio.values):
                rows.append(dict(
                    variant=str(var), kernel=str(kern), ratio=float(r), neighbours=int(ds.neighbours[i]),
                    error_limit=e[i, -1], behaviour=behaviour(e[i, -window:], settle_band, round_off),
                    cond_max_n=k[i, -1], cond_over_n=k[i, -1] / nmax,
                    ill_conditioned=ill_conditioned(k[i, -window:], ns, settle_band),
                    residue=float(res[i])))
    return pd.DataFrame(rows)


def summarise(cases):
    """Per (variant, kernel, neighbours): median/min/max error at the largest N over the
    non-divergent ratios, number of divergent and ill-conditioned ratios and which."""
    out = []
    for (var, kern, nb), g in cases.groupby(["variant", "kernel", "neighbours"], sort=False):
        ok = g[g.behaviour != "divergent"]
        div = g[g.behaviour == "divergent"]
        out.append(dict(
            variant=var, kernel=kern, neighbours=nb, ratios=len(g),
            median_error=ok.error_limit.median(), min_error=ok.error_limit.min(), max_error=ok.error_limit.max(),
            settled=int((g.behaviour == "settled").sum()), decreasing=int((g.behaviour == "decreasing").sum()),
            exact=int((g.behaviour == "exact").sum()), undetermined=int((g.behaviour == "undetermined").sum()),
            divergent=len(div), divergent_ratios=" ".join(f"{r:.2f}" for r in div.ratio),
            ill_conditioned=int(g.ill_conditioned.sum()),
            ill_conditioned_ratios=" ".join(f"{r:.2f}" for r in g[g.ill_conditioned].ratio),
            max_cond_over_n=g.cond_over_n.max()))
    return pd.DataFrame(out)
