"""Single-vessel figures: paper Figs. 5-8, calibration and convergence."""

import numpy as np

from ....figures.style import case_name  # noqa: F401
from .. import metrics, theory
from ....runfile import read
from ....theory import free_surface_level
from ....figures.style import (CALIBRATED, COMPUTED, LABEL_BOX, OURS_LEVEL, PAPER_LEVEL, THEORY, draw_walls,
                    legend_below, literal_levels, nice_value, plt, run_caption, save, scale_bar, state_phrase)


def _law_axes(ax, l_u, r_u, sym, title, note=""):
    l = np.linspace(0, 1.6 * l_u, 200)
    ax.plot(l, np.where(l < l_u, r_u * (1 - l / l_u), 0.0) / 1000, color="k")
    ax.set_xlabel(f"$l_{sym}$ (cm)")
    ax.set_ylabel(f"$R_{sym}$ (kN)")
    ax.set_title(title)
    # labels beside the line, never across it
    ax.annotate(f"$R_{{{sym}u}}$ = {r_u / 1000:.3g} kN", (0, r_u / 1000), xytext=(0.3 * l_u, 0.92 * r_u / 1000),
                va="center", arrowprops=dict(arrowstyle="->", lw=0.6))
    ax.annotate(f"$l_{{{sym}u}}$ = {l_u:.3g} cm", (l_u, 0), xytext=(1.08 * l_u, 0.2 * r_u / 1000),
                ha="left", arrowprops=dict(arrowstyle="->", lw=0.6))
    ax.text(0.97, 0.75, f"stiffness $R_{{{sym}u}}/l_{{{sym}u}}$\n= {r_u / l_u:.4g} N/cm{note}", transform=ax.transAxes,
            ha="right", va="top", fontsize=8)
    ax.set_xlim(0, 1.6 * l_u)
    ax.set_ylim(0, 1.08 * r_u / 1000)


def inferred_note(fig, note, width=150):
    """The figure's inferred inputs (config/methods/isa_workflow.yaml 'inferred'), a red header line above the
    title marked 'inferred' (the saved figure's tight box takes it in)."""
    if note:
        import textwrap

        text = "\n".join(textwrap.wrap(f"inferred: {note}", width))
        fig.text(0.5, 1.0, text, fontsize=8, color="tab:red", style="italic", ha="center", va="bottom")


