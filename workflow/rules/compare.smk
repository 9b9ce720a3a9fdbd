# Every method on the same tank: one table, one figure, one report section, one claim.
# The method summaries list each method's run files; all measures come from metrics on those files.
METHOD_SUMMARIES = ["results/sph/summary.csv", "results/mps/summary.csv"]


rule methods_tables:
    input:
        isa_errors="figures/error_vs_runtime.csv",
        isa_metrics="results/metrics.csv",
        summaries=METHOD_SUMMARIES,
        code=code("tables", "metrics", "theory"),
    output:
        "figures/methods_error_vs_runtime.csv",
        "figures/methods_flow.csv",
    params:
        func="tables.methods_tables",
    conda:
        "../envs/isaflow.yaml"
    log:
        "logs/compare/tables.log",
    script:
        "../scripts/call.py"


rule fig_methods:
    input:
        inputs=["figures/methods_error_vs_runtime.csv"],
        code=FIGURE_CODE,
    output:
        report_figure("methods_error_vs_runtime", "methods_figure", "Methods compared"),
    params:
        func="figures.methods.methods_error_vs_runtime_figure",
    conda:
        "../envs/isaflow.yaml"
    log:
        "logs/figures/methods_error_vs_runtime.log",
    script:
        "../scripts/call.py"


rule report_methods:
    input:
        single="figures/methods_error_vs_runtime.csv",
        flow="figures/methods_flow.csv",
        code=code("report/__init__", "report/methods"),
    output:
        "results/report/70_methods.md",
        "results/claims/methods.csv",
    params:
        func="report.methods.methods_section",
    conda:
        "../envs/isaflow.yaml"
    log:
        "logs/report/methods.log",
    script:
        "../scripts/call.py"


register(targets=figure("methods_error_vs_runtime") + ["figures/methods_flow.csv"])
register(report=["results/report/70_methods.md"])
register(claims=["results/claims/methods.csv"])
