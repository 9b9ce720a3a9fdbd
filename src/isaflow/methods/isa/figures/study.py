"""Study figures: error against run time, stability map.  Drawn from the study tables
(results/isa/study/error_vs_runtime.csv, stability_map.csv, stability_cases.csv), which
methods.isa.tables builds from the run files."""

import textwrap

import numpy as np
import pandas as pd

from ..plan import VARIANTS
from ....figures.style import OUTCOME_STYLE, plt, save, variant_style

LATTICE_MARKER = {"coarse": "o", "refined": "s", "fine": "^", "finer": "D"}
FLOOR = 1e-4  # smallest |error| drawn on the log axes (exact zeros sit on it)

PANELS = [
    ("level_err_paper_cm", "|level - paper's level| (cm)",
     "(a) free surface (top centres + half the layer pitch) against the paper\n(k_p calibrated on the top centres: "
     "config/inferred.yaml)"),
    ("level_err_hydro_cm", "|level - level implied by side loads| (cm)",
     "(b) level against hydrostatic consistency (2 B F_side / W)"),
    ("side_err", "|side-wall total / hydrostatic - 1| (-)", "(c) side-wall loads against hydrostatics"),
    ("contact_rms", "RMS contact error (floor-contact loads γha)", "(d) per-contact wall loads against hydrostatics"),
    ("residual", "residual max|F| (N)", "(e) residual out-of-balance force"),
]


X_AXES = {"wall_time_s": ("solver wall-clock time (s)", "Error against run time"),
          "particle_steps": ("particles x force evaluations", "Error against work (particle-steps, hardware-independent)")}


def error_vs_runtime_figure(inputs, outputs, x="wall_time_s"):
    """Every error measure against solver wall-clock time (x='wall_time_s', a timing figure: it changes from run
    to run) or against the work, particles x force evaluations (x='particle_steps': the same from run to run),
    log-log: one marker per run; colour = update rule, marker shape = lattice, filled = converged to f_tol,
    open = not; a black ring marks the paper's configuration of each lattice."""
    tab = pd.read_csv(inputs[0])
    tab["particle_steps"] = tab["particles"] * tab["steps"]
    if "residual" not in tab and "residual_N" in tab:
        tab["residual"] = tab["residual_N"]
    fig, axes = plt.subplots(2, 3, figsize=(15, 9))
    axes = axes.ravel()
    variants = [v for v in VARIANTS if v in set(tab["variant"])]
    for ax, (col, ylabel, title) in zip(axes, PANELS):
        for var in variants:
            for lat, marker in LATTICE_MARKER.items():
                g = tab[(tab["variant"] == var) & (tab["lattice"] == lat)].sort_values("du_factor")
                g = g[np.isfinite(g[col])]
                if g.empty:
                    continue
                y = np.maximum(g[col].abs(), FLOOR)
                conv = (g["status"] == "converged").values
                c = variant_style("isa", var)[0]
                ax.scatter(g[x][conv], y[conv], marker=marker, color=c, s=36, zorder=3)
                ax.scatter(g[x][~conv], y[~conv], marker=marker, facecolors="none", edgecolors=c, s=36, zorder=3)
        paper = tab[tab["paper_config"].astype(bool) & np.isfinite(tab[col])]
        ax.scatter(paper[x], np.maximum(paper[col].abs(), FLOOR), s=230, facecolors="none",
                   edgecolors="k", lw=1.1, zorder=4)
        if col == "residual":
            for ft in sorted(set(tab["f_tol_N"])):
                ax.axhline(ft, color="gray", ls=":", lw=0.8)
            ax.text(0.02, 0.02, "dotted: f_tol of each lattice", transform=ax.transAxes, fontsize=7, color="gray")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(X_AXES[x][0])
        ax.set_ylabel(ylabel)
        ax.set_title(title)
        ax.grid(True, which="major", alpha=0.3)
    _error_legend(axes[-1], tab, variants)
    fig.subplots_adjust(hspace=0.3)
    fig.suptitle(f"{X_AXES[x][1]}, single 100 cm vessel: paper's update and two variants (not in the paper)")
    save(fig, outputs)


