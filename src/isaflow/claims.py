"""Every claim's verdict, computed from run outputs: the one place a verdict is written.

The claims are the registry (config/claims/<paper>.yaml, isaflow.claims_registry): quote, kind, the printed
numbers, the tolerance with its derivation and source, and the row's ``checks``, which isaflow.judge executes
(quantities of isaflow.quantities over the runs, a reduction, a comparison).  :func:`measure_checks` judges a row on
the paper's version (its file's ``versions.paper.runs``), reports the project's kept runs beside it, and judges the
same checks at every swept value of each inferred input; :func:`verdict` turns the outcome into the verdict:

- ``not testable here``: the registry says so (its reason), or a run the claim needs is missing;
- ``reproduced only after calibrating <input>``: passed, but an input the claim rests on was chosen to match it
  (``calibrated_against``) and the paper states no value for it;
- ``reproduced`` / ``not reproduced``: the checks pass / fail.

A ``project deviation`` row (a point where this project departs from the paper by its own choice) is judged on
the paper's version when that was run (``deviation.runs``); otherwise it is ``not testable here``.

Robustness, from runs only.  A verdict is ``robust`` when it holds at both ends of every inferred input it rests on,
at the values that are readings of its sentence, ``fragile`` when a reading flips it (named), ``unswept`` when an
input has no judged values at its ends.  Values marked ``reading: false`` (brackets, this project's variants) or
named in the row's ``not_readings`` are sensitivity only; an input the paper states is not inferred at all.

For a ``paper inconsistency`` row the checks test for the inconsistency; finding it means the quoted claim does not
hold, so the row is ``not reproduced`` and says why.  Units: cm, N, s.
"""

import json
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from . import claims_registry, judge as J, runfile
from .html import page

VERDICTS = ("reproduced", "reproduced only after calibrating", "not reproduced", "not testable here")
ROBUSTNESS = ("robust", "fragile", "unswept")
COLUMNS = ["id", "paper", "section", "kind", "half", "claim", "measured", "tolerance", "verdict", "robustness",
           "flips", "robustness_evidence", "evidence", "why", "margin", "sensitivity", "depends_on", "post_hoc", "sweep",
           "judged_on", "kept_verdict", "kept_measured", "short"]


@dataclass
class Measurement:
    """What a claim's measure found: the numbers (text with units), whether the tolerance's test passed
    (None: the runs cannot test it; ``measured`` says why), and where to look."""

    measured: str
    passed: bool | None
    evidence: str = ""
    why: str = ""  # the explanation of a failure
    margin: str = ""  # where the verdict would flip (the threshold a referee would look at)
    sensitivity: str = ""  # the verdict across the inferred inputs' ranges (text)
    sweep: tuple = ()  # ((input id, value label, passed True / False / None[, reading]), ...) in range order
    judged_on: str = ""  # the view the verdict is judged on (the paper's version, or the project's runs)
    kept_passed: object = None  # the project's kept runs, where they differ from the judged ones: passed
    kept_measured: str = ""  # ... and what they measure (a variant reported beside, never the verdict)
    short: str = ""  # the numbers alone, for the first screen's cell


