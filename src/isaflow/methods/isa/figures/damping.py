"""The paper's update against overdamped dynamics of the same particles (claim pap-7-strong-damping).

"This incremental static analysis approximates dynamic behavior with strong damping": the overdamped
variant (methods.isa.dynamics, not the paper's) moves the same particles under the same force laws with
masses w/g and a drag c = 2 zeta sqrt(m lambda_max).  The figure puts both on a common normalised time
axis tau = t / t_50 (t_50: half the final transfer) and, next to the curves, the end states the claim is
judged on (particles left, second-vessel surface) for every damping run, with the claim's tolerances.  Levels
are the one surface (metrics.surface_of).  Units: cm, N, s.
"""

import numpy as np

from .. import metrics
from ....figures.style import COMPUTED, draw_walls, legend_below, plt, save
from ....metrics import flow_measures, surface_of, vessels
from ....runfile import read
from .single import inferred_note

OD_COLOURS = ("tab:olive", "tab:orange", "tab:red", "tab:purple")
TAU = np.linspace(0.0, 5.0, 501)


def _by_stem(inputs):
    return {p.rsplit("/", 1)[-1].removesuffix(".nc"): read(p) for p in inputs}


def overdamped_figure(inputs, outputs, isa_chain=("flow_incomplete", "flow_complete"), single="single_coarse",
                      flows=("flow_overdamped",), singles=("single_coarse_overdamped",), inferred=None):
    """(a) transferred fraction on tau = t / t_50, the paper's update and the overdamped runs (every zeta given);
    (b) next to it, the end states of every run of (a) against the paper's update's, with the tolerances of
    pap-7-strong-damping (half a floor row, a/4); (c) the flow's end positions (zeta as the first of flows);
    (d) the single vessel's overdamped run: kinetic energy e = KE / (W h) and max|F| against time; (e) its end state
    against the paper's update's.  inputs: the run files named by the other arguments (run ids); inferred: the footer
    naming the inferred inputs."""
    runs = _by_stem(inputs)
    fig = plt.figure(figsize=(19, 12))
    gs = fig.add_gridspec(2, 3, width_ratios=[1.0, 0.62, 1.15])
    ax_f, ax_s, ax_e, ax_v = (fig.add_subplot(gs[0, 0]), fig.add_subplot(gs[0, 2]), fig.add_subplot(gs[1, 0]),
                              fig.add_subplot(gs[1, 2]))
    sub = gs[0, 1].subgridspec(2, 1, hspace=0.5)
    ax_n, ax_h = fig.add_subplot(sub[0]), fig.add_subplot(sub[1])
    # (a) transfer curves
    chain = [runs[k] for k in isa_chain]
    t, f = metrics.transfer_curve(chain)
    g, s50 = metrics.normalised_curve(t, f, TAU)
    ax_f.plot(TAU, g, color=COMPUTED, lw=2, label=f"paper's update (t_50 = {s50:,.0f} steps after the opening)")
    for k, c in zip(flows, OD_COLOURS):
        d = runs[k]
        t, f = metrics.transfer_curve([d])
        go, t50 = metrics.normalised_curve(t, f, TAU)
        ax_f.plot(TAU, go, color=c, lw=1.3, ls="--",
                  label=f"overdamped, zeta = {float(d.attrs['solver.zeta']):g} (t_50 = {t50:.3g} s): sup |diff| "
                        f"{np.abs(go - g).max():.3f}")
    ax_f.set_xlabel("tau = t / t_50 (the paper's update: steps; overdamped: time)")
    ax_f.set_ylabel("fraction of the particles in the second vessel")
    ax_f.set_xlim(0, TAU[-1])
    ax_f.set_ylim(0, 1)
    ax_f.set_title("(a) transfer on the normalised time axis (reported, not judged)")
    legend_below(ax_f, ncol=1)
    # (b) the end states of every run of (a), the ones the claim is judged on
    _end_states(ax_n, ax_h, chain[-1], [runs[k] for k in flows])
    # (b) end states of the flow
    isa, od = chain[-1], runs[flows[0]]
    draw_walls(ax_s, isa)
    ax_s.plot(*isa["pos"].values.T, "o", ms=3.2, color=COMPUTED,
              label=f"paper's update: {flow_measures(isa)['particles_left']} left ({isa.attrs['status']})")
    ax_s.plot(*od["pos"].values.T, "o", ms=5.5, mfc="none", color=OD_COLOURS[0],
              label=f"overdamped zeta {float(od.attrs['solver.zeta']):g}: {flow_measures(od)['particles_left']} left "
                    f"({od.attrs['status']}, t = {float(od['sim_time']):.3g} s)")
    second = vessels(isa)[-1]
    fl = metrics.vessel_view(isa, second)["floor_y"]
    ax_s.set_title(f"(c) end positions: second-vessel surface {surface_of(isa, second) - fl:.1f} cm (update) and "
                   f"{surface_of(od, second) - fl:.1f} cm (overdamped)", fontsize=10)
    ax_s.set_aspect("equal")
    ax_s.set_xlabel("x (cm)")
    ax_s.set_ylabel("y (cm)")
    ax_s.legend(loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=1, fontsize=8, frameon=False)
    # (c) the single vessel's overdamped history
    so = runs[singles[0]]
    tt = (so["hist_step"].values - int(so["start_step"])) * float(so.attrs["solver.dt"])
    e = so["hist_energy"].values / (float(so["weight"].values.sum()) * float(so.attrs["tank_depth"]))
    ax_e.semilogy(tt, np.maximum(e, 1e-16), color=OD_COLOURS[0], label="kinetic energy e = KE / (W h)")
    ax_e.semilogy(tt, so["hist_fmax"].values, color="k", lw=0.8, label="max|F| (N)")
    ax_e.axhline(float(so.attrs["rest_energy_ratio"]), color=OD_COLOURS[0], ls=":", lw=1,
                 label=f"rest: e < {float(so.attrs['rest_energy_ratio']):g} (config/rest.yaml)")
    ax_e.axhline(float(so.attrs["solver.f_tol"]), color="k", ls=":", lw=1, label=f"f_tol = {float(so.attrs['solver.f_tol']):g} N")
    ax_e.set_xlabel("t (s)")
    ax_e.set_ylabel("e = KE / (W h) (1); max|F| (N)")
    ax_e.set_title(f"(d) single vessel, overdamped (zeta {float(so.attrs['solver.zeta']):g}, dt = "
                   f"{float(so.attrs['solver.dt']):.3g} s): {so.attrs['status']} at t = {float(so['sim_time']):.3g} s")
    ax_e.legend(loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2, fontsize=8, frameon=False)
    # (d) single-vessel end states
    si = runs[single]
    draw_walls(ax_v, si)
    ax_v.plot(*si["pos"].values.T, "o", ms=3.2, color=COMPUTED, label=f"paper's update ({si.attrs['status']}): "
                                                                    f"surface {surface_of(si):.2f} cm")
    for k, c in zip(singles, OD_COLOURS):
        d = runs[k]
        ax_v.plot(*d["pos"].values.T, "o", ms=5.5, mfc="none", color=c,
                  label=f"overdamped zeta {float(d.attrs['solver.zeta']):g} ({d.attrs['status']}): surface {surface_of(d):.2f} cm, "
                        f"particle by particle at most "
                        f"{np.abs(d['pos'].values - si['pos'].values).max():.2g} cm from the update's")
    ax_v.set_aspect("equal")
    ax_v.set_xlabel("x (cm)")
    ax_v.set_ylabel("y (cm)")
    ax_v.set_title("(e) single vessel: end states")
    ax_v.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=1, fontsize=8, frameon=False)
    fig.suptitle("The paper's update against overdamped dynamics of the same particles and force laws "
                 "(m x'' = F - c x', m = w/g, c = 2 zeta sqrt(m lambda_max); a project addition, not the paper's)",
                 fontsize=10)
    fig.subplots_adjust(hspace=0.62, wspace=0.35, bottom=0.13, top=0.92)
    inferred_note(fig, inferred)
    save(fig, outputs)


