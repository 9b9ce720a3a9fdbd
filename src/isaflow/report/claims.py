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
    flips = f" ({cell(r['flips'], FLIPS_CELL)})" if r["robustness"] == "fragile" and r["flips"] else ""
    return f"**{SHORT.get(verdict_class(r['verdict']), r['verdict'])}**", f"{r['robustness']}{flips}"


def _short(r):
    return cell(r.get("short") if isinstance(r.get("short"), str) and r.get("short") else r["measured"], SHORT_CELL)


def _unit_line(u):
    """One table row of the first screen: a method result (with how many rows it stands for) or a root cause outside
    the method results."""
    r = u["row"]
    more = f" (+{len(u['members'])})" if u["members"] else ""
    if u["kind"] == "method result" and r is not None:
        v, rb = _verdict_cell(r)
        return f"| `{r['id']}`{more} \"{cell(r['claim'], QUOTE_CELL)}\" | {_short(r)} | {v} | {rb} |"
    what = _short(r) if r is not None else ""
    return f"| `{u['id']}`{more} ({u['kind']}) | {what} | **{SHORT.get(u['verdict'], u['verdict'])}** | {u['robustness']} |"


QUOTE_CELL, SHORT_CELL, FLIPS_CELL = 32, 48, 40  # characters of a first-screen cell (a test counts them)
PAGE_WORDS = 55 * 14  # a paper's first screen fits one printed page: an A4 page of 10 pt holds about 55 lines of
# 14 words, the table one line a row (tests/test_report.py counts its words, images aside)


def status(head):
    """The ReScience-style line of a paper: replicated (every tested method result reproduced), not replicated
    (none), else partly replicated."""
    tested = head["units"] - head[VERDICTS[3]]
    good = head[VERDICTS[0]] + head[VERDICTS[1]]
    return "no method results" if not tested else (
        "replicated" if good == tested else ("not replicated" if good == 0 else "partly replicated"))


def sentence_holds(sentence, rows):
    """True when a finding's sentence is borne out by the judged row it names (its verdict class, and robustness if
    stated); False if contradicted; None if that row was not judged."""
    r = rows.get(sentence["row"])
    if r is None:
        return None
    ok = verdict_class(r["verdict"]) == sentence["verdict"]
    return ok and (sentence.get("robustness") in (None, r["robustness"]))


def first_screen(paper, df, registry, findings):
    """Markdown lines: one paper's first screen, one printed page: its status line with the counts, the findings that
    matter (each sentence checked against the judged row it names, its figure inline), then the method results."""
    us = units(df, registry).get(paper, [])
    head = headline(df, registry).get(paper, Counter())
    rows = _rows(df)
    lines = [f"### {PAPERS.get(paper, paper)}", ""]
    if not us:
        lines += ["No method results: every row is arithmetic, an input rule, an inconsistency found or a deviation "
                  "of this project (the lists below).", ""]
    else:
        parts = ", ".join(f"{head[k]} {SHORT[k]}" for k in ORDER if head[k])
        rob = ", ".join(f"{head[k]} {k}" for k in ("robust", "fragile", "unswept") if head[k])
        lines += [f"**{status(head).capitalize()}** on the paper's version: {head['units']} method results ({parts}; "
                  f"{rob}; of {head['rows']} rows).", ""]
    for k, f in enumerate(findings.get(paper, []), 1):
        said = []
        for snt in f.get("sentences", []):
            ok = sentence_holds(snt, rows)  # its numbers are the row's, in the table below
            said.append(cell(snt["text"]) + ("" if ok else f" *[{'not judged' if ok is None else 'contradicted'} by "
                                                            f"`{snt['row']}`]*"))
        lines += [f"{k}. **{cell(f['title'])}** " + " ".join(said), "",
                  f"   ![{cell(f['title'])}](../{f['figure']})", ""]
    if us:
        lines += ["| claim | measured (paper's version) | verdict | robust |", "|---|---|---|---|"]
        tested = [u for u in us if u["verdict"] != VERDICTS[3]]
        lines += [_unit_line(u) for u in sorted(tested, key=lambda u: (FIRST.index(u["verdict"]), u["id"]))]
        untested = [u for u in us if u["verdict"] == VERDICTS[3]]
        lines.append("")
        if untested:
            ids = ", ".join(f"`{u['id']}`" for u in untested)
            lines += [f"Not testable here: {ids}.", ""]
    apart = Counter(c["kind"] for c in registry if c["paper"] == paper and c["kind"] != "method result")
    if apart:
        lines += ["Apart (below): " + ", ".join(f"{apart[k]} {t.lower()}" for k, t in LISTS if apart[k]) + ".", ""]
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
    """The claims part's first paragraph (short: the first screens follow): what a verdict is judged on, what robust
    means, where the full rows and the post-hoc tolerances are."""
    marked = post_hoc(registry)
    return [
        "Each claim is a row of `config/claims/<paper>.yaml` (quote, kind, checks, tolerance with its derivation), "
        "judged from run files by one judge (`isaflow.judge`) on **the paper's own version** (its stated inputs, update "
        "and stop rule); the project's calibrated or completed runs are shown beside it (columns `kept_verdict`, "
        "`kept_measured`). **Robust**: the verdict holds at every value of each inferred input that is a reading of the "
        f"sentence (runs, not arguments); **fragile**: one flips it. {len(marked)} tolerances were set after their value "
        "was seen (marked post hoc; the closing note lists them). Full rows: `results/claims/registry/<paper>.csv`.",
        "",
    ]


