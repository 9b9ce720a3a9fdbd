"""Figures of the 1D study, from the sweep file and the case table only (sweep.classify)."""

import numpy as np
import pandas as pd
import xarray as xr


from isaflow.figures.style import plt, save

KERNEL_COLOURS = {"cubic_spline": "tab:gray", "wendland_c2": "tab:red", "wendland_c4": "tab:blue",
                  "wendland_c6": "tab:green"}
KERNEL_LABELS = {"cubic_spline": "cubic spline", "wendland_c2": "Wendland C2", "wendland_c4": "Wendland C4",
                 "wendland_c6": "Wendland C6"}
SHOWN_RATIOS = (0.75, 1.25, 1.45, 1.75, 2.0, 2.5)  # one to four neighbours per side


def _bands(ax, ratios):
    """Shade alternate neighbour-count bands (n/2, (n+1)/2] of h/dx and label them on top."""
    for nb in range(1, int(np.ceil(2 * ratios.max()))):
        lo, hi = nb / 2, (nb + 1) / 2
        if nb % 2:
            ax.axvspan(lo, hi, color="0.93", zorder=0)
        ax.text((lo + hi) / 2, 1.01, f"{nb} nb", transform=ax.get_xaxis_transform(), ha="center",
                va="bottom", fontsize=7)


def error_vs_n(sweep_nc, cases_csv, variant, outputs):
    """Log-log error against N for selected h/dx, one panel per kernel; divergent cases dashed."""
    ds = xr.open_dataset(sweep_nc).load()
    cases = pd.read_csv(cases_csv)
    kernels = list(ds.kernel.values)
    fig, axes = plt.subplots(2, 2, figsize=(8, 6.2), sharex=True, sharey=True)
    for ax, kern in zip(axes.flat, kernels):
        c = cases[(cases.variant == variant) & (cases.kernel == kern)]
        div = list(c[c.behaviour == "divergent"].ratio.values[:2])
        cmap = plt.get_cmap("viridis")
        for i, r in enumerate([*SHOWN_RATIOS, *div]):
            e = ds.error.sel(variant=variant, kernel=kern).sel(ratio=r, method="nearest")
            bad = r in div
            ax.loglog(ds.n, np.clip(e, 1e-17, None), "x--" if bad else "o-", ms=3, lw=1,
                      color="k" if bad else cmap(i / len(SHOWN_RATIOS)),
                      label=f"h/dx = {r:.2f}" + (" (divergent)" if bad else ""))
        ax.set_title(KERNEL_LABELS[kern])
        ax.set_ylim(1e-6, 30)
        ax.legend(fontsize=6.5, loc="lower left", ncol=2)
        ax.grid(True, which="major", lw=0.3)
    for ax in axes[-1]:
        ax.set_xlabel("particles N (dx = H / N) [1]")
    for ax in axes[:, 0]:
        ax.set_ylabel("relative quadratic error [1]")
    fig.suptitle(f"Error against N at fixed h/dx (variant {variant}; cubic spline at h/dx = 1 is exact, not shown)",
                 fontsize=9)
    fig.tight_layout()
    save(fig, outputs)


def maps(sweep_nc, cases_csv, variant, outputs):
    """Error at the largest N and cond_1(A)/N against h/dx for every kernel; divergent (x) and
    ill-conditioned (o) cases marked (the case table's classes, sweep.classify)."""
    ds = xr.open_dataset(sweep_nc).load()
    cases = pd.read_csv(cases_csv)
    c = cases[cases.variant == variant]
    nmax = int(ds.n[-1])
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(8, 6.8), sharex=True)
    for kern in ds.kernel.values:
        k = c[c.kernel == kern].sort_values("ratio")
        col = KERNEL_COLOURS[kern]
        a1.semilogy(k.ratio, np.clip(k.error_limit, 1e-17, None), color=col, lw=1.1, label=KERNEL_LABELS[kern])
        a1.semilogy(ds.ratio, ds.residue.sel(kernel=kern), color=col, lw=2.5, alpha=0.35)
        a2.semilogy(k.ratio, k.cond_over_n, color=col, lw=1.1, label=KERNEL_LABELS[kern])
        d = k[k.behaviour == "divergent"]
        a1.plot(d.ratio, d.error_limit, "x", color=col, ms=5)
        a2.plot(d.ratio, d.cond_over_n, "x", color=col, ms=5)
        ill = k[k.ill_conditioned.astype(bool)]
        a2.plot(ill.ratio, ill.cond_over_n, "o", mfc="none", color=col, ms=6)
    a1.plot([], [], "x", color="k", label="divergent (error jumps up, no net decrease, over the window)")
    a1.plot([], [], color="k", lw=2.5, alpha=0.35, label="closed form |kappa - 1| (one neighbour)")
    a2.plot([], [], "o", mfc="none", color="k", label="ill-conditioned (cond_1 grows faster than N)")
    a1.set_ylabel(f"relative quadratic error at N = {nmax} [1]")
    a2.set_ylabel(f"cond_1(A) / N at N = {nmax} [1]")
    a2.set_xlabel("h / dx [1] (kernel support 2 h; nb = neighbours per side)")
    a1.set_ylim(1e-5, 1e4)
    for ax in (a1, a2):
        _bands(ax, ds.ratio.values)
        ax.grid(True, lw=0.3)
    a1.legend(fontsize=7, ncol=2, loc="upper right")
    a2.legend(fontsize=7, ncol=3, loc="upper left")
    fig.tight_layout()
    save(fig, outputs)


def variants(cases_csv, labels, outputs, surface=None):
    """Error at the largest N against h/dx for every variant (does a claim depend on the reading?), and (surface:
    sweep.classify rows of the first variant with the top particle on the surface, input surface_placement) the
    same reading with the other particle placement, dashed."""
    cases = pd.read_csv(cases_csv)
    kernels = list(dict.fromkeys(cases.kernel))
    fig, axes = plt.subplots(2, 2, figsize=(8, 6.2), sharex=True, sharey=True)
    for ax, kern in zip(axes.flat, kernels):
        for var, (label, colour) in labels.items():
            k = cases[(cases.kernel == kern) & (cases.variant == var)].sort_values("ratio")
            ax.semilogy(k.ratio, np.clip(k.error_limit, 1e-17, None), color=colour, lw=1, label=var)
            d = k[k.behaviour == "divergent"]
            ax.plot(d.ratio, d.error_limit, "x", color=colour, ms=4)
        if surface is not None:
            k = surface[surface.kernel == kern].sort_values("ratio")
            ax.semilogy(k.ratio, np.clip(k.error_limit, 1e-17, None), color="k", lw=0.8, ls="--",
                        label=f"{k.variant.iloc[0]}, top particle on the surface")
            d = k[k.behaviour == "divergent"]
            ax.plot(d.ratio, d.error_limit, "x", color="k", ms=4)
        ax.set_title(KERNEL_LABELS[kern])
        ax.set_ylim(1e-5, 1e4)
        ax.grid(True, lw=0.3)
    axes[0, 0].legend(fontsize=7)
    for ax in axes[-1]:
        ax.set_xlabel("h / dx [1]")
    for ax in axes[:, 0]:
        ax.set_ylabel("error at the largest N [1]")
    fig.suptitle("Gradient form, floor closure and the top particle's placement (inputs gradient_form, "
                 "floor_treatment, surface_placement; x: divergent)", fontsize=9)
    fig.tight_layout()
    save(fig, outputs)
