"""Adding a claim takes what docs/architecture.md ("Adding a claim") says and nothing more: a registry row with its
checks in config/claims/<paper>.yaml and, for a new quantity, one function entered with @quantity in the
quantities module of the method whose runs it reads.  Added to a copy of the project, the row is judged by the one
judge from a run file: its verdict, its measured text (built from the numbers) and its evidence (the file read)."""

import shutil
import subprocess
import sys
import textwrap

import pandas as pd

from conftest import ROOT, run_isa

QUANTITY = '''


@quantity("particles in the top row", fmt=".4g")
def top_row(ds):
    """How many particles share the highest initial row (a test quantity: tests/test_add_a_claim.py)."""
    y = ds["pos0"].values[:, 1]
    return int((abs(y - y.max()) < 1e-9).sum())
'''

ROW = '''
  - id: pap-6.1-top-row-added
    paper: papadopoulos2016
    section: "6.1"
    quote: "There are 10 rows of 9 particles, alternated with 9 rows of 10 particles"
    kind: input rule
    judged_on: kept
    checks: [{q: isa.top_row_added, runs: ["isa:single_coarse"], op: within, target: row_a_len}]
    numbers:
      row_a_len: {value: 9, units: "1", where: "the paper, section 6.1: ten rows of 9 alternate with nine of 10, so the outer rows hold 9"}
    tolerance:
      value: 0
      units: particles
      kind: absolute
      derivation: "A count: exact."
      source: "page text: section 6.1"
    testable: true
    inferred_inputs: []
'''


def test_a_row_with_a_new_quantity_is_judged(tmp_path):
    copy = tmp_path / "project"
    for part in ("src", "config"):
        shutil.copytree(ROOT / part, copy / part, ignore=shutil.ignore_patterns("__pycache__"))
    q = copy / "src/isaflow/methods/isa/quantities.py"
    q.write_text(q.read_text() + QUANTITY.replace("def top_row(", "def top_row_added("))
    reg = copy / "config/claims/papadopoulos2016.yaml"
    reg.write_text(reg.read_text().rstrip("\n") + "\n" + ROW)
    run = tmp_path / "single_coarse.nc"
    assert run_isa(run, "single", "coarse", "paper") == 0
    out = tmp_path / "out"
    script = textwrap.dedent(f"""
        from isaflow import claims
        claims.write_paper([{str(out / 'p.csv')!r}, {str(out / 'p.html')!r}], {str(copy / 'config/claims')!r},
                           "papadopoulos2016", runs={{"isa:single_coarse": {str(run)!r}}})
    """)
    env = {"PYTHONPATH": str(copy / "src"), "NUMBA_DISABLE_JIT": "0", "PATH": "/usr/bin:/bin"}
    p = subprocess.run([sys.executable, "-c", script], cwd=copy, env=env, capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr[-2000:]
    df = pd.read_csv(out / "p.csv").set_index("id")
    r = df.loc["pap-6.1-top-row-added"]
    assert r["verdict"] == "reproduced" and r["kind"] == "input rule", r["measured"]
    assert "particles in the top row: single_coarse 9" in r["measured"] and str(run) in r["evidence"]
    assert (out / "p.html").read_text().count("pap-6.1-top-row-added") == 1
