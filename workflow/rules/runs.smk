# The one rule of every tank run of every method: results/runs/{method}/{run}.nc from the run's
# declaration (tank, variant, resolution, overrides, start), passed to isaflow.run as data.


rule run:
    input:
        unpack(run_inputs),
    output:
        "results/runs/{method}/{run}.nc",
    params:
        decl=lambda wc: RUNS[wc.method][wc.run],
    # threads: the declaration's (numba and OpenMP threads of the solver); mem_mb and runtime: from the
    # run's cost estimate (common.smk run_resources, isaflow.budget.job_resources)
    threads: lambda wc: RUNS[wc.method][wc.run].get("threads", 1)
    resources:
        mem_mb=lambda wc: run_resources(wc)["mem_mb"],
        runtime=lambda wc: run_resources(wc)["runtime"],
    message:
        "run {wildcards.method}/{wildcards.run}: {threads} thread(s), {resources.mem_mb} MB, {resources.runtime} min"
    log:
        "logs/runs/{method}/{run}.log",
    benchmark:
        "results/benchmarks/runs/{method}/{run}.tsv"
    wildcard_constraints:
        method="|".join(TANK_METHODS),
        run="[A-Za-z0-9_.]+",
    conda:
        "../envs/isaflow.yaml"
    script:
        "../scripts/run.py"