class Context:
    """Run outputs a measure reads: run files by '<method>:<run id>' and tables by path, each read once.

    runs: {'<method>:<run id>': path}; tables: {name: path}.  A missing run raises Missing (the claim is
    then 'not testable here', naming the run).  :meth:`only` gives the view a registry row's measure reads
    through: its declared runs, any other key raises Undeclared.
    """

    def __init__(self, runs=None, tables=None):
        self.paths = dict(runs or {})
        self.table_paths = dict(tables or {})
        self._cache = {}
        self.allowed, self.claim = None, ""  # a view's keys (None: every key) and the claim it reads for

    def only(self, keys, claim=""):
        """A view of the same files and cache that reads only keys (a registry row's declared runs): paths holds
        only those, and run, group or has of any other key raises Undeclared naming the claim."""
        view = Context(tables=self.table_paths)
        view.allowed, view.claim, view._cache = frozenset(keys), claim, self._cache  # the files are read once
        view.paths = {k: p for k, p in self.paths.items() if k in view.allowed}
        return view

    def _check(self, key):
        if self.allowed is not None and key not in self.allowed:
            raise Undeclared(f"claim '{self.claim}' reads '{key}', which its registry row does not declare (its runs, "
                             "controls, deviation's runs, inferred inputs' runs or the runs of the rows it depends on)")

    def run(self, key):
        """The run file of '<method>:<run id>' (xarray Dataset)."""
        self._check(key)
        if key not in self._cache:
            path = self.paths.get(key)
            if not isinstance(path, str) or not Path(path).is_file():
                raise Missing(key)
            self._cache[key] = runfile.read(path)
        return self._cache[key]

    def group(self, key):
        """{run id: Dataset} of a group of runs '<method>:<group>' (e.g. a study's error-against-run-time runs)."""
        self._check(key)
        paths = self.paths.get(key)
        if not isinstance(paths, (list, tuple)) or not all(Path(p).is_file() for p in paths):
            raise Missing(key)
        return {Path(p).stem: self.run_path(p) for p in paths}

    def run_path(self, path):
        if path not in self._cache:
            self._cache[path] = runfile.read(path)
        return self._cache[path]

    def has(self, key):
        self._check(key)
        path = self.paths.get(key)
        return isinstance(path, str) and Path(path).is_file()

    def table(self, name):
        if ("table", name) not in self._cache:
            path = self.table_paths.get(name)
            if path is None or not Path(path).is_file():
                raise Missing(name)
            self._cache["table", name] = pd.read_csv(path)
        return self._cache["table", name]


class Missing(KeyError):
    """A run or table a measure needs does not exist."""


class Undeclared(Exception):
    """A measure read a run its registry row does not declare: a defect of the measure or of the row, never a
    verdict (judge lets it stop the claims job)."""


# ------------------------------------------------------------------------- rows as executable declarations
def roles(entry):
    """Every role a row's checks read (their runs, else the row's)."""
    out = []
    for c in entry.get("checks", []):
        out += list(c.get("runs") or [r["id"] for r in entry.get("runs", [])])
    return list(dict.fromkeys(out))


def judged_value(inp):
    """The value of an input a headline is judged at: the paper's stated value, else the project's kept one."""
    sweep = inp.get("sweep", [])
    if "paper_version" in inp:
        return next((v for v in sweep if str(v["value"]) == str(inp["paper_version"])), None)
    return next((v for v in sweep if v.get("judged")), None) or next((v for v in sweep if v.get("kept")), None)


def _reading(entry, name, v):
    """True when a swept value is a reading of the row's sentence (a flip there makes the verdict fragile): not a
    value the input marks ``reading: false`` (a bracket, a variant) nor one the row names in ``not_readings``."""
    return v.get("reading", True) and str(v["value"]) not in [str(x) for x in entry.get("not_readings", {}).get(name, [])]