def inputs_figure(inputs, outputs, inferred=None):
    """Paper Figs. 5 / 7: initial lattice, rhombic element, both force laws; inferred: the footer naming the
    inferred inputs drawn (config/methods/isa_workflow.yaml)."""
    ds = read(inputs[0])
    a = float(ds.attrs["spacing"])
    pos = ds["pos0"].values
    fig, ax = plt.subplots(2, 2, figsize=(9, 8.5))
    ax0 = ax[0, 0]
    draw_walls(ax0, ds)
    ax0.plot(pos[:, 0], pos[:, 1], "o", ms=3 if len(pos) < 300 else 1.5, color=COMPUTED)
    ax0.set_aspect("equal")
    ax0.set_xlabel("x (cm)")
    ax0.set_ylabel("y (cm)")
    ax0.set_title(f"(a) vessel and initial positions: {len(pos)} particles, w = {ds['weight'].values[0]:g} N")
    # (b) enlarged rhombic element next to the floor
    axb = ax[0, 1]
    c = np.array([0.0, 0.5 * a])
    rh = np.array([c + [0, -a / 2], c + [a / 2, 0], c + [0, a / 2], c + [-a / 2, 0], c + [0, -a / 2]])
    axb.plot(rh[:, 0], rh[:, 1], "-o", color=COMPUTED)
    axb.plot([c[0] - a / 2, c[0] + a / 2], [c[1]] * 2, "--", color="gray")
    axb.plot([c[0]] * 2, [c[1] - a / 2, c[1] + a / 2], "--", color="gray")
    wl = float(ds.attrs["forces.wall.l_u"])
    floor_y = c[1] - a / 2 - float(pos[:, 1].min() - ds["wall_segment"].values[:, [1, 3]].min())
    axb.axhline(floor_y, color="k", lw=2.5)
    axb.annotate("", (c[0] + 0.15 * a, floor_y), (c[0] + 0.15 * a, c[1] - a / 2), arrowprops=dict(arrowstyle="<->"))
    axb.text(c[0] + 0.18 * a, 0.5 * (floor_y + c[1] - a / 2), f"{c[1] - a / 2 - floor_y:.3g} cm to wall\n"
             f"($l_{{bu}}$ = {wl:.3g} cm)", va="center")
    # the horizontal diagonal's label left of the vertical one; the side's label outside the rhomb
    axb.text(c[0] - 0.56 * a, c[1], f"diagonal\na = {a:g} cm", ha="right", va="center")
    axb.text(c[0] + 0.32 * a, c[1] + 0.32 * a, f"a/√2 = {a / np.sqrt(2):.3g} cm", rotation=-45,
             rotation_mode="anchor", ha="center", va="bottom")
    axb.set_aspect("equal")
    axb.set_xlim(c[0] - 1.15 * a, c[0] + 1.15 * a)
    axb.set_ylim(floor_y - 0.12 * a, c[1] + 0.8 * a)
    axb.set_xlabel("x (cm)")
    axb.set_ylabel("y (cm)")
    axb.set_title("(b) rhombic element and distance from the boundary")
    _law_axes(ax[1, 0], wl, float(ds.attrs["forces.wall.r_u"]), "b", "(c) boundary-particle function $R_b - l_b$")
    _law_axes(ax[1, 1], float(ds.attrs["forces.pair.l_u"]), float(ds.attrs["forces.pair.r_u"]), "p",
              "(d) inter-particle function $R_p - l_p$",
              note=f"\ncalibrated to the paper's levels\n(config/inferred.yaml); the literal\n"
                   f"k_p = k_b/2 would be {float(ds.attrs['forces.wall.r_u']) / wl / 2:.4g} N/cm")
    fig.subplots_adjust(hspace=0.3)
    fig.suptitle(f"Inputs of scene {case_name(ds)}: du = {ds.attrs['solver.du'] * 10:g} mm, f_tol = {ds.attrs['solver.f_tol']:g} N "
                 f"(solver: {ds.attrs['variant_label']})")
    inferred_note(fig, inferred)
    save(fig, outputs)


def _contact_bars(ax, ds, th, scale):
    """Computed (blue) and theoretical (orange) contact loads as bars outside the walls."""
    walls = ds["wall_segment"].values
    cw = ds["contact_wall"].values
    cp = ds["contact_point"].values
    mag = np.hypot(*ds["contact_force"].values.T)
    for k in range(len(cw)):
        x0, y0, x1, y1 = walls[cw[k]]
        e = np.array([x1 - x0, y1 - y0]) / np.hypot(x1 - x0, y1 - y0)
        out = np.array([e[1], -e[0]])  # right normal: away from the liquid
        for val, color, off in ((mag[k], COMPUTED, -0.6), (th[k], THEORY, 0.6)):
            if not np.isfinite(val):
                continue
            base = cp[k] + off * e
            tip = base + out * val * scale
            ax.plot([base[0], tip[0]], [base[1], tip[1]], color=color, lw=2.2, solid_capstyle="butt")


def _level_lines(ax, x_span, level, paper_level, literal, initial=None):
    """Our level (solid blue), the initial (uncompacted) lattice's level (thin grey) and the paper's (dashed red)
    across x_span, named in the legend only."""
    if initial is not None:
        ax.plot(x_span, [initial] * 2, color="0.45", ls=(0, (2, 2)), lw=1.1, zorder=3,
                label=f"initial (uncompacted) lattice, same reading: {initial:.1f} cm ({1 - level / initial:.0%} "
                      f"of the depth lost)")
    ours = f"our surface {level:.1f} cm (top centres + half the layer pitch)"
    if paper_level is not None:
        ours += f":\n{CALIBRATED}"
        if literal is not None:
            ours += f";\nthe literal reading k_p = k_b/2 gives {literal:.1f} cm (results/calibration.csv)"
    # the paper's line under ours: both stay visible where they (almost) coincide
    ax.plot(x_span, [level] * 2, label=ours, zorder=5, **OURS_LEVEL)
    if paper_level is not None:
        ax.plot(x_span, [paper_level] * 2, label=f"paper's level {paper_level:g} cm", zorder=4,
                **{**PAPER_LEVEL, "lw": 3.0, "alpha": 0.7})


