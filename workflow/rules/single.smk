# Single-vessel applications 1-2: Figures 5-8, free-surface calibration, convergence.
CAL_FILES = [
    f"results/calibration/{run}_kb{kb:g}_r{ratio:g}.nc"
    for run in CAL["runs"]
    for kb in CAL["wall_stiffness"]
    for ratio in CAL["stiffness_ratio"]
]


rule calibration_run:
    input:
        scene=lambda wc: RUNS[wc.run]["scene"],
        code=SOLVER_CODE,
    output:
        "results/calibration/{run}_kb{kb}_r{ratio}.nc",
    params:
        overrides=calibration_overrides,
    conda:
        "../envs/isaflow.yaml"
    log:
        "logs/calibration/{run}_kb{kb}_r{ratio}.log",
    benchmark:
        "results/benchmarks/calibration/{run}_kb{kb}_r{ratio}.tsv"
    shell:
        "isaflow run {input.scene} -o {output} {params.overrides} --config config/config.yaml -q 2> {log}"


rule calibration_table:
    input:
        runs=CAL_FILES,
        code=code("tables", "metrics", "theory"),
    output:
        "results/calibration.csv",
    params:
        func="tables.calibration_table",
    conda:
        "../envs/isaflow.yaml"
    priority: 10  # the paper's own outputs first (snakemake -c2 paper)
    log:
        "logs/calibration_table.log",
    script:
        "../scripts/call.py"


FIGS = config["figures"]


rule fig_inputs:
    input:
        inputs=lambda wc: [run_file(FIGS[wc.name])],
        code=FIGURE_CODE,
    output:
        report_figure("{name}", "paper_figure", "Paper figures"),
    params:
        func="figures.single.inputs_figure",
    conda:
        "../envs/isaflow.yaml"
    priority: 10  # the paper's own outputs first (snakemake -c2 paper)
    log:
        "logs/figures/{name}.log",
    wildcard_constraints:
        name="fig05_inputs_coarse|fig07_inputs_refined",
    script:
        "../scripts/call.py"


rule fig_single:
    input:
        inputs=lambda wc: [run_file(FIGS[wc.name])],
        code=FIGURE_CODE,
    output:
        report_figure("{name}", "paper_figure", "Paper figures"),
    params:
        func="figures.single.single_vessel_figure",
        kw=lambda wc: {"paper_level": config["paper"][FIGS[wc.name].removesuffix("_capped")]["level"]},
    conda:
        "../envs/isaflow.yaml"
    priority: 10  # the paper's own outputs first (snakemake -c2 paper)
    log:
        "logs/figures/{name}.log",
    wildcard_constraints:
        name="fig06_single_coarse|fig08_single_refined",
    script:
        "../scripts/call.py"


rule fig_calibration:
    input:
        inputs=CAL_FILES,
        code=FIGURE_CODE,
    output:
        report_figure("calibration_free_surface", "study_figure", "Studies"),
    params:
        func="figures.single.calibration_figure",
        kw={"paper_levels": {k: v["level"] for k, v in config["paper"].items()}, "adopted": CAL["adopted"]},
    conda:
        "../envs/isaflow.yaml"
    log:
        "logs/figures/calibration_free_surface.log",
    script:
        "../scripts/call.py"


rule fig_convergence:
    input:
        inputs=[run_file(r) for r in ["single_coarse", "single_coarse_capped", "single_refined", "single_refined_capped"]],
        code=FIGURE_CODE,
    output:
        report_figure("convergence_single", "study_figure", "Studies"),
    params:
        func="figures.single.convergence_figure",
    conda:
        "../envs/isaflow.yaml"
    log:
        "logs/figures/convergence_single.log",
    script:
        "../scripts/call.py"


register(targets=figure("fig05_inputs_coarse") + figure("fig06_single_coarse"))
register(targets=figure("fig07_inputs_refined") + figure("fig08_single_refined"))
register(targets=figure("calibration_free_surface") + figure("convergence_single"))
