# The one rule of every tank run of every method: results/runs/{method}/{run}.nc from the run's
# declaration (tank, variant, resolution, overrides, start), passed to isaflow.run as data.


rule run:
    input:
        unpack(run_inputs),
    output:
        "results/runs/{method}/{run}.nc",
    params:
        decl=lambda wc: RUNS[wc.method][wc.run],
    threads: lambda wc: RUNS[wc.method][wc.run].get("threads", 1)
    resources:
        mem_mb=lambda wc: RUNS[wc.method][wc.run].get("mem_mb", 1000),
        runtime=lambda wc: RUNS[wc.method][wc.run].get("runtime", 20),
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
