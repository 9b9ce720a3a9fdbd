# Weakly compressible SPH (marko2017 section 2, completed): its runs (config/methods/sph.yaml runs: the
# single vessel, both flow tanks, stability cases) go through the shared rule `run`; here the summary,
# figures, claims, report fragment 50 and timing fragment.  Package: src/isaflow/methods/sph/.
_SPH_RUNS = RUNS["sph"]  # its settings file's runs (common.smk)
# the periodic blocks (tensile-instability test, settings.domain periodic_block) load no wall: claims only
_SPH_BLOCKS = [r for r, d in _SPH_RUNS.items()
               if d.get("set", {}).get("settings.domain", {}).get("value") == "periodic_block"]
SPH_FILES = [run_file("sph", r) for r in _SPH_RUNS if r not in _SPH_BLOCKS]
SPH_SINGLE = [run_file("sph", r) for r, d in _SPH_RUNS.items() if r.startswith("single_wcsph_") and d["variant"] == "wcsph"]
SPH_FLOW = [run_file("sph", r) for r, d in _SPH_RUNS.items() if d["tank"] != "single" and d.get("start")]
SPH_FIGURES = [f for name in ("sph_single", "sph_flow", "sph_flow_snapshots") for f in figure(name)]


use rule call as sph_summary with:
    input:
        runs=SPH_FILES,
        code=code("methods.sph.outputs"),
    output:
        "results/sph/summary.csv",
    params:
        func="methods.sph.outputs.summary",
    log:
        "logs/sph/summary.log",


use rule call as sph_figures with:
    input:
        single_runs=SPH_SINGLE,
        flow_runs=SPH_FLOW,
        code=code("methods.sph.figures"),
    output:
        SPH_FIGURES,
    params:
        func="methods.sph.figures.all_figures",
    log:
        "logs/sph/figures.log",


# the finest flow into the stepped second vessel as an animation (its stored states)
SPH_ANIMATED = run_file("sph", "flow_wcsph_dx2.5")


use rule call as sph_flow_animation with:
    input:
        runs=[SPH_ANIMATED],
        code=code("figures.animation"),
    output:
        "figures/sph_flow_animation.gif",
    params:
        func="figures.animation.flow_animation",
    log:
        "logs/sph/flow_animation.log",


use rule call as sph_report with:
    input:
        summary="results/sph/summary.csv",
        code=code("methods.sph.report"),
    output:
        "results/report/50_sph.md",
        "results/timing/50_sph.md",
    params:
        func="methods.sph.report.write",
    log:
        "logs/sph/report.log",


rule sph_bench:
    input:
        script="benchmarks/bench_sph.py",
        code=code("methods/sph/*"),
    output:
        "benchmarks/results/sph_step_cost.csv",
    threads: 2  # 1 and 2 threads side by side; it takes the whole 2-core machine
    message:
        JOB
    resources:
        **BENCH,
    log:
        "logs/sph/bench.log",
    conda:
        "../../envs/isaflow.yaml"
    params:
        src=os.path.join(workflow.basedir, "src"),  # this checkout's source (no install needed)
    shell:
        "PYTHONPATH={params.src} python {input.script} > {log} 2>&1"


register(SPH_FILES + ["results/sph/summary.csv"] + SPH_FIGURES + ["figures/sph_flow_animation.gif"],
         ["results/report/50_sph.md"], timing=["results/timing/50_sph.md"])
register(bench=["benchmarks/results/sph_step_cost.csv"])
