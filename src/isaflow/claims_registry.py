"""The claims registry: every testable statement of the registered methods' papers, one YAML file per paper.

``config/claims/<paper>.yaml`` lists the paper's statements (id, section, verbatim quote, kind,
quantity, measure, tolerance with its derivation and source, runs, inferred inputs, the replaced
row of the old claims table) and the inputs its verdicts rest on (with the range a sensitivity
sweep covers).  Each file is read through :func:`isaflow.inputs.load` (no aliases, tags,
duplicate keys, NaN) against ``claims.schema.json``; :func:`load` then checks what a schema
cannot: the paper is a registered method's (isaflow.methods.papers(): a new method's paper needs no edit of the
schema), file name = paper, ids unique across files, every reference (inferred inputs,
``depends_on``, ``calibrated_against``) resolves, id prefix = paper, testable entries carry a
tolerance that can fail, untestable ones say why, every run names a registered method.  A run id
holding ``{tank_method}`` is one entry per tank method of the registry (e.g. the solid floor under each
method's liquid), so a new method's run is judged without editing a registry file.

Kinds: ``method result`` (a number or property the method produces), ``paper arithmetic`` (the
paper's own formula or number re-evaluated), ``holds by construction`` (true because of how the
method or an inferred input was built; not evidence), ``input rule`` (how the paper chose an
input, checked against the inputs the runs use), ``paper inconsistency`` (two statements of the
paper that cannot both hold), ``project deviation`` (a row whose outcome is decided by this project's own
choice -- a stop rule, a reading, an unimplemented coupling: what the paper says, what the project does and
why, and the paper's version where it can be run; a finding about this project, never counted in a paper's
tally) and ``project check`` (a check of ours, quoted from no paper, never counted in a paper's tally).

``depends_on`` names the rows whose root cause a row shares (its verdict follows from theirs); the report
groups a row under its roots (:func:`roots`) and counts a root cause once.

No verdict is computed here: this module is the data.  Units: cm, N, s unless a field says
otherwise.
"""

import json
import re
from collections import Counter
from importlib import resources
from pathlib import Path

from .inputs import InputError, load as load_yaml
from .methods import papers, registry

SCHEMA = json.loads(resources.files("isaflow").joinpath("claims.schema.json").read_text())
PAPERS = tuple(papers())  # the paper ids of the method registry, the paper replicated first
PREFIX = {p: p[:3] for p in PAPERS}  # claim ids start with it: pap-, mar-, hat-, mer-
KINDS = ("method result", "paper inconsistency", "paper arithmetic", "input rule", "holds by construction",
         "project deviation", "project check")
PAPER_KINDS = KINDS[:-2]  # the kinds counted in a paper's tally (never the project's deviations or checks)
OWN_KINDS = KINDS[-2:]  # findings about this project
DEFAULT_DIRECTORY = "config/claims"
_ROOT = Path(__file__).resolve().parents[2]


def _directory(directory):
    """The registry folder: as given, or (relative and absent) under the repository root."""
    d = Path(directory)
    if not d.is_absolute() and not d.is_dir() and (_ROOT / d).is_dir():
        d = _ROOT / d
    return d


def load_files(directory=DEFAULT_DIRECTORY):
    """{paper: validated file mapping} of every registry file in directory (InputError otherwise)."""
    d = _directory(directory)
    if not d.is_dir():
        raise InputError(f"{d}: claims registry folder not found")
    files = sorted(p for p in d.iterdir() if p.suffix in (".yaml", ".yml"))
    out = {}
    for path in files:
        _, spec = load_yaml(path, SCHEMA, "claims registry file")
        if spec["paper"] not in PAPERS:  # the schema names no paper: the method registry's are the ones
            raise InputError(f"{path}: field 'paper': '{spec['paper']}' is no registered method's paper "
                             f"(choose from {', '.join(PAPERS)})")
        if spec["paper"] != path.stem:
            raise InputError(f"{path}: field 'paper': '{spec['paper']}' does not match the file name "
                             f"'{path.stem}' (one file per paper, named after it)")
        _expand_runs(spec, str(path))
        out[spec["paper"]] = spec | {"_path": str(path)}
    missing = [p for p in PAPERS if p not in out]
    if missing:
        raise InputError(f"{d}: no registry file for {', '.join(missing)}")
    return out


TANK_METHOD = "{tank_method}"


def paper_versions(directory=DEFAULT_DIRECTORY):
    """{paper: {role: run}} of each file's paper's version (its ``versions.paper.runs``; {} where none)."""
    return {p: spec.get("versions", {}).get("paper", {}).get("runs", {}) for p, spec in load_files(directory).items()}