def _end_states(ax_n, ax_h, isa, ods):
    """Particles left and second-vessel surface of the paper's update (first bar) and of every overdamped run, with
    the bands of pap-7-strong-damping around the update's values: half a floor row (B / a / 2 particles) and a/4."""
    runs = [isa, *ods]
    names = ["update"] + [f"zeta {float(d.attrs['solver.zeta']):g}" for d in ods]
    colours = [COMPUTED, *OD_COLOURS]
    second = vessels(isa)[-1]
    v = metrics.vessel_view(isa, second)
    a = float(isa.attrs["spacing"])
    row = metrics.vessel_view(isa, vessels(isa)[0])["width"] / a / 2  # half a floor row of the first vessel
    left = [flow_measures(d)["particles_left"] for d in runs]
    surf = [surface_of(d, second) - v["floor_y"] for d in runs]
    for ax, vals, band, what, unit in ((ax_n, left, row, "particles left in the first vessel", ""),
                                       (ax_h, surf, a / 4, "second-vessel surface above its floor", " cm")):
        ax.axhspan(vals[0] - band, vals[0] + band, color=COMPUTED, alpha=0.13, lw=0)
        ax.bar(range(len(vals)), vals, color=colours[:len(vals)], width=0.6)
        for k, y in enumerate(vals):
            ax.text(k, y, f"{y:.3g}", ha="center", va="bottom", fontsize=8)
        ax.set_xticks(range(len(vals)), names, fontsize=8)
        ax.set_ylim(0, max(vals) * 1.25)
        head = "(b) end states of every run of (a): " if ax is ax_n else ""
        ax.set_title(f"{head}{what}\n(shaded: the update's +- {band:g}{unit}, the claim's tolerance)", fontsize=9)
    ax_n.set_ylabel("particles")
    ax_h.set_ylabel("cm")
