"""The one judge of the claims registry (isaflow.judge, isaflow.claims.measure_checks): comparisons, reductions,
views (the paper's version, the project's kept runs, swept values), texts built from the numbers, robustness from
runs only, paper arithmetic from the row's numbers, and every registry row's quantities resolvable."""

import numpy as np
import pytest
import xarray as xr

from isaflow import claims, claims_registry, judge as J, quantities as Q


def _run(tmp_path, name, **attrs):
    p = str(tmp_path / f"{name}.nc")
    xr.Dataset({"steps": ((), 10, {"units": "1"})}, attrs=attrs).to_netcdf(p)
    return p


def _row(checks, kind="method result", numbers=None, tol=None, inputs=(), **extra):
    return {"id": "pap-x", "paper": "papadopoulos2016", "section": "1", "kind": kind, "testable": True,
            "checks": checks, "numbers": {k: {"value": v} for k, v in (numbers or {}).items()},
            "tolerance": {"value": tol, "units": "cm"}, "inferred_inputs": list(inputs), **extra}


@pytest.mark.parametrize("op, q, target, b, ok", [
    ("<=", 1.0, None, 1.0, True), ("<", 1.0, None, 1.0, False), (">=", 2, None, 2.5, False), (">", 3, None, 2.5, True),
    ("within", 74.9, 72.5, 2.5, True), ("within", 75.1, 72.5, 2.5, False), ("outside", 75.1, 72.5, 2.5, True),
    ("within_rel", 1.04, 1.0, 0.05, True), ("in", 5.667, None, [3.0, 5.667], True),
    ("in_halfopen", 2500, None, [1500, 2500], False), ("==", "converged", "converged", None, True),
    ("!=", "cycle", "converged", None, True), ("==", 0, None, 0, True), ("in", float("nan"), None, [1, 2], False)])
def test_comparisons(op, q, target, b, ok):
    assert J.compare(op, q, target, b) is ok


def test_op_and_margin_texts_carry_the_numbers():
    assert J.op_text("within", 72.5, 2.5, "cm") == "|x - 72.5| <= 2.5 cm"
    assert J.op_text("in_halfopen", None, [1500, 2500]) == "1,500 <= x < 2,500"
    assert J.margin_text("within", 75.13, 72.5, 2.5) == "flips at 70 and 75 (now +2.63 from 72.5)"


def test_paper_arithmetic_from_the_row_numbers_alone():
    """core.expr evaluates the printed numbers (and tol[k]); a paper-inconsistency row that finds its inconsistency
    does not hold (passed False), its why text quoting the numbers."""
    row = _row([{"q": "core.expr", "args": {"expr": "(n + tol[1]) * du"}, "op": "<", "bound": 20}],
               kind="paper inconsistency", numbers={"n": 2000, "du": 0.0025}, tol=[0, 500])
    out = J.evaluate(row, J.View(claims.Context({})))
    assert out.passed is False and "(n + tol[1]) * du = 6.25" in out.measured and "contradict" in out.why
    with pytest.raises(ValueError, match="not allowed"):
        Q.evaluate("__import__('os')", {})
    assert Q.evaluate("sum(parts) + sqrt(4)", {"parts": [50, 50, 20]}) == 122.0


