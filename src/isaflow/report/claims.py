"""The claims part of docs/replication.md: the first screen per paper, the separately counted lists, and the
closing note.

The first screen of a paper holds its **method results** only, each with its verdict and whether the verdict is
robust or fragile (isaflow.claims.robustness), and the findings that matter most (the registry's ``findings``,
each with its figure).  Rows that share a root cause (``depends_on``, isaflow.claims_registry.roots) are
grouped under it and the cause is counted once: the headline's units are the method results without
``depends_on`` and every other root that method results depend on.  Paper inconsistencies, paper arithmetic,
input rules, rows that hold by construction, the project's deviations and its checks are counted in lists of
their own, never in a paper's method-result headline.  :func:`headline` is the one count; the test recounts it
from the registry and the judged tables by kind.

Nothing here computes a verdict: the verdicts, robustness classes and measurements come from the claims rule's
tables (results/claims/registry/<paper>.csv); the registry adds only its data (kinds, roots, deviations,
post-hoc marks, findings).
"""

from collections import Counter

from .. import claims_registry
from ..claims import VERDICTS, verdict_class
from ..methods import papers

PAPERS = papers()
ORDER = (VERDICTS[0], VERDICTS[1], VERDICTS[2], VERDICTS[3])  # reproduced, calibrated, not reproduced, not testable
FIRST = (VERDICTS[2], VERDICTS[1], VERDICTS[0], VERDICTS[3])  # the first screen's rows: failures first
SHORT = {VERDICTS[0]: "reproduced", VERDICTS[1]: "calibrated", VERDICTS[2]: "not reproduced",
         VERDICTS[3]: "not testable"}
# what a verdict means for the kinds that are not method results (display only; the classes are the verdict's)
MEANING = {
    "paper inconsistency": {VERDICTS[2]: "inconsistency found", VERDICTS[0]: "consistent"},
    "paper arithmetic": {VERDICTS[0]: "arithmetic holds", VERDICTS[2]: "arithmetic does not hold"},
    "input rule": {VERDICTS[0]: "followed", VERDICTS[2]: "not followed"},
    "holds by construction": {VERDICTS[0]: "holds", VERDICTS[2]: "does not hold"},
    "project deviation": {VERDICTS[0]: "paper's version run: the claim holds on it",
                          VERDICTS[2]: "paper's version run: the claim fails on it",
                          VERDICTS[3]: "paper's version not run"},
    "project check": {VERDICTS[0]: "passes", VERDICTS[2]: "fails"},
}
LISTS = (("paper inconsistency", "Paper inconsistencies found"), ("paper arithmetic", "Paper arithmetic"),
         ("input rule", "Input rules and copied inputs"), ("holds by construction", "Holds by construction"),
         ("project deviation", "Deviations of this project"), ("project check", "Project checks"))
SURFACE = ("**One convention per quantity.** The free surface of a particle method is its top particle centres "
           "(mean over strips one spacing wide) plus half its layer pitch (dy of a square lattice, l0 for MPS, a / 2 "
           "for ISA's rhombic lattice, so +a/4): a lattice of layers of pitch d filling [0, h] has its surface at h. "
           "Every claims row, every figure and the methods comparison read a surface this way; the paper's own "
           "level readings are the input `level_definition` (top centres alone, the reading the k_p calibration "
           "used; + a/2, the paper's y_in = 100 cm for a top row at 95 cm), swept. Time to rest of a dynamic run "
           "is counted from the start of that run (the release of its liquid: the opening for a flow), in every "
           "method.")


def _rows(df):
    return {r["id"]: r for _, r in df.iterrows()}


