# Metrics table and docs/replication.md, regenerated from the run files.
# Each part writes a fragment results/report/NN_part.md (REPORT_PARTS).


rule metrics:
    input:
        [run_file(r) for r in METRIC_RUNS],
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
    output:
        "results/report/90_inferred.md",
    log:
        "logs/report/inferred.log",
    run:
        from isaflow import report

        report.inferred_section(input.inferred, input.scenes, output[0])


REPORT_PARTS += ["results/report/10_single.md", "results/report/90_inferred.md"]


rule replication_report:
    input:
        REPORT_PARTS,
    output:
        "docs/replication.md",
    log:
        "logs/report/assemble.log",
    run:
        from isaflow import report

        report.assemble(input, output[0])


ALL_TARGETS += ["results/metrics.csv", "docs/replication.md"]