def _expand_runs(spec, path):
    """Every ``runs`` and ``controls`` list and every check's runs of a registry file in place: '{tank_method}'
    entries become one per tank method (registry order); a run naming no registered method is refused (InputError
    naming the file and entry)."""
    methods = registry()
    tank = [name for name, m in methods.items() if m.tank]
    for where, node in _run_nodes(spec):
        for field in ("runs", "controls"):
            if field not in node:
                continue
            runs = []
            for r in node[field]:
                method = r["id"].split(":", 1)[0]
                if method not in methods:
                    raise InputError(f"{path}: {where}.{field}: '{r['id']}' names no registered method "
                                     f"(choose from {', '.join(methods)})")
                runs += [dict(r, id=r["id"].replace(TANK_METHOD, m)) for m in tank] if TANK_METHOD in r["id"] else [r]
            node[field] = runs
        for k, chk in enumerate(node.get("checks", [])):  # a check's runs too ('<method>:<id>' strings)
            for r in chk.get("runs", []):
                if r.split(":", 1)[0] not in methods:
                    raise InputError(f"{path}: {where}.checks.{k}.runs: '{r}' names no registered method "
                                     f"(choose from {', '.join(methods)})")
            if "runs" in chk:
                chk["runs"] = [r.replace(TANK_METHOD, m) for r in chk["runs"]
                               for m in (tank if TANK_METHOD in r else [""])]


def _run_nodes(spec):
    """[(where, node)] of every part of a registry file that may list runs and controls: its inputs, claims and
    the claims' deviations."""
    return [(f"inputs.{k}", i) for k, i in enumerate(spec.get("inputs", []))] + [
        (f"claims.{k}", c) for k, c in enumerate(spec.get("claims", []))] + [
        (f"claims.{k}.deviation", c["deviation"]) for k, c in enumerate(spec.get("claims", [])) if "deviation" in c]


def _check_file(paper, spec, ids):
    """Per-file rules a schema cannot state; ids: every claim id of every file."""
    path = spec["_path"]
    inputs = [i["id"] for i in spec.get("inputs", [])]
    dup = [k for k, n in Counter(inputs).items() if n > 1]
    if dup:
        raise InputError(f"{path}: input id '{dup[0]}' is defined twice")
    for i in spec.get("inputs", []):
        values = [str(v) for v in i["range"]["values"]]
        if "versions" in spec and ("paper_version" in i) == ("paper_states" in i):
            raise InputError(f"{path}: input '{i['id']}': say what the paper states: paper_version (its value) or "
                             "paper_states: none")
        if "paper_version" in i and str(i["paper_version"]) not in values:
            raise InputError(f"{path}: input '{i['id']}': paper_version '{i['paper_version']}' is not a value of its range")
        for c in i.get("calibrated_against", []):
            if c not in ids:
                raise InputError(f"{path}: input '{i['id']}': calibrated_against names no claim '{c}'")
        _check_sweep(path, i, values)
    for k, c in enumerate(spec["claims"]):
        where = f"{path}: claims.{k} ('{c['id']}')"
        if c["paper"] != paper:
            raise InputError(f"{where}: paper '{c['paper']}' in the file of '{paper}'")
        if c["kind"] != "project check" and not c["id"].startswith(PREFIX[paper] + "-"):
            raise InputError(f"{where}: id must start with '{PREFIX[paper]}-' (the paper's prefix)")
        for name in c["inferred_inputs"]:
            if name not in inputs:
                raise InputError(f"{where}: inferred input '{name}' is not defined under 'inputs' of this file")
        for d in c.get("depends_on", []):
            if d not in ids or d == c["id"]:
                raise InputError(f"{where}: depends_on names no other claim '{d}'")
        if c["testable"]:
            t = c["tolerance"]
            for field in ("derivation", "source") + (() if "checks" in c else ("test",)):
                if not t.get(field, "").strip():
                    raise InputError(f"{where}: a testable claim needs tolerance.{field}")
            if c["kind"] == "method result" and not c.get("runs") and not any(chk.get("runs") for chk in c.get("checks", [])):
                raise InputError(f"{where}: a testable method result needs the runs it is judged on")
        elif not c.get("why_not", "").strip():
            raise InputError(f"{where}: an untestable claim needs why_not")
        for j, chk in enumerate(c.get("checks", [])):
            if isinstance(chk.get("target"), str) and chk["target"] not in c.get("numbers", {}) and chk["op"] not in ("==", "!="):
                raise InputError(f"{where}: checks.{j}.target: '{chk['target']}' is no printed number of the row")
        for name in c.get("not_readings", {}):
            if name not in c["inferred_inputs"]:
                raise InputError(f"{where}: not_readings names '{name}', which is not among its inferred_inputs")
        if "quote" in c and "..." in c["quote"] and any(not f.strip() for f in c["quote"].split("...")):
            raise InputError(f"{where}: quote has an empty fragment around '...'")


