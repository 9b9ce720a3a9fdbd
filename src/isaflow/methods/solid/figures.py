"""Figures of the solid cases, from run files only: deformed bars (Fig. 1), Hertz load and pressure (Fig. 3)."""


import numpy as np

from isaflow import runfile
from isaflow.figures.style import PAPER, THEORY, plt, save
from isaflow.methods import variant as variant_of

from . import settings
from . import theory as T
from .cases import to_pa


def read_runs(paths):
    """{(case, variant): Dataset} of the solid run files."""
    out = {}
    for f in paths:
        ds = runfile.read(f)
        out[(ds.attrs["case"], ds.attrs["variant"])] = ds
    return out


def _slice(ds, scale):
    """(ref x, y), (deformed x, y) of the middle z layer, displacements times scale [cm]."""
    k = ds["lattice_index"].values[:, 2]
    mid = k == (k.max() // 2)
    p0, p = ds["pos0"].values[mid], ds["pos"].values[mid]
    return p0, p0 + scale * (p - p0)


def bar_figure(config_path, runs, outputs, variant="hooke"):
    """Fig. 1 analogue: bar unloaded, in tension, in compression, and the shear block; middle z layer."""
    cfg = settings.load(config_path)
    scale = cfg["bar"]["exaggeration"]
    runs = read_runs(runs)
    fig, axes = plt.subplots(1, 4, figsize=(10, 4.6), sharey=True, gridspec_kw={"width_ratios": [1, 1, 1, 2.2]})
    panels = [("bar_tension", "(a) no stress", 0.0), ("bar_tension", "(b) tension", scale),
              ("bar_compression", "(c) compression", scale), ("shear", "(d) shear", scale)]
    for ax, (case, title, s) in zip(axes, panels):
        ds = runs[(case, variant)]
        p0, p = _slice(ds, s)
        k = ds["lattice_index"].values[:, 2]
        sig = to_pa(ds["stress"].values[k == k.max() // 2, 3 if case == "shear" else 1]) / 1e6
        lim = 20.0 if case == "shear" else 2.0
        ax.scatter(p0[:, 0], p0[:, 1], s=40, marker="s", facecolors="none", edgecolors="0.75", lw=0.6)
        sc = ax.scatter(p[:, 0], p[:, 1], s=40, marker="s", c=sig * (1 if s else 0), cmap="coolwarm",
                        vmin=-lim, vmax=lim, edgecolors="k", lw=0.3)
        ax.set_title(title)
        ax.set_aspect("equal")
        ax.set_xlabel("x [cm]")
        ax.set_xlim(min(p0[:, 0].min(), p[:, 0].min()) - 2.5, max(p0[:, 0].max(), p[:, 0].max()) + 2.5)
        if case == "shear":
            fig.colorbar(sc, ax=ax, orientation="horizontal", pad=0.25, label="tau_yx [MPa]")
        elif s and case == "bar_compression":
            fig.colorbar(sc, ax=axes[1:3], orientation="horizontal", pad=0.12, label="sigma_yy [MPa]")
    axes[0].set_ylabel("y [cm]")
    fig.suptitle(f"{variant_of('solid', variant).label}\nmiddle z layer; displacements x {scale:g}; "
                 "grey outlines: unloaded", fontsize=8)
    save(fig, outputs)


def hertz_figure(config_path, runs, outputs):
    """Fig. 3 analogue: (a) load per unit thickness and (b) peak contact pressure against indentation."""
    cfg = settings.load(config_path)
    hz = cfg["hertz"]
    E, nu = cfg["material"]["E_GPa"] * 1e9, cfg["material"]["nu"]
    Er, R = T.reduced_modulus(E, nu), hz["radius_mm"] * 1e-3
    d = np.linspace(hz["depths_um"][0], hz["depths_um"][-1], 50) * 1e-6
    runs = read_runs(runs)
    fig, (a, b) = plt.subplots(1, 2, figsize=(9, 3.6))
    a.plot(d * 1e6, T.load_candidates(R, d, Er, 0)["line_per_m"] / 1e6, color=THEORY,
           label="Hertz line contact pi a p_max / 2 (chord a)")
    b.plot(d * 1e6, T.hertz_pmax(R, d, Er) / 1e9, color=THEORY, label="eq. 25: a E' / (2 R)")
    b.plot([hz["depths_um"][0], hz["depths_um"][-1]], [7.3, 10.0], "x", color=PAPER, ms=8,
           label="paper's stated range 7.3-10 GPa")
    for var in ("paper", "hooke"):
        ds = runs[("hertz", var)]
        ok = ds["increment_converged"].values.astype(bool)
        v = variant_of("solid", var)
        dep = ds["depth"].values * 1e4
        a.plot(dep[ok], ds["load"].values[ok] * 100 / 1e6, v.marker, color=v.colour, label=f"{var} variant: settled increments")
        b.plot(dep[ok], to_pa(ds["pmax"].values[ok]) / 1e9, v.marker, color=v.colour, label=f"{var} variant: settled increments")
    a.set(xlabel="indentation delta [um]", ylabel="load per unit thickness [MN/m]", title="(a) total load")
    b.set(xlabel="indentation delta [um]", ylabel="peak contact pressure [GPa]", title="(b) peak pressure")
    a.legend(fontsize=6, loc="upper left")
    b.legend(fontsize=6, loc="upper left")
    fig.tight_layout()
    save(fig, outputs)


def bar_and_hertz(cfg, runs, outputs):
    """Both figures (workflow entry point): outputs are the bar's [png, pdf], then Hertz's."""
    bar_figure(cfg, runs, outputs[:2])
    hertz_figure(cfg, runs, outputs[2:])
