"""Where each fragile verdict flips: one picture of every fragile method result's sweep (the claims rule's tables,
results/claims/registry/<paper>.csv, column ``sweep``).

One line per (row, inferred input it flips in): a cell per value of the input's range, in range order, green where
the quoted claim's test passes, red where it fails, grey where no run stands for that value; the value the row is
judged at is outlined.  The verdict and the row's id label each line.
"""

import json
import textwrap
from pathlib import Path

import pandas as pd

from .style import plt, save

COLOURS = {True: "#8fd18f", False: "#f08a8a", None: "#dddddd"}


def _lines(tables):
    """[(paper, id, verdict, input, [(label, passed)])] of every fragile method result, per input it flips in."""
    out = []
    for path in tables:
        df = pd.read_csv(path, keep_default_na=False)
        rows = df[(df["kind"] == "method result") & (df["robustness"] == "fragile")]
        for _, r in rows.iterrows():
            sweep = json.loads(r["sweep"] or "[]")
            flipped = [f.split(":")[0].strip() for f in str(r["flips"]).split(";") if f.strip()]
            for name in flipped:
                vals = [(label, passed) for i, label, passed in sweep if i == name]
                if vals:
                    out.append((r["paper"], r["id"], r["verdict"], name, vals))
    return out


def judged_at(vals, kept_text=""):
    """Index of the value a row is judged at among [(label, passed)]: the one labelled 'judged' (an input whose
    paper's version is run), else the one labelled 'kept', else the one the registry's kept text starts with."""
    for word in ("judged", "kept"):
        hit = [k for k, (label, _) in enumerate(vals) if word in label.lower()]
        if hit:
            return hit[0]
    return next((k for k, (label, _) in enumerate(vals) if kept_text.startswith(label.split(" (")[0])), None)


def robustness_figure(tables, outputs, registry=()):
    """tables: the claims rule's per-paper CSVs; registry: the claims registry's files (each input's kept value);
    outputs: [png, pdf]."""
    from ..claims_registry import inputs

    kept = {i["id"]: str(i.get("kept", "")) for lst in (inputs(Path(registry[0]).parent) if registry else {}).values()
            for i in lst}
    lines = _lines(tables)
    width = max((len(v) for *_, v in lines), default=1)
    fig, ax = plt.subplots(figsize=(4.5 + 2.3 * width, 0.42 * len(lines) + 1.4))
    for y, (paper, cid, verdict, name, vals) in enumerate(lines):
        at = judged_at(vals, kept.get(name, ""))
        for x, (label, passed) in enumerate(vals):
            ax.add_patch(plt.Rectangle((x + 0.03, -y - 0.42), 0.94, 0.84, fc=COLOURS[passed],
                                       ec="k" if x == at else "none", lw=1.6 if x == at else 0))
            ax.text(x + 0.5, -y, "\n".join(textwrap.wrap(label, 34, max_lines=2, placeholder="...")),
                    ha="center", va="center", fontsize=6.2)
        ax.text(-0.1, -y, f"{cid}: {verdict}\n{name}", ha="right", va="center", fontsize=7)
    ax.set_xlim(-0.05, width)
    ax.set_ylim(-len(lines) + 0.4, 0.6)
    ax.axis("off")
    handles = [plt.Rectangle((0, 0), 1, 1, color=c) for c in COLOURS.values()]
    ax.legend(handles + [plt.Rectangle((0, 0), 1, 1, fc="white", ec="k", lw=1.6)],
              ["the quoted claim's test passes", "fails", "no run for this value", "the value the row is judged at"],
              loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=4, fontsize=7, frameon=False)
    ax.set_title("Where each fragile method result flips: its test at every value of the inferred input "
                 "(config/claims/<paper>.yaml ranges)", fontsize=9, pad=22)
    save(fig, outputs)
