"""Shared figure helpers: saving, wall drawing, variant labels."""

from pathlib import Path

import numpy as np

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from ..core import fixed_order as FO  # noqa: E402

plt.rcParams.update({"font.size": 9, "axes.titlesize": 9, "figure.dpi": 110, "savefig.dpi": 150})

COMPUTED, THEORY, PAPER = "tab:blue", "tab:orange", "tab:red"
# colour and marker of each outcome (contract.OUTCOMES); method/variant colours live in the registry
OUTCOME_STYLE = {
    "converged": ("tab:green", "o"),
    "cycle": ("tab:blue", "s"),
    "step_limit": ("tab:orange", "^"),
    "escaped": ("tab:red", "X"),
    "nonfinite": ("k", "*"),
    "solver_failed": ("tab:brown", "P"),
}


def variant_style(method, variant):
    """(colour, label) of a method's variant, from the registry."""
    from ..methods import variant as lookup

    v = lookup(method, variant)
    return v.colour, v.label


def method_marker(method):
    """Marker of a method where methods share a figure (the registry's)."""
    from ..methods import get

    return get(method).marker


def case_name(ds):
    """'<tank>_<resolution>' of a run file (e.g. single_coarse): one name per tank and resolution."""
    return f"{ds.attrs['tank']}_{ds.attrs['resolution']}"


def save(fig, outputs):
    """Write fig to every output path (PNG, PDF), creating folders."""
    for out in outputs:
        Path(out).parent.mkdir(parents=True, exist_ok=True)
        # no creation date in PDFs: two runs of the same commit give the same bytes
        meta = {"CreationDate": None} if str(out).endswith(".pdf") else {}
        fig.savefig(out, bbox_inches="tight", metadata=meta)
    plt.close(fig)


def draw_walls(ax, ds, **kw):
    """Draw the wall segments of a run Dataset."""
    for x0, y0, x1, y1 in ds["wall_segment"].values:
        ax.plot([x0, x1], [y0, y1], color="k", lw=2.5, solid_capstyle="butt", **kw)


def run_caption(ds):
    """One line naming the run, its tank, the algorithm variant and the outcome."""
    a = ds.attrs
    return f"run {a.get('run_id', '')} on tank {a['tank']} | {a['variant_label']} | {a['status']}: {a['status_message']}"


# ---- shared helpers for readable figures -------------------------------------------------
OURS_LEVEL = dict(color=COMPUTED, ls="-", lw=1.2)  # our measured level / surface
PAPER_LEVEL = dict(color=PAPER, ls=(0, (5, 3)), lw=1.6)  # a level the paper measured
PAPER_EXPECTED = dict(color="tab:purple", ls=(0, (1, 2)), lw=1.8)  # a level the paper computed
LABEL_BOX = dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.85)
CALIBRATED = "k_p calibrated to match the paper's level with the top centres (config/inferred.yaml)"


def state_phrase(ds):
    """What the drawn positions are: 'state at the detected cycle, step N' for a cycle,
    'converged state, step N', 'state at the step limit, step N', ... (from the run's status)."""
    st, n = ds.attrs["status"], int(ds["steps"])
    return {
        "converged": f"converged state, step {n:,}",
        "cycle": f"state at the detected cycle, step {n:,}",
        "step_limit": f"state at the step limit, step {n:,}",
    }.get(st, f"last state ({st}), step {n:,}")


def nice_value(x):
    """Largest 1, 2 or 5 x 10^k not above x (for scale bars)."""
    k = np.floor(np.log10(x))
    return max(m * 10**k for m in (1, 2, 5) if m * 10**k <= x)


def scale_bar(ax, xy, length, label, vertical=False, color="gray", label_right=False):
    """A scale bar of ``length`` data units starting at xy, labelled below it (or right of it)."""
    x, y = xy
    end = (x, y + length) if vertical else (x + length, y)
    ax.plot([x, end[0]], [y, end[1]], color=color, lw=2.2, solid_capstyle="butt")
    if label_right and not vertical:
        ax.text(end[0] + 1.5, y, label, color=color, va="center", ha="left", fontsize=8)
    elif vertical:
        ax.text(x + 1.5, y + length / 2, label, color=color, va="center", ha="left", fontsize=8)
    else:
        ax.text(x + length / 2, y - 1.5, label, color=color, va="top", ha="center", fontsize=8)


def legend_below(ax, ncol=2, **kw):
    """Legend under the axes (never on the data)."""
    return ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.1), ncol=ncol, fontsize=8, frameon=False, **kw)


def surface_line(ax, ds, vessel, color, name=None):
    """Draw the measured free surface of a vessel: the top particle of each strip of width a
    (theory.surface_profile) and its least-squares line; the legend entry states slope (deg),
    range (cm) and the mean depth of the one surface (metrics.surface_of: top centres + half the layer
    pitch) from metrics.surface_measures."""
    from .. import metrics, theory

    v = metrics.vessel_view(ds, vessel)
    x, top = theory.surface_profile(ds["pos"].values, float(ds.attrs["spacing"]), v["x_range"])
    if len(x) == 0:
        return None
    s = metrics.surface_measures(ds, vessel)
    depth = metrics.surface_of(ds, vessel) - v["floor_y"]
    ax.plot(x, top, "-", color=color, lw=1.1, drawstyle="steps-mid", zorder=4,
            label=f"top particles, {name or vessel} vessel (per {float(ds.attrs['spacing']):g} cm strip): "
                  f"slope {s['slope_deg']:.1f}°{_falls(s['slope_deg'])}, range {s['surface_range_cm']:.1f} cm; "
                  f"surface (+ half the layer pitch) at mean depth {depth:.1f} cm")
    if len(x) > 1:
        k, c = FO.line(x, top)
        ax.plot(x, k * np.asarray(x) + c, ":", color=color, lw=1, zorder=4)
    return s


def _falls(slope_deg):
    return " (falls to the right)" if slope_deg < 0 else " (rises to the right)" if slope_deg > 0 else ""


def literal_levels(calibration_csv, k_wall=2000, ratio=0.5):
    """{run: level (cm)} of the literal reading k_p = k_b / 2 (ratio 0.5) in results/calibration.csv."""
    import pandas as pd

    t = pd.read_csv(calibration_csv)
    t = t[np.isclose(t["k_wall"], k_wall) & np.isclose(t["ratio"], ratio)]
    return dict(zip(t["run"], t["level"]))
