"""MPS figures from run files: wall loads per panel against hydrostatics (Fig. 6-like, with the noise band),
the rms speed of the liquid at rest against time (every single-vessel run, with its rest limit), and the
flow (Fig. 10-like snapshots and the final state)."""

import numpy as np

from isaflow import metrics, runfile
from isaflow.figures.style import plt, save
from isaflow.methods import registry

VARIANTS = registry()["mps"].variants


def pick_runs(paths):
    """Per variant, the finest run that neither escaped nor became non-finite (else the coarsest)."""
    best = {}
    for p in paths:
        ds = runfile.read(p)
        ok = ds.attrs["status"] not in ("escaped", "nonfinite")
        key = (ok, -float(ds.attrs["spacing"]) if ok else float(ds.attrs["spacing"]))
        v = ds.attrs["variant"]
        if v not in best or key > best[v][0]:
            best[v] = (key, p)
    return [best[v][1] for v in VARIANTS if v in best]


def wall_loads(runs, outputs):
    """Per variant (pick_runs): |panel force| [N] along the walls (mean and +- std over the window) vs hydrostatic theory."""
    out = outputs
    paths = pick_runs(runs)
    n = len(paths)
    fig, axes = plt.subplots(1, n, figsize=(4.2 * n, 3.6), squeeze=False, sharey=True)
    for ax, p in zip(axes[0], paths):
        ds = runfile.read(p)
        e, (cw, cp, mag, th) = metrics.contact_loads(ds)
        win = ds["in_window"].values.astype(bool)
        hist = np.hypot(*np.moveaxis(ds["hist_panel_force"].values[win], -1, 0))
        k = np.arange(len(mag))
        v = VARIANTS[ds.attrs["variant"]]
        ax.errorbar(k, mag, yerr=hist.std(0), fmt=v.marker, color=v.colour, ms=4, capsize=2, label="MPS mean +- std")
        ax.plot(k, th, "k_", ms=10, mew=2, label="hydrostatic theory")
        names = [str(x) for x in ds["wall"].values]
        for w in range(len(names)):
            on = np.flatnonzero(cw == w)
            if len(on):
                ax.text(on.mean(), 0.97, names[w], transform=ax.get_xaxis_transform(), ha="center", va="top", fontsize=8)
        ax.set_xticks([])
        top = max(np.nanmax(mag + hist.std(0)), np.nanmax(th))
        ax.set_ylim(-0.05 * top, 1.15 * top)  # headroom for the wall names
        ax.set_title(f"{ds.attrs['variant']}, l0 = {float(ds.attrs['spacing']):.3g} cm\n{ds.attrs['status']}", fontsize=9)
        ax.set_xlabel("10 cm panels along the walls (left, floor, right)")
    axes[0, 0].set_ylabel("wall force per panel |F| [N]")
    axes[0, 0].legend(fontsize=7, loc="lower center")
    fig.tight_layout()
    save(fig, out)


def flow(runs, outputs):
    """Rows: runs; columns: position snapshots of the flow [cm] with the walls."""
    out = outputs
    dss = [runfile.read(p) for p in runs]
    ncol = max(ds.sizes.get("snapshot", 1) for ds in dss)
    fig, axes = plt.subplots(len(dss), ncol, figsize=(3.0 * ncol, 1.9 * len(dss) + 1.0), squeeze=False)
    for row, ds in zip(axes, dss):
        v = VARIANTS[ds.attrs["variant"]]
        m = metrics.run_row(ds)
        row[0].annotate(f"{ds.attrs['variant']} ({ds.attrs['status']}): {m['particles_left']} of {m['particles']} left, "
                        f"second vessel depth {m['depth']:.1f} cm, surface slope {m['slope_deg']:+.1f} deg, range "
                        f"{m['surface_range_cm']:.1f} cm", (0, 1.32), xycoords="axes fraction", fontsize=8,
                        color=v.colour, fontweight="bold")
        snaps = ds["snap_pos"].values if "snap_pos" in ds else ds["pos"].values[None]
        times = ds["snap_time"].values if "snap_time" in ds else [float(ds["sim_time"])]
        for ax, pos, t in zip(row, snaps, times):
            for w in ds["wall_segment"].values:
                ax.plot(w[[0, 2]], w[[1, 3]], "k-", lw=1)
            ax.plot(pos[:, 0], pos[:, 1], ".", color=v.colour, ms=1.5)
            ax.set_xlim(-10, 310)
            ax.set_ylim(-60, 110)
            ax.set_aspect("equal")
            ax.set_title(f"l0 = {float(ds.attrs['spacing']):.3g} cm, t = {t:.2f} s", fontsize=7)
            ax.tick_params(labelsize=6)
        for ax in row[len(snaps):]:
            ax.axis("off")
    for ax in axes[-1]:
        ax.set_xlabel("x [cm]", fontsize=7)
    for ax in axes[:, 0]:
        ax.set_ylabel("y [cm]", fontsize=7)
    fig.suptitle("MPS flow into the second vessel: snapshots per pressure source term (last column: end state)", fontsize=9)
    fig.tight_layout()
    save(fig, out)


def rest(runs, outputs):
    """One panel per source term: kinetic energy / (W h) of the liquid started at rest against time, one line
    per spacing; dashed: the rest limit of isaflow.rest (config/rest.yaml)."""
    dss = [runfile.read(p) for p in runs]
    fig, axes = plt.subplots(1, len(VARIANTS), figsize=(4.2 * len(VARIANTS), 3.4), squeeze=False, sharey=True)
    for ax, name in zip(axes[0], VARIANTS):
        mine = sorted((ds for ds in dss if ds.attrs["variant"] == name), key=lambda d: -float(d.attrs["spacing"]))
        for k, ds in enumerate(mine):
            c = plt.cm.viridis(k / max(1, len(mine) - 1) * 0.85)
            ax.semilogy(ds["hist_time"].values, ds["hist_energy_ratio"].values, color=c, lw=1.2,
                        label=f"l0 = {float(ds.attrs['spacing']):.3g} cm ({ds.attrs['status']})")
        if mine:
            ax.axhline(float(mine[0].attrs["rest_energy_ratio"]), color="k", ls="--", lw=0.8)
        ax.set_title(f"source term: {name}", fontsize=9)
        ax.set_xlabel("time t [s]")
        ax.legend(fontsize=7, loc="lower right")
    axes[0, 0].set_ylabel("kinetic energy / (W h)\n(dashed: rest limit)")
    fig.tight_layout()
    save(fig, outputs)
