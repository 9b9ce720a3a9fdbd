"""SPH figures from run files only: Fig. 6-like single vessel, Fig. 10-like flow, flow snapshots."""

import textwrap

import numpy as np

from isaflow import metrics, runfile
from isaflow.figures.style import draw_walls as _walls
from isaflow.figures.style import plt, save
from isaflow.methods.sph.outputs import row


def _method_title(fig, ds, what):
    """Suptitle naming the method, the variant (its registry label, wrapped) and what the figure shows."""
    label = textwrap.fill(f"variant {ds.attrs['variant']}: {ds.attrs['variant_label']}", 90)
    fig.suptitle(f"Weakly compressible SPH, {what}\n{label}", fontsize=9)
    lines = 2 + label.count("\n")
    fig.tight_layout(rect=(0, 0, 1, 1 - 0.012 * lines * 12 / fig.get_figheight()))


def single(paths, out):
    """(a) finest single-vessel run, particles coloured by pressure; (b) per-panel wall loads of
    every run against hydrostatic theory (metrics.contact_loads)."""
    runs = [runfile.read(p) for p in paths]
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 5.2), gridspec_kw={"width_ratios": [1, 1.25]})
    ds = min(runs, key=lambda d: float(d.attrs["spacing"]))
    sc = a.scatter(*ds["pos"].values.T, c=ds["pressure"].values, s=max(1.0, 3000 / ds.sizes["particle"]), cmap="viridis")
    fig.colorbar(sc, ax=a, label="pressure (N/cm$^2$)")
    _walls(a, ds)
    a.set(aspect="equal", xlabel="x (cm)", ylabel="y (cm)",
          title=f"(a) {ds.sizes['particle']} particles, t = {float(ds['sim_time']):.2f} s, {ds.attrs['status']}")
    a.title.set_fontsize(9)
    names = [str(n) for n in ds["wall"].values]
    for d in sorted(runs, key=lambda d: -float(d.attrs["spacing"])):
        _, (cw, cp, mag, th) = metrics.contact_loads(d)
        wet = np.isfinite(th)
        lab = f"{d.sizes['particle']} particles (dx {float(d.attrs['spacing']):.3g} cm)"
        s_ = [f"{names[w]}" for w in cw[wet]]
        pos = np.array([f"{w}:{c[0] if w == 'floor' else c[1]:.0f}" for w, c in zip(s_, cp[wet])])
        b.plot(np.arange(wet.sum()), mag[wet], "o-", ms=3, lw=0.8, label=lab)
    b.plot(np.arange(wet.sum()), th[wet], "k_", ms=12, mew=2, label="hydrostatic theory (measured level)")
    b.set_xticks(np.arange(wet.sum()), pos, rotation=90, fontsize=7)
    b.set(xlabel="wall panel (wall: panel centre x or y, cm)", ylabel="panel load |F| (N)",
          title="(b) per-panel wall loads, mean over the final window")
    b.title.set_fontsize(9)
    b.legend(fontsize=7)
    _method_title(fig, ds, "single vessel, W = 9 kN")
    save(fig, out)


def flow(paths, out):
    """Final state of each flow run (both flow tanks) with the measured second-vessel surface and the tank's
    level at rest (its liquid, rho g, at rest in the communicating vessels)."""
    paths = sorted(paths, key=lambda p: (runfile.read(p).attrs["tank"], -float(runfile.read(p).attrs["spacing"])))
    fig, axes = plt.subplots(len(paths), 1, figsize=(10, 3.3 * len(paths)), squeeze=False)
    for ax, path in zip(axes[:, 0], paths):
        ds, r = runfile.read(path), row(path)
        pos = ds["pos"].values
        sc = ax.scatter(*pos.T, c=ds["pressure"].values, s=max(1.0, 2000 / ds.sizes["particle"]), cmap="viridis")
        fig.colorbar(sc, ax=ax, label="pressure (N/cm$^2$)")
        _walls(ax, ds)
        x0, x1 = ds["vessel_x"].values[-1]
        for y, style, what in ((r["second_surface_cm"], dict(color="tab:red", lw=1), "measured surface"),
                               (r["second_tank_surface_cm"], dict(color="k", ls="--", lw=1),
                                "the tank's liquid at rest")):
            ax.plot([x0, x1], [y, y], label=f"{what} {y:.1f} cm (slope {r['second_slope_deg']:+.1f} deg)"
                    if what == "measured surface" else f"{what} {y:.1f} cm", **style)
        label = ds.attrs.get("run_label", "none")  # a sweep's run says which value of which input it is
        label = "" if label == "none" else label  # isaflow.run writes 'none' for a run without a label
        ax.set(aspect="equal", xlabel="x (cm)", ylabel="y (cm)",
               title=f"{ds.attrs['run_id']}" + (f" ({label})" if label else "") + f"\ntank {ds.attrs['tank']}, "
                     f"{ds.sizes['particle']} particles: t = {float(ds['sim_time']):.1f} s, {ds.attrs['status']}, "
                     f"{r['left_fraction']:.1%} of the weight left in the first vessel")
        ax.title.set_fontsize(9)
        ax.legend(fontsize=7, loc="upper right")
    _method_title(fig, ds, "flow into the second vessel, final states")
    save(fig, out)


SNAPSHOT_TIMES = (0.0, 0.25, 0.5, 1.0, 2.0, 4.0)  # s after the opening: the drain (about 2 s) and after


def snapshots(path, out, times=SNAPSHOT_TIMES):
    """Snapshots of one flow run: the recorded ones nearest ``times`` (s after the opening), titled with their own."""
    ds = runfile.read(path)
    t_all = ds["snap_time"].values - float(ds.attrs.get("start_time", 0.0))  # time since the opening
    keep = sorted({int(np.argmin(np.abs(t_all - t))) for t in times})
    t, pos = t_all[keep], ds["snap_pos"].values[keep]
    n = len(t)
    fig, axes = plt.subplots((n + 1) // 2, 2, figsize=(12, 3.3 * ((n + 1) // 2) + 0.8), squeeze=False)
    for k, ax in enumerate(axes.ravel()):
        if k >= n:
            ax.axis("off")
            continue
        ax.scatter(*pos[k].T, s=max(0.5, 1000 / ds.sizes["particle"]), color="tab:blue")
        _walls(ax, ds)
        ax.set(aspect="equal", ylabel="y (cm)", title=f"{t[k]:.2f} s after the opening",
               xlabel="x (cm)" if k >= n - 2 else "")  # the bottom panel of each column: no label under a title
        ax.title.set_fontsize(9)
    _method_title(fig, ds, f"flow snapshots, tank {ds.attrs['tank']}, {ds.sizes['particle']} particles")
    save(fig, out)


def all_figures(single_runs, flow_runs, outputs):
    """outputs: [png, pdf] of single(single_runs), flow(flow_runs), snapshots(the finest flow run on the
    step tank, flow_step50), in that order."""
    single(single_runs, outputs[0:2])
    flow(flow_runs, outputs[2:4])
    step = [p for p in flow_runs if runfile.read(p).attrs["tank"] == "flow_step50"] or list(flow_runs)
    snapshots(max(step, key=lambda p: runfile.read(p).sizes["particle"]), outputs[4:6])