def units(df, registry):
    """{paper: [unit]} of the headline: a unit is a method result without depends_on, or a root (of any kind)
    that method results depend on; unit = dict(id, kind, verdict class, robustness, members: [ids of the method
    results grouped under it], row)."""
    rows = _rows(df)
    root = claims_registry.roots(registry)
    kind = {c["id"]: c["kind"] for c in registry}
    out = {}
    for c in registry:
        if c["kind"] != "method result" or c["id"] not in rows:
            continue
        targets = [c["id"]] if not c.get("depends_on") else list(root[c["id"]])
        if len(targets) > 1:  # an aggregate over several roots: grouped under those that share its verdict
            mine = verdict_class(rows[c["id"]]["verdict"])
            same = [t for t in targets if kind[t] != "method result" or t not in rows
                    or verdict_class(rows[t]["verdict"]) == mine]
            targets = same or targets[:1]
        for t in targets:
            lst = out.setdefault(c["paper"], {})
            u = lst.setdefault(t, dict(id=t, kind=kind[t], members=[], row=rows.get(t)))
            if t != c["id"]:
                u["members"].append(c["id"])
    for paper, lst in out.items():
        for u in lst.values():
            own = [rows[m] for m in u["members"]]
            u["own"] = own
            if u["kind"] == "method result" and u["row"] is not None:
                u["verdict"] = verdict_class(u["row"]["verdict"])
                u["robustness"] = _worst([u["row"]["robustness"]] + [r["robustness"] for r in own])
            else:  # a cause outside the method results: the verdict its method results share
                classes = Counter(verdict_class(r["verdict"]) for r in own)
                u["verdict"] = VERDICTS[2] if classes[VERDICTS[2]] else classes.most_common(1)[0][0]
                u["robustness"] = _worst([r["robustness"] for r in own])
        out[paper] = list(lst.values())
    return out


def cell(x, limit=None):
    """Text for one Markdown table cell (one line, pipes escaped, cut at limit characters)."""
    text = " ".join(str(x).split()).replace("|", "\\|")
    return text if limit is None or len(text) <= limit else text[:limit - 3].rstrip() + "..."


def _worst(classes):
    """A group is fragile if any of its rows is, else unswept if any is, else robust."""
    return next((k for k in ("fragile", "unswept") if k in classes), "robust")


def headline(df, registry):
    """{paper: Counter}: the headline's units by verdict class and by robustness ('robust', 'fragile', 'unswept'),
    'units', 'rows' (the method results), and 'grouped' (method results counted under a shared cause)."""
    out = {}
    for paper, us in units(df, registry).items():
        c = Counter(u["verdict"] for u in us)
        c.update(u["robustness"] for u in us)
        c["units"] = len(us)
        c["rows"] = sum(1 for x in registry if x["paper"] == paper and x["kind"] == "method result")
        c["grouped"] = len({m for u in us for m in u["members"]})
        out[paper] = c
    return out


def _verdict_cell(r):
    flips = f" ({cell(r['flips'], 120)})" if r["robustness"] == "fragile" and r["flips"] else ""
    return f"**{cell(r['verdict'])}**", f"{r['robustness']}{flips}"


def _rows_word(n):
    return f"{n} row" + ("" if n == 1 else "s")


def _unit_line(u):
    """One table row of the first screen: a method result (with the rows grouped under it) or a root cause outside
    the method results (the rows that fail for it)."""
    r = u["row"]
    if u["kind"] == "method result" and r is not None:
        v, rb = _verdict_cell(r)
        if u["robustness"] != r["robustness"]:
            rb = f"{rb}; the group: {_group_robustness(u)}"
        same = f" (+ {_rows_word(len(u['members']))}, same cause: {', '.join(f'`{m}`' for m in u['members'])})" \
            if u["members"] else ""
        return f"| `{r['id']}` \"{cell(r['claim'], 70)}\"{same} | {cell(r['measured'], 110)} | {v} | {rb} |"
    what = cell(r["measured"], 110) if r is not None else ""
    return (f"| {len(u['members'])} rows for one cause, `{u['id']}` ({u['kind']}): "
            f"{', '.join(f'`{m}`' for m in u['members'])} | {what} | **{u['verdict']}** | {_group_robustness(u)} |")


def _group_robustness(u):
    """The group's class, with the rows that make it fragile or unswept and where they flip."""
    odd = [m for m in u["own"] if m["robustness"] != "robust"]
    if not odd:
        return u["robustness"]
    return f"{u['robustness']} (" + "; ".join(f"`{m['id']}` {m['robustness']}" + (f": {cell(m['flips'], 90)}" if
                                                                                   m["flips"] else "")
                                             for m in odd) + ")"


