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
        code=code("figures.methods", "report.methods"),
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


# Every tank method on a tank of your own (isaflow.compare, as `isaflow compare TANK.yaml -o DIR`):
#     snakemake -c2 compare --config tank=TANK.yaml [resolution=refined]
# writes results/compare/<the tank's name>/ (runs/<method>.nc, compare.csv, methods.png, report.md).  Each method
# runs in a process of its own on its kernels, compiled first by rule compile.  Not part of the full run.  The tank
# is read (and refused with one line) while the workflow is parsed.
from isaflow import compare as _compare  # noqa: E402

try:
    OWN_TANK = _compare.workflow_tank(config.get("tank"))  # (tank file, its name), or None without --config tank=
except _inputs.InputError as err:
    refuse(err)


rule compare:
    input:
        lambda wc: f"results/compare/{OWN_TANK[1]}" if OWN_TANK else refuse(
            "the target compare needs a tank file: snakemake -c2 compare --config tank=TANK.yaml"),


use rule call as compare_tank with:
    input:
        tank=lambda wc: OWN_TANK[0] if OWN_TANK and OWN_TANK[1] == wc.tank else refuse(
            f"results/compare/{wc.tank}: made by the target compare from --config tank=TANK.yaml"),
        code=code("compare", "isaflow.run", *[REGISTRY[m].entry for m in TANK_METHODS]),
        compiled=[ancient(f"results/compiled/{m}.txt") for m in TANK_METHODS],
    output:
        directory("results/compare/{tank}"),
    params:
        func="compare.run_tank",
        kw=lambda wc: {"resolution": str(config.get("resolution", "coarse"))},
    resources:
        mem_mb=2000,
        runtime=30,
    log:
        "logs/compare/tank_{tank}.log",
    wildcard_constraints:
        tank="[a-z0-9_]+",
