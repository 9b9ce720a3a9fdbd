"""SPH figures from run files only: Fig. 6-like single vessel, Fig. 10-like flow, flow snapshots."""

import numpy as np

from isaflow import metrics, runfile
from isaflow.figures.style import draw_walls as _walls
from isaflow.figures.style import plt, save
from isaflow.methods.sph.outputs import level as _level


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
    fig.tight_layout()
    save(fig, out)


def flow(paths, out):
    """Final state of each flow run with the measured second-vessel surface and the expected flat one."""
    runs = sorted([runfile.read(p) for p in paths], key=lambda d: -float(d.attrs["spacing"]))
    fig, axes = plt.subplots(len(runs), 1, figsize=(10, 3.3 * len(runs)), squeeze=False)
    for ax, ds in zip(axes[:, 0], runs):
        pos = ds["pos"].values
        sc = ax.scatter(*pos.T, c=ds["pressure"].values, s=max(1.0, 2000 / ds.sizes["particle"]), cmap="viridis")
        fig.colorbar(sc, ax=ax, label="pressure (N/cm$^2$)")
        _walls(ax, ds)
        lev = _level(ds, "second") + float(ds.attrs["cell_dy"]) / 2
        w = ds["weight"].values
        left = w[pos[:, 0] < 100].sum()
        gamma = w.sum() / (float(ds.attrs["first_vessel_width"]) * float(ds.attrs["liquid_depth"]))
        expect = -50 + (w.sum() - left) / (gamma * 200)
        ax.axhline(lev, xmin=1 / 3, color="tab:red", lw=1, label=f"measured surface {lev:.1f} cm")
        ax.axhline(expect, xmin=1 / 3, color="k", ls="--", lw=1, label=f"flat surface of the liquid held {expect:.1f} cm")
        ax.set(aspect="equal", xlabel="x (cm)", ylabel="y (cm)", ylim=(-55, 105),
               title=f"{ds.sizes['particle']} particles: t = {float(ds['sim_time']):.1f} s, {ds.attrs['status']}, "
                     f"{left / w.sum():.1%} of the weight left in the first vessel")
        ax.title.set_fontsize(9)
        ax.legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    save(fig, out)


def snapshots(path, out):
    """Snapshots of one flow run at the recorded times."""
    ds = runfile.read(path)
    t = ds["snap_time"].values
    n = len(t)
    fig, axes = plt.subplots((n + 1) // 2, 2, figsize=(12, 2.4 * ((n + 1) // 2)), squeeze=False)
    for k, ax in enumerate(axes.ravel()):
        if k >= n:
            ax.axis("off")
            continue
        ax.scatter(*ds["snap_pos"].values[k].T, s=max(0.5, 1000 / ds.sizes["particle"]), color="tab:blue")
        _walls(ax, ds)
        ax.set(aspect="equal", ylim=(-55, 105), xlabel="x (cm)", ylabel="y (cm)", title=f"t = {t[k]:.2f} s")
        ax.title.set_fontsize(9)
    fig.tight_layout()
    save(fig, out)


def all_figures(single_runs, flow_runs, outputs):
    """outputs: [png, pdf] of single(single_runs), flow(flow_runs), snapshots(finest flow run), in that order."""
    single(single_runs, outputs[0:2])
    flow(flow_runs, outputs[2:4])
    snapshots(flow_runs[-1], outputs[4:6])
