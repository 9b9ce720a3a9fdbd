"""Quantities the claims registry's rows declare: functions from run files (or a paper's printed numbers) to numbers.

A row of ``config/claims/<paper>.yaml`` names each quantity it reads as ``<package>.<function>`` in its ``checks``:
``core.<name>`` lives here (quantities any method's run file has), ``<method>.<name>`` in
``isaflow.methods.<method>.quantities`` (the package of the method whose runs it reads).  Every quantity is entered
with :func:`quantity`, which states what it is (``name``), its ``units`` and what it reads (``over``):

- ``"run"`` (default): ``fn(ds, **args)``, one run file (xarray Dataset) -> one value;
- ``"runs"``: ``fn([ds, ...], **args)``, the check's runs together -> one value (a trend over a sweep, a chain);
- ``"numbers"``: ``fn(numbers, **args)``, the row's printed numbers (``numbers``: name -> value) -> one value:
  paper arithmetic, no run.

A value is a number, a bool or a string, or a :class:`Value` (the number and a short text of its parts, e.g. the two
side walls of a worst error).  Reading parameters of an inferred input that needs no run (the level definition) reach
a quantity as keyword arguments when its signature names them.  No quantity holds a tolerance, a paper number or a
run id: those are fields of the row.  Units: cm, N, s.
"""

import ast
import functools
import importlib
import inspect
import math
import operator
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Value:
    """A quantity's value with the text of its parts (shown after it in the measured text)."""

    value: object
    text: str = ""


def quantity(name, units="", over="run", fmt=".4g"):
    """Decorator entering a function as a quantity (module docstring): name (what it is, in the measured text),
    units, over ('run', 'runs' or 'numbers'), fmt (the format of its number)."""
    if over not in ("run", "runs", "numbers"):
        raise ValueError(f"quantity '{name}': over must be run, runs or numbers, not {over!r}")

    def enter(fn):
        fn.quantity = dict(name=name, units=units, over=over, fmt=fmt)
        return fn

    return enter


@functools.lru_cache(maxsize=None)
def get(qid):
    """The quantity function of an id '<package>.<function>' (KeyError naming it if there is none)."""
    package, _, name = qid.partition(".")
    module = "isaflow.quantities" if package == "core" else f"isaflow.methods.{package}.quantities"
    try:
        fn = getattr(importlib.import_module(module), name)
    except (ModuleNotFoundError, AttributeError):
        raise KeyError(f"no quantity '{qid}' ({module}.{name} does not exist)") from None
    if not hasattr(fn, "quantity"):
        raise KeyError(f"'{qid}' ({module}.{name}) is not entered as a quantity (@quantity)")
    return fn


@functools.lru_cache(maxsize=None)
def accepts(fn):
    """The keyword names fn accepts (the reading parameters it may be given)."""
    return frozenset(inspect.signature(fn).parameters)


def call(fn, data, args, params):
    """fn(data, **args, **the reading parameters its signature names) as a Value."""
    extra = {k: v for k, v in params.items() if k in accepts(fn) and k not in args}
    out = fn(data, **args, **extra)
    return out if isinstance(out, Value) else Value(out)


def fmt(fn, v):
    """A value as the measured text prints it (number in the quantity's format, with its units)."""
    x, units = v.value, fn.quantity["units"]
    if isinstance(x, (bool, np.bool_)):
        s = "yes" if x else "no"
    elif isinstance(x, (int, np.integer)):
        s = f"{int(x):,}" + (f" {units}" if units else "")
    elif isinstance(x, (float, np.floating)) and not np.isfinite(x):
        s = "none" if np.isnan(x) else ("infinite" if x > 0 else "-infinite")
    elif isinstance(x, (float, np.floating)):
        s = format(float(x), fn.quantity["fmt"]) + (f" {units}" if units else "")
    else:
        s = str(x)
    return s + (f" ({v.text})" if v.text else "")


# ------------------------------------------------------------------------- paper arithmetic: expressions
_OPS = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
        ast.Pow: operator.pow, ast.USub: operator.neg, ast.UAdd: operator.pos}
_FUNCS = {"sqrt": math.sqrt, "abs": abs, "min": min, "max": max, "sum": sum, "log": math.log, "exp": math.exp,
          "floor": math.floor, "round": round, "len": len}
