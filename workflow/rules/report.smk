# Metrics table, the claims of the paper, every report fragment of the paper's
# workflow, docs/replication.md and docs/timing.md.  Each part writes a fragment
# results/report/NN_part.md (register(report=...)); long tables go to docs/tables/.


rule metrics:
    input:
        runs=[run_file(r) for r in METRIC_RUNS],
        code=code("tables", "metrics", "theory"),
    output:
        "results/metrics.csv",
    params:
        func="tables.metrics_table",
    conda:
        "../envs/isaflow.yaml"
    priority: 10  # the paper's own outputs first (snakemake -c2 paper)
    log:
        "logs/metrics.log",
    script:
        "../scripts/call.py"


rule report_claims:
    input:
        metrics="results/metrics.csv",
        calibration="results/calibration.csv",
        config="config/config.yaml",
        code=code("report/__init__", "report/claims", "metrics"),
    output:
        report_file("results/claims/papadopoulos2016.csv", "claims", "Claims"),
        "results/report/findings.md",
    params:
        func="report.claims.paper_claims",
    conda:
        "../envs/isaflow.yaml"
    priority: 10  # the paper's own outputs first (snakemake -c2 paper)
    log:
        "logs/report/claims.log",
    script:
        "../scripts/call.py"


rule report_single:
    input:
        metrics="results/metrics.csv",
        calibration="results/calibration.csv",
        config="config/config.yaml",
        code=code("report/__init__", "report/single", "metrics"),
    output:
        "results/report/10_single.md",
        "docs/tables/single_tolerances.csv",
        "docs/tables/calibration.csv",
    params:
        func="report.single.single_section",
    conda:
        "../envs/isaflow.yaml"
    priority: 10  # the paper's own outputs first (snakemake -c2 paper)
    log:
        "logs/report/single.log",
    script:
        "../scripts/call.py"


rule report_flow:
    input:
        metrics="results/metrics.csv",
        config="config/config.yaml",
        code=code("report/__init__", "report/flow"),
    output:
        "results/report/20_flow.md",
    params:
        func="report.flow.flow_section",
    conda:
        "../envs/isaflow.yaml"
    priority: 10  # the paper's own outputs first (snakemake -c2 paper)
    log:
        "logs/report/flow.log",
    script:
        "../scripts/call.py"


rule report_inferred:
    input:
        inferred="config/inferred.yaml",
        scenes=sorted({r["scene"] for r in RUNS.values()}),
        code=code("report/__init__", "report/inferred"),
    output:
        "results/report/90_inferred.md",
    params:
        func="report.inferred.inferred_section",
    conda:
        "../envs/isaflow.yaml"
    log:
        "logs/report/inferred.log",
    script:
        "../scripts/call.py"


rule timing_report:
    input:
        step_cost="benchmarks/results/step_cost.csv",
        compile="benchmarks/results/compile.csv",
        memory="benchmarks/results/memory.csv",
        machine="benchmarks/results/machine.txt",
        output_cost="benchmarks/results/output_cost.csv",
        table1="figures/table1.csv",
        table1_md="figures/table1.md",
        parts=lambda wc: sorted(TARGETS["timing"]),
        code=code("report/__init__", "report/speed"),
    output:
        "docs/timing.md",
    params:
        func="report.speed.speed_section",
    conda:
        "../envs/isaflow.yaml"
    log:
        "logs/report/timing.log",
    script:
        "../scripts/call.py"


REPORT_PAPER = ["10_single", "20_flow", "90_inferred"]
register(report=[f"results/report/{part}.md" for part in REPORT_PAPER])
register(claims=["results/claims/papadopoulos2016.csv"])


rule replication_report:
    input:
        parts=lambda wc: sorted(TARGETS["report"], key=lambda p: p.rsplit("/", 1)[-1]),
        claims=lambda wc: sorted(TARGETS["claims"]),
        findings="results/report/findings.md",
        code=code("report/__init__"),
    output:
        "docs/replication.md",
    params:
        func="report.assemble",
    conda:
        "../envs/isaflow.yaml"
    log:
        "logs/report/assemble.log",
    script:
        "../scripts/call.py"


register(targets=["results/metrics.csv", "docs/replication.md", "docs/timing.md"])
