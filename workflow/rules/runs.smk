# Every tank run of every method: results/runs/{method}/{run}.nc from the run's declaration (tank, variant,
# resolution, overrides, start), passed to isaflow.run as data.  A run declaring `block: NAME` runs with the
# other runs of its method's block in one job, one process (rule block_<method>_<NAME>: short sweep points
# solve in seconds, so one process saves their start-up); every other run is its own job (rule `run`).
# Before any run of a method, rule `compile` fills that method's kernel cache in one process
# (isaflow.core.jit: a cache filled by several processes at once can segfault).  Included after the methods'
# rules files, which declare the runs.

RUN_BLOCKS = run_blocks()  # {block id: [(method, run id), ...] in run order} (common.smk)
BLOCKED = {run for members in RUN_BLOCKS.values() for _, run in members}


# The stamp is kept (not temp): a temp stamp is made again whenever any of its consumers must run, and a job
# that makes it makes every run of the method rerun (one changed run declaration reran all of them).  A stamp
# older than the cache folder is harmless: the first run that finds its generation unsealed fills it (core.jit).
rule compile:
    input:
        code=lambda wc: code("isaflow.run", REGISTRY[wc.method].entry) + ["workflow/scripts/compile.py"],
    output:
        "results/compiled/{method}.txt",
    message:
        "compile {wildcards.method}: every kernel its runs use, into its cache"
    threads: 1
    # first among the jobs that can start: every run of its method waits for it (a fresh paper run started SPH's
    # compile at 466 s of 674, its runs after it)
    priority: 100
    resources:
        **SMALL,
    log:
        "logs/compile/{method}.log",
    wildcard_constraints:
        method="|".join(TANK_METHODS),
    conda:
        "../envs/isaflow.yaml"
    script:
        "../scripts/compile.py"


rule run:
    input:
        unpack(lambda wc: runs_inputs([(wc.method, wc.run)])),
    output:
        "results/runs/{method}/{run}.nc",
    params:
        runs=lambda wc: [run_job(wc.method, wc.run)],
    # threads: the declaration's (numba and OpenMP threads of the solver); mem_mb and runtime: from the
    # run's cost estimate (common.smk run_resources, isaflow.budget.job_resources)
    threads: lambda wc: RUNS[wc.method][wc.run].get("threads", 1)
    resources:
        mem_mb=lambda wc: run_resources([(wc.method, wc.run)])["mem_mb"],
        runtime=lambda wc: run_resources([(wc.method, wc.run)])["runtime"],
    message:
        "run {wildcards.method}/{wildcards.run}: {threads} thread(s), {resources.mem_mb} MB, {resources.runtime} min"
    log:
        "logs/runs/{method}/{run}.log",
    benchmark:
        "results/benchmarks/runs/{method}/{run}.tsv"
    wildcard_constraints:
        method="|".join(TANK_METHODS),
        # a run of a block is made by its block's rule only
        run="(?!(?:" + "|".join(re.escape(r) for r in sorted(BLOCKED)) + ")\\.nc$)[A-Za-z0-9_.]+" if BLOCKED
        else "[A-Za-z0-9_.]+",
    conda:
        "../envs/isaflow.yaml"
    script:
        "../scripts/run.py"


for _block, _members in RUN_BLOCKS.items():

    rule:
        name:
            f"block_{_block}"
        input:
            unpack(lambda wc, m=_members: runs_inputs(m)),
        output:
            [run_file(m, r) for m, r in _members],
        params:
            runs=[run_job(m, r) for m, r in _members],
        threads: max(RUNS[m][r].get("threads", 1) for m, r in _members)
        resources:
            mem_mb=lambda wc, m=_members: run_resources(m)["mem_mb"],
            runtime=lambda wc, m=_members: run_resources(m)["runtime"],
        message:
            f"block {_block}: {len(_members)} runs in one process"
        log:
            f"logs/blocks/{_block}.log",
        benchmark:
            f"results/benchmarks/blocks/{_block}.tsv"
        conda:
            "../envs/isaflow.yaml"
        script:
            "../scripts/run.py"
