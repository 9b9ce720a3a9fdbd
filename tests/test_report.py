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


def _compare_table(tmp_path, sph_left, sph_status):
    rows = [
        dict(method="isa", variant="capped", run="flow_complete_capped", tank="flow_step50", spacing_cm=10,
             particles=180, status="converged", left_fraction=30 / 180, second_slope_deg=-10.2,
             second_surface_range_cm=39.8, compare=True),
        dict(method="sph", variant="wcsph", run="flow_wcsph_dx2.5", tank="flow_step50", spacing_cm=2.5, particles=1160,
             status=sph_status, left_fraction=sph_left, second_slope_deg=-0.5, second_surface_range_cm=3.0,
             compare=True),
    ]
    path = tmp_path / "runs.csv"
    pd.DataFrame(rows).to_csv(path, index=False)
    return str(path)


def test_damping_claim_bounds_the_liquid_left_at_its_time_limit(tmp_path):
    """The liquid's share left at its time limit bounds its share at rest, so 17 % against 5 % is
    'not reproduced' (tolerance one floor row, 10/180 = 5.6 %)."""
    from isaflow.methods.isa.report import claims

    out = [str(tmp_path / "claims.csv")]
    claims.damping_claim(_compare_table(tmp_path, 0.05, "step_limit"), out)
    row = pd.read_csv(out[0]).iloc[0]
    assert row["verdict"] == "not reproduced" and "upper bound" in row["measured"]


def test_damping_verdict_needs_the_heap_gone_as_well(tmp_path):
    """Mass left within a floor row is not enough: the ISA surface range (39.8 cm) must be within a/2 = 5 cm."""
    from isaflow.methods.isa.report import claims

    out = [str(tmp_path / "claims.csv")]
    claims.damping_claim(_compare_table(tmp_path, 0.12, "converged"), out)
    assert pd.read_csv(out[0]).iloc[0]["verdict"] == "not reproduced"
