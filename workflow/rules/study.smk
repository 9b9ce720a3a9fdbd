# Error against run time, FIRE tuning and numerical stability (config/study.yaml).
# Every point is one `isaflow run` with its own netCDF under results/study/runs/.
import re

from isaflow import plan as S

validate(config["study"], "../schemas/study.schema.yaml")

STUDY = config["study"]
STUDY_RUNS = S.plan(STUDY)
STUDY_META = S.meta(STUDY_RUNS)


STUDY_FIG_CODE = FIGURE_CODE


rule study_run:
    input:
        scene=lambda wc: STUDY_RUNS[wc.sid]["scene"],
        code=SOLVER_CODE,
    output:
        "results/study/runs/{sid}.nc",
    params:
        overrides=lambda wc: S.cli_overrides(STUDY_RUNS, wc.sid),
    conda:
        "../envs/isaflow.yaml"
    log:
        "logs/study/run/{sid}.log",
    benchmark:
        "results/benchmarks/study/{sid}.tsv"
    wildcard_constraints:
        sid="|".join(re.escape(s) for s in STUDY_RUNS),
    shell:
        "isaflow run {input.scene} -o {output} {params.overrides} --config config/study.yaml -q 2> {log}"


rule study_error_table:
    input:
        runs=S.run_files(STUDY_RUNS, "error_runtime"),
        code=code("tables", "plan", "metrics", "theory"),
    output:
        "figures/error_vs_runtime.csv",
    params:
        func="tables.error_table",
        kw={"meta": STUDY_META, "paper": config["paper"]},
    conda:
        "../envs/isaflow.yaml"
    log:
        "logs/study/error_table.log",
    script:
        "../scripts/call.py"


rule study_fire_tables:
    input:
        tuning=S.run_files(STUDY_RUNS, "fire_tuning"),
        references=[
            f
            for lat in STUDY["fire_tuning"]["lattices"]
            for var in ("capped", "paper")
            for f in S.run_files(STUDY_RUNS, "error_runtime", lattice=lat, variant=var, du_factor=1)
        ],
        code=code("tables", "plan", "metrics", "theory"),
    output:
        "results/study/fire_tuning.csv",
        "results/study/fire_ratio.csv",
    params:
        func="tables.fire_tables",
        kw={
            "meta": STUDY_META,
            "paper": config["paper"],
            "required_ratio": STUDY["fire_tuning"]["required_ratio"],
        },
    conda:
        "../envs/isaflow.yaml"
    log:
        "logs/study/fire_tables.log",
    script:
        "../scripts/call.py"


rule study_map_table:
    input:
        runs=S.run_files(STUDY_RUNS, "stability_map"),
        code=code("tables", "plan", "metrics", "theory"),
    output:
        "results/study/stability_map.csv",
    params:
        func="tables.map_table",
        kw={"meta": STUDY_META},
    conda:
        "../envs/isaflow.yaml"
    log:
        "logs/study/map_table.log",
    script:
        "../scripts/call.py"


rule study_cases_table:
    input:
        runs=S.run_files(STUDY_RUNS, "cases"),
        code=code("tables", "plan", "metrics", "theory"),
    output:
        "figures/stability_cases.csv",
    params:
        func="tables.cases_table",
        kw={"meta": STUDY_META},
    conda:
        "../envs/isaflow.yaml"
    log:
        "logs/study/cases_table.log",
    script:
        "../scripts/call.py"


rule fig_error_vs_runtime:
    input:
        inputs=["figures/error_vs_runtime.csv"],
        code=STUDY_FIG_CODE,
    output:
        report_figure("error_vs_runtime", "study_figure", "Studies"),
    params:
        func="figures.study.error_vs_runtime_figure",
    conda:
        "../envs/isaflow.yaml"
    log:
        "logs/figures/error_vs_runtime.log",
    script:
        "../scripts/call.py"


rule fig_stability_map:
    input:
        inputs=["results/study/stability_map.csv", "figures/stability_cases.csv"],
        code=STUDY_FIG_CODE,
    output:
        report_figure("stability_map", "study_figure", "Studies"),
    params:
        func="figures.study.stability_map_figure",
    conda:
        "../envs/isaflow.yaml"
    log:
        "logs/figures/stability_map.log",
    script:
        "../scripts/call.py"


rule report_study:
    input:
        errors="figures/error_vs_runtime.csv",
        fire_ratio="results/study/fire_ratio.csv",
        fire_grid="results/study/fire_tuning.csv",
        stability_map="results/study/stability_map.csv",
        cases="figures/stability_cases.csv",
        study_config="config/study.yaml",
        code=code("report/__init__", "report/study", "tables", "plan"),
    output:
        "results/report/30_study.md",
        "docs/tables/study_recommendation.csv",
        "docs/tables/study_cases.csv",
    params:
        func="report.study.report_section",
    conda:
        "../envs/isaflow.yaml"
    log:
        "logs/report/study.log",
    script:
        "../scripts/call.py"


register(report=["results/report/30_study.md"])
register(targets=figure("error_vs_runtime") + figure("stability_map"))
register(targets=["figures/error_vs_runtime.csv", "figures/stability_cases.csv", "results/study/fire_ratio.csv"])
