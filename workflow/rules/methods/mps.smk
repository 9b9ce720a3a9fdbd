# MPS with three pressure source terms (Hattori et al.'s eq. 6 against the standard and mixed ones): its
# runs (config/methods/mps.yaml runs: single vessel, both flow tanks, stiff cases, time-step study) go
# through the shared rule `run`; here the summary, figures, report fragment 55 and timing fragment (the claims:
# claims.smk, quantities in methods/mps/quantities.py).
# Package: src/isaflow/methods/mps/.
_MPS_RUNS = RUNS["mps"]  # its settings file's runs (common.smk)
MPS_FILES = [run_file("mps", r) for r in _MPS_RUNS]
MPS_SINGLE = [run_file("mps", r) for r in _MPS_RUNS if r.startswith("single_")]
MPS_BEFORE = [run_file("mps", r) for r in _MPS_RUNS if r.startswith("kog_")]  # the settings before issue 30
MPS_FLOW_FINEST = [run_file("mps", r) for r, d in _MPS_RUNS.items() if r.startswith("flow_") and d["resolution"] == "dx3.45"]


use rule call as mps_summary with:
    input:
        runs=MPS_FILES,
        code=code("methods.mps.outputs"),
    output:
        "results/mps/summary.csv",
    params:
        func="methods.mps.outputs.summary",
    log:
        "logs/mps/summary.log",


use rule call as mps_figure_loads with:
    input:
        runs=MPS_SINGLE,
        code=code("methods.mps.figures"),
    output:
        figure("mps_wall_loads"),
    params:
        func="methods.mps.figures.wall_loads",
    log:
        "logs/mps/figure_loads.log",


use rule call as mps_figure_rest with:
    input:
        runs=MPS_SINGLE,
        before=MPS_BEFORE,
        code=code("methods.mps.figures"),
    output:
        figure("mps_rest"),
    params:
        func="methods.mps.figures.rest",
    log:
        "logs/mps/figure_rest.log",


use rule call as mps_figure_column with:
    input:
        runs=MPS_SINGLE,
        code=code("methods.mps.figures"),
    output:
        figure("mps_column"),
    params:
        func="methods.mps.figures.column",
    log:
        "logs/mps/figure_column.log",


use rule call as mps_figure_flow with:
    input:
        runs=MPS_FLOW_FINEST,
        code=code("methods.mps.figures"),
    output:
        figure("mps_flow"),
    params:
        func="methods.mps.figures.flow",
    log:
        "logs/mps/figure_flow.log",


# the standard source term's flow at the finer spacing as an animation (its stored states)
use rule call as mps_flow_animation with:
    input:
        runs=[run_file("mps", "flow_standard_dx3.45")],
        code=code("figures.animation"),
    output:
        "figures/mps_flow_animation.gif",
    params:
        func="figures.animation.flow_animation",
    log:
        "logs/mps/figure_flow_animation.log",


rule mps_bench:
    input:
        script="benchmarks/bench_mps.py",
        code=code("methods/mps/*"),
    output:
        "benchmarks/results/mps_step_cost.csv",
    threads: 2  # the benchmark times 1 and 2 threads; it takes the whole 2-core machine
    message:
        JOB
    resources:
        **BENCH,
    log:
        "logs/mps/bench.log",
    conda:
        "../../envs/isaflow.yaml"
    params:
        src=os.path.join(workflow.basedir, "src"),  # this checkout's source (no install needed)
    shell:
        "PYTHONPATH={params.src} python {input.script} > {log} 2>&1"


use rule call as mps_report with:
    input:
        summary="results/mps/summary.csv",
        cfg=REGISTRY["mps"].settings,
        code=code("methods.mps.report"),
    output:
        report="results/report/55_mps.md",
        timing="results/timing/55_mps.md",
        table="docs/tables/mps_single.csv",
    params:
        func="methods.mps.report.write",
    log:
        "logs/mps/report.log",


register(MPS_FILES + ["results/mps/summary.csv"] + figure("mps_wall_loads") + figure("mps_flow") + figure("mps_rest")
         + figure("mps_column") + ["figures/mps_flow_animation.gif"],
         ["results/report/55_mps.md"], timing=["results/timing/55_mps.md"])


use rule call as mps_bench_fragment with:
    input:
        bench="benchmarks/results/mps_step_cost.csv",
        code=code("methods.mps.report"),
    output:
        "results/bench/55_mps.md",
    params:
        func="methods.mps.report.bench_fragment",
    log:
        "logs/mps/bench_fragment.log",


register(bench=["results/bench/55_mps.md"])
