"""MPS figures from run files: wall loads per panel against hydrostatics (Fig. 6-like, with the noise band),
the kinetic energy of the liquid started at rest against time (every single-vessel run, with its rest limit and
the runs before issue 30), the column at rest (pressure against depth, wall loads against time by both readings),
and the flow (Fig. 10-like snapshots and the final state)."""

import numpy as np

from isaflow import metrics, runfile
from isaflow.core import units
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
        hist = np.hypot(*np.moveaxis(ds["sample_panel_force"].values[win], -1, 0))
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


FLOW_COLUMNS = 5  # snapshots per flow row: a fifth of the time limit apart


def _flow_columns(ds):
    """(positions, times) of the stored states nearest k / FLOW_COLUMNS of the run's time limit after its start
    (k = 1 ...) that fall before its end, each state once, then the end state: a run that stopped early (converged)
    has fewer columns; the final state alone for a run without snapshots."""
    if "snap_pos" not in ds:
        return ds["pos"].values[None], [float(ds["sim_time"])]
    t = ds["snap_time"].values
    t0, limit = float(ds.attrs.get("start_time", t[0])), float(ds.attrs["time_limit_s"])
    keep = []
    for k in range(1, FLOW_COLUMNS):
        i = int(np.argmin(np.abs(t - (t0 + limit * k / FLOW_COLUMNS))))
        if i < len(t) - 1 and i not in keep:
            keep.append(i)
    keep.append(len(t) - 1)
    return ds["snap_pos"].values[keep], t[keep]


def flow(runs, outputs):
    """Rows: runs; columns: position snapshots of the flow [cm] with the walls: the stored ones nearest a fifth,
    two fifths ... of the run's time limit after its start, before its end (the last: its end state)."""
    out = outputs
    dss = [runfile.read(p) for p in runs]
    ncol = FLOW_COLUMNS
    fig, axes = plt.subplots(len(dss), ncol, figsize=(3.0 * ncol, 1.9 * len(dss) + 1.0), squeeze=False)
    for row, ds in zip(axes, dss):
        v = VARIANTS[ds.attrs["variant"]]
        m = metrics.run_row(ds)
        row[0].annotate(f"{ds.attrs['variant']} ({ds.attrs['status']}): {m['particles_left']} of {m['particles']} left, "
                        f"second vessel depth {m['depth']:.1f} cm, surface slope {m['slope_deg']:+.1f} deg, range "
                        f"{m['surface_range_cm']:.1f} cm", (0, 1.32), xycoords="axes fraction", fontsize=8,
                        color=v.colour, fontweight="bold")
        snaps, times = _flow_columns(ds)
        for col, (ax, pos, t) in enumerate(zip(row, snaps, times)):
            for w in ds["wall_segment"].values:
                ax.plot(w[[0, 2]], w[[1, 3]], "k-", lw=1)
            ax.plot(pos[:, 0], pos[:, 1], ".", color=v.colour, ms=1.5)
            ax.set_xlim(-10, 310)
            ax.set_ylim(-60, 110)
            ax.set_aspect("equal")
            end = " (end state)" if col == len(snaps) - 1 else ""
            ax.set_title(f"l0 = {float(ds.attrs['spacing']):.3g} cm, t = {t:.2f} s{end}", fontsize=7)
            ax.tick_params(labelsize=6)
        for ax in row[len(snaps):]:
            ax.axis("off")
    for ax in axes[-1]:
        ax.set_xlabel("x [cm]", fontsize=7)
    for ax in axes[:, 0]:
        ax.set_ylabel("y [cm]", fontsize=7)
    fig.suptitle("MPS flow into the second vessel: snapshots per pressure source term (last column: end state; "
                 "a run that converged early has fewer)", fontsize=9)
    fig.tight_layout()
    save(fig, out)


def _by_variant(dss, name):
    """The runs of source term ``name``, coarsest spacing first, with each one's colour (by spacing)."""
    mine = sorted((ds for ds in dss if ds.attrs["variant"] == name), key=lambda d: -float(d.attrs["spacing"]))
    spacings = sorted({float(d.attrs["spacing"]) for d in dss}, reverse=True)
    return [(ds, plt.cm.viridis(spacings.index(float(ds.attrs["spacing"])) / max(1, len(spacings) - 1) * 0.85))
            for ds in mine]


