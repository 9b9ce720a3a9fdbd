"""Figures of the solid cases, from run files only: deformed bars (Fig. 1), Hertz load and pressure (Fig. 3)."""


import numpy as np
from matplotlib.colors import to_hex

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


def finish(fig, outputs, *panels):
    """Label every panel (axes, legend location, Axes.set keywords; legend in 6 pt), lay the figure out and save
    it to outputs [png, pdf]."""
    for ax, loc, labels in panels:
        ax.set(**labels)
        ax.legend(fontsize=6, loc=loc)
    fig.tight_layout()
    save(fig, outputs)


def _slice(ds, scale):
    """(ref x, y), (deformed x, y) of the middle z layer, displacements times scale [cm]."""
    k = ds["lattice_index"].values[:, 2]
    mid = k == (k.max() // 2)
    p0, p = ds["pos0"].values[mid], ds["pos"].values[mid]
    return p0, p0 + scale * (p - p0)


def bar_figure(config_path, runs, outputs, variant="hooke"):
    """Fig. 1 analogue: bar unloaded, in tension, in compression, and the shear block; middle z layer."""
    cfg = settings.checked_values(config_path)
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
    cfg = settings.checked_values(config_path)
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
    finish(fig, outputs, (a, "upper left", dict(xlabel="indentation delta [um]", ylabel="load per unit thickness [MN/m]",
                                               title="(a) total load")),
           (b, "upper left", dict(xlabel="indentation delta [um]", ylabel="peak contact pressure [GPa]",
                                  title="(b) peak pressure")))


def vessel_figure(config_path, runs, outputs):
    """Fig. 7 analogue: (a) the ring's inner-wall radial displacement against time (undamped, from rest)
    per variant, the settled value, Lame's and the paper's 58.7 us; (b) the SPH water's mean pressure
    (variant water_particles); (c) the settled ring (pressure_load)."""
    cfg = settings.checked_values(config_path)
    vs = {var: d for (case, var), d in read_runs(runs).items() if case == "vessel"}
    fig, (a, b, c) = plt.subplots(1, 3, figsize=(13, 4.4), gridspec_kw={"width_ratios": [1.6, 1.1, 1]})
    one = lambda ds, k: float(ds[k].values.ravel()[0])  # noqa: E731
    ds0 = next(iter(vs.values()))
    t_paper = one(ds0, "t_paper") * 1e6
    for var, ds in sorted(vs.items()):
        v = variant_of("solid", var)
        t, u = ds["time"].values * 1e6, ds["u_inner_t"].values * 1e4
        a.plot(t, u, color=v.colour, lw=1.1, label=f"{var}: inner particles (mean)")
        a.plot([t_paper], [one(ds, "u_paper_end") * 1e4], "o", color=v.colour, ms=5)
        if var == "pressure_load":
            a.axhline(one(ds, "u_inner_settled") * 1e4, color=v.colour, ls="--", lw=1,
                      label=f"{var}: settled (kinetic damping)")
        else:
            a.axhline(one(ds, "u_inner_mean_cycles") * 1e4, color=v.colour, ls="--", lw=1,
                      label=f"{var}: mean over whole cycles")
            a.axhline(one(ds, "u_lame_compressible") * 1e4, color="0.45", ls=":", lw=1.4,
                      label="Lame at the pressure the water keeps")
            b.plot(t, ds["p_water_t"].values / 1e-4 / 1e3, color=v.colour, lw=1.1, label="mean water pressure")
            b.axhline(one(ds, "p_equilibrium") / 1e-4 / 1e3, color="0.45", ls=":", lw=1.4,
                      label="p0 / (1 + 2 K u_L / (a p0))")
            b.axhline(cfg["vessel"]["pressure_Pa"] / 1e3, color=THEORY, lw=1.2, label="p0 (paper: 101,135 Pa)")
    a.axhline(one(ds0, "u_lame_inner") * 1e4, color=THEORY, lw=1.4, label="Lame thick cylinder at p0")
    for ax in (a, b):
        ax.axvline(t_paper, color=PAPER, ls="-.", lw=1.2, label=f"paper's run: {cfg['vessel']['steps']} x "
                   f"{cfg['vessel']['dt_ns']:g} ns = {t_paper:.1f} us")
        ax.set_xlim(0, float(ds0["time"].values.max() * 1e6))
        ax.set_xlabel("time since the start from rest [us]")
    a.set(ylabel="radial displacement [um]", title="(a) ring inner wall against time")
    a.set_ylim(0.0 if a.get_ylim()[0] > -0.1 else None, a.get_ylim()[1] * 1.45)
    a.legend(fontsize=6, loc="upper right", ncol=2)
    b.set(ylabel="pressure [kPa]", title="(b) SPH water pressure (water_particles)")
    lo, hi = b.get_ylim()
    b.set_ylim(lo - 0.75 * (hi - lo), hi)
    b.legend(fontsize=6, loc="lower right")
    ds = vs.get("pressure_load", ds0)
    p0, p = ds["pos0"].values, ds["pos"].values
    r = np.hypot(p0[:, 0], p0[:, 1])
    ur = ((p - p0) * p0 / r[:, None]).sum(1) * 1e4
    sc = c.scatter(p0[:, 0], p0[:, 1], c=ur, s=7, marker="s", cmap="viridis")
    fig.colorbar(sc, ax=c, label="radial displacement [um]", shrink=0.8)
    c.set_aspect("equal")
    c.set(xlabel="x [cm]", ylabel="y [cm]", title=f"(c) settled ring ({ds.attrs['variant']})")
    fig.tight_layout()
    save(fig, outputs)


def floor_figure(config_path, runs, outputs):
    """Elastic floor: (a) deflection of the plate's middle row per load source against beam theory,
    (b) the nodal loads, summed from x = 0."""
    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4.4))
    first, used = True, set()
    for (case, var), ds in sorted(read_runs(runs).items()):
        if not case.startswith("floor_"):
            continue
        x = ds["x_mid"].values
        if first:
            a.plot(x, ds["w_theory_uniform"].values * 10, color="k", lw=1.6,
                   label="Euler-Bernoulli, uniform W / span")
            first = False
        if var == "oneway":
            src = variant_of(ds.attrs["load_method"], ds.attrs["load_variant"])
            colour, marker, name = src.colour, src.marker, f"{ds.attrs['load_method']} {ds.attrs['load_variant']}"
        else:
            v = variant_of("solid", var)
            colour, marker, name = v.colour, v.marker, "uniform W / span"
        if to_hex(colour) in used:  # two methods' registry colours coincide (isa paper, mps standard): next free
            colour = next(c for c in (to_hex(f"C{i}") for i in range(10)) if c not in used)
        used.add(to_hex(colour))
        a.plot(x[::4], ds["w_mid"].values[::4] * 10, marker, ms=3.5, ls="none", color=colour,
               label=f"plate, loads: {name}")
        a.plot(x, ds["w_theory_actual"].values * 10, ls="--", lw=0.9, color=colour,
               label=f"beam theory, loads: {name}")
        b.plot(x, np.cumsum(ds["nodal_load"].values), color=colour, lw=1.2, label=name)
    a.invert_yaxis()
    finish(fig, outputs, (a, "upper center", dict(xlabel="x [cm]", ylabel="deflection (down) [mm]",
                                                 title="(a) plate deflection, middle row")),
           (b, "upper left", dict(xlabel="x [cm]", ylabel="floor load from x = 0 to x [N per cm thickness]",
                                  title="(b) applied floor load, cumulative")))


def pair_of(first, second):
    """A workflow entry point (cfg: the settings file, runs, outputs) drawing two figures: outputs are first's
    [png, pdf], then second's."""

    def both(cfg, runs, outputs):
        first(cfg, runs, outputs[:2])
        second(cfg, runs, outputs[2:])

    return both


bar_and_hertz = pair_of(bar_figure, hertz_figure)
vessel_and_floor = pair_of(vessel_figure, floor_figure)
