# Every method on every tank: one table (metrics.comparison_row of every compared run), the figures, the
# report section.  Which runs take part is each method's declaration ('compare: true' on a tank of
# config.yaml's compare.tanks; 'runtime: true' adds single-vessel points to the run-time figure).


rule compare_table:
    input:
        runs=lambda wc: sorted(set(compare_runs()) | set(runtime_runs())),
        code=code("tables"),
    output:
        "results/compare/runs.csv",
    params:
        func="tables.compare_table",
        kw=lambda wc: {"compare": compare_runs()},
    message:
        JOB
    resources:
        **SMALL,
    log:
        "logs/compare/table.log",
    conda:
        "../envs/isaflow.yaml"
    script:
        "../scripts/call.py"


rule compare_figure_tanks:
    input:
        table="results/compare/runs.csv",
        code=code("figures.methods"),
    output:
        figure("methods_tanks"),
    params:
        func="figures.methods.tanks_figure",
        kw={"tanks": config["compare"]["tanks"]},
    message:
        JOB
    resources:
        **SMALL,
    log:
        "logs/compare/figure_tanks.log",
    conda:
        "../envs/isaflow.yaml"
    script:
        "../scripts/call.py"


rule compare_figure_runtime:
    input:
        table="results/compare/runs.csv",
        code=code("figures.methods"),
    output:
        figure("methods_error_vs_runtime"),
    params:
        func="figures.methods.error_vs_runtime_figure",
    message:
        JOB
    resources:
        **SMALL,
    log:
        "logs/compare/figure_runtime.log",
    conda:
        "../envs/isaflow.yaml"
    script:
        "../scripts/call.py"


rule compare_report:
    input:
        table="results/compare/runs.csv",
        code=code("report.methods"),
    output:
        "results/report/70_methods.md",
        "docs/tables/methods_compare.csv",
    params:
        func="report.methods.methods_section",
        kw={"tanks": config["compare"]["tanks"]},
    message:
        JOB
    resources:
        **SMALL,
    log:
        "logs/compare/report.log",
    conda:
        "../envs/isaflow.yaml"
    script:
        "../scripts/call.py"


register(targets=figure("methods_tanks") + figure("methods_error_vs_runtime") + ["docs/tables/methods_compare.csv"])
register(report=["results/report/70_methods.md"])
