# One solver run per configured run id.


rule run:
    input:
        scene=lambda wc: RUNS[wc.run]["scene"],
        start=lambda wc: start_file(wc.run),
        code=SOLVER_CODE,
    output:
        "results/runs/{run}.nc",
    params:
        overrides=run_overrides,
    conda:
        "../envs/isaflow.yaml"
    priority: 10  # the paper's own outputs first (snakemake -c2 paper)
    log:
        "logs/run/{run}.log",
    benchmark:
        "results/benchmarks/run/{run}.tsv"
    wildcard_constraints:
        run="|".join(RUNS),
    shell:
        "isaflow run {input.scene} -o {output} {params.overrides} --config config/config.yaml -q 2> {log}"
