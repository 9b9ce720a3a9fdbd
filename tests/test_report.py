"""docs/replication.md assembly: the claims first (counts by kind, one table per paper in the registry's paper
order, why not reproduced, what changed), the findings, then the fragments in name order."""

import pandas as pd

from isaflow import claims, report


def test_assemble_puts_the_claims_first_and_every_part_after(tmp_path):
    rows = {
        "hattori": dict(id="hat-x", paper="hattori", section="eq. 6", kind="method result", claim="c2", measured="m2",
                        verdict="not testable here (x)", why=""),
        "papadopoulos2016": dict(id="pap-x", paper="papadopoulos2016", section="6.1", kind="paper inconsistency",
                                 claim="c1", measured="m1", verdict="not reproduced", why="because"),
    }
    files = []
    for paper, row in rows.items():  # one file per paper, as the claims rule writes them
        files.append(tmp_path / f"{paper}.csv")
        pd.DataFrame([row], columns=claims.COLUMNS).to_csv(files[-1], index=False)
    counts = tmp_path / "counts.csv"
    claims.counts(pd.DataFrame(list(rows.values()))).to_csv(counts, index=False)
    findings = tmp_path / "findings.md"
    findings.write_text("- a finding\n")
    parts = [tmp_path / "20_b.md", tmp_path / "10_a.md"]
    for p in parts:
        p.write_text(f"## section {p.stem}\n")
    out = tmp_path / "replication.md"
    report.assemble([str(p) for p in parts], [str(f) for f in files[::-1]], str(counts), str(findings), [str(out)])
    text = out.read_text()
    order = [text.index(s) for s in ("## Claims", "### Counts by paper and kind", "| paper inconsistency | 1 | 0 | 1 |",
                                     "1 not reproduced", "| `pap-x` 6.1 | paper inconsistency | \"c1\"",
                                     "| `hat-x` eq. 6 | method result | \"c2\"", "## Why not reproduced", "because",
                                     "- a finding", "## section 10_a", "## section 20_b")]
    assert order == sorted(order)


def test_a_calibrated_verdict_is_counted_as_calibrated_not_as_reproduced():
    df = pd.DataFrame([dict(paper="p", kind="method result", verdict="reproduced only after calibrating k_pair"),
                       dict(paper="p", kind="method result", verdict="reproduced")])
    c = claims.counts(df).iloc[0]
    assert c["reproduced"] == 1 and c["reproduced only after calibrating"] == 1
