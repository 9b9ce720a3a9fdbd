# Applications 3-6: flow into the second vessel, Figures 9-10, flow history, Table 1.
FLOW = config["flow"]
TABLE1_RUNS = sorted({run for row in config["table1"] for run in row["chain"]})


rule fig_flow:
    input:
        inputs=lambda wc: [run_file(FIGS[wc.name])],
        code=FIGURE_CODE,
    output:
        report_figure("{name}", "paper_figure", "Paper figures"),
    params:
        func=lambda wc: {
            "fig09_flow_incomplete": "figures.flow.flow_incomplete_figure",
            "fig10_flow_complete": "figures.flow.flow_complete_figure",
        }[wc.name],
        kw={"paper": FLOW["paper"]},
    conda:
        "../envs/isaflow.yaml"
    priority: 10  # the paper's own outputs first (snakemake -c2 paper)
    log:
        "logs/figures/{name}.log",
    wildcard_constraints:
        name="fig09_flow_incomplete|fig10_flow_complete",
    script:
        "../scripts/call.py"


rule fig_flow_history:
    input:
        inputs=sorted({run_file(r) for chain in FLOW["chains"].values() for r in chain}),
        code=FIGURE_CODE,
    output:
        report_figure("flow_history", "study_figure", "Studies"),
    params:
        func="figures.flow.flow_history_figure",
        kw={"chains": FLOW["chains"]},
    conda:
        "../envs/isaflow.yaml"
    log:
        "logs/figures/flow_history.log",
    script:
        "../scripts/call.py"


rule table1:
    input:
        runs=[run_file(r) for r in TABLE1_RUNS],
        benchmarks=[f"results/benchmarks/run/{r}.tsv" for r in TABLE1_RUNS],
        code=code("tables", "report/__init__"),
    output:
        report_file("figures/table1.csv", "table", "Claims"),
        "figures/table1.md",
    conda:
        "../envs/isaflow.yaml"
    priority: 10  # the paper's own outputs first (snakemake -c2 paper)
    log:
        "logs/table1.log",
    params:
        func="tables.write_table1",
        kw={"rows": config["table1"]},
    script:
        "../scripts/call.py"




register(targets=figure("fig09_flow_incomplete") + figure("fig10_flow_complete") + figure("flow_history"))
register(targets=["figures/table1.csv", "figures/table1.md"])
