"""The one judge of a registry row's ``checks``: a row is an executable declaration.

A row of ``config/claims/<paper>.yaml`` states, for each check, the **quantity** it reads (``q``: an
``isaflow.quantities`` id, a function of run files or of the row's printed numbers), the **runs** it reads (roles:
'<method>:<run id>' as the workflow names them), the **reduction** over them (``reduce``: ``each`` run passes, or one
value from ``max``, ``min``, ``mean``, ``sum``, ``ratio`` (first / second), ``difference`` (first - second)), and the
**comparison** (``op`` with ``target``, a printed number of the row or a literal, and the tolerance: the row's
``tolerance.value``, its ``tol``-th entry for a list).  This module executes that; the measured text, the evidence (the
files read), the failure text and the margin are built from the row and the numbers, never written by hand.

**Views.**  A row is judged on a *view* of the runs: each role maps to the run file that stands for it.
- The headline view: the paper's version (the file's ``versions.paper.runs``: each role's run with every input the
  paper states at its stated value), unless the row is about this project's own runs (``judged_on: kept``);
- the kept view: the roles themselves, the project's kept runs (its calibrations and completions), reported beside
  the headline when it differs, never the headline;
- a sweep view per value of each inferred input the row rests on (the input's ``sweep``: per value, the runs standing
  in for roles, ``affects``: the roles the value changes, as glob patterns, and ``params``: reading parameters that
  need no run); a role the value affects without a stand-in has no run at that value.

Oscillating signals are read over declared windows (the quantity ``window`` of isaflow.quantities), never at one
sample.  Units: cm, N, s.
"""

import fnmatch
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import quantities as Q

OPS = ("<=", "<", ">=", ">", "==", "!=", "within", "within_rel", "outside", "in", "in_halfopen")
REDUCE = ("each", "max", "min", "mean", "sum", "ratio", "difference")


class NoRun(KeyError):
    """A view has no run for a role (a swept value that changes it without a stand-in)."""


@dataclass
class View:
    """Runs as one view sees them: a role's stand-in at this value (subs), else no run if the value changes it
    (affected), else its run in the view varied (base); params: reading parameters; the keys read are the evidence."""

    ctx: object
    base: dict = field(default_factory=dict)  # {role: run key} of the view it varies (the headline's)
    subs: dict = field(default_factory=dict)  # {role: run key} standing in at this value
    affected: object = None  # role -> True when this value changes it (then a stand-in is needed)
    params: dict = field(default_factory=dict)
    keeps: tuple = ()  # outcomes of an affected run that stand for themselves at this value (a run at rest before
    # its t_max runs step for step the same with a longer one)
    label: str = ""
    read: list = field(default_factory=list)

    def key(self, role):
        if role in self.subs:
            return self.subs[role]
        k = self.base.get(role, role)
        if self.affected is not None and self.affected(role):
            if not (self.keeps and self.ctx.has(k) and self.ctx.run(k).attrs.get("status") in self.keeps):
                raise NoRun(role)
        return k

    def run(self, role):
        k = self.key(role)
        ds = self.ctx.group(k) if isinstance(self.ctx.paths.get(k), (list, tuple)) else self.ctx.run(k)
        if k not in self.read:
            self.read.append(k)
        return k, ds


def affects(patterns):
    """role -> True if a glob of patterns (a list; '!pattern' excludes) matches it; None for no patterns."""
    if not patterns:
        return None
    pats = [patterns] if isinstance(patterns, str) else list(patterns)

    def fn(role):
        hit = False
        for p in pats:
            if p.startswith("!"):
                hit = hit and not fnmatch.fnmatchcase(role, p[1:])
            else:
                hit = hit or fnmatch.fnmatchcase(role, p)
        return hit

    return fn


# ------------------------------------------------------------------------------------------- comparisons
def _number(entry, x):
    """A target: a printed number of the row (by name) or a literal."""
    if isinstance(x, str) and x in entry.get("numbers", {}):
        return entry["numbers"][x]["value"]
    return x


def bound(entry, check):
    """The tolerance a check compares with: its own ``bound`` (a fixed number the comparison needs, e.g. 1 for a
    ratio, when the tolerance enters the quantity), else tolerance.value or its ``tol``-th entry (a pair for 'in')."""
    if "bound" in check:
        return check["bound"]
    v = (entry.get("tolerance") or {}).get("value")
    k = check.get("tol")
    if k is None:
        return v
    return [v[i] for i in k] if isinstance(k, list) else v[k]