def single_vessel_figure(inputs, outputs, paper_level=None, calibration=None, inferred=None):
    """Paper Figs. 6 / 8: final state, level (and the uncompacted initial lattice's), wall reactions vs
    hydrostatic theory.

    calibration: results/calibration.csv, for the level of the literal reading k_p = k_b / 2; inferred: the
    footer naming the inferred inputs the figure rests on."""
    ds = read(inputs[0])
    e, (_, _, _, th) = metrics.contact_loads(ds, None, "own")
    pos = ds["pos"].values
    walls = ds["wall_segment"].values
    literal = literal_levels(calibration).get(case_name(ds)) if calibration else None
    fig, (ax, axp) = plt.subplots(1, 2, figsize=(12.5, 6.2), gridspec_kw={"width_ratios": [1.1, 1]})
    draw_walls(ax, ds)
    ax.plot(pos[:, 0], pos[:, 1], "o", ms=3 if len(pos) < 300 else 1.6, color="k")
    x0, x1 = walls[:, [0, 2]].min(), walls[:, [0, 2]].max()
    initial = initial_level(ds)
    _level_lines(ax, (x0 - 28, x1 + 28), e["level"], paper_level, literal, initial)
    fmax = np.nanmax(np.concatenate([np.hypot(*ds["contact_force"].values.T), th]))
    scale = 25.0 / fmax
    _contact_bars(ax, ds, th, scale)
    ax.plot([], [], color=COMPUTED, lw=2.2, label="computed reaction $R_b$ of each contact")
    ax.plot([], [], color=THEORY, lw=2.2, label="hydrostatic theory (tributary length)")
    # force scale in the empty lower-left corner, clear of every bar
    bar = nice_value(0.8 * fmax)
    scale_bar(ax, (x0 - 30, -18), bar * scale, f"{bar:g} N")
    legend_below(ax, ncol=1)
    ax.set_aspect("equal")
    ax.set_xlim(x0 - 33, x1 + 30)
    ax.set_ylim(-30, 110)
    ax.set_xlabel("x (cm)")
    ax.set_ylabel("y (cm)")
    names = list(ds["wall"].values)
    totals = ", ".join(f"{n} {e['load_' + n]:.0f} N (theory {e['theory_' + n]:.0f})" for n in names)
    ax.set_title(f"(a) {state_phrase(ds)}, and wall reactions\n{totals}")
    _pressure_panel(axp, ds, e, names, x0, x1)
    fig.suptitle(run_caption(ds), fontsize=8)
    inferred_note(fig, inferred)
    save(fig, outputs)


def initial_level(ds):
    """Surface [cm] of the run's initial lattice (pos0) read as the final one (top particle centres over strips of
    width a, plus half the layer pitch: the one surface): the uncompacted liquid's."""
    return float(free_surface_level(ds["pos0"].values, float(ds.attrs["spacing"]), metrics.vessel_view(ds)["x_range"])
                 + metrics.layer_pitch(ds) / 2)


def _pressure_panel(axp, ds, e, names, x0, x1):
    """(b) hydrostatic pressure on the walls, drawn to a stated scale; the text below the axes."""
    h, gamma = e["level"], e["gamma"]
    draw_walls(axp, ds)
    pbot = gamma * h  # N/cm per cm of wall = N/cm^2 x cm
    s = 30.0 / pbot  # drawing cm per N/cm
    y = np.linspace(0, h, 50)
    axp.fill_betweenx(y, x0, x0 - gamma * (h - y) * s, color=THEORY, alpha=0.5, lw=0)
    axp.fill_betweenx(y, x1, x1 + gamma * (h - y) * s, color=THEORY, alpha=0.5, lw=0)
    axp.fill_between([x0, x1], 0, -pbot * s, color=THEORY, alpha=0.5, lw=0)
    axp.plot([x0 - 30, x1 + 30], [h, h], **OURS_LEVEL)
    axp.text(x0 + 3, h + 2, f"h = {h:.1f} cm", color=COMPUTED, va="bottom")
    # the scale: a dimension line on the floor diagram, the pressure at the bottom
    xd = 0.5 * (x0 + x1)
    axp.annotate("", (xd, 0), (xd, -pbot * s), arrowprops=dict(arrowstyle="<->", lw=0.8))
    axp.text(xd + 2, -pbot * s / 2, f"γh = {pbot:.1f} N/cm", va="center", ha="left", bbox=LABEL_BOX)
    bar = nice_value(0.6 * pbot)
    scale_bar(axp, (x0 - 38, -40), bar * s, f"pressure scale: {bar:g} N/cm", label_right=True)
    axp.set_aspect("equal")
    axp.set_xlim(x0 - 40, x1 + 40)
    axp.set_ylim(-48, 110)
    axp.set_xlabel("x (cm)")
    axp.set_ylabel("y (cm)")
    axp.set_title("(b) theoretical hydrostatic pressure on the boundaries\n(2D, per unit depth; p = γ (h - y))")
    axp.text(0.5, -0.15, f"γ = W/(B h) = {gamma:.3f} N/cm² (W: weight held, B: width, h: our surface)\n"
             f"floor: γhB = W = {e['theory_floor']:.0f} N\n"
             f"each side: γh²/2 = {e['theory_' + names[0]]:.0f} N, acting at h/3 = {h / 3:.1f} cm",
             transform=axp.transAxes, ha="center", va="top", fontsize=8)