def _check_findings(paper, spec):
    """A finding names claims of its own file, and each of its sentences one of them."""
    own = {c["id"] for c in spec["claims"]}
    for k, f in enumerate(spec.get("findings", [])):
        for c in f["claims"] + [snt["row"] for snt in f.get("sentences", [])]:
            if c not in own:
                raise InputError(f"{spec['_path']}: findings.{k}: names no claim '{c}' of this file")


def _check_sweep(path, i, values):
    """An input's sweep: its values are those of its range, at most one is kept, and every run standing in at a
    value is one of the input's runs."""
    sweep = i.get("sweep", [])
    where = f"{path}: input '{i['id']}': sweep"
    if sweep and sorted(str(v["value"]) for v in sweep) != sorted(values):
        raise InputError(f"{where}: its values {[v['value'] for v in sweep]} are not those of the range ({values})")
    if sum(v.get("kept", False) for v in sweep) > 1:
        raise InputError(f"{where}: more than one value is kept")
    own = {r["id"] for r in i.get("runs", [])}
    for v in sweep:
        for run in v.get("runs", {}).values():
            if run not in own:
                raise InputError(f"{where}: value '{v['value']}' stands in run '{run}', which is not one of the "
                                 f"input's runs")


def load(directory=DEFAULT_DIRECTORY):
    """Every registry entry of every paper, in file then file order: a list of dicts (InputError
    naming the file and entry on any violation)."""
    return _checked(load_files(directory))


def _checked(files):
    """The claims of the loaded files, after every check across them (:func:`load`)."""
    claims = [c for p in PAPERS for c in files[p]["claims"]]
    seen = Counter(c["id"] for c in claims)
    dup = [k for k, n in seen.items() if n > 1]
    if dup:
        raise InputError(f"claim id '{dup[0]}' occurs {seen[dup[0]]} times across the registry files")
    ids = set(seen)
    for p in PAPERS:
        _check_file(p, files[p], ids)
        _check_findings(p, files[p])
    cycle = _depends_cycle(claims)
    if cycle:
        raise InputError(f"depends_on forms a cycle: {' -> '.join(cycle)}")
    _derived_of(files)
    return claims


def _depends_cycle(claims):
    """A depends_on cycle as a list of ids (empty if none)."""
    deps = {c["id"]: c.get("depends_on", []) for c in claims}
    state = {}

    def visit(k, path):
        if state.get(k) == 1:
            return path[path.index(k):] + [k]
        if state.get(k) == 2:
            return []
        state[k] = 1
        for d in deps.get(k, []):
            found = visit(d, path + [k])
            if found:
                return found
        state[k] = 2
        return []

    for k in deps:
        found = visit(k, [])
        if found:
            return found
    return []


def roots(claims):
    """{claim id: tuple of root ids}: the rows with no depends_on that a row's depends_on leads to (a root is its
    own root).  The report groups a row under its roots and counts each root cause once."""
    deps = {c["id"]: c.get("depends_on", []) for c in claims}
    out = {}

    def walk(k):
        if k not in out:
            out[k] = (k,) if not deps[k] else tuple(dict.fromkeys(r for d in deps[k] for r in walk(d)))
        return out[k]

    for k in deps:
        walk(k)
    return out


def declared_runs(entry, inputs, entries=None, versions=None):
    """The run keys ('<method>:<run id>' or a group '<method>:<group>') a claim's measure may read: its runs and
    controls, its checks' runs and their paper's versions (versions: {role: run} of its file), its deviation's runs
    and the runs of each of its inferred inputs (inputs: {input id: input}); with entries ({claim id: entry}), also
    those of the rows it depends on, transitively (an aggregate measures through theirs)."""
    keys, todo, seen = set(), [entry], set()
    while todo:
        e = todo.pop()
        seen.add(e["id"])
        if "checks" in e:  # an executable row reads what its checks name
            keys |= {r for c in e["checks"] for r in c.get("runs", [])}
        else:
            keys |= {r["id"] for r in e.get("runs", []) + e.get("controls", [])}
        keys |= {(versions or {}).get(k) for k in set(keys)} - {None}
        keys |= {r["id"] for r in e.get("deviation", {}).get("runs", [])}
        for name in e.get("inferred_inputs", []):
            keys |= {r["id"] for r in inputs.get(name, {}).get("runs", [])}
        todo += [entries[d] for d in e.get("depends_on", []) if entries and d in entries and d not in seen]
    return keys


