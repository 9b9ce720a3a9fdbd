"""Flow figures: paper Figs. 9-10 and the flow history (from run files only)."""

import numpy as np

from .. import metrics
from ..runfile import read
from .single import _contact_bars
from .style import COMPUTED, PAPER, THEORY, draw_walls, plt, run_caption, save


def _state_axes(ax, ds):
    """Walls, particles coloured by vessel, and their counts."""
    draw_walls(ax, ds)
    pos = ds["pos"].values
    fm = metrics.flow_measures(ds)
    names = [str(n) for n in ds["vessel"].values]
    for name, color in zip(names, ("tab:green", "k")):
        x0, x1 = ds["vessel_x"].sel(vessel=name).values
        sel = (pos[:, 0] >= x0) & (pos[:, 0] < x1)
        ax.plot(pos[sel, 0], pos[sel, 1], "o", ms=3, color=color,
                label=f"{fm['particles_' + name]} particles in the {name} vessel")
    ax.set_aspect("equal")
    ax.set_xlabel("x (cm)")
    ax.set_ylabel("y (cm)")
    return fm


def _reaction_arrows(ax, ds, scale):
    """Each wall's resultant reaction on the liquid as an arrow from the wall's middle."""
    walls = ds["wall_segment"].values
    for name, w, r in zip(ds["wall"].values, walls, ds["wall_resultant"].values):
        if np.hypot(*r) < 1.0:
            continue
        mid = 0.5 * (w[:2] + w[2:])
        ax.annotate("", mid + r * scale, mid, arrowprops=dict(arrowstyle="->", color=COMPUTED, lw=1.5))
        ax.text(*(mid + r * scale), f"{name}: ({r[0]:.0f}, {r[1]:.0f}) N", fontsize=7, color=COMPUTED)


def flow_incomplete_figure(inputs, outputs, paper=None):
    """Paper Fig. 9: state at step 100,000 with boundary reactions and sum F_x."""
    ds = read(inputs[0])
    fig, ax = plt.subplots(figsize=(12, 5.5))
    fm = _state_axes(ax, ds)
    _reaction_arrows(ax, ds, 0.004)
    mag = np.hypot(*ds["contact_force"].values.T)
    _contact_bars(ax, ds, np.full(len(mag), np.nan), 12.0 / max(mag.max(), 1.0))
    sfx = fm["sum_fx_N"]
    ax.set_title(f"(Fig. 9) step {int(ds['steps']):,}: sum of horizontal wall reactions ΣF_x = {sfx:+.0f} N "
                 f"(paper: ΣF_x >> 0, to the right); max|F| = {float(ds['residual']):.3g} N; "
                 f"{fm['particles_second']} of {ds.sizes['particle']} particles transferred")
    ax.plot([], [], color=COMPUTED, lw=2.2, label="contact reactions $R_b$ (bars) and wall resultants (arrows)")
    ax.legend(loc="upper right", fontsize=8)
    ax.set_ylim(-75, 115)
    fig.suptitle(run_caption(ds), fontsize=8)
    save(fig, outputs)