def calibration_figure(inputs, outputs, paper_levels=None, adopted=None):
    """Free surface (the one surface: top centres + half the layer pitch) against wall stiffness and stiffness ratio,
    per resolution; the adopted k_p was calibrated on the top centres alone, whose reading is marked for it.

    adopted: {k_wall, ratio} of the scenes' reading, starred in the panels of the scenes
    that use it (those with a paper level); the literal reading k_p = k_b / 2 is ringed."""
    import tempfile

    from ..tables import calibration_table

    with tempfile.TemporaryDirectory() as tmp:
        tab = calibration_table(inputs, [f"{tmp}/calibration.csv"])
    scenes = list(dict.fromkeys(tab["run"]))
    fig, axes = plt.subplots(1, len(scenes), figsize=(5.2 * len(scenes), 4.4), sharey=True, squeeze=False)
    handles, literal = {}, {}
    for ax, sc in zip(axes[0], scenes):
        t = tab[tab["run"] == sc]
        for ratio, g in t.groupby("ratio"):
            g = g.sort_values("k_wall")
            line, = ax.plot(g["k_wall"], g["level"], "-", label=f"$k_p/k_b$ = {ratio:g}")
            handles.setdefault(line.get_label(), line)
            ok = g["status"] == "converged"
            ax.plot(g["k_wall"][ok], g["level"][ok], "o", color=line.get_color())
            ax.plot(g["k_wall"][~ok], g["level"][~ok], "o", mfc="none", color=line.get_color())
        base = sc.removesuffix("_lbu25")
        if paper_levels and base in paper_levels:
            h = ax.axhline(paper_levels[base], label="paper's level ("
                           + ", ".join(f"{v:g} cm {k}" for k, v in paper_levels.items()) + ")", **PAPER_LEVEL)
            handles.setdefault("paper", h)
        if adopted and paper_levels and sc in paper_levels:  # only the scenes that use the reading
            pick = t[np.isclose(t["k_wall"], adopted["k_wall"]) & np.isclose(t["ratio"], adopted["ratio"])]
            h, = ax.plot(pick["k_wall"], pick["level"], "*", ms=16, mfc="none", mec="k", ls="none",
                         label=f"adopted: k_b = {adopted['k_wall']:g} N/cm, k_p/k_b = {adopted['ratio']:g} "
                               f"(k_p calibrated to match the paper's level with the top particle centres)")
            handles.setdefault("adopted", h)
            h, = ax.plot(pick["k_wall"], pick["level_top"], "x", ms=9, color="k", ls="none",
                         label="the adopted pair's top particle centres (the calibration's reading)")
            handles.setdefault("adopted_top", h)
            lit = t[np.isclose(t["k_wall"], adopted["k_wall"]) & np.isclose(t["ratio"], 0.5)]
            h, = ax.plot(lit["k_wall"], lit["level"], "o", ms=14, mfc="none", mec="k", ls="none")
            literal[sc] = float(lit["level"].iloc[0]) if len(lit) else np.nan
            handles["literal"] = h
        ax.set_xscale("log")
        ks = sorted(t["k_wall"].unique())
        ax.set_xticks(ks, [f"{k:g}" for k in ks])
        ax.minorticks_off()
        ax.set_xlabel("wall stiffness $k_b = R_{bu}/l_{bu}$ (N/cm)")
        what = "" if sc in (paper_levels or {}) else ": alternative $l_{bu}$, not adopted"
        ax.set_title(f"{sc} ({t['variant'].iloc[0]}){what}")
    axes[0, 0].set_ylabel("free surface: top centres + half the layer pitch (cm)")
    if "literal" in handles:
        handles["literal"].set_label("literal reading k_p = k_b/2 (page text: \"half\"): "
                                     + ", ".join(f"{v:.1f} cm {k}" for k, v in literal.items()))
    fig.legend(list(handles.values()), [h.get_label() for h in handles.values()], loc="upper center",
               bbox_to_anchor=(0.5, 0.0), ncol=3, fontsize=8, frameon=False)
    fig.suptitle("Free surface vs force-law stiffness (filled: converged to f_tol, open: not converged)")
    save(fig, outputs)


