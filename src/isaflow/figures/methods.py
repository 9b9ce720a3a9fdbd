"""Every method on the shared tanks (results/compare/runs.csv): one figure of every tank's errors against
the tank's theory and the method's own depth, and one of the errors against solver time.

Colour = variant, marker = method (both from the registry); filled = the run met its own stop criterion
(converged or at rest), hollow = any other outcome.
"""

import numpy as np
import pandas as pd

from .style import OUTCOME_STYLE, method_marker, plt, save, variant_style
from ..report.methods import at_rest

FLOOR = 1e-4  # smallest |error| drawn on log axes


def _label(r):
    return f"{r['method']} {r['variant']} {r['resolution']}" + ("" if r["status"] == "converged" else " *")


def _vessels(g):
    """Vessel prefixes of a tank's rows ('' for a single vessel), source first."""
    names = [c[: -len("tank_surface_cm")] for c in g.columns if c.endswith("tank_surface_cm") and g[c].notna().any()]
    return names or [""]


def tanks_figure(table, outputs, tanks=()):
    """Columns = tanks (in the order given, then any other); rows: free-surface error against the tank's
    level at rest [cm], side-wall and floor errors of the receiving vessel against the tank's theory (the
    method's marker) and the run's own depth ('+').  Filled: the run met its stop criterion; a dynamic run still moving at
    its time limit is not drawn (report.methods.at_rest)."""
    df = pd.read_csv(table)
    df = df[df["compare"].astype(bool)]
    tanks = [t for t in tanks if t in set(df["tank"])] + [t for t in dict.fromkeys(df["tank"]) if t not in tanks]
    fig, axes = plt.subplots(3, len(tanks), figsize=(6.2 * len(tanks), 12.5), squeeze=False,
                             gridspec_kw={"hspace": 0.08, "wspace": 0.32})
    handles = {}
    for col, tank in enumerate(tanks):
        g = df[df["tank"] == tank].reset_index(drop=True)
        vess = _vessels(g)
        recv = vess[-1]
        x = np.arange(len(g))
        for k, r in g.iterrows():
            colour, label = variant_style(r["method"], r["variant"])
            mk = method_marker(r["method"])
            done = r["status"] == "converged"
            handles.setdefault(f"{r['method']}: {label}", plt.Line2D([], [], ls="", marker=mk, color=colour))
            if not at_rest(r):  # a dynamic run still moving at its time limit: no end state to compare
                continue
            for v, shift in zip(vess, np.linspace(-0.15, 0.15, len(vess))):
                y = r.get(f"{v}surface_err_tank_cm", np.nan)
                first = v != recv
                axes[0, col].plot(k + shift, y, marker="x" if first else mk, color=colour, ls="", ms=7,
                                  mfc=colour if done else "none")
            for row, key in ((1, "side_err"), (2, "floor_err")):
                axes[row, col].plot(k - 0.12, r.get(f"{recv}{key}_tank", np.nan), marker=mk, ls="", ms=7,
                                    color=colour, mfc=colour if done else "none")
                axes[row, col].plot(k + 0.12, r.get(f"{recv}{key}_own", np.nan), marker="+", ls="", ms=9, mew=1.6,
                                    color=colour)
        floorless = not g.get(f"{recv}floor_err_tank", pd.Series(dtype=float)).notna().any()
        if floorless and "walls_weight_err" in g:  # no floor wall (a V): the walls' vertical load against the weight
            for k, r in g.iterrows():
                colour, _ = variant_style(r["method"], r["variant"])
                axes[2, col].plot(k, r["walls_weight_err"], marker=method_marker(r["method"]), ls="", ms=7,
                                  color=colour, mfc=colour if r["status"] == "converged" else "none")
        for row in range(3):
            ax = axes[row, col]
            ax.axhline(0, color="k", lw=0.6)
            ax.grid(True, axis="y", alpha=0.3)
            ax.set_xticks(x, [_label(r) for _, r in g.iterrows()] if row == 2 else [], rotation=90, fontsize=7)
            ax.set_xlim(-0.7, len(g) - 0.3)
        where = "" if recv == "" else f" ({recv.rstrip('_')} vessel)"
        axes[0, col].set_title(f"tank {tank}")
        axes[0, col].set_ylabel("free surface - tank's level at rest (cm)" + (
            "\n(x: first vessel, marker: receiving vessel)" if len(vess) > 1 else ""))
        axes[1, col].set_ylabel(f"side-wall load error{where}\nmarker: vs tank theory; +: vs own depth")
        axes[2, col].set_ylabel(f"floor load error{where}\nmarker: vs tank theory; +: vs own depth" if not floorless
                                else "no floor: the walls' vertical load\n/ the liquid's weight - 1")
        for row in (1, 2):
            _percent_axis(axes[row, col])
    handles["hollow marker, * after the label: the run did not meet its stop criterion (" + ", ".join(
        k for k in OUTCOME_STYLE if k != "converged") + ")"] = plt.Line2D([], [], ls="", marker="o", mfc="none", color="k")
    handles["+: the same load against the run's own weight and depth; x: the first vessel's surface"] = \
        plt.Line2D([], [], ls="", marker="+", color="k", ms=9, mew=1.6)
    fig.legend(handles.values(), handles.keys(), loc="upper center", bbox_to_anchor=(0.5, 0.0), ncol=2, fontsize=8,
               frameon=False)
    fig.suptitle("Every method on every tank, judged by the same measures: free surface = top particle centres + "
                 "half a layer pitch;\ntheory = the tank's liquid (W, rho g) at rest in its vessels, or the run's own "
                 "weight and depth", y=0.93)
    save(fig, outputs)