_CONST = {"pi": math.pi}


def evaluate(expr, names):
    """The value of an arithmetic expression over names (numbers, lists of numbers): + - * / **, unary -,
    calls of sqrt abs min max sum log exp floor round len, subscripts, pi.  Anything else raises ValueError."""
    def ev(node):
        if isinstance(node, ast.Expression):
            return ev(node.body)
        if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)):
            return node.value
        if isinstance(node, ast.Name):
            if node.id in names:
                return names[node.id]
            if node.id in _CONST:
                return _CONST[node.id]
            raise ValueError(f"unknown name '{node.id}' in '{expr}'")
        if isinstance(node, ast.BinOp) and type(node.op) in _OPS:
            return _OPS[type(node.op)](ev(node.left), ev(node.right))
        if isinstance(node, ast.UnaryOp) and type(node.op) in _OPS:
            return _OPS[type(node.op)](ev(node.operand))
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in _FUNCS and not node.keywords:
            return _FUNCS[node.func.id](*(ev(a) for a in node.args))
        if isinstance(node, ast.Subscript):
            return ev(node.value)[int(ev(node.slice))]
        if isinstance(node, (ast.List, ast.Tuple)):
            return [ev(e) for e in node.elts]
        raise ValueError(f"'{expr}': {type(node).__name__} is not allowed in a registry expression")

    return ev(ast.parse(expr, mode="eval"))


@quantity("expression of the paper's numbers", over="numbers", fmt=".6g")
def expr(numbers, expr):
    """Paper arithmetic: an expression over the row's printed numbers (:func:`evaluate`)."""
    return evaluate(expr, numbers)


@quantity("statement of the paper's text", over="numbers")
def stated(numbers, value):
    """A fact of the paper's text the row states (a logical reading, e.g. two sections that call one state two
    things): the row's value, so the judge compares it like any other."""
    return value


# ------------------------------------------------------------------------- any method's run file
@quantity("attribute")
def attr(ds, name):
    """A run-file attribute (a number or a string: status, f_tol, du ...)."""
    v = ds.attrs[name]
    return v.item() if hasattr(v, "item") else v


@quantity("outcome")
def status(ds):
    """The run's outcome (contract.OUTCOMES)."""
    return str(ds.attrs["status"])


@quantity("steps")
def steps(ds):
    """The run's step count at its end (counted from its chain's start)."""
    return int(ds["steps"])


@quantity("particles")
def particles(ds):
    """The run's particle count."""
    return int(ds.sizes["particle"])


@quantity("windowed signal")
def window(ds, var, last, stat="mean", coord=None, column=None):
    """A signal read over a window, never at one sample: ``stat`` (mean, min, max, range, std, or 'extremes'
    for the min and max as text) of variable ``var`` over its last ``last`` units of its first coordinate (``coord``,
    default that dimension's coordinate or the sample index); ``column``: index along a second dimension."""
    da = ds[var]
    dim = da.dims[0]
    x = da.values if column is None else da.values[:, column]
    t = ds[coord].values if coord is not None else (ds[dim].values if dim in ds.coords else np.arange(len(x)))
    keep = t >= t[-1] - last
    w = np.asarray(x[keep], float)
    if stat == "extremes":
        return Value(float(w.mean()), f"min {w.min():.4g}, max {w.max():.4g} over the last {last:g} ({keep.sum()} samples)")
    return {"mean": np.mean, "min": np.min, "max": np.max, "std": np.std, "range": np.ptp}[stat](w).item()


@quantity("share of the weight left in the first vessel", fmt=".1%")
def share_left(ds):
    """The weight in the first vessel over the run's weight (any method's flow)."""
    from . import metrics as M

    w = ds["weight"].values
    return float(w[M.vessel_view(ds, M.vessels(ds)[0])["inside"]].sum()) / float(w.sum())


@quantity("second vessel's free surface above its floor", "cm", fmt=".2f")
def second_surface(ds):
    """The project's one surface (isaflow.metrics.surface_of) of the last vessel, above its floor."""
    from . import metrics as M

    v = M.vessels(ds)[-1]
    return M.surface_of(ds, v) - M.vessel_view(ds, v)["floor_y"]