def compare(op, q, target, b):
    """The comparison of a value q (OPS): against the bound b, or |q - target| against b."""
    if op in ("==", "!="):
        ref = target if target is not None else b
        same = math.isclose(q, ref, rel_tol=0, abs_tol=0) if _isnum(q) and _isnum(ref) else q == ref
        return same if op == "==" else not same
    q = float(q)
    if op == "within":
        return abs(q - target) <= b
    if op == "outside":
        return abs(q - target) > b
    if op == "within_rel":
        return abs(q / target - 1) <= b
    if op == "in":
        return b[0] <= q <= b[1]
    if op == "in_halfopen":
        return b[0] <= q < b[1]
    return {"<=": q <= b, "<": q < b, ">=": q >= b, ">": q > b}[op]


def _isnum(x):
    return isinstance(x, (int, float, np.integer, np.floating)) and not isinstance(x, (bool, np.bool_))


def _g(x):
    return f"{x:,}" if isinstance(x, (int, np.integer)) and not isinstance(x, bool) else (
        f"{x:.6g}" if _isnum(x) else str(x))


def op_text(op, target, b, units=""):
    """The comparison as the test text prints it ('x' stands for the quantity)."""
    u = f" {units}" if units and units not in ("1", "none", "dimensionless") else ""
    if op in ("==", "!="):
        return f"x {op} {_g(target if target is not None else b)}{u}"
    if op == "within":
        return f"|x - {_g(target)}| <= {_g(b)}{u}"
    if op == "outside":
        return f"|x - {_g(target)}| > {_g(b)}{u}"
    if op == "within_rel":
        return f"|x / {_g(target)} - 1| <= {_g(b)}"
    if op == "in":
        return f"{_g(b[0])} <= x <= {_g(b[1])}{u}"
    if op == "in_halfopen":
        return f"{_g(b[0])} <= x < {_g(b[1])}{u}"
    return f"x {op} {_g(b)}{u}"


def margin_text(op, q, target, b):
    """Where the comparison flips, and how far the value is from it."""
    if not _isnum(q):
        return ""
    q = float(q)
    if op in ("within", "outside"):
        return f"flips at {target - b:g} and {target + b:g} (now {q - target:+.4g} from {target:g})"
    if op == "within_rel":
        return f"flips at {target * (1 - b):.4g} and {target * (1 + b):.4g} (now {q / target - 1:+.3g} relative)"
    if op in ("in", "in_halfopen"):
        return f"flips at {b[0]:g} and {b[1]:g} (now {q:.6g})"
    if op in ("<=", "<", ">=", ">") and _isnum(b):
        return f"flips at {b:g} (now {q:.6g}, {q - b:+.4g})"
    return ""


# --------------------------------------------------------------------------------------------- a check
@dataclass
class Result:
    """What one check found under one view."""

    passed: object  # True / False / None (nothing to judge at this view)
    text: str  # the measured text
    margin: str = ""
    why: str = ""  # what failed, with the numbers
    partial: list = field(default_factory=list)  # roles left out (no run at this view)
    values: list = field(default_factory=list)  # [(run key, value)] read
    short: str = ""  # the numbers alone, for a table cell


def _short(key):
    return key.split(":", 1)[1] if ":" in key else key


def _reduce(how, vals):
    xs = [float(v) for v in vals]
    if how == "ratio":
        return xs[0] / xs[1]
    if how == "difference":
        return xs[0] - xs[1]
    return {"max": max, "min": min, "mean": lambda x: sum(x) / len(x), "sum": sum}[how](xs)