def _percent_axis(ax):
    """Tick labels of a fractional error axis in signed percent, with as many decimals as the tick step needs."""
    ticks = ax.get_yticks()
    step = 100 * float(np.min(np.diff(ticks))) if len(ticks) > 1 else 1.0
    digits = int(min(3, max(0, -np.floor(np.log10(step) + 1e-9)))) if step > 0 else 0
    # a step such as 0.25 % needs two decimals: as many as it has
    while digits < 3 and abs(round(step, digits) - step) > 1e-9 * step:
        digits += 1
    ax.yaxis.set_major_formatter(plt.FuncFormatter(lambda v, _: f"{v:+.{digits}%}"))


PANELS = [
    ("side_err_tank", "|side-wall load / tank theory - 1|", "(a) side walls against the tank's theory"),
    ("surface_err_tank_cm", "|free surface - tank level| (cm)", "(b) free surface against the tank's 72.5 cm"),
    ("side_err_own", "|side-wall load / own-depth theory - 1|", "(c) side walls against the run's own depth"),
    ("contact_rms_tank", "per-panel RMS error (rho g h a)", "(d) per-panel wall loads against the tank's theory"),
]


def error_vs_runtime_figure(table, outputs):
    """Single vessel: every method's errors against its solver wall-clock time (a timing figure)."""
    df = pd.read_csv(table)
    df = df[(df["tank"] == "single") & (df["wall_time_s"] > 0)]
    fig, axes = plt.subplots(2, 2, figsize=(12, 9.5), constrained_layout=True)
    handles = {}
    for ax, (col, ylabel, title) in zip(axes.ravel(), PANELS):
        for (method, variant), g in df.groupby(["method", "variant"], sort=False):
            colour, label = variant_style(method, variant)
            g = g[np.isfinite(g[col])]
            done = g["status"] == "converged"
            y = np.maximum(g[col].abs(), FLOOR)
            mk = method_marker(method)
            ax.scatter(g["wall_time_s"][done], y[done], s=36, marker=mk, color=colour, edgecolor="k", linewidth=0.4,
                       zorder=3)
            ax.scatter(g["wall_time_s"][~done], y[~done], s=36, marker=mk, facecolor="none", edgecolor=colour, zorder=3)
            handles[f"{method}: {label}"] = plt.Line2D([], [], ls="", marker=mk, color=colour)
        ax.set(xscale="log", yscale="log", xlabel="solver wall-clock time (s)", ylabel=ylabel, title=title)
        ax.grid(True, which="both", alpha=0.25)
    handles["filled: reached its stop criterion; hollow: " + ", ".join(k for k in OUTCOME_STYLE if k != "converged")] = \
        plt.Line2D([], [], ls="", marker="o", mfc="none", color="k")
    fig.legend(handles.values(), handles.keys(), loc="outside lower center", ncol=1, fontsize=8, frameon=False)
    fig.suptitle("Single vessel (W = 9 kN, h = 72.5 cm): every tank method, the same 10 cm wall panels, against "
                 "solver time (threads as recorded in each run file)")
    save(fig, outputs)