def measure_checks(ctx, entry, inputs, paper_runs):
    """The Measurement of a row with ``checks`` (isaflow.judge): judged on the paper's version (paper_runs: {role:
    run} of the row's file, unless the row is judged on the project's runs, ``judged_on: kept``), the project's kept
    runs reported beside, every swept inferred input's values judged the same way."""
    base = {} if entry.get("judged_on") == "kept" else dict(paper_runs)
    head = J.View(ctx, base=base)
    out = J.evaluate(entry, head, partial_ok=False)
    changed = {r: head.key(r) for r in roles(entry) if head.key(r) != r}
    judged_on = ("the paper's version: " + ", ".join(f"{J._short(k)} for {J._short(r)}" for r, k in changed.items())
                 if changed else "the runs as declared")
    kept_passed, kept_text = None, ""
    if changed:
        try:
            k = J.evaluate(entry, J.View(ctx), partial_ok=False)
            kept_passed, kept_text = k.passed, k.measured
        except (J.NoRun, Missing) as err:
            kept_text = f"no run ({err.args[0]})"
    sweep, parts = [], []
    for name in entry.get("inferred_inputs", []):
        inp = inputs.get(name, {})
        values = inp.get("sweep", [])
        if not values:
            parts.append(f"{name}: not swept")
            continue
        at, vals = judged_value(inp), []
        if name in entry.get("judged_at", {}):  # the row's checks read the runs of another value (its sentence's)
            at = next((v for v in values if str(v["value"]) == str(entry["judged_at"][name])), at)
        for v in values:
            # a value swept around the project's kept runs says nothing of the paper's version's robustness
            reading = (_reading(entry, name, v) and "paper_version" not in inp
                       and (v.get("base") != "kept" or entry.get("judged_on") == "kept"))
            if at is not None and v["value"] == at["value"]:
                p, short = out.passed, "judged here"
            else:
                sub_base = {} if v.get("base") == "kept" else base
                view = J.View(ctx, base=sub_base, subs=dict(v.get("runs", {})), affected=J.affects(v.get("affects")),
                              params=dict(v.get("params", {})), keeps=tuple(v.get("keeps", ())))
                try:
                    o = J.evaluate(entry, view, partial_ok=bool(entry.get("aggregate")))
                    p, short = o.passed, (f"without {', '.join(J._short(x) for x in o.partial)}" if o.partial else "")
                except (J.NoRun, Missing) as err:
                    p, short = None, f"no run for {J._short(err.args[0])}"
            sweep.append((name, v["label"], p, reading))
            vals.append(f"{v['label']}: {_word(p)}" + (f" ({short})" if short else "") + ("" if reading else
                                                                                          " [not a reading]"))
        parts.append(f"{name}: " + "; ".join(vals))
    return Measurement(measured=out.measured, passed=out.passed, evidence=J.evidence(ctx, out.read),
                       why=out.why if out.passed is False else "", margin=out.margin, sensitivity=" | ".join(parts),
                       sweep=tuple(sweep), judged_on=judged_on, kept_passed=kept_passed, kept_measured=kept_text,
                       short=out.short)


def _word(passed):
    return "cannot be judged" if passed is None else ("passes" if passed else "fails")


def calibrated_inputs(entry, inputs, kept=False):
    """Names of the inputs this claim rests on that were calibrated against it (registry 'calibrated_against'); a
    row judged on the paper's version rests on a calibrated input only if the paper states no value for it (kept:
    the verdict of the project's kept runs, where the calibrated value is used)."""
    paper = not kept and entry.get("judged_on") != "kept" and "checks" in entry
    return [i for i in entry.get("inferred_inputs", []) if entry["id"] in inputs.get(i, {}).get("calibrated_against", [])
            and not (paper and "paper_version" in inputs.get(i, {}))]


def verdict(entry, m, inputs):
    """The verdict of one claim from its Measurement (module docstring).  A project deviation whose paper's
    version is not run (no deviation.runs) is not testable here: its measure describes the project's choice."""
    if not entry.get("testable") or m is None or m.passed is None:
        return "not testable here"
    if entry["kind"] == "project deviation" and not entry["deviation"].get("runs"):
        return "not testable here"
    return _passed_verdict(entry, m.passed, inputs)


def _passed_verdict(entry, passed, inputs, kept=False):
    if passed is None:
        return "not testable here"
    if not passed:
        return "not reproduced"
    cal = calibrated_inputs(entry, inputs, kept)
    return f"reproduced only after calibrating {', '.join(cal)}" if cal else "reproduced"


