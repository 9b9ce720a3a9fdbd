"""Flow figures: paper Figs. 9-10 and the flow history (from run files only)."""

import numpy as np
from matplotlib.ticker import FuncFormatter

from .. import metrics
from ....runfile import read
from ....theory import surface_profile
from .single import _contact_bars, inferred_note
from ....figures.style import (COMPUTED, LABEL_BOX, PAPER_EXPECTED, PAPER_LEVEL, THEORY, draw_walls, legend_below, nice_value,
                    plt, run_caption, save, scale_bar, state_phrase, surface_line)

RESULTANT = "tab:brown"
VESSEL_COLOURS = ("tab:green", "k")


def _state_axes(ax, ds):
    """Walls, particles coloured by vessel, and their counts."""
    draw_walls(ax, ds)
    pos = ds["pos"].values
    fm = metrics.flow_measures(ds)
    names = [str(n) for n in ds["vessel"].values]
    for name, color in zip(names, VESSEL_COLOURS):
        x0, x1 = ds["vessel_x"].sel(vessel=name).values
        sel = (pos[:, 0] >= x0) & (pos[:, 0] < x1)
        ax.plot(pos[sel, 0], pos[sel, 1], "o", ms=3, color=color,
                label=f"{fm['particles_' + name]} particles in the {name} vessel")
    ax.set_aspect("equal")
    ax.set_xlabel("x (cm)")
    ax.set_ylabel("y (cm)")
    return fm


def _reaction_arrows(ax, ds, bar_room):
    """Each wall's resultant reaction on the liquid as an arrow from the wall's middle into the
    liquid, its value written outside the wall beyond the contact bars (bar_room cm); returns the
    arrow scale (cm per N)."""
    walls = ds["wall_segment"].values
    res = ds["wall_resultant"].values
    scale = 30.0 / max(np.hypot(*res.T).max(), 1.0)
    for name, w, r in zip(ds["wall"].values, walls, res):
        if np.hypot(*r) < 1.0:
            continue
        mid = 0.5 * (w[:2] + w[2:])
        e = (w[2:] - w[:2]) / np.hypot(*(w[2:] - w[:2]))
        out = np.array([e[1], -e[0]])  # away from the liquid
        ax.annotate("", mid + r * scale, mid, arrowprops=dict(arrowstyle="-|>", color=RESULTANT, lw=1.8), zorder=6)
        at = mid + out * (bar_room + 3)
        ha = "right" if out[0] < -0.5 else "left" if out[0] > 0.5 else "center"
        va = "top" if out[1] < -0.5 else "bottom" if out[1] > 0.5 else "center"
        ax.text(*at, f"{name}:\n({int(round(r[0]))}, {int(round(r[1]))}) N", fontsize=7, color=RESULTANT, ha=ha, va=va,
                bbox=LABEL_BOX)
    return scale


def _scales(ax, xy, arrow_scale, bar_scale, bar_max):
    """Scale of the resultant arrows and of the contact bars, stacked from xy down."""
    x, y = xy
    f = nice_value(15.0 / arrow_scale)
    ax.annotate("", (x + f * arrow_scale, y), (x, y), arrowprops=dict(arrowstyle="-|>", color=RESULTANT, lw=1.8))
    ax.text(x + f * arrow_scale + 2, y, f"{f:g} N (resultant)", va="center", fontsize=8, color=RESULTANT)
    b = nice_value(bar_max)
    scale_bar(ax, (x, y - 10), b * bar_scale, f"{b:g} N (contact $R_b$)", color=COMPUTED, label_right=True)


def _surfaces(ax, ds):
    """Measured free surface of every vessel (top particle per strip), coloured as its particles."""
    for name, color in zip([str(n) for n in ds["vessel"].values], VESSEL_COLOURS):
        surface_line(ax, ds, name, color)


