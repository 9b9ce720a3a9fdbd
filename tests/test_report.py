"""docs/replication.md assembly: claims table first, verdict counts, the findings, why-not-reproduced, fragments."""

import pandas as pd

from isaflow import report


def test_assemble_puts_the_claims_first_and_every_part_after(tmp_path):
    claims = tmp_path / "claims.csv"
    pd.DataFrame([
        dict(paper="hattori", section="eq. 6", claim="c2", measured="m2", verdict="not testable here (x)", evidence="e2",
             why=None),
        dict(paper="papadopoulos2016", section="6.1", claim="c1", measured="m1", verdict="not reproduced", evidence="e1",
             why="because"),
    ]).to_csv(claims, index=False)
    findings = tmp_path / "findings.md"
    findings.write_text("- a finding\n")
    parts = [tmp_path / "20_b.md", tmp_path / "10_a.md"]
    for p in parts:
        p.write_text(f"## section {p.stem}\n")
    out = tmp_path / "replication.md"
    report.assemble([str(p) for p in parts], [str(claims)], str(findings), [str(out)])
    text = out.read_text()
    order = [text.index(s) for s in ("## Claims", "| papadopoulos2016 6.1 | c1", "| hattori eq. 6 | c2", "## Summary",
                                     "1 not reproduced", "- a finding", "## Why not reproduced", "because",
                                     "## section 10_a", "## section 20_b")]
    assert order == sorted(order)
