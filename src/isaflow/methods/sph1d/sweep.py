"""The sweep: N (dx -> 0 at fixed h/dx) x h/dx x kernel x variant, and the behaviour of each case.

run_sweep -> xarray Dataset (dims variant, kernel, ratio, n) of the relative
quadratic error and the 1-norm condition number of A; classify -> one row per
(variant, kernel, ratio): the error at the largest N, its behaviour over the
last ``window`` N and the conditioning there.
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
EXACT = 1e-9  # errors below this are round-off of an exact solution (cond <= 1e4, eps 2e-16)


def run_sweep(s):
    """Solve every case of settings s (settings.load); Dataset with units on every variable."""
    variants, kernels, ratios, ns = list(s["variants"]), s["kernels"], s["ratios"], s["n"]
    height, rho_g = s["column"]["height"], s["column"]["rho_g"]
    err = np.full((len(variants), len(kernels), len(ratios), len(ns)), np.nan)
    cond = np.full_like(err, np.nan)
    t0 = last = time.perf_counter()
    for a, var in enumerate(variants):
        form = s["variants"][var]
        for b, kern in enumerate(kernels):
            kind = kernel_id(kern)
            for c, r in enumerate(ratios):
                for d, n in enumerate(ns):
                    sol = solve_column(n, r, kind, form["gradient"], form["floor"], height, rho_g)
                    err[a, b, c, d], cond[a, b, c, d] = sol.error, sol.cond
            if time.perf_counter() - last > PROGRESS_S or b == len(kernels) - 1:
                last = time.perf_counter()
                log.info("sph1d sweep: variant %s kernel %s done (%.1f s)", var, kern, last - t0)
    kappa = np.array([closed_form.kappa(k, ratios) for k in kernels])
    one = neighbours_per_side(ratios) == 1
    return xr.Dataset(
        {
            "error": (("variant", "kernel", "ratio", "n"), err,
                      {"units": "1", "long_name": "relative quadratic error ||p - p_exact||_2 / ||p_exact||_2"}),
            "cond": (("variant", "kernel", "ratio", "n"), cond,
                     {"units": "1", "long_name": "1-norm condition number of A (Higham's lower-bound estimate)"}),
            "neighbours": (("ratio",), neighbours_per_side(ratios),
                           {"units": "1", "long_name": "neighbours per side inside the support 2 h"}),
            "kappa": (("kernel", "ratio"), np.where(one, kappa, np.nan),
                      {"units": "1", "long_name": "one-neighbour slope factor 1 / (2 dx^2 |dW/dr(dx)|)"}),
            "residue": (("kernel", "ratio"), np.where(one, np.abs(kappa - 1.0), np.nan),
                        {"units": "1", "long_name": "closed-form limit |kappa - 1| of the relative error"}),
        },
        coords={"variant": variants, "kernel": list(kernels),
                "ratio": ("ratio", ratios, {"units": "1", "long_name": "h / dx (kernel support 2 h)"}),
                "n": ("n", np.asarray(ns), {"units": "1", "long_name": "particles N (dx = H / N)"})},
        attrs={"height_cm": height, "rho_g_N_cm3": rho_g, "solve_seconds": time.perf_counter() - t0,
               "method": "sph1d", "settings_file": s["path"]},
    )


def behaviour(errors, settle_factor):
    """'settled' | 'decreasing' | 'divergent' from the errors (window,) at increasing N.

    settled: max/min <= settle_factor (or all below EXACT); decreasing: monotone decrease beyond it;
    divergent: anything else (grows, or jumps from one N to the next).
    """
    e = np.asarray(errors, float)
    if not np.all(np.isfinite(e)):
        return "divergent"
    if e.max() < EXACT:
        return "settled"
    if e.max() <= settle_factor * e.min():
        return "settled"
    return "decreasing" if np.all(np.diff(e) < 0) else "divergent"


def classify(ds, s):
    """DataFrame, one row per (variant, kernel, ratio): neighbours, error_limit (error at the
    largest N), behaviour, cond_max_n, cond_over_n, ill_conditioned, residue (one neighbour)."""
    c = s["classify"]
    window, nmax = c["window"], int(ds.n[-1])
    rows = []
    for var in ds.variant.values:
        for kern in ds.kernel.values:
            e = ds.error.sel(variant=var, kernel=kern).values
            k = ds.cond.sel(variant=var, kernel=kern).values
            for i, r in enumerate(ds.ratio.values):
                rows.append(dict(
                    variant=var, kernel=kern, ratio=float(r), neighbours=int(ds.neighbours[i]),
                    error_limit=e[i, -1], behaviour=behaviour(e[i, -window:], c["settle_factor"]),
                    cond_max_n=k[i, -1], cond_over_n=k[i, -1] / nmax,
                    ill_conditioned=bool(k[i, -1] / nmax > c["ill_conditioned"]),
                    residue=float(ds.residue.sel(kernel=kern).values[i])))
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
            divergent=len(div), divergent_ratios=" ".join(f"{r:.2f}" for r in div.ratio),
            ill_conditioned=int(g.ill_conditioned.sum()),
            ill_conditioned_ratios=" ".join(f"{r:.2f}" for r in g[g.ill_conditioned].ratio),
            max_cond_over_n=g.cond_over_n.max()))
    return pd.DataFrame(out)