def robustness(entry, m, inputs=None):
    """(class, flips, evidence) of a judged row (module docstring): class one of ROBUSTNESS; flips 'input: values
    where the verdict flips' ('; '-joined); evidence one line per input.  inputs: {input id: input} of the registry."""
    names = entry.get("inferred_inputs", [])
    inputs = inputs or {}
    deviation = entry.get("kind") == "project deviation"
    if not entry.get("testable") or m is None or m.passed is None or (deviation and not entry["deviation"].get("runs")):
        return "robust", "", "no test runs on any value of its inputs: the verdict is 'not testable here' at every one"
    if not names:
        return "robust", "", "rests on no inferred input"
    flips, evidence, unswept = [], [], []
    for name in names:
        inp = inputs.get(name, {})
        if deviation and inp.get("status") == "project addition":
            evidence.append(f"{name}: the project's own addition is the deviation; the row is judged at the paper's "
                            "version")
            continue
        if "paper_version" in inp:
            evidence.append(f"{name}: stated by the paper (judged at {inp['paper_version']}); its other values are this "
                            "project's variants (sensitivity)")
            continue
        vals = [(s[1], s[2]) for s in m.sweep if s[0] == name and (len(s) < 4 or s[3])]
        off = [s[1] for s in m.sweep if s[0] == name and len(s) > 3 and not s[3] and s[2] is not None
               and bool(s[2]) != bool(m.passed)]
        if off:
            evidence.append(f"{name}: flips at {', '.join(off)}, values that are no reading of the sentence")
        flip = [v for v, p in vals if p is not None and bool(p) != bool(m.passed)]
        if flip:
            flips.append(f"{name}: {', '.join(flip)}")
            evidence.append(f"{name}: flips at {', '.join(flip)}")
        elif vals and vals[0][1] is not None and vals[-1][1] is not None:  # judged at both ends of its readings
            evidence.append(f"{name}: same verdict at {', '.join(v for v, p in vals if p is not None)}")
        else:
            unswept.append(name)
            evidence.append(f"{name}: not swept at both ends of its readings" + (
                f" (judged at {', '.join(v for v, p in vals if p is not None)})" if any(p is not None for _, p in vals)
                else ""))
    cls = "fragile" if flips else ("unswept" if unswept else "robust")
    return cls, "; ".join(flips), "; ".join(evidence)


def tolerance_text(entry):
    """One line of the tolerance: its test (a row with checks: the checks' comparisons) and its source."""
    t = entry.get("tolerance")
    if not t:
        return ""
    return f"{test_text(entry)} ({t.get('source', '')})"


def test_text(entry):
    """The test a row applies, in words: its checks' comparisons (x the quantity), or the registry's test."""
    if "checks" not in entry:
        return (entry.get("tolerance") or {}).get("test", "")
    from . import quantities as Q

    parts = []
    for c in entry["checks"]:
        fn = Q.get(c["q"])
        runs = c.get("runs") or [r["id"] for r in entry.get("runs", [])]
        where = "" if fn.quantity["over"] == "numbers" else (
            f" ({c.get('reduce', 'each')} of {', '.join(J._short(r) for r in runs)})")
        parts.append(f"{c.get('label') or c.get('args', {}).get('expr') or fn.quantity['name']}: "
                     f"{J.op_text(c['op'], J._number(entry, c.get('target')), J.bound(entry, c), fn.quantity['units'])}"
                     f"{where}")
    lead = "inconsistent if " if entry["kind"] == "paper inconsistency" else ""
    return lead + " and ".join(parts)


