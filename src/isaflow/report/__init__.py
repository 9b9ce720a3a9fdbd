"""docs/replication.md, assembled from fragments the workflow generates.

Each part of the workflow writes a Markdown fragment under results/report/ (here:
``inferred``, the inferred inputs, and ``methods``, the methods' comparison; every method
its own, e.g. methods/isa/report/ ``single``, ``flow``, ``study``); :func:`assemble` puts
the claims part first (``claims``, from the claims rule's tables) and joins the fragments
in name order under a generated header.  ``speed`` assembles docs/timing.md from the
timing fragments.  Nothing in docs/replication.md is typed by hand.
"""

from pathlib import Path

import numpy as np
import pandas as pd

from .. import claims_registry
from ..claims import VERDICTS, verdict_class as _verdict_class
from ..html import page
from ..methods import papers
from . import claims as RC
from .claims import cell as _cell


def md_table(df, floatfmt="{:.4g}"):
    """Markdown table of a DataFrame (no index); NaN as an empty cell."""
    cols = list(df.columns)
    out = ["| " + " | ".join(str(c) for c in cols) + " |", "|" + "---|" * len(cols)]
    for _, r in df.iterrows():
        out.append("| " + " | ".join(_fmt(r[c], floatfmt) for c in cols) + " |")
    return "\n".join(out)


def _fmt(v, floatfmt="{:.4g}"):
    if isinstance(v, (float, np.floating)):
        return "" if np.isnan(v) else floatfmt.format(v)
    return str(v)


def write(lines, out):
    """Write a fragment (list of lines) to out, creating its folder."""
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    Path(out).write_text("\n".join(lines) + "\n")


def verdict(diff, tol, note=""):
    """'agrees' when |diff| <= tol, else 'differs' (with the note's reason)."""
    if diff is None or tol is None:
        return note or "n/a"
    ok = abs(diff) <= tol
    return ("agrees" if ok else "differs") + f" (tol {tol:.3g})" + (f"; {note}" if note and not ok else "")


def comparison(quantity, paper, ours, diff, tol=None, note=""):
    return {"quantity": quantity, "paper": paper, "ours": ours, "difference": diff if diff is not None else "",
            "verdict": verdict(diff, tol, note)}


PAPERS = papers()  # {paper id: label}, from the method registry


def claims_frame(claims):
    """The claims rule's judged tables (results/claims/registry/<paper>.csv: isaflow.claims.COLUMNS) as one
    table, in the registry's paper order (the paper replicated first), rows in file order."""
    import pandas as pd

    frames = [pd.read_csv(c, keep_default_na=False) for c in claims]
    df = pd.concat([f for f in frames if len(f)], ignore_index=True)
    order = {p: i for i, p in enumerate(PAPERS)}
    df["_p"] = df["paper"].map(lambda p: order.get(p, len(order)))
    return df.sort_values("_p", kind="stable").drop(columns="_p")


def counts_table(counts):
    """Markdown: claims per paper and kind by verdict class (the claims rule's counts.csv)."""
    import pandas as pd

    c = pd.read_csv(counts)
    cols = [v for v in VERDICTS if v in c.columns]
    lines = ["| paper | kind | " + " | ".join(cols) + " | total |", "|---|---|" + "---|" * (len(cols) + 1)]
    for _, r in c.iterrows():
        n = [int(r[k]) for k in cols]
        lines.append(f"| {PAPERS.get(r['paper'], r['paper'])} | {r['kind']} | " + " | ".join(map(str, n))
                     + f" | {sum(n)} |")
    return "\n".join(lines)


def claims_table(df):
    """Markdown claims table of one paper: id and section | kind | claim (quoted) | what we measured | verdict |
    robust / fragile."""
    lines = ["| claim id, section | kind | claim (quoted) | what we measured | verdict | robust / fragile |",
             "|---|---|---|---|---|---|"]
    for _, r in df.iterrows():
        quote = f"\"{_cell(r['claim'])}\"" if r["claim"] else "(project check)"
        rob = r.get("robustness", "") + (f": {_cell(r['flips'])}" if r.get("flips") else "")
        lines.append(f"| `{r['id']}` {_cell(r['section'])} | {r['kind']} | {quote} | {_cell(r['measured'])} | "
                     f"**{_cell(r['verdict'])}** | {rob} |")
    return "\n".join(lines)


