# Metrics table and docs/replication.md, regenerated from the run files.
# Each part writes a fragment results/report/NN_part.md (register(report=...)).


rule metrics:
    input:
        runs=[run_file(r) for r in METRIC_RUNS],
        code=code("metrics", "theory"),
    output:
        "results/metrics.csv",
    log:
        "logs/metrics.log",
    script:
        "../scripts/metrics.py"


rule report_single:
    input:
        metrics="results/metrics.csv",
        calibration="results/calibration.csv",
        config="config/config.yaml",
        code=code("report", "metrics"),
    output:
        "results/report/10_single.md",
    params:
        func="single_section",
    log:
        "logs/report/single.log",
    script:
        "../scripts/report.py"


rule report_inferred:
    input:
        inferred="config/inferred.yaml",
        scenes=sorted({r["scene"] for r in RUNS.values()}),
        code=code("report"),
    output:
        "results/report/90_inferred.md",
    log:
        "logs/report/inferred.log",
    run:
        from isaflow import report

        report.inferred_section(input.inferred, input.scenes, output[0])


register(report=["results/report/10_single.md", "results/report/90_inferred.md"])


rule replication_report:
    input:
        parts=lambda wc: sorted(TARGETS["report"], key=lambda p: p.rsplit("/", 1)[-1]),
        code=code("report"),
    output:
        "docs/replication.md",
    log:
        "logs/report/assemble.log",
    run:
        from isaflow import report

        report.assemble(input.parts, output[0])


register(targets=["results/metrics.csv", "docs/replication.md"])
