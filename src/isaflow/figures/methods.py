"""The methods compared on the same tank: wall-load and level errors against solver time (one set of axes)."""

import numpy as np
import pandas as pd

from .style import METHOD_MARKER, OUTCOME_STYLE, plt, save, variant_style

PANELS = [
    ("side_err", "|side-wall total / hydrostatic - 1|", "(a) side-wall loads"),
    ("contact_rms", "per-panel RMS error (γ h a)", "(b) per-panel (per-contact) wall loads"),
    ("side_height_err_cm", "|side resultant height - h/3| (cm)", "(c) side resultant height"),
    ("level_err_hydro_cm", "|level - level implied by side loads| (cm)", "(d) level against hydrostatic consistency"),
]
FLOOR = 1e-4  # smallest |error| drawn on log axes


def methods_error_vs_runtime_figure(inputs, outputs):
    """Every method and variant on one set of axes per measure: marker = method, colour = variant
    (registry), filled = reached its stop criterion (converged / at rest), hollow = any other outcome."""
    tab = pd.read_csv(inputs[0])
    fig, axes = plt.subplots(2, 2, figsize=(12, 9), constrained_layout=True)
    handles = {}
    for ax, (col, ylabel, title) in zip(axes.ravel(), PANELS):
        for (method, variant), g in tab.groupby(["method", "variant"], sort=False):
            colour, label = variant_style(method, variant)
            g = g[np.isfinite(g[col]) & (g["wall_time_s"] > 0)]
            done = g["status"] == "converged"
            y = np.maximum(g[col].abs(), FLOOR)
            mk = METHOD_MARKER.get(method, "o")
            ax.scatter(g["wall_time_s"][done], y[done], s=36, marker=mk, color=colour, edgecolor="k", linewidth=0.4,
                       zorder=3)
            ax.scatter(g["wall_time_s"][~done], y[~done], s=36, marker=mk, facecolor="none", edgecolor=colour, zorder=3)
            handles[f"{method}: {label}"] = plt.Line2D([], [], ls="", marker=mk, color=colour)
        ax.set(xscale="log", yscale="log", xlabel="solver wall-clock time (s)", ylabel=ylabel, title=title)
        ax.grid(True, which="both", alpha=0.25)
    handles["filled: reached its stop criterion; hollow: " + ", ".join(k for k in OUTCOME_STYLE if k != "converged")] = \
        plt.Line2D([], [], ls="", marker="o", mfc="none", color="k")
    fig.legend(handles.values(), handles.keys(), loc="outside lower center", ncol=1, fontsize=8, frameon=False)
    fig.suptitle("Single vessel, W = 9 kN: every method on the same tank and the same 10 cm wall panels")
    save(fig, outputs)