def _error_legend(leg, tab, variants):
    """The key of error_vs_runtime: colour patches (update rule), grey filled shapes (lattice),
    fill (outcome) shown on a shape no lattice uses, and the ring (the paper's configuration)."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    leg.axis("off")
    h = [Patch(color=variant_style("isa", v)[0], label=variant_style("isa", v)[1]) for v in variants]
    for lat, marker in LATTICE_MARKER.items():
        g = tab[tab["lattice"] == lat]
        if len(g):
            h.append(Line2D([], [], ls="none", marker=marker, color="gray",
                            label=f"shape: {lat} lattice, a = {g['a_cm'].iloc[0]:g} cm, {int(g['particles'].iloc[0])} particles"))
    h.append(Patch(facecolor="gray", edgecolor="gray", label="filled: converged (max|F| < f_tol)"))
    h.append(Patch(facecolor="none", edgecolor="gray", label="open: cycle / step limit / escaped"))
    paper = tab[tab["paper_config"].astype(bool)]
    cfg = "; ".join(f"{r['lattice']} du {10 * r['du_cm']:g} mm" for _, r in paper.iterrows())
    h.append(Line2D([], [], ls="none", marker="o", ms=13, mfc="none", mec="k", label=f"ring: the paper's configuration\n({cfg})"))
    leg.legend(handles=h, loc="center", fontsize=8, frameon=False)
    leg.text(0.5, 0.0, "du swept from 0.1x to 100x the paper's rule;\n"
             f"|errors| below {FLOOR:g} are drawn at {FLOOR:g}", transform=leg.transAxes, ha="center", fontsize=7)


def stability_map_figure(inputs, outputs):
    """Outcome over (k_b du / w, du / a) per update rule, and the extreme cases as a table.

    inputs: [stability_map.csv, stability_cases.csv]."""
    smap = pd.read_csv(inputs[0])
    cases = pd.read_csv(inputs[1])
    variants = [v for v in VARIANTS if v in set(smap["variant"])]
    fig = plt.figure(figsize=(5 * len(variants), 10.5))
    gs = fig.add_gridspec(2, len(variants), height_ratios=[1, 1.05])
    for k, var in enumerate(variants):
        ax = fig.add_subplot(gs[0, k])
        g = smap[smap["variant"] == var]
        for status, (color, marker) in OUTCOME_STYLE.items():
            s = g[g["status"] == status]
            if len(s):
                ax.scatter(s["k_du_over_w"], s["du_over_a"], color=color, marker=marker, s=80, label=status,
                           edgecolors="k", linewidths=0.4, zorder=3)
        paper = g[(g["k_factor"] == 1) & (g["du_factor"] == 1)]
        if len(paper):
            ax.scatter(paper["k_du_over_w"], paper["du_over_a"], s=260, facecolors="none", edgecolors="k", lw=1.2,
                       zorder=4)
            ax.annotate("paper's\nsetting", (paper["k_du_over_w"].iloc[0], paper["du_over_a"].iloc[0]),
                        xytext=(-10, 18), textcoords="offset points", fontsize=7, ha="right")
        for kf, kg in g.groupby("k_factor"):
            kg = kg.sort_values("du_factor")
            ax.plot(kg["k_du_over_w"], kg["du_over_a"], color="gray", lw=0.4, zorder=1)
            # the line's k_b under its lowest point, horizontal, inside the axes
            ax.annotate(f"{kg['k_wall'].iloc[0]:.0e}".replace("e+0", "e"), (kg["k_du_over_w"].iloc[0], kg["du_over_a"].iloc[0]),
                        xytext=(0, -11), textcoords="offset points", fontsize=6.5, ha="center", va="top", color="dimgray")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("k_b du / w (-)  [k_b: wall stiffness, N/cm; du: cm; w: N]")
        ax.set_ylabel("du / a (-)  [a: lattice spacing, cm]")
        ax.set_ylim(g["du_over_a"].min() / 8, g["du_over_a"].max() * 8)
        ax.set_title(f"{variant_style('isa', var)[1]}\nstep limit {int(g['max_steps'].max()):,} steps; "
                     "grey lines: constant k_b,\nits value (N/cm) under the line's lowest point")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, loc="upper left")  # the empty corner: constant-k_b lines rise to the right
    # table of extreme cases
    ax = fig.add_subplot(gs[1, :])
    ax.axis("off")
    case_ids = list(dict.fromkeys(cases["case"]))
    cvars = [v for v in VARIANTS if v in set(cases["variant"])]
    cells, colors = [], []
    for c in case_ids:
        g = cases[cases["case"] == c].set_index("variant")
        row, col = [g["note"].iloc[0]], ["white"]
        for v in cvars:
            if v in g.index:
                r = g.loc[v]
                txt = f"{r['status']}" + (" (wall crossing refused)" if "crossed" in r["outcome_detail"] else "")
                txt += " (left box)" if "box" in r["outcome_detail"] else ""
                txt += f", {int(r['steps']):,} steps"
                row.append(txt)
                col.append(_light(OUTCOME_STYLE[r["status"]][0]))
            else:
                row.append("not run")
                col.append("white")
        cells.append(row)
        colors.append(col)
    heads = ["extreme case"] + [textwrap.fill(variant_style("isa", v)[1], 30) for v in cvars]
    table = ax.table(cellText=cells, cellColours=colors, colLabels=heads,
                     loc="upper center", cellLoc="left", colWidths=[0.43] + [0.19] * len(cvars))
    table.auto_set_font_size(False)
    table.set_fontsize(6.5)
    table.scale(1, 1.5)
    lines = max(h.count("\n") + 1 for h in heads)
    for c in range(len(heads)):  # room for the longest wrapped header
        table[0, c].set_height(lines * table[1, 0].get_height())
    ax.set_title("Extreme cases (figures/stability_cases.csv): outcome and steps per update rule", fontsize=9)
    fig.suptitle("Numerical stability of the single vessel: outcome classes of every run (status in its run file)")
    save(fig, outputs)


def _light(color):
    from matplotlib.colors import to_rgb

    r, g, b = to_rgb(color)
    return (0.65 + 0.35 * r, 0.65 + 0.35 * g, 0.65 + 0.35 * b)