def rest(runs, outputs, before=()):
    """One panel per source term: kinetic energy / (W h) of the liquid started at rest against time, one line per
    spacing, solid the settings' gradient, dashed the runs ``before`` (the K&O gradient and radii before issue 30);
    black dashed: the rest limit of isaflow.rest (config/rest.yaml)."""
    dss = [runfile.read(p) for p in list(runs) + list(before)]
    fig, axes = plt.subplots(1, len(VARIANTS), figsize=(4.4 * len(VARIANTS), 3.6), squeeze=False, sharey=True)
    for ax, name in zip(axes[0], VARIANTS):
        mine = _by_variant(dss, name)
        for ds, c in mine:
            old = ds.attrs["model.gradient"] != "variational"
            e_mean = float(ds.attrs["window_energy_ratio_mean"])
            ax.semilogy(ds["sample_time"].values, ds["sample_energy_ratio"].values, color=c, lw=0.9 if old else 1.2,
                        ls="--" if old else "-", label=f"l0 = {float(ds.attrs['spacing']):.3g} cm, {ds.attrs['model.gradient']} "
                                                         f"({ds.attrs['status']}; last {float(ds.attrs['rest_window']):g} s: mean {e_mean:.1e})")
        if mine:
            ax.axhline(float(mine[0][0].attrs["rest_energy_ratio"]), color="k", ls=":", lw=0.8)
        ax.set_title(f"source term: {name}", fontsize=9)
        ax.set_xlabel("time t [s]")
        ax.set_ylim(1e-7, 10.0)  # room above the lines for the legend
        ax.legend(fontsize=6, loc="upper right")
    axes[0, 0].set_ylabel("kinetic energy / (W h) [1]\n(dotted: rest limit)")
    fig.tight_layout()
    save(fig, outputs)


def column(runs, outputs):
    """The column at rest, one column of panels per source term, one colour per spacing: (a) the liquid's pressure
    (mean over the averaging window) against depth below its top (top particle centre + l0/2) with rho0 g depth;
    (b) floor plus side walls' vertical force over the weight, (c) side-wall load over rho g h^2 / 2, both against
    time by the pair-force reading (solid) and the panel reading (dotted)."""
    from .outputs import SIDE_LOAD, wall_series

    dss = [runfile.read(p) for p in runs]
    fig, axes = plt.subplots(3, len(VARIANTS), figsize=(4.4 * len(VARIANTS), 9.0), squeeze=False, sharey="row")
    for k, name in enumerate(VARIANTS):
        for ds, c in _by_variant(dss, name):
            l0 = float(ds.attrs["spacing"])
            pos, p = ds["pos"].values, ds["pressure_mean"].values
            depth = pos[:, 1].max() + 0.5 * l0 - pos[:, 1]
            rho_g = float(ds.attrs["rho0_N_s2_cm4"]) * units.G
            axes[0, k].plot(depth, p, ".", color=c, ms=2.5, label=f"l0 = {l0:.3g} cm ({ds.attrs['status']})")
            d = np.array([0.0, depth.max()])
            axes[0, k].plot(d, rho_g * d, "-", color=c, lw=0.7)
            t = ds["sample_time"].values
            for reading, ls in (("pair", "-"), ("panel", ":")):
                series = wall_series(ds, reading)
                if series is None:
                    continue
                axes[1, k].plot(t, 100 * (series["vertical"] / float(ds.attrs["tank_weight"]) - 1), ls=ls, color=c,
                                lw=0.8, label=f"l0 = {l0:.3g} cm, {reading} reading")
                axes[2, k].plot(t, 100 * (series["side"] / SIDE_LOAD - 1), ls=ls, color=c, lw=0.8,
                                label=f"l0 = {l0:.3g} cm, {reading} reading")
        axes[0, k].axvline(0, color="k", lw=0.5)
        axes[0, k].set_title(f"source term: {name}", fontsize=9)
        axes[0, k].set_xlabel("depth below the liquid's top [cm]")
        axes[0, k].legend(fontsize=7, loc="upper left", title="lines: rho0 g depth", title_fontsize=7)
        for row in (1, 2):
            axes[row, k].axhline(0, color="k", lw=0.5)
            axes[row, k].set_xlabel("time t [s]")
            axes[row, k].set_ylim(-15, 15)
        axes[1, k].legend(fontsize=6, loc="lower right")
    axes[0, 0].set_ylabel("pressure P [N/cm^2]")
    axes[1, 0].set_ylabel("floor + side walls, vertical,\nagainst W [%]")
    axes[2, 0].set_ylabel("side-wall load against\nrho g h^2 / 2 = 3262.5 N [%]")
    fig.tight_layout()
    save(fig, outputs)