def flow_incomplete_figure(inputs, outputs, paper=None, inferred=None):
    """Paper Fig. 9: state at step 100,000 with boundary reactions and sum F_x; inferred: the footer naming the
    inferred inputs (the second vessel's floor drop)."""
    ds = read(inputs[0])
    fig, ax = plt.subplots(figsize=(12, 6.2))
    fm = _state_axes(ax, ds)
    _surfaces(ax, ds)
    mag = np.hypot(*ds["contact_force"].values.T)
    bar_scale = 12.0 / max(mag.max(), 1.0)
    _contact_bars(ax, ds, np.full(len(mag), np.nan), bar_scale)
    arrow_scale = _reaction_arrows(ax, ds, 12.0)
    _scales(ax, (5, -35), arrow_scale, bar_scale, mag.max())
    sfx = fm["sum_fx_N"]
    ax.set_title(f"(Fig. 9) {state_phrase(ds)}: sum of horizontal wall reactions ΣF_x = {sfx:+.0f} N "
                 f"(paper: ΣF_x >> 0, to the right)\nmax|F| = {float(ds['residual']):.3g} N; "
                 f"{fm['particles_second']} of {ds.sizes['particle']} particles transferred")
    ax.plot([], [], color=COMPUTED, lw=2.2, label="contact reactions $R_b$ (bars outside the walls)")
    ax.plot([], [], color=RESULTANT, lw=1.8, marker=">", label="resultant reaction of each wall on the liquid (arrows)")
    legend_below(ax, ncol=1)
    ax.set_xlim(-45, 355)
    ax.set_ylim(-78, 108)
    fig.suptitle(run_caption(ds), fontsize=8)
    inferred_note(fig, inferred)
    save(fig, outputs)


def column_weights(ds, vessel):
    """(C,) load [N] on each floor contact of a vessel from the weight of the liquid column above it, under the
    vessel's own measured surface (top particle per strip of width a), scaled so the floor carries the vessel's
    weight; NaN on every other contact.  What a heap at rest puts on its floor if no arch carries part of it
    (no hydrostatic theory applies to a surface that is not level)."""
    v = metrics.vessel_view(ds, vessel)
    a = float(ds.attrs["spacing"])
    x, top = surface_profile(ds["pos"].values, a, v["x_range"])
    walls = ds["wall_segment"].values
    cw = np.where(metrics.contact_in_vessel(ds, v["x_range"]), ds["contact_wall"].values, -1)
    cp = ds["contact_point"].values
    out = np.full(len(cw), np.nan)
    floor = [w for w in range(len(walls)) if v["wall_in"][w] and v["horizontal"][w]
             and np.isclose(walls[w, 1], v["floor_y"])]
    if not floor or not len(x):
        return out
    idx = np.flatnonzero(cw == floor[0])
    if not len(idx):
        return out
    xs = cp[idx, 0]
    order = np.argsort(xs)
    lo, hi = sorted(walls[floor[0], [0, 2]])
    b = np.concatenate([[lo], 0.5 * (xs[order][1:] + xs[order][:-1]), [hi]])
    height = np.interp(xs[order], x, top) - v["floor_y"]
    col = np.clip(height, 0, None) * np.diff(b)
    weight = float(ds["weight"].values[v["inside"]].sum())
    out[idx[order]] = weight * col / col.sum()
    return out


