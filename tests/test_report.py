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


def _method_tables(tmp_path, sph_left, sph_status):
    single = pd.DataFrame([
        dict(method="isa", variant="paper", run="a", spacing_cm=10, particles=180, status="cycle", steps=8000,
             dynamic=False, wall_time_s=0.03, side_err=0.001, contact_rms=0.1, side_height_err_cm=0.1, level_err_hydro_cm=0),
        dict(method="isa", variant="capped", run="b", spacing_cm=10, particles=180, status="converged", steps=9964,
             dynamic=False, wall_time_s=0.04, side_err=-0.045, contact_rms=0.17, side_height_err_cm=2.3,
             level_err_hydro_cm=0),
        dict(method="sph", variant="wcsph", run="c", spacing_cm=2.5, particles=1160, status="step_limit", steps=9,
             dynamic=True, wall_time_s=9.0, side_err=0.005, contact_rms=0.002, side_height_err_cm=0.4,
             level_err_hydro_cm=0),
    ])
    flow = pd.DataFrame([
        dict(method="isa", variant="capped", run="flow_complete_capped", spacing_cm=10, particles=180, status="converged",
             left_fraction=30 / 180, depth=31.4, slope_deg=-10.2, surface_range_cm=39.8, side_err=0.32),
        dict(method="sph", variant="wcsph", run="flow_wcsph_dx2.5", spacing_cm=2.5, particles=1160, status=sph_status,
             left_fraction=sph_left, depth=32.2, slope_deg=-0.5, surface_range_cm=3.0, side_err=0.08),
    ])
    paths = [tmp_path / "single.csv", tmp_path / "flow.csv"]
    single.to_csv(paths[0], index=False)
    flow.to_csv(paths[1], index=False)
    return [str(p) for p in paths]


def test_methods_section_judges_equilibria_and_time_averaged_states_only(tmp_path):
    """A static run in a cycle (here with a lucky 0.1 % side error) is not judged; a dynamic run at its time
    limit is; the liquid's share left at its time limit bounds its share at rest, so 17 % against 5 % is
    'not reproduced' (tolerance one floor row, 10/180 = 5.6 %); 10 % against 5 % would be within it."""
    from isaflow.report import methods

    out = [str(tmp_path / "70.md"), str(tmp_path / "claims.csv")]
    methods.methods_section(*_method_tables(tmp_path, 0.05, "step_limit"), out)
    text = open(out[0]).read()
    assert "isa 4.50%; sph 0.50%" in text
    row = pd.read_csv(out[1]).iloc[0]
    assert row["verdict"] == "not reproduced" and "upper bound" in row["measured"]


def test_methods_verdict_needs_the_heap_gone_as_well(tmp_path):
    """Mass left within a floor row is not enough: the ISA surface range (39.8 cm) must be within a/2 = 5 cm."""
    from isaflow.report import methods

    out = [str(tmp_path / "70.md"), str(tmp_path / "claims.csv")]
    methods.methods_section(*_method_tables(tmp_path, 0.12, "converged"), out)
    assert pd.read_csv(out[1]).iloc[0]["verdict"] == "not reproduced"