def paper_runs(directory=DEFAULT_DIRECTORY):
    """{paper: set of run keys} every row of the paper's file may read (declared_runs of each, with its inputs, the rows
    it depends on in any file and its file's paper's version): the inputs of that paper's claims job."""
    files = load_files(directory)
    claims = [c for p in PAPERS for c in files[p]["claims"]]
    by_id = {c["id"]: c for c in claims}
    inputs = {i["id"]: i for spec in files.values() for i in spec.get("inputs", [])}
    out = {}
    for p in PAPERS:
        versions = files[p].get("versions", {}).get("paper", {}).get("runs", {})
        keys = set()
        for c in files[p]["claims"]:
            keys |= declared_runs(c, inputs, by_id, versions)
        out[p] = keys
    return out


def derived(directory=DEFAULT_DIRECTORY):
    """{id: entry} of every file's ``derived`` entries (isaflow.derived), in file order, after every check of
    :func:`load` (the workflow reads them while it is parsed, so a bad registry file stops it before any job: a
    claim id twice or of another paper's prefix passed until the claims job)."""
    files = load_files(directory)
    _checked(files)
    return _derived_of(files)


def _derived_of(files):
    """The derived entries of the loaded files; InputError naming the file and entry for an id defined twice, a
    method not registered, or an entry no row or input of its file reads."""
    methods, out = registry(), {}
    for spec in files.values():
        named = {r["id"] for _, node in _run_nodes(spec) for f in ("runs", "controls") for r in node.get(f, [])}
        named |= {r for c in spec["claims"] for chk in c.get("checks", []) for r in chk.get("runs", [])}
        named |= set(spec.get("versions", {}).get("paper", {}).get("runs", {}).values())
        for k, d in enumerate(spec.get("derived", [])):
            where = f"{spec['_path']}: derived.{k} ('{d['id']}')"
            for field in ("id", "from"):
                if d[field].split(":", 1)[0] not in methods:
                    raise InputError(f"{where}: field '{field}' names no registered method "
                                     f"(choose from {', '.join(methods)})")
            if d["id"] in out:
                raise InputError(f"{where}: defined twice")
            if d["id"] not in named:
                raise InputError(f"{where}: no row or input of its file reads it (name it among a row's runs)")
            out[d["id"]] = d | {"_path": spec["_path"], "_where": f"derived.{k}"}
    return out


def inputs(directory=DEFAULT_DIRECTORY):
    """{paper: [input dicts]}: the inferred inputs of each file, with their sweep ranges."""
    return {p: spec.get("inputs", []) for p, spec in load_files(directory).items()}


def fragments(quote):
    """The verbatim fragments of a quote ('...' separates them), whitespace-normalised."""
    return [normalise(f) for f in quote.split("...") if f.strip()]


def normalise(text):
    """Whitespace runs to one space, ends stripped (how quotes are matched against a paper's text)."""
    return re.sub(r"\s+", " ", text).strip()


def quote_found(quote, text):
    """True when every fragment of quote occurs in text, in order (both whitespace-normalised)."""
    body, at = normalise(text), 0
    for frag in fragments(quote):
        k = body.find(frag, at)
        if k < 0:
            return False
        at = k + len(frag)
    return True


def counts(claims=None, directory=DEFAULT_DIRECTORY):
    """{paper: {kind: n}} over the registry (project deviations and checks under their own kinds, never in a
    paper's tally); 'testable' and 'independent' (testable, no depends_on) are added per paper."""
    claims = load(directory) if claims is None else claims
    out = {}
    for c in claims:
        row = out.setdefault(c["paper"], {k: 0 for k in KINDS} | {"testable": 0, "independent": 0})
        row[c["kind"]] += 1
        if c["kind"] in PAPER_KINDS and c["testable"]:
            row["testable"] += 1
            row["independent"] += not c.get("depends_on")
    return out


def format_counts(table=None):
    """The counts as a Markdown table (papers x kinds, with the paper tally = all kinds but the project's own)."""
    table = counts() if table is None else table
    heads = ["paper", *KINDS, "paper tally", "testable", "independent"]
    lines = ["| " + " | ".join(heads) + " |", "|" + "---|" * len(heads)]
    total = Counter()
    for p in PAPERS:
        r = table.get(p, {})
        tally = sum(r.get(k, 0) for k in PAPER_KINDS)
        vals = [r.get(k, 0) for k in KINDS] + [tally, r.get("testable", 0), r.get("independent", 0)]
        total.update(dict(zip(heads[1:], vals)))
        lines.append("| " + " | ".join([p, *map(str, vals)]) + " |")
    lines.append("| all | " + " | ".join(str(total[h]) for h in heads[1:]) + " |")
    return "\n".join(lines)
