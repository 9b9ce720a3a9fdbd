# Every method on every tank: one table (metrics.comparison_row of every compared run), the figures, the
# report section.  Which runs take part is each method's declaration ('compare: true' on a tank of
# config.yaml's compare.tanks; 'runtime: true' adds single-vessel points to the run-time figure).


use rule call as compare_table with:
    input:
        runs=lambda wc: sorted(set(compare_runs()) | set(runtime_runs())),
        code=code("tables"),
    output:
        "results/compare/runs.csv",
    params:
        func="tables.compare_table",
        kw=lambda wc: {"compare": compare_runs()},
    log:
        "logs/compare/table.log",


use rule call as compare_figure_tanks with:
    input:
        table="results/compare/runs.csv",
        code=code("figures.methods"),
    output:
        figure("methods_tanks"),
    params:
        func="figures.methods.tanks_figure",
        kw={"tanks": config["compare"]["tanks"]},
    log:
        "logs/compare/figure_tanks.log",


use rule call as compare_figure_runtime with:
    input:
        table="results/compare/runs.csv",
        code=code("figures.methods"),
    output:
        figure("methods_error_vs_runtime"),
    params:
        func="figures.methods.error_vs_runtime_figure",
    log:
        "logs/compare/figure_runtime.log",


use rule call as compare_report with:
    input:
        table="results/compare/runs.csv",
        code=code("report.methods"),
    output:
        "results/report/70_methods.md",
        "docs/tables/methods_compare.csv",
    params:
        func="report.methods.methods_section",
        kw={"tanks": config["compare"]["tanks"]},
    log:
        "logs/compare/report.log",


register(targets=figure("methods_tanks") + figure("methods_error_vs_runtime") + ["docs/tables/methods_compare.csv"])
register(report=["results/report/70_methods.md"])