def flow_complete_figure(inputs, outputs, paper=None):
    """Paper Fig. 10: final state, particles left, level in the second vessel,
    and the hydrostatic overlay on the second vessel's walls."""
    ds = read(inputs[0])
    paper = paper or {}
    fig, ax = plt.subplots(figsize=(12, 6))
    fm = _state_axes(ax, ds)
    second = str(ds["vessel"].values[-1])
    e, (_, _, mag, th) = metrics.contact_loads(ds, second)
    v = metrics.vessel_view(ds, second)
    _contact_bars(ax, ds, th, 15.0 / np.nanmax(np.concatenate([mag, th])))
    x0, x1 = v["x_range"]
    fy = v["floor_y"]
    ax.plot([x0, x1], [e["level"]] * 2, "--", color=COMPUTED, lw=1)
    ax.text(x1 - 2, e["level"] + 2, f"level {e['depth']:.1f} cm above the floor (ours)", color=COMPUTED, ha="right")
    if "level_expected" in paper:
        ax.plot([x0, x1], [fy + paper["level_expected"]] * 2, ":", color=PAPER, lw=1.2)
        ax.text(x0 + 2, fy + paper["level_expected"] + 2, f"paper: expected {paper['level_expected']:g} cm, "
                f"observed {paper.get('level_second', np.nan):g} cm", color=PAPER)
    ax.plot([], [], color=COMPUTED, lw=2.2, label="computed reaction $R_b$")
    ax.plot([], [], color=THEORY, lw=2.2, label="hydrostatic theory, second vessel (flat level, tributary length)")
    ax.legend(loc="upper right", fontsize=8)
    left = fm["particles_left"]
    exp_ours = (ds.sizes["particle"] - left) / ds.sizes["particle"] * paper.get("level_first", np.nan) / 2
    ax.set_title(f"(Fig. 10) step {int(ds['steps']):,}: {left} particles left in the first vessel "
                 f"(paper {paper.get('particles_left', '?')}); second vessel depth {e['depth']:.1f} cm "
                 f"(paper {paper.get('level_second', '?')} cm; ((N - {left})/N) x {paper.get('level_first', '?')}/2 "
                 f"= {exp_ours:.1f} cm)\nsecond-vessel loads: floor {e.get('floor_err', np.nan):+.1%}, "
                 f"side walls {e['side_err']:+.1%} against hydrostatics")
    ax.set_ylim(-75, 115)
    fig.suptitle(run_caption(ds), fontsize=8)
    save(fig, outputs)


def flow_history_figure(inputs, outputs, chains=None):
    """Particles per vessel, sum F_x and max|F| against the step along each chain.

    chains: {label: [run file stems in order]}; inputs are the run files.
    """
    by_stem = {p.rsplit("/", 1)[-1].removesuffix(".nc"): p for p in inputs}
    fig, axes = plt.subplots(3, len(chains), figsize=(6.5 * len(chains), 9), sharex="col", squeeze=False)
    for col, (label, stems) in enumerate(chains.items()):
        ax_n, ax_f, ax_m = axes[:, col]
        for stem in stems:
            ds = read(by_stem[stem])
            if "hist_step" in ds:
                ax_m.plot(ds["hist_step"], ds["hist_fmax"], lw=0.6, color="k")
                ax_m.fill_between(ds["hist_step"], ds["hist_fmax_lo"], ds["hist_fmax_hi"], color="gray", alpha=0.3, lw=0)
            if "hist_vessel_count" in ds:
                st = ds["sample_step"].values
                for name, color in zip(ds["vessel"].values, ("tab:green", "k")):
                    ax_n.plot(st, ds["hist_vessel_count"].sel(vessel=name), color=color,
                              label=f"{name} vessel" if stem == stems[1] else None)
                ax_f.plot(st, ds["hist_sum_fx"], color=COMPUTED)
            ax_m.axvline(int(ds["start_step"]), color="gray", ls=":", lw=0.8)
            ax_m.text(int(ds["start_step"]), 1e3, f" {stem}\n {ds.attrs['variant']}", fontsize=6, va="top")
        ax_n.set_ylabel("particles")
        ax_n.legend(fontsize=8)
        ax_n.set_title(f"{label} chain: {' -> '.join(stems)}")
        ax_f.axhline(0, color="k", lw=0.5)
        ax_f.set_ylabel("ΣF_x of wall reactions (N)")
        ax_m.set_yscale("log")
        ax_m.axhline(0.1, color="k", ls=":", lw=0.8)
        ax_m.set_ylabel("max|F| (N)")
        ax_m.set_xlabel("algorithm step (from the start of application 1 / 2)")
    fig.suptitle("Flow history (band: min-max of max|F| over each record stride; dotted: f_tol = 0.1 N)")
    save(fig, outputs)
