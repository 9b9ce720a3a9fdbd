# The report every method feeds: the inferred inputs of every method, docs/replication.md (claims table
# first, then every registered fragment in NN order) and docs/timing.md (every timing fragment).


use rule call as report_inferred with:
    input:
        inferred="config/inferred.yaml",
        settings=[m.settings for m in REGISTRY.values()],
        code=code("report.inferred"),
    output:
        "results/report/90_inferred.md",
    params:
        func="report.inferred.inferred_section",
    log:
        "logs/report/inferred.log",


use rule call as replication_report with:
    input:
        parts=lambda wc: sorted(TARGETS["report"], key=lambda p: p.rsplit("/", 1)[-1]),
        claims=[f"results/claims/registry/{p}.csv" for p in CLAIM_PAPERS],
        counts="results/claims/registry/counts.csv",
        findings="results/report/findings.md",
        registry=sorted(glob.glob("config/claims/*.yaml")),
        figures="workflow/report/figures.yaml",
        baseline="docs/tables/claims_baseline.csv",
        code=code("report", "report.claims"),
    output:
        "docs/replication.md",
        report_file("results/report/replication.html", "replication", "Report"),
    params:
        func="report.assemble",
    log:
        "logs/report/assemble.log",


use rule call as timing_report with:
    input:
        parts=lambda wc: sorted(TARGETS["timing"]),
        code=code("report.speed"),
    output:
        "docs/timing.md",
    params:
        func="report.speed.timing_report",
    log:
        "logs/report/timing.log",


register(targets=["docs/replication.md", "docs/timing.md"], report=["results/report/90_inferred.md"])


# the benchmarks (snakemake -c2 benchmarks): step costs, compile and memory of every method against its peers;
# each takes the whole machine for minutes, so the full run leaves them out
use rule call as bench_report with:
    input:
        parts=lambda wc: sorted(p for p in TARGETS["bench"] if p.endswith(".md")),
        code=code("report.speed"),
    output:
        "docs/benchmarks.md",
    params:
        func="report.speed.timing_report",
        kw={"title": "Benchmarks"},
    log:
        "logs/report/benchmarks.log",


# every method's step cost against its floor and its peers, from the benchmarks' CSVs (benchmarks/floors.py)
rule bench_floors:
    input:
        script="benchmarks/floors.py",
        csv=["benchmarks/results/step_floor.csv", "benchmarks/results/sph_step_cost.csv",
             "benchmarks/results/mps_step_cost.csv", "benchmarks/results/solid_step_cost.csv"],
    output:
        "results/bench/05_floors.md",
    message:
        JOB
    localrule: True
    resources:
        **SMALL,
    log:
        "logs/report/bench_floors.log",
    conda:
        "../envs/isaflow.yaml"
    shell:
        "python {input.script} {output} benchmarks/results > {log} 2>&1"


register(bench=["results/bench/05_floors.md"])


rule benchmarks:
    input:
        lambda wc: TARGETS["bench"] + ["docs/benchmarks.md"],


# The report's copy of a figure (or an animation, .gif), with its own caption (workflow/report/figures.yaml, the verdicts of the claims
# it bears on from this run's claims registry), category and subcategory.  Only a run of this checkout makes
# it, so a report never shows a committed figure the run did not make.
rule report_figure_copy:
    input:
        "figures/{name}.{ext}",
    output:
        report("results/report/figures/{name}.{ext}", caption="../report/figure.rst",
               category=lambda wc: REPORT_FIGURES[wc.name]["category"],
               subcategory=lambda wc: REPORT_FIGURES[wc.name]["subcategory"]),
    message:
        JOB
    localrule: True
    resources:
        **SMALL,
    log:
        "logs/report/figures/{name}.{ext}.log",
    wildcard_constraints:
        name="|".join(REPORT_FIGURES),
        ext="png|gif",  # a figure or an animation
    conda:
        "../envs/isaflow.yaml"
    shell:
        "cp {input} {output} 2> {log}"