def flow_complete_figure(inputs, outputs, paper=None, inferred=None):
    """Paper Fig. 10: final state, particles left, the measured surface in both vessels, the paper's measured
    and expected levels, and the loads of the second vessel against what this liquid is: a heap whose floor
    carries the weight of the column above each contact (column_weights).  The paper's hydrostatic comparison
    (a level liquid of the mean depth) is not drawn: a surface that falls by tens of cm is no liquid at rest,
    and the side walls of a heap carry what its friction sets, which no hydrostatic line gives.
    inferred: the footer naming the inferred inputs (the second vessel's floor drop)."""
    ds = read(inputs[0])
    paper = paper or {}
    fig, ax = plt.subplots(figsize=(12, 6.9))
    fm = _state_axes(ax, ds)
    second = str(ds["vessel"].values[-1])
    e, (_, _, mag, _) = metrics.contact_loads(ds, second, "own")
    th = column_weights(ds, second)
    v = metrics.vessel_view(ds, second)
    bar_scale = 15.0 / np.nanmax(np.concatenate([mag, th]))
    _contact_bars(ax, ds, th, bar_scale)
    _surfaces(ax, ds)
    x0, x1 = v["x_range"]
    fy = v["floor_y"]
    if "level_second" in paper:
        ax.plot([x0, x1], [fy + paper["level_second"]] * 2, label=f"paper: level measured in the second vessel "
                f"{paper['level_second']:.1f} cm above its floor", **PAPER_LEVEL)
    if "level_expected" in paper:
        ax.plot([x0, x1], [fy + paper["level_expected"]] * 2, label=f"paper: level expected from the particles "
                f"transferred, {paper['level_expected']:.1f} cm", **PAPER_EXPECTED)
    ax.plot([], [], color=COMPUTED, lw=2.2, label="computed reaction $R_b$")
    ax.plot([], [], color=THEORY, lw=2.2, label="second vessel's floor: weight of the column above each contact, under "
                                                 "the heap's own surface (no hydrostatic line: the surface is not level)")
    b = nice_value(np.nanmax(mag))
    scale_bar(ax, (5, -35), b * bar_scale, f"{b:g} N (contact $R_b$)", color=COMPUTED, label_right=True)
    legend_below(ax, ncol=1)
    left = fm["particles_left"]
    n = ds.sizes["particle"]
    exp_ours = (n - left) / n * paper.get("level_first", np.nan) / 2
    fin = np.isfinite(th)
    dev = float(np.sqrt(np.mean((mag[fin] - th[fin]) ** 2))) if fin.any() else np.nan
    rel = dev / float(np.mean(th[fin])) if fin.any() else np.nan
    ax.set_title(f"(Fig. 10) {state_phrase(ds)}: {left} particles left in the first vessel "
                 f"(paper {paper.get('particles_left', '?')})\nsecond vessel: mean depth {e['depth']:.1f} cm "
                 f"(paper {paper.get('level_second', np.nan):.1f} cm); from the particles transferred ((N - {left})/N) x "
                 f"{paper.get('level_first', '?')}/2 = {exp_ours:.1f} cm\nsecond vessel, a heap: floor contacts against the "
                 f"column above them, RMS {dev:.0f} N ({rel:.0%} of their mean); no hydrostatic overlay (the surface is "
                 f"not level)")
    ax.set_xlim(-15, 335)
    ax.set_ylim(-62, 108)
    fig.suptitle(run_caption(ds), fontsize=8)
    inferred_note(fig, inferred)
    save(fig, outputs)


def flow_history_figure(inputs, outputs, chains=None):
    """Particles per vessel, sum F_x and max|F| against the step along each chain.

    chains: {label: [run file stems in order]}; inputs are the run files.  Each run of a
    chain is a numbered, alternately shaded stretch of steps, named in the column's key.
    """
    by_stem = {p.rsplit("/", 1)[-1].removesuffix(".nc"): p for p in inputs}
    fig, axes = plt.subplots(3, len(chains), figsize=(6.5 * len(chains), 9.5), sharex="col", squeeze=False)
    for col, (label, stems) in enumerate(chains.items()):
        ax_n, ax_f, ax_m = axes[:, col]
        key = []
        for k, stem in enumerate(stems):
            ds = read(by_stem[stem])
            start, end = int(ds["start_step"]), int(ds["steps"])  # both counted from the chain's start
            key.append(f"{k + 1}: {stem} ({ds.attrs['variant']} update, steps {start:,}-{end:,}, "
                       f"{ds.attrs['status']})")
            for ax in (ax_n, ax_f, ax_m):
                if k % 2 == 0:
                    ax.axvspan(start, end, color="0.93", lw=0, zorder=0)
            ax_n.annotate(f"{k + 1}", (0.5 * (start + end), 1.0), xycoords=("data", "axes fraction"),
                          xytext=(0, 2), textcoords="offset points", ha="center", va="bottom", fontsize=8,
                          fontweight="bold")
            if "hist_step" in ds:
                ax_m.plot(ds["hist_step"], ds["hist_fmax"], lw=0.6, color="k")
                ax_m.fill_between(ds["hist_step"], ds["hist_fmax_lo"], ds["hist_fmax_hi"], color="gray", alpha=0.3, lw=0)
            if "sample_vessel_count" in ds:
                st = ds["sample_step"].values
                for name, color in zip(ds["vessel"].values, VESSEL_COLOURS):
                    ax_n.plot(st, ds["sample_vessel_count"].sel(vessel=name), color=color,
                              label=f"{name} vessel" if stem == stems[1] else None)
                ax_f.plot(st, ds["sample_sum_fx"], color=COMPUTED)
        ax_n.set_ylabel("particles")
        ax_n.legend(fontsize=8, loc="center right")
        ax_n.set_title(f"{label} chain\n\n", fontsize=9)
        ax_f.axhline(0, color="k", lw=0.5)
        ax_f.set_ylabel("ΣF_x of wall reactions (N)")
        ax_m.set_yscale("log")
        ax_m.axhline(0.1, color="k", ls=":", lw=0.8)
        ax_m.set_ylabel("max|F| (N)")
        ax_m.set_xlabel("algorithm step, thousands (k), from the start of application 1 / 2")
        ax_m.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v / 1000:g}k"))
        ax_m.text(0.0, -0.22, "\n".join(key), transform=ax_m.transAxes, va="top", ha="left", fontsize=8)
    fig.suptitle("Flow history (band: min-max of max|F| over each record stride; dotted: f_tol = 0.1 N;\n"
                 "numbers: the runs of each chain, listed under it; shading alternates between runs)")
    save(fig, outputs)