def test_views_the_paper_version_the_kept_runs_and_a_swept_value(tmp_path):
    """The headline reads the paper's version of a role; the kept view the role itself; a swept value its stand-in,
    and no run for a role it changes without one."""
    paths = {"isa:a": _run(tmp_path, "a", status="cycle"), "isa:a_paper": _run(tmp_path, "a_paper", status="converged"),
             "isa:a_alt": _run(tmp_path, "a_alt", status="cycle")}
    ctx = claims.Context(paths)
    row = _row([{"q": "core.status", "runs": ["isa:a"], "op": "==", "target": "converged"}], inputs=["law"])
    inputs = {"law": {"id": "law", "sweep": [{"value": "linear", "label": "linear", "kept": True},
                                             {"value": "quad", "label": "quad", "runs": {"isa:a": "isa:a_alt"},
                                              "affects": "isa:*"},
                                             {"value": "quartic", "label": "quartic", "affects": "isa:*"},
                                             {"value": "cubic", "label": "cubic", "runs": {"isa:a": "isa:a_paper"},
                                              "affects": "isa:*"}]}}
    m = claims.measure_checks(ctx, row, inputs, {"isa:a": "isa:a_paper"})
    assert m.passed is True and "a_paper converged" in m.measured and "a_paper for a" in m.judged_on
    assert m.kept_passed is False and "a cycle" in m.kept_measured
    assert [s[:3] for s in m.sweep] == [("law", "linear", True), ("law", "quad", False), ("law", "quartic", None),
                                        ("law", "cubic", True)]  # quartic: no run
    assert "a_paper.nc" in m.evidence
    rob, flips, _ = claims.robustness(row, m, inputs)
    assert rob == "fragile" and flips == "law: quad"
    inputs["law"]["sweep"][1]["reading"] = False  # a bracket: its flip is sensitivity, not fragility
    rob, flips, ev = claims.robustness(row, claims.measure_checks(ctx, row, inputs, {"isa:a": "isa:a_paper"}), inputs)
    assert rob == "robust" and "no reading" in ev


def test_reductions_and_an_aggregate_judged_on_part_of_its_runs(tmp_path):
    paths = {f"isa:{k}": _run(tmp_path, k, status="converged", x=float(i + 1)) for i, k in enumerate("abc")}
    ctx = claims.Context(paths)
    runs = ["isa:a", "isa:b", "isa:c"]
    for how, b, ok in (("max", 3.0, True), ("min", 0.5, False), ("mean", 2.0, True), ("sum", 6.0, True)):
        row = _row([{"q": "core.attr", "args": {"name": "x"}, "runs": runs, "reduce": how, "op": "<=", "bound": b}])
        assert J.evaluate(row, J.View(ctx)).passed is ok, how
    row = _row([{"q": "core.attr", "args": {"name": "x"}, "runs": ["isa:a", "isa:b"], "reduce": "ratio", "op": "==",
                 "bound": 0.5}])
    assert J.evaluate(row, J.View(ctx)).passed
    row = _row([{"q": "core.attr", "args": {"name": "x"}, "runs": runs, "op": "<=", "bound": 2.5}])
    part = J.View(ctx, affected=J.affects(["isa:*", "!isa:a", "!isa:b"]))
    assert J.evaluate(row, part, partial_ok=True).passed is None  # a pass on part of the runs proves nothing
    row["checks"][0]["bound"] = 1.5
    assert J.evaluate(row, part, partial_ok=True).passed is False  # a failure on part of them stands
    with pytest.raises(J.NoRun):
        J.evaluate(row, part, partial_ok=False)


def test_a_window_reads_a_swinging_signal_over_its_last_stretch(tmp_path):
    t = np.arange(0, 100001, 500)
    y = 200 + 100 * np.sin(t / 300.0)
    ds = xr.Dataset({"sample_sum_fx": (("sample",), y), "sample_step": (("sample",), t)})
    v = Q.window(ds, "sample_sum_fx", last=2000, coord="sample_step", stat="extremes")
    assert v.value == pytest.approx(y[-5:].mean()) and "5 samples" in v.text


def test_every_registry_check_names_a_quantity_that_exists_with_its_arguments():
    """Each check's quantity resolves, its args are keywords it takes, and its target is a number of the row or a
    literal; a row's checks read only roles the paper's version or the runs the workflow declares can give."""
    import inspect

    for c in claims_registry.load():
        for chk in c.get("checks", []):
            fn = Q.get(chk["q"])
            params = inspect.signature(fn).parameters
            assert set(chk.get("args", {})) <= set(params), (c["id"], chk["q"])
            assert (fn.quantity["over"] == "numbers") == (not chk.get("runs")), c["id"]
