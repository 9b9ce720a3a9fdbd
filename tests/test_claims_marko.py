"""marko2017's claims (issue 23): every testable row has a measure, no measure writes a verdict, the verdict
follows the data and the registry's tolerance, and a few measures recompute the paper's own numbers.

Runs: the four 4.1 bar runs (3D, 275 particles, about a second together once compiled), written to a
temporary folder; every other check needs no run.
"""

import copy
import re
from pathlib import Path

import numpy as np
import pytest

from isaflow import claims as C
from isaflow import claims_registry, runfile
from isaflow.methods.solid import claims as SC
from isaflow.methods.solid import outputs
from isaflow.methods.sph import claims as HC

ROOT = Path(__file__).resolve().parents[1]
CFG = ROOT / "config" / "methods" / "solid.yaml"
ENTRIES = {c["id"]: c for c in claims_registry.load() if c["paper"] == "marko2017"}
INPUTS = {i["id"]: i for lst in claims_registry.inputs().values() for i in lst}
MODULES = [ROOT / "src/isaflow/methods/solid/claims.py", ROOT / "src/isaflow/methods/sph/claims.py",
           ROOT / "src/isaflow/methods/solid/report.py"]


def test_every_testable_marko_claim_has_a_measure():
    found = C.measures()
    testable = {cid for cid, e in ENTRIES.items() if e["testable"]}
    assert testable - set(found) == set()
    # the solid module measures the solid and section 3-4 rows, the SPH module section 1-2's
    assert {cid for cid in found if cid in ENTRIES} == testable
    assert set(HC.MEASURES) == {"mar-1-spam-tensile", "mar-1-exponential-cost", "mar-2-derivative",
                                "mar-2-eq4-normalisation"}


def test_no_verdict_strings_in_the_measures():
    """Only isaflow.claims.verdict writes a verdict: the measures and the report fragment name none."""
    for path in MODULES:
        text = path.read_text()
        for word in C.VERDICTS:
            assert not re.search(re.escape(word), text, re.I), f"{path.name} writes '{word}'"


def test_paper_numbers_come_from_the_registry():
    """No paper number the registry holds is typed in a measure (the printed values of section 4)."""
    text = MODULES[0].read_text() + MODULES[1].read_text()
    for printed in ("1.4758", "0.1329", "0.34125", "79.6154", "1.9593", "15.5992", "15.8993", "227.4725", "101135",
                    "101325", "9.3619", "18.3429", "1.7132", "2.66", "5.98", "0.054", "0.104"):
        assert printed not in re.sub(r'"""(.|\n)*?"""', "", text), printed


def judge(cid, ctx=None, entry=None):
    """(Measurement, verdict) of one row."""
    e = entry or ENTRIES[cid]
    m = C.measures()[cid](ctx or C.Context(), e)
    return m, C.verdict(e, m, INPUTS)


def test_paper_arithmetic_recomputes_the_papers_numbers():
    m, _ = judge("mar-4.3-pmax-arith")
    assert "7.274" in m.measured and "9.981" in m.measured and m.passed  # eq. 25: 7.3-10 GPa
    m, _ = judge("mar-4.1-poisson-arith")
    assert "0.34133" in m.measured and m.passed  # eq. 17 on 0.1329 um: the printed 0.34125
    m, _ = judge("mar-2-eq4-normalisation")
    assert "1.428571" in m.measured and m.passed is False  # 10/7, not 1
    m, _ = judge("mar-4.3-dt-vs-eq26")
    assert "7.72 ns" in m.measured and m.passed is False  # eq. 26 with the bar speed, below 15 ns
    m, _ = judge("mar-1-exponential-cost")
    assert m.passed is False and "4.000006" in m.measured  # polynomial, not exponential


def test_verdict_follows_the_registry_tolerance():
    """The same numbers give the other verdict when the registry's tolerance is moved across the margin."""
    e = copy.deepcopy(ENTRIES["mar-4.4-atm"])  # |101325 - 101135| = 190 Pa against 0.5 Pa
    assert judge("mar-4.4-atm", entry=e)[1] == C.VERDICTS[2]
    e["tolerance"]["value"] = 190.5
    assert judge("mar-4.4-atm", entry=e)[1] == C.VERDICTS[0]
    e = copy.deepcopy(ENTRIES["mar-4.2-error-arith"])  # 1.924 % against 2 %
    assert judge("mar-4.2-error-arith", entry=e)[1] == C.VERDICTS[0]
    e["tolerance"]["value"] = 0.019
    assert judge("mar-4.2-error-arith", entry=e)[1] == C.VERDICTS[2]


def test_printed_tau_is_not_the_printed_product():
    """tau = 79.6154e9 x 1.9593e-4 is 15.59905e6 as printed; the printed 15.5992e6 is the unrounded product."""
    m, _ = judge("mar-4.2-tau-arith")
    assert m.passed is False and "15599045" in m.measured and "15599152" in m.sensitivity


def test_printed_lattice_has_no_shear_stiffness():
    g = SC.lattice_shear_modulus(207.0, 0.3)
    assert g < 1e-9 * 207.0 / 2.6


@pytest.fixture(scope="module")
def bar_runs(tmp_path_factory):
    d = tmp_path_factory.mktemp("bars")
    paths = {}
    for case in ("bar_tension", "bar_compression"):
        for v in ("paper", "hooke"):
            paths[f"solid:{case}_{v}"] = str(d / f"{case}_{v}.nc")
            outputs.write_run(CFG, case, v, paths[f"solid:{case}_{v}"])
    return paths


def test_bar_rows_judged_on_the_printed_method(bar_runs):
    ctx = C.Context(bar_runs)
    m, v = judge("mar-4.1-tension-hooke", ctx)  # eqs. 11-16 give E delta / (10 dx) exactly
    assert v == C.VERDICTS[0] and "1.51552 MPa" in m.measured
    m, v = judge("mar-4.1-necking-value", ctx)  # no Poisson term: no necking; hooke (beside) 0.105 um
    assert v == C.VERDICTS[2] and "hooke (completion) 0.1050 um" in m.measured
    assert judge("mar-4.1-compression-symmetric", ctx)[1] == C.VERDICTS[0]
    assert judge("mar-4.1-neck-bulge", ctx)[1] == C.VERDICTS[2]
    assert judge("mar-4.1-bar-inputs", ctx)[1] == C.VERDICTS[0]


def test_verdict_follows_the_run_data(bar_runs, tmp_path):
    """A tension run whose peak stress were 1 % off Hooke's law turns the row's verdict."""
    ds = runfile.read(bar_runs["solid:bar_tension_paper"]).load()
    ds["sigma_peak"] = ds["sigma_peak"] * 1.01
    bad = tmp_path / "bar_tension_paper.nc"
    ds.to_netcdf(bad)
    ctx = C.Context({**bar_runs, "solid:bar_tension_paper": str(bad)})
    m, v = judge("mar-4.1-tension-hooke", ctx)
    assert v == C.VERDICTS[2] and "+1.00e-02" in m.measured


def test_missing_runs_make_a_row_untestable():
    df = C.judge(C.Context(), [ENTRIES["mar-4.2-shear-num"]], INPUTS)
    assert df.loc[0, "verdict"] == C.VERDICTS[3] and "solid:shear_paper" in df.loc[0, "measured"]