def judge(ctx, claims=None, inputs=None, versions=None):
    """DataFrame (COLUMNS) of every claim's measurement and verdict.  inputs: {input id: input} of the
    registry (default: every file's 'inputs'); versions: {paper: {role: run}} of each file's paper's version
    (default: the registry's)."""
    claims = claims_registry.load() if claims is None else claims
    if inputs is None:
        inputs = {i["id"]: i for lst in claims_registry.inputs().values() for i in lst}
    if versions is None:
        versions = claims_registry.paper_versions()
    by_id = {e["id"]: e for e in claims}
    rows = []
    for e in claims:
        m = None
        if not e.get("testable"):
            m = Measurement(f"not testable: {e.get('why_not', '')}", None)
        elif "checks" not in e:
            m = Measurement("the row declares no checks", None)
        else:
            view = ctx.only(claims_registry.declared_runs(e, inputs, by_id, versions.get(e["paper"], {})), e["id"])
            try:
                m = measure_checks(view, e, inputs, versions.get(e["paper"], {}))
            except (Missing, J.NoRun) as err:
                m = Measurement(f"needs {err.args[0]}, which this workflow did not make", None)
        rob, flips, rob_ev = robustness(e, m, inputs)
        post = (e.get("tolerance") or {}).get("post_hoc")
        rows.append(dict(id=e["id"], paper=e["paper"], section=e["section"], kind=e["kind"], half=e.get("half", ""),
                         claim=e.get("quote", ""), measured=m.measured, tolerance=tolerance_text(e),
                         verdict=verdict(e, m, inputs), robustness=rob, flips=flips, robustness_evidence=rob_ev,
                         evidence=m.evidence, why=m.why, margin=m.margin, sensitivity=m.sensitivity,
                         depends_on=" ".join(e.get("depends_on", [])),
                         post_hoc=f"{post['commit']}: {post['seen']}" if post else "", sweep=sweep_json(m),
                         judged_on=m.judged_on,
                         kept_verdict=_passed_verdict(e, m.kept_passed, inputs, kept=True) if m.kept_measured else "",
                         kept_measured=m.kept_measured, short=m.short or m.measured))
    return pd.DataFrame(rows, columns=COLUMNS)


def sweep_json(m):
    """The measurement's sweep as JSON: [[input id, value label, passed (true / false / null)], ...] in range order
    (figures.robustness draws it)."""
    rows = [] if m is None else [[str(s[0]), str(s[1]), None if s[2] is None else bool(s[2])] for s in m.sweep]
    return json.dumps(rows)


def verdict_class(v):
    """The verdict's class (one of VERDICTS) of a verdict string."""
    return next((k for k in sorted(VERDICTS, key=len, reverse=True) if str(v).startswith(k)), "other")


def counts(df):
    """DataFrame: claims per paper and kind, by verdict class (project checks apart)."""
    d = df.assign(verdict_class=df["verdict"].map(verdict_class))
    t = d.groupby(["paper", "kind", "verdict_class"]).size().unstack("verdict_class", fill_value=0)
    return t.reindex(columns=[v for v in VERDICTS if v in t.columns]).reset_index()


def write_paper(outputs, registry, paper, runs=None, tables=None, run_files=(), registry_files=()):
    """The claims rule of one paper: results/claims/registry/<paper>.csv and its HTML page (outputs), its rows judged
    from the runs it reads (runs: {'<method>:<run>': path or [paths]})."""
    csv, html = [str(o) for o in outputs]
    inputs = {i["id"]: i for lst in claims_registry.inputs(registry).values() for i in lst}
    rows = [c for c in claims_registry.load(registry) if c["paper"] == paper]
    df = judge(Context(runs, tables), rows, inputs, versions=claims_registry.paper_versions(registry))
    Path(csv).parent.mkdir(parents=True, exist_ok=True)
    df.to_csv(csv, index=False)
    Path(html).write_text(html_table(df, paper))
    return df


def write_counts(outputs, tables):
    """The counts by paper and kind (counts.csv, the output) of the papers' judged tables."""
    counts(pd.concat([pd.read_csv(t) for t in tables], ignore_index=True)).to_csv(str(outputs[0]), index=False)


def html_table(df, title):
    """A self-contained HTML page of one paper's judged claims (read in a browser, e.g. the Snakemake report)."""
    cols = ["id", "section", "kind", "claim", "measured", "verdict", "robustness", "flips", "tolerance", "post_hoc",
            "why", "margin", "evidence", "sensitivity", "robustness_evidence", "depends_on"]
    body = df[cols].fillna("").to_html(index=False, escape=True, border=0)
    return page(f"Claims: {title}", f"<h2>Claims of {title}: {len(df)} rows</h2>{body}")