def convergence_figure(inputs, outputs):
    """max|F| against the step: the paper's update and the capped variant (the project's kept inputs, k_p = 500 N/cm,
    with its cycle stop); the paper's version (k_p = k_b / 2 and the paper's own stop rule, no cycle stop: the run
    the claims are judged on) is drawn as its last max|F| band at the right edge, with the step it reached."""
    runs = [read(p) for p in inputs]
    lattice = lambda ds: (ds.attrs["tank"], len(ds["pos"]))  # noqa: E731  (the paper's version: its own resolution)
    scenes = list(dict.fromkeys(lattice(ds) for ds in runs))
    fig, axes = plt.subplots(1, len(scenes), figsize=(6 * len(scenes), 4.2), squeeze=False)
    for ax, sc in zip(axes[0], scenes):
        here = [d for d in runs if lattice(d) == sc]
        xmax = max(int(d["steps"]) for d in here if int(d.attrs.get("solver.stop_on_cycle", 1)))
        for ds in (d for d in here if not int(d.attrs.get("solver.stop_on_cycle", 1))):
            lo, hi = float(ds["hist_fmax_lo"].values[-10:].min()), float(ds["hist_fmax_hi"].values[-10:].max())
            ax.errorbar([xmax * 1.03], [np.sqrt(lo * hi)], yerr=[[np.sqrt(lo * hi) - lo], [hi - np.sqrt(lo * hi)]],
                        color="tab:purple", capsize=4, lw=2,
                        label=f"the paper's version (k_p = k_b / 2, its own stop rule; claims judged on it):\n"
                              f"-> {ds.attrs['status']} "
                              f"at step {int(ds['steps']):,}, last band {lo:.3g}-{hi:.3g} N (right edge)")
        for ds in (d for d in here if int(d.attrs.get("solver.stop_on_cycle", 1))):
            a = ds.attrs
            st = ds["hist_step"].values
            line, = ax.plot(st, ds["hist_fmax"].values, lw=0.8, label=f"{a['variant_label']}\n-> {a['status']} at step {int(ds['steps']):,}"
                            + (" (detected: max|F| repeats, not a convergence step)" if a["status"] == "cycle" else ""))
            ax.fill_between(st, ds["hist_fmax_lo"].values, ds["hist_fmax_hi"].values, color=line.get_color(), alpha=0.25, lw=0)
            if a["variant"] == "paper":
                lam, floor = theory.step_floor(ds["pos"].values, ds["wall_segment"].values, a["forces.wall.l_u"],
                                               a["forces.wall.r_u"], a["forces.pair.l_u"], a["forces.pair.r_u"], a["solver.du"])
                ax.axhline(floor, color=line.get_color(), ls="--", lw=1,
                           label=f"stability floor λ_max du/2 = {floor:.3g} N (λ_max = {lam:.0f} N/cm)")
        ax.axhline(float(runs[0].attrs["solver.f_tol"]), color="k", ls=":", label="f_tol = 0.1 N")
        ax.set_yscale("log")
        ax.set_xlabel("algorithm step")
        ax.set_ylabel("max|F| (N)")
        ax.set_title(case_name(here[0]))
        legend_below(ax, ncol=1, handlelength=2.5)
    fig.suptitle("Convergence of the single-vessel runs (band: min-max of max|F| over each record stride)")
    save(fig, outputs)