def run_check(entry, check, view, partial_ok=False):
    """Execute one check of a row on a view (module docstring); Result."""
    fn = Q.get(check["q"])
    meta = fn.quantity
    args = dict(check.get("args", {}))
    op, how = check["op"], check.get("reduce", "each")
    target, b = _number(entry, check.get("target")), bound(entry, check)
    params = {**(entry.get("tolerance") or {}).get("parameters", {}), **view.params}
    label = check.get("label") or args.get("expr") or meta["name"]
    test = op_text(op, target, b, meta["units"])
    nums = {k: v["value"] for k, v in entry.get("numbers", {}).items()}
    if meta["over"] == "numbers":
        nums |= {"tol": (entry.get("tolerance") or {}).get("value")}
        v = Q.call(fn, nums, args, params)
        ok = compare(op, v.value, target, b)
        return Result(bool(ok), f"{label} = {Q.fmt(fn, v)} [{test}]", margin_text(op, v.value, target, b),
                      "" if ok else f"{label} = {Q.fmt(fn, v)}, not {test}", values=[("numbers", v.value)],
                      short=f"{Q.fmt(fn, Q.Value(v.value))} [{test}]")
    params["numbers"] = nums  # a run quantity naming 'numbers' compares a run with the row's printed values
    roles = list(check.get("runs") or [r["id"] for r in entry.get("runs", [])])
    got, left = [], []
    for role in roles:
        try:
            got.append(view.run(role))
        except NoRun:
            left.append(role)
    if left and (not partial_ok or not got or how in ("ratio", "difference") or meta["over"] == "runs"):
        raise NoRun(left[0])
    if meta["over"] == "runs":
        v = Q.call(fn, [ds for _, ds in got], args, params)
        ok = compare(op, v.value, target, b)
        names = ", ".join(_short(k) for k, _ in got)
        return Result(bool(ok), f"{label} of {names}: {Q.fmt(fn, v)} [{test}]", margin_text(op, v.value, target, b),
                      "" if ok else f"{label} of {names} = {Q.fmt(fn, v)}, not {test}",
                      values=[(names, v.value)], short=f"{Q.fmt(fn, Q.Value(v.value))} [{test}]")
    vals = [(k, Q.call(fn, ds, args, params)) for k, ds in got]
    each = "; ".join(f"{_short(k)} {Q.fmt(fn, v)}" for k, v in vals)
    if how == "each":
        oks = [compare(op, v.value, target, b) for _, v in vals]
        bad = [f"{_short(k)} {Q.fmt(fn, v)}" for (k, v), o in zip(vals, oks) if not o]
        worst = _worst(op, [v.value for _, v in vals], target, b)
        ok = all(oks)
        plain = ", ".join(Q.fmt(fn, Q.Value(v.value)) for _, v in vals)
        return Result(bool(ok), f"{label}: {each} [{test}, each]", margin_text(op, worst, target, b),
                      "" if ok else f"{label}: {', '.join(bad)}, not {test}", partial=left,
                      values=[(k, v.value) for k, v in vals], short=f"{plain} [{test}]")
    x = _reduce(how, [v.value for _, v in vals])
    ok = compare(op, x, target, b)
    return Result(bool(ok), f"{label}: {each}; {how} {x:.6g} [{test}]", margin_text(op, x, target, b),
                  "" if ok else f"{label}: {how} {x:.6g}, not {test}", partial=left, values=[(how, x)],
                  short=f"{how} {x:.4g} [{test}]")


def _worst(op, xs, target, b):
    """The value of a list closest to failing (for the margin of an 'each' check)."""
    nums = [float(x) for x in xs if _isnum(x)]
    if not nums:
        return xs[0] if xs else float("nan")
    if op in ("within", "within_rel", "outside"):
        ref = target if op != "within_rel" else target
        return max(nums, key=lambda x: abs(x - ref)) if op != "outside" else min(nums, key=lambda x: abs(x - ref))
    if op in ("<=", "<"):
        return max(nums)
    if op in (">=", ">"):
        return min(nums)
    if op in ("in", "in_halfopen"):
        return max(nums, key=lambda x: max(b[0] - x, x - b[1]))
    return nums[0]


@dataclass
class Outcome:
    """A row's checks under one view: passed (all checks; None when none can judge), the texts, the keys read."""

    passed: object
    measured: str
    margin: str
    why: str
    read: list
    partial: list
    short: str = ""


def evaluate(entry, view, partial_ok=False):
    """Every check of a row on one view -> Outcome; a paper-inconsistency row's checks test for the inconsistency,
    so finding it means the quoted claim does not hold (passed = not found)."""
    results = []
    for c in entry["checks"]:
        try:
            results.append(run_check(entry, c, view, partial_ok))
        except NoRun as err:  # an aggregate judged on part of its runs leaves out a check with none of them
            if not partial_ok:
                raise
            results.append(Result(True, f"{c.get('label') or c['q']}: no run at this value", partial=[err.args[0]]))
    if all(r.text.endswith("no run at this value") for r in results):
        raise NoRun(results[0].partial[0])
    found = (any if entry.get("combine") == "any" else all)(r.passed for r in results)
    texts = [r.text for r in results]
    if entry["kind"] == "paper inconsistency":
        passed = not found
        why = ("the paper's own statements contradict it: " + "; ".join(texts)) if found else ""
    else:
        passed = found
        why = "; ".join(r.why for r in results if r.why)
    left = sorted({k for r in results for k in r.partial})
    if left and passed:
        passed = None  # an aggregate judged on part of its runs: a failure stands, a pass proves nothing
    margin = "; ".join(r.margin for r in results if r.margin)
    return Outcome(passed, "; ".join(texts), margin, why, list(view.read), left, "; ".join(r.short for r in results))


def evidence(ctx, keys):
    """The files a view read, as the evidence column lists them."""
    out = []
    for k in keys:
        p = ctx.paths.get(k)
        out.append(f"{k} ({len(p)} run files)" if isinstance(p, (list, tuple)) else (str(p) if p else k))
    return ", ".join(dict.fromkeys(out))


def path_of(p):
    return str(Path(p))