def first_screen(paper, df, registry, findings):
    """Markdown lines: one paper's first screen (fits on a page: short cells; the untestable ones on one line)."""
    us = units(df, registry).get(paper, [])
    head = headline(df, registry).get(paper, Counter())
    rows = _rows(df)
    label = PAPERS.get(paper, paper)
    lines = [f"### {label}", ""]
    if not us:
        lines += ["No method results: every row of this paper is arithmetic, an input rule, an inconsistency found "
                  "or a deviation of this project (the lists below).", ""]
    else:
        parts = ", ".join(f"{head[k]} {SHORT[k]}" for k in ORDER if head[k])
        rob = ", ".join(f"{head[k]} {k}" for k in ("robust", "fragile", "unswept") if head[k])
        grouped = (f" ({head['grouped']} rows that share a root cause are counted once, under it.)"
                   if head["grouped"] else "")
        lines += [f"Method results: {head['rows']} rows, counted as {head['units']}: {parts}; {rob}.{grouped}", "",
                  "| claim (quoted) | what we measured | verdict | robust / fragile |", "|---|---|---|---|"]
        tested = [u for u in us if u["verdict"] != VERDICTS[3]]
        for u in sorted(tested, key=lambda u: (FIRST.index(u["verdict"]), u["id"])):
            lines.append(_unit_line(u))
        untested = [u for u in us if u["verdict"] == VERDICTS[3]]
        lines.append("")
        if untested:
            ids = ", ".join(f"`{u['id']}`" + (f" (+ {len(u['members'])})" if u["members"] else "") for u in untested)
            lines += [f"Not testable here ({len(untested)}): {ids}; why: the full rows below.", ""]
    apart = Counter(c["kind"] for c in registry if c["paper"] == paper and c["kind"] != "method result")
    if apart:
        lines += ["Counted apart (the lists below): " + ", ".join(
            f"{apart[k]} {t.lower()}" for k, t in LISTS if apart[k]) + ".", ""]
    found = [f for f in findings.get(paper, [])]
    if found:
        lines += ["The findings that matter:", ""]
        for k, f in enumerate(found, 1):
            lead = rows.get(f["claims"][0])
            state = f" (`{lead['id']}`: {cell(lead['verdict'])}, {lead['robustness']})" if lead is not None else ""
            lines.append(f"{k}. **{cell(f['title'])}**{state}. {cell(f['text'])} "
                         f"Figure: [`{f['figure']}`](../{f['figure']}).")
        lines.append("")
    return lines


def lists(df, registry):
    """Markdown lines: the rows that are no method results, one counted list per kind (over every paper)."""
    by_id = {c["id"]: c for c in registry}
    out = ["## Besides the method results: inconsistencies, arithmetic, inputs, deviations, checks", "",
           "Counted separately and never in a paper's method-result headline."]
    counts = Counter(c["kind"] for c in registry)
    out += ["", "| list | " + " | ".join(title for _, title in LISTS) + " |",
            "|---|" + "---|" * len(LISTS),
            "| rows | " + " | ".join(str(counts[k]) for k, _ in LISTS) + " |", ""]
    for kind, title in LISTS:
        sub = df[df["kind"] == kind]
        cls = Counter(MEANING[kind].get(verdict_class(v), verdict_class(v)) for v in sub["verdict"])
        out += [f"### {title} ({len(sub)}: " + ", ".join(f"{n} {k}" for k, n in cls.items()) + ")", ""]
        for _, r in sub.iterrows():
            what = MEANING[kind].get(verdict_class(r["verdict"]), r["verdict"])
            quote = f"\"{cell(r['claim'], 100)}\" " if r["claim"] else ""
            if kind == "project deviation":
                d = by_id[r["id"]]["deviation"]
                out.append(f"- **`{r['id']}`** ({PAPERS.get(r['paper'], r['paper'])}). Paper: {cell(d['paper'])} "
                           f"Project: {cell(d['project'])} Why: {cell(d['why'])} Paper's version: "
                           f"{cell(d['paper_version'])} **{what}**: {cell(r['measured'], 260)} ({r['robustness']})")
            else:
                out.append(f"- `{r['id']}` {quote}**{what}** ({r['robustness']}): {cell(r['measured'], 200)}")
        out.append("")
    return out


