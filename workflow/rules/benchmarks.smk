# Speed benchmarks (benchmarks/, reported in files; never timed tests).
# The step-cost benchmark takes both cores so other jobs do not perturb it.


rule bench_step:
    input:
        script="benchmarks/bench_step.py",
        reference="benchmarks/numpy_reference.py",
        code=code("core/*", "methods/isa/*", "scene"),
    output:
        "benchmarks/results/step_cost.csv",
        "benchmarks/results/compile.csv",
        "benchmarks/results/memory.csv",
        "benchmarks/results/summary.txt",
        "benchmarks/results/machine.txt",
        "benchmarks/results/step_cost.png",
    threads: 2  # the benchmark takes the whole 2-core machine so other jobs do not perturb it
    conda:
        "../envs/isaflow.yaml"
    log:
        "logs/benchmarks/bench_step.log",
    shell:
        "python {input.script} > {log} 2>&1"


rule bench_output:
    input:
        script="benchmarks/bench_output.py",
        scene="config/scenes/single_refined.yaml",
        code=SOLVER_CODE,
    output:
        "benchmarks/results/output_cost.csv",
    threads: 2  # the benchmark takes the whole 2-core machine so other jobs do not perturb it
    conda:
        "../envs/isaflow.yaml"
    log:
        "logs/benchmarks/bench_output.log",
    shell:
        "python {input.script} > {log} 2>&1"


register(targets=["benchmarks/results/output_cost.csv"])