def changes(df, registry, baseline):
    """[(id, was, now, why)]: every row whose kind, verdict class or robustness differs from the baseline table (the
    verdicts at the commit the baseline names, docs/tables/claims_baseline.csv), new rows, and rows gone, with the
    reason its registry row gives (``changed.why``; '' when it gives none: a change no one explained)."""
    if baseline is None:
        return []
    by = {c["id"]: c for c in registry}
    base = {r["id"]: r for _, r in baseline.iterrows()}
    out = []
    for _, r in df.iterrows():
        now = f"{verdict_class(r['verdict'])}; {r['kind']}; {r['robustness']}"
        b = base.get(r["id"])
        was = "new row" if b is None else f"{verdict_class(b['verdict'])}; {b['kind']}; {b['robustness']}"
        if was != now:
            out.append((r["id"], was, now, by.get(r["id"], {}).get("changed", {}).get("why", "")))
    out += [(k, f"{verdict_class(b['verdict'])}; {b['kind']}; {b['robustness']}", "removed", "")
            for k, b in base.items() if k not in set(df["id"])]
    return out


def closing(df, registry, figures=None, baseline=None):
    """The closing note: every verdict, kind or robustness changed since the baseline and why, every post-hoc
    tolerance, which rows are judged at the paper's version and which cannot be, the figures viewed."""
    out = ["## Closing note: what changed, tolerances set after the fact, figures viewed", ""]
    ch = changes(df, registry, baseline)
    since = baseline["commit"].iloc[0] if baseline is not None and "commit" in baseline else "the baseline"
    out += [f"**Changed since {since} ({len(ch)}: verdict; kind; robustness).**", ""]
    out += [f"- `{i}`: was {cell(w)}, now **{cell(n)}**. " + (cell(why) if why else "**unexplained**")
            for i, w, n, why in ch]
    paper = df[df["judged_on"].astype(str).str.startswith("the paper's version")] if "judged_on" in df else df[:0]
    out += ["", f"**Judged at the paper's version ({len(paper)} rows)**: "
            + ", ".join(f"`{i}`" for i in paper["id"]) + ". The other rows read runs no input of the paper changes, or "
            "this project's own runs (deviations and checks, `judged_on: kept`).", ""]
    marked = post_hoc(registry)
    out += [f"**Tolerances marked post hoc ({len(marked)}).**", ""]
    out += [f"- `{i}` ({commit}): seen {cell(seen)}" + (f"; {cell(note)}" if note else "") for i, commit, seen, note
            in marked]
    if figures:
        viewed = [(n, f) for n, f in figures.items() if f.get("viewed")]
        out += ["", f"**Figures viewed ({len(viewed)} of the {len(figures)} with a caption).** Each was opened as a "
                "picture; what it shows:", ""]
        ext = lambda n: "gif" if n.endswith("_animation") else "png"  # noqa: E731  (figures.animation writes GIFs)
        out += [f"- `figures/{n}.{ext(n)}` (viewed {f['viewed']['date']}): {cell(f['viewed']['shows'])}"
                for n, f in viewed]
    out.append("")
    return out
