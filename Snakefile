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


# one rules file per additional method (SPH, MPS, 1D SPH, solid), each
# registering its own targets, report fragment and claims
for _rules in sorted(glob.glob("workflow/rules/methods/*.smk")):

    include: _rules


rule all:
    input:
        lambda wc: TARGETS["targets"],
    default_target: True
