"""Every claim's verdict, computed from run outputs: the one place a verdict is written.

The claims are the registry (config/claims/<paper>.yaml, isaflow.claims_registry): quote, kind,
the quantity, the tolerance with its derivation and source, the runs.  What each claim measures is a
function of the run outputs, kept with the method it measures: every method package may define a
module ``claims`` with ``MEASURES = {claim id: function(ctx, entry) -> Measurement}``, filled by
:func:`measure_table`'s decorator ``@claim(id)`` on each measure.  A measure
returns numbers and whether the tolerance's test passed (reading the tolerance from the entry, never
holding one of its own); :func:`verdict` turns that into the verdict:

- ``not testable here``: the registry says so (its reason), or a run the claim needs is missing;
- ``reproduced only after calibrating <input>``: passed, but an input the claim rests on was chosen
  to match it (``calibrated_against`` in the registry's inputs);
- ``reproduced`` / ``not reproduced``: the test passed / failed.

A ``project deviation`` row (a point where this project departs from the paper by its own choice) is judged on
the paper's version when that was run (``deviation.runs``); otherwise it is ``not testable here`` and its
measurement describes what the project does instead.

Robustness.  A verdict is ``robust`` when it holds at both ends of every inferred input it rests on and
``fragile`` when some value of an input's range flips it (the input and the values where it flips are named).
The evidence is the measure's ``sweep`` (the test at other values of the inputs, from runs or readings) or,
for an input no run covers, the registry row's ``robustness`` argument; an input with neither is ``unswept``.
A row that rests on no inferred input is robust by construction.

A measure's ``passed`` always says whether the *quoted claim* holds.  For a ``paper inconsistency`` row
the registry's test reads "inconsistent if ..."; when it finds the inconsistency the claim does not hold
(the paper's own statements contradict it), so the row is ``not reproduced`` and says why.

Units: cm, N, s.
"""

import importlib
import json
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from . import claims_registry, methods, runfile
from .html import page

VERDICTS = ("reproduced", "reproduced only after calibrating", "not reproduced", "not testable here")
ROBUSTNESS = ("robust", "fragile", "unswept")
COLUMNS = ["id", "paper", "section", "kind", "half", "claim", "measured", "tolerance", "verdict", "robustness",
           "flips", "robustness_evidence", "evidence", "why", "margin", "sensitivity", "depends_on", "post_hoc", "sweep"]


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
    sweep: tuple = ()  # ((input id, value label, passed True / False / None), ...) in range order, the kept value included


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


def measures():
    """{claim id: measure function} of every method package's ``claims`` module (ids must be unique)."""
    out = {}
    for name in methods.PACKAGES:
        try:
            module = importlib.import_module(f"isaflow.methods.{name}.claims")
        except ModuleNotFoundError as err:
            if err.name != f"isaflow.methods.{name}.claims":
                raise
            continue
        for cid, fn in getattr(module, "MEASURES", {}).items():
            if cid in out:
                raise ValueError(f"claim '{cid}' is measured twice (methods.{name}.claims)")
            out[cid] = fn
    return out


def measure_table():
    """(MEASURES, claim): a claims module's empty {claim id: measure function} and the decorator that enters a
    function under its claim ids, ``@claim("id", ...)`` (returns the function; an id entered twice: ValueError)."""
    table = {}

    def claim(*ids):
        def enter(fn):
            for cid in ids:
                if cid in table:
                    raise ValueError(f"claim '{cid}' is measured twice")
                table[cid] = fn
            return fn

        return enter

    return table, claim


def number(entry, name):
    """A number of the entry's ``numbers`` (the paper's printed values, a test's constants): its value, a
    float or a list."""
    return entry["numbers"][name]["value"]


def calibrated_inputs(entry, inputs):
    """Names of the inputs this claim rests on that were calibrated against it (registry 'calibrated_against')."""
    return [i for i in entry.get("inferred_inputs", []) if entry["id"] in inputs.get(i, {}).get("calibrated_against", [])]


def verdict(entry, m, inputs):
    """The verdict of one claim from its Measurement (module docstring).  A project deviation whose paper's
    version is not run (no deviation.runs) is not testable here: its measure describes the project's choice."""
    if not entry.get("testable") or m is None or m.passed is None:
        return "not testable here"
    if entry["kind"] == "project deviation" and not entry["deviation"].get("runs"):
        return "not testable here"
    if not m.passed:
        return "not reproduced"
    cal = calibrated_inputs(entry, inputs)
    return f"reproduced only after calibrating {', '.join(cal)}" if cal else "reproduced"


