"""Shared figure helpers: saving, wall drawing, variant labels."""

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

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
LATTICE_MARKER = {"coarse": "o", "refined": "s", "fine": "^", "finer": "D"}


def variant_style(method, variant):
    """(colour, label) of a method's variant, from the registry."""
    from ..methods import variant as lookup

    v = lookup(method, variant)
    return v.colour, v.label


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
    """One line naming the scene, the algorithm variant and the outcome."""
    a = ds.attrs
    return f"scene {a['scene']} | {a['variant_label']} | {a['status']}: {a['status_message']}"
