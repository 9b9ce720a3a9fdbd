# Replication of Papadopoulos, Koutitas & Lazaridis (2016).
#   snakemake -c2                                   everything
#   snakemake -c1 figures/fig06_single_coarse.png   one figure and what it needs
import glob


configfile: "config/config.yaml"
configfile: "config/study.yaml"  # error against run time, stability study


include: "workflow/rules/common.smk"
include: "workflow/rules/runs.smk"
include: "workflow/rules/single.smk"
include: "workflow/rules/flow.smk"
include: "workflow/rules/study.smk"
include: "workflow/rules/benchmarks.smk"
include: "workflow/rules/report.smk"
include: "workflow/rules/compare.smk"


# one rules file per additional method (SPH, MPS, 1D SPH, solid), each
# registering its own targets, report fragment and claims
for _rules in sorted(glob.glob("workflow/rules/methods/*.smk")):

    include: _rules


# the paper's own outputs: Figures 5-10, Table 1, the report's single-vessel and
# flow sections (quick start: snakemake -c2 paper)
PAPER_TARGETS = [
    f"figures/{name}.{ext}"
    for name in ("fig05_inputs_coarse", "fig06_single_coarse", "fig07_inputs_refined", "fig08_single_refined",
                 "fig09_flow_incomplete", "fig10_flow_complete")
    for ext in ("png", "pdf")
] + ["figures/table1.csv", "figures/table1.md", "results/report/10_single.md", "results/report/20_flow.md",
      "results/claims/papadopoulos2016.csv"]


rule paper:
    input:
        PAPER_TARGETS,


rule all:
    input:
        lambda wc: TARGETS["targets"],
    default_target: True