def robustness(entry, m, inputs=None):
    """(class, flips, evidence) of a judged row (module docstring): class one of ROBUSTNESS; flips 'input: values
    where the verdict flips' ('; '-joined); evidence one line per input.  inputs: {input id: input} of the
    registry (an input's own robustness argument stands for the rows whose measure does not sweep it)."""
    names = entry.get("inferred_inputs", [])
    deviation = entry.get("kind") == "project deviation"
    if not entry.get("testable") or m is None or m.passed is None or (deviation and not entry["deviation"].get("runs")):
        return "robust", "", "no test runs on any value of its inputs: the verdict is 'not testable here' at every one"
    if not names:
        return "robust", "", "rests on no inferred input"
    argued = {n: (inputs or {}).get(n, {}).get("robustness") for n in names}
    argued = {n: a for n, a in argued.items() if a} | entry.get("robustness", {})
    flips, evidence, unswept = [], [], []
    for name in names:
        if deviation and (inputs or {}).get(name, {}).get("status") == "project addition":
            evidence.append(f"{name}: the project's own addition is the deviation; the row is judged at the paper's "
                            "version")
            continue
        vals = [(v, p) for i, v, p in m.sweep if i == name]
        flip = [v for v, p in vals if p is not None and bool(p) != bool(m.passed)]
        if flip:
            flips.append(f"{name}: {', '.join(flip)}")
            evidence.append(f"{name}: flips at {', '.join(flip)}")
        elif len(vals) >= 2 and vals[0][1] is not None and vals[-1][1] is not None:
            evidence.append(f"{name}: same verdict at {', '.join(v for v, p in vals if p is not None)}"
                            + (f"; the rest of its range: {argued[name]}" if name in argued else ""))
        elif name in argued:
            evidence.append(f"{name}: {argued[name]}")
        else:
            unswept.append(name)
            evidence.append(f"{name}: not swept" + (f" (judged at {', '.join(v for v, p in vals if p is not None)})"
                                                     if any(p is not None for _, p in vals) else ""))
    cls = "fragile" if flips else ("unswept" if unswept else "robust")
    return cls, "; ".join(flips), "; ".join(evidence)


def tolerance_text(entry):
    """One line of the tolerance: its test and its source."""
    t = entry.get("tolerance")
    if not t:
        return ""
    return f"{t.get('test', '')} ({t.get('source', '')})"


def judge(ctx, claims=None, inputs=None, found=None):
    """DataFrame (COLUMNS) of every claim's measurement and verdict.  inputs: {input id: input} of the
    registry (default: every file's 'inputs')."""
    claims = claims_registry.load() if claims is None else claims
    if inputs is None:
        inputs = {i["id"]: i for lst in claims_registry.inputs().values() for i in lst}
    found = measures() if found is None else found
    by_id = {e["id"]: e for e in claims}
    rows = []
    for e in claims:
        m = None
        if not e.get("testable"):
            m = Measurement(f"not testable: {e.get('why_not', '')}", None)
        elif e["id"] not in found:
            m = Measurement("no measure implemented for this claim", None)
        else:
            try:
                m = found[e["id"]](ctx.only(claims_registry.declared_runs(e, inputs, by_id), e["id"]), e)
            except Missing as err:
                m = Measurement(f"needs {err.args[0]}, which this workflow did not make", None)
        rob, flips, rob_ev = robustness(e, m, inputs)
        post = (e.get("tolerance") or {}).get("post_hoc")
        rows.append(dict(id=e["id"], paper=e["paper"], section=e["section"], kind=e["kind"], half=e.get("half", ""),
                         claim=e.get("quote", ""), measured=m.measured, tolerance=tolerance_text(e),
                         verdict=verdict(e, m, inputs), robustness=rob, flips=flips, robustness_evidence=rob_ev,
                         evidence=m.evidence, why=m.why, margin=m.margin, sensitivity=m.sensitivity,
                         depends_on=" ".join(e.get("depends_on", [])),
                         post_hoc=f"{post['commit']}: {post['seen']}" if post else "", sweep=sweep_json(m)))
    return pd.DataFrame(rows, columns=COLUMNS)


def sweep_json(m):
    """The measurement's sweep as JSON: [[input id, value label, passed (true / false / null)], ...] in range order
    (figures.robustness draws it)."""
    rows = [] if m is None else [[str(i), str(v), None if p is None else bool(p)] for i, v, p in m.sweep]
    return json.dumps(rows)


def verdict_class(v):
    """The verdict's class (one of VERDICTS) of a verdict string."""
    return next((k for k in sorted(VERDICTS, key=len, reverse=True) if str(v).startswith(k)), "other")


def counts(df):
    """DataFrame: claims per paper and kind, by verdict class (project checks apart)."""
    d = df.assign(verdict_class=df["verdict"].map(verdict_class))
    t = d.groupby(["paper", "kind", "verdict_class"]).size().unstack("verdict_class", fill_value=0)
    return t.reindex(columns=[v for v in VERDICTS if v in t.columns]).reset_index()


def write(outputs, registry, runs=None, tables=None, run_files=(), registry_files=()):
    """The claims rule: results/claims/<paper>.csv for every paper (outputs, in the registry's paper order)
    and the counts by kind (the last output).  runs: {'<method>:<run>': path or [paths]}; tables: {name: path};
    run_files, registry_files: the same files as the rule's inputs (what it depends on)."""
    inputs = {i["id"]: i for lst in claims_registry.inputs(registry).values() for i in lst}
    df = judge(Context(runs, tables), claims_registry.load(registry), inputs)
    *papers, summary = [str(o) for o in outputs if not str(o).endswith(".html")]
    pages = {str(o) for o in outputs if str(o).endswith(".html")}
    for out in papers:
        paper = Path(out).stem
        Path(out).parent.mkdir(parents=True, exist_ok=True)
        df[df["paper"] == paper].to_csv(out, index=False)
        page = str(Path(out).with_suffix(".html"))
        if page in pages:
            Path(page).write_text(html_table(df[df["paper"] == paper], paper))
    counts(df).to_csv(summary, index=False)
    return df


def html_table(df, title):
    """A self-contained HTML page of one paper's judged claims (read in a browser, e.g. the Snakemake report)."""
    cols = ["id", "section", "kind", "claim", "measured", "verdict", "robustness", "flips", "tolerance", "post_hoc",
            "why", "margin", "evidence", "sensitivity", "robustness_evidence", "depends_on"]
    body = df[cols].fillna("").to_html(index=False, escape=True, border=0)
    return page(f"Claims: {title}", f"<h2>Claims of {title}: {len(df)} rows</h2>{body}")