def changes(df, registry=None):
    """Markdown list: every registry entry that replaces a row of the former 42-row table ('was'), with what
    changed and its verdict now."""
    now = dict(zip(df["id"], df["verdict"]))
    out = []
    for e in claims_registry.load(registry or claims_registry.DEFAULT_DIRECTORY):
        if "was" in e:
            out.append(f"- `{e['id']}` (now **{now.get(e['id'], 'not judged')}**): was \"{_cell(e['was']['row'], 160)}\"; "
                       f"{_cell(e['was']['changes'])}")
    return out


def assemble(parts, claims, counts, findings, outputs, registry=None, figures=None, baseline=None):
    """docs/replication.md: the first screen per paper (method results with robust / fragile, the findings that
    matter), the separately counted lists, every row by paper (counts by kind, one table per paper), why not
    reproduced, what changed from the former table, the findings, the fragments in name order, and the closing
    note.  registry: the claims registry folder (default config/claims); figures: workflow/report/figures.yaml
    (the figures viewed)."""

    df = claims_frame(claims)
    if isinstance(registry, (list, tuple)):  # the rule's input: the registry's files
        registry = str(Path(registry[0]).parent)
    reg = claims_registry.load(registry or claims_registry.DEFAULT_DIRECTORY)
    files = claims_registry.load_files(registry or claims_registry.DEFAULT_DIRECTORY)
    found = {p: spec.get("findings", []) for p, spec in files.items()}
    head = ["# Replication report: Papadopoulos, Koutitas & Lazaridis (2016) and its neighbours", "",
            "Generated by the workflow (`snakemake -c2`) from run files; do not edit by hand. Units: cm, N, s. "
            "Timings live in [`docs/timing.md`](timing.md).", "",
            "## Claims: the first screen, per paper", ""] + RC.opening(df, reg)
    for paper in PAPERS:
        head += RC.first_screen(paper, df, reg, found)
    head += RC.lists(df, reg)
    head += ["## Every row, by paper", "", RC.SURFACE, "", "### Counts by paper and kind", "", counts_table(counts), ""]
    for paper, g in df.groupby("paper", sort=False):
        head += [f"### {PAPERS.get(paper, paper)}: every row", "", claims_table(g), ""]
    why = df[df["verdict"].map(_verdict_class).eq(VERDICTS[2]) & df["why"].astype(bool)]
    if len(why):
        head += ["## Why not reproduced", ""]
        head += [f"- **`{r['id']}`** ({_cell(r['claim'], 80) or 'project check'}): {_cell(r['why'])}"
                 for _, r in why.iterrows()]
        head.append("")
    moved = changes(df, registry)
    if moved:
        head += ["## What changed from the former claims table", "",
                 f"{len(moved)} registry rows replace rows of the former 42-row table (docs/claims_audit.md); the "
                 "methods-comparison rows are judged on the fixed measure (one surface: top centres plus half a "
                 "spacing; errors against the tank's W, h and rho g, and separately against the method's own "
                 "depth).", ""]
        head += moved + [""]
    head += [Path(findings).read_text().strip(), ""]
    body = [Path(f).read_text() for f in sorted(parts, key=lambda p: Path(p).name)]
    figs = None
    if figures:
        from ..inputs import read_yaml

        figs = read_yaml(figures)[1]
    base = pd.read_csv(baseline) if baseline else None
    text = "\n".join(head + body + RC.closing(df, reg, figs, base))
    Path(outputs[0]).parent.mkdir(parents=True, exist_ok=True)
    Path(outputs[0]).write_text(text)
    if len(outputs) > 1:  # the same report as an HTML page (the Snakemake report shows it inline)
        write_html(text, outputs[1], "Replication report")


def write_html(markdown_text, out, title):
    """A self-contained HTML page of a Markdown text (tables rendered)."""
    import markdown

    Path(out).parent.mkdir(parents=True, exist_ok=True)
    Path(out).write_text(page(title, markdown.markdown(markdown_text, extensions=["tables"])))

