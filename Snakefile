# Replication of Papadopoulos, Koutitas & Lazaridis (2016).
#   snakemake -c2                                   everything
#   snakemake -c1 figures/fig06_single_coarse.png   one figure and what it needs
configfile: "config/config.yaml"
configfile: "config/study.yaml"  # error against run time, stability study


include: "workflow/rules/common.smk"
include: "workflow/rules/runs.smk"
include: "workflow/rules/single.smk"
include: "workflow/rules/flow.smk"
include: "workflow/rules/study.smk"
include: "workflow/rules/benchmarks.smk"
include: "workflow/rules/report.smk"


rule all:
    input:
        ALL_TARGETS,
    default_target: True