def fig10_sweep_figure(inputs, outputs, sweep=None, registry=None, inferred=None):
    """Figure 10 at every value of one inferred input the claims sweep (e.g. second_floor_drop, k_pair): top row,
    the end of the complete flow at each value (particles by vessel, the one surface); bottom row, what the rows
    read at each value against their tolerances: particles left (pap-6.4-fourteen: the paper's 14, +- half a floor
    row) and the horizontal resultant at 100,000 steps (pap-6.3-sum-fx: >= 10 N f_tol).

    sweep: config/methods/isa_workflow.yaml fig10_sweeps entry {input, what, axis, units, kept, runs: [{value,
    complete, incomplete}]} (run ids; inputs: their run files); registry: the claims registry's files (the paper's
    14, the tolerances of both rows are read from it)."""
    from ....claims_registry import load

    by = {p.rsplit("/", 1)[-1].removesuffix(".nc"): p for p in inputs}
    reg = {c["id"]: c for c in load(str(__import__("pathlib").Path(registry[0]).parent) if registry else
                                     "config/claims")}
    four, sfx = reg["pap-6.4-fourteen"], reg["pap-6.3-sum-fx"]
    claims = {"fourteen": (four["numbers"]["particles_left"]["value"], four["tolerance"]["value"]),
              "sum_fx": sfx["tolerance"]["value"]}
    kept, units, what = sweep["kept"], sweep["units"], sweep["what"]
    rows = []
    for d in sweep["runs"]:
        ds, di = read(by[d["complete"]]), read(by[d["incomplete"]])
        rows.append(dict(value=float(d["value"]), ds=ds, left=metrics.flow_measures(ds)["particles_left"],
                         sum_fx=metrics.flow_measures(di)["sum_fx_N"], steps_i=int(di["steps"])))
    n = len(rows)
    fig = plt.figure(figsize=(max(3.3 * n, 14.0), 7.4))
    grid = dict(height_ratios=[0.8, 1.0], hspace=0.32, top=0.86, bottom=0.08)
    gs = fig.add_gridspec(2, n, wspace=0.08, **grid)  # top row: one panel per value
    gb = fig.add_gridspec(2, 2, wspace=0.16, **grid)  # bottom row: the two rows' readings, half each
    p14, t14 = claims["fourteen"]
    thr = claims["sum_fx"]
    for k, r in enumerate(rows):
        ax = fig.add_subplot(gs[0, k])
        ds = r["ds"]
        draw_walls(ax, ds)
        pos = ds["pos"].values
        for name, color in zip([str(v) for v in ds["vessel"].values], VESSEL_COLOURS):
            x0, x1 = ds["vessel_x"].sel(vessel=name).values
            sel = (pos[:, 0] >= x0) & (pos[:, 0] < x1)
            ax.plot(pos[sel, 0], pos[sel, 1], "o", ms=1.6, color=color)
            v = metrics.vessel_view(ds, name)
            if sel.any():
                ax.plot(v["x_range"], [metrics.surface_of(ds, name)] * 2, "-", color=color, lw=0.8)
        ax.set_aspect("equal")
        ax.set_xlim(-8, 308)
        ax.set_ylim(-108, 104)
        ax.set_xticks([0, 100, 300])
        ax.tick_params(labelsize=7)
        if k:
            ax.set_yticklabels([])
        ok = abs(r["left"] - p14) <= t14
        tag = " (kept)" if r["value"] == kept else ""
        ax.set_title(f"{what} {r['value']:g} {units}{tag}\n{r['left']} left ({'within' if ok else 'outside'} "
                     f"{p14:g} ± {t14:g}); {ds.attrs['status']}", fontsize=8.5,
                     fontweight="bold" if r["value"] == kept else "normal")
    d = np.array([r["value"] for r in rows])
    ax_l = fig.add_subplot(gb[1, 0])
    ax_f = fig.add_subplot(gb[1, 1])
    left = np.array([r["left"] for r in rows])
    ax_l.axhspan(p14 - t14, p14 + t14, color="tab:red", alpha=0.12, lw=0,
                 label=f"the paper's {p14:g} ± {t14:g} (half a floor row): pap-6.4-fourteen passes")
    ax_l.axhline(p14, color="tab:red", lw=1, ls="--")
    ax_l.plot(d, left, "o-", color="k", label="particles left in the first vessel at the end of application 4")
    fx = np.array([r["sum_fx"] for r in rows])
    ax_f.axhspan(thr, max(fx.max(), thr) * 1.35, color="tab:red", alpha=0.12, lw=0,
                 label=f"ΣF_x >= {thr:g} N (10 N f_tol, '>> 0'): pap-6.3-sum-fx passes")
    ax_f.axhline(thr / 10, color="0.4", lw=1, ls=":", label=f"equilibrium bound N f_tol = {thr / 10:g} N")
    ax_f.plot(d, fx, "o-", color=RESULTANT, label="ΣF_x at the end of application 3 (step 100,000 or an earlier cycle)")
    for r, y in zip(rows, fx):
        ax_f.annotate(f"{y:+.0f} N\n(step {r['steps_i']:,})", (r["value"], y), xytext=(0, 8), textcoords="offset points",
                      ha="center", fontsize=7)
    for ax, quantity in ((ax_l, "particles"), (ax_f, "ΣF_x (N)")):
        ax.axvline(kept, color="0.5", lw=1, ls="--")
        ax.text(kept, 1.01, f"kept {kept:g} {units}", transform=ax.get_xaxis_transform(), ha="center", va="bottom",
                fontsize=8, color="0.3")
        ax.set_xlabel(f"{sweep['axis']} ({units}), inferred: {sweep['input']}")
        ax.set_ylabel(quantity)
        if d.max() / d.min() > 4:  # a range of factors (k_p): log axis
            ax.set_xscale("log")
            ax.minorticks_off()
        ax.set_xticks(d, [f"{v:g}" for v in d])
        ax.legend(loc="upper right" if ax is ax_l else "upper left", fontsize=7.5, frameon=True, framealpha=0.9)
    for r, y in zip(rows, left):
        ax_l.annotate(f"{y}", (r["value"], y), xytext=(6, 4), textcoords="offset points", fontsize=8)
    ax_l.set_ylim(0, max(left.max(), p14 + t14) * 1.35)
    ax_f.set_ylim(min(0.0, fx.min() * 1.3), max(fx.max(), thr) * 1.35)
    fig.suptitle(f"Figure 10 at every {what} the claims sweep ({sweep['input']}): the end of the complete flow (paper's "
                 "update) and two rows that read it: particles left and the horizontal resultant", fontsize=10)
    inferred_note(fig, inferred)
    save(fig, outputs)