def post_hoc(registry):
    """[(id, commit, seen, note)] of every tolerance marked as chosen after its measured value was printed."""
    return [(c["id"], c["tolerance"]["post_hoc"]["commit"], c["tolerance"]["post_hoc"]["seen"],
             c["tolerance"]["post_hoc"].get("note", "")) for c in registry
            if c.get("testable") and "post_hoc" in c.get("tolerance", {})]


def opening(df, registry):
    """The first paragraph of the claims part: what the first screen holds, and exactly which tolerances were
    chosen after their measured values had been printed."""
    marked = post_hoc(registry)
    testable = sum(1 for c in registry if c.get("testable"))
    ids = ", ".join(f"`{i}` ({c})" for i, c, _, _ in marked)
    return [
        "Every claim is a row of the claims registry (`config/claims/<paper>.yaml`: the quote, its kind, the quantity, "
        "the tolerance with its derivation, the runs, the inferred inputs it rests on); the claims rule measures it on "
        "the run files and computes its verdict (`isaflow.claims.verdict`): `reproduced`, `reproduced only after "
        "calibrating <input>` (an input was chosen to match that very number), `not reproduced`, `not testable here`. "
        "A verdict is **robust** when it holds at both ends of every inferred input it rests on, **fragile** when a "
        "value of an input's range flips it (the input and the values are named); the evidence is in the full rows "
        "(`results/claims/registry/<paper>.csv`, column `robustness_evidence`), and "
        "[`figures/claims_robustness.png`](../figures/claims_robustness.png) draws where each fragile method result "
        "flips. Rows decided by this project's own choices are deviations of this project, listed apart and never "
        "scored against a paper; where the paper's version could be run the claim is judged on it.",
        "",
        f"**Tolerances.** Of the {testable} testable rows' tolerances, {len(marked)} were chosen after the measured "
        "value had been printed and are marked post hoc in their rows (with the commit that set them): "
        f"{ids or 'none'}. Every other tolerance was derived from the sentence quoted (its wording or printed "
        "precision) and the discretisation, physics, statistics or round-off named in its `source` field.",
        "",
        SURFACE,
        "",
    ]


def closing(df, registry, figures=None):
    """The closing note: every verdict changed by issue 31 and why, every post-hoc tolerance, the figures viewed."""
    rows = _rows(df)
    out = ["## Closing note: verdicts changed, tolerances set after the fact, figures viewed", ""]
    changed = [c for c in registry if "changed" in c]
    out += [f"**Verdicts changed ({len(changed)}).** Each row's verdict at the commit named and now (computed by "
            "this run), and why:", ""]
    for c in changed:
        ch = c["changed"]
        now = rows[c["id"]]["verdict"] if c["id"] in rows else "not judged"
        out.append(f"- `{c['id']}` ({c['kind']}): was **{cell(ch['was'])}** ({ch['commit']}), now **{cell(now)}**. "
                   f"{cell(ch['why'])}")
    marked = post_hoc(registry)
    out += ["", f"**Tolerances marked post hoc ({len(marked)}).**", ""]
    out += [f"- `{i}` ({commit}): seen {cell(seen)}" + (f"; {cell(note)}" if note else "") for i, commit, seen, note
            in marked]
    if figures:
        viewed = [(n, f) for n, f in figures.items() if f.get("viewed")]
        out += ["", f"**Figures viewed ({len(viewed)} of the {len(figures)} with a caption).** Each was opened as a "
                "picture; what it shows:", ""]
        out += [f"- `figures/{n}.png` (viewed {f['viewed']['date']}): {cell(f['viewed']['shows'])}" for n, f in viewed]
    out.append("")
    return out
