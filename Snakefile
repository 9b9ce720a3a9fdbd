# Replication of Papadopoulos, Koutitas & Lazaridis (2016) and its neighbours.
#   snakemake -c2                                   everything
#   snakemake -c2 paper                             the paper's own outputs (Figures 5-10, Table 1; the claims need the full run)
#   snakemake -c1 figures/fig06_single_coarse.png   one figure and only what it needs
#   snakemake -c2 vtk                               the flows of every method as VTK files for ParaView (results/vtk/)
# Parses with only Snakemake installed: the project's source is read from src/ (workflow/rules/common.smk).
import glob

from snakemake.utils import min_version

min_version("8.20")

# the About page of `snakemake --report report.html <target>`
report: "workflow/report/workflow.rst"


include: "workflow/rules/common.smk"
# the template of every rule calling one package function (use rule call as <name> with:)
include: "workflow/rules/templates.smk"
include: "workflow/rules/compare.smk"
include: "workflow/rules/export.smk"
include: "workflow/rules/report.smk"
include: "workflow/rules/claims.smk"


# one rules file per method (its runs, figures, report fragments, claims, timing), each registering
# its own targets
for _rules in sorted(glob.glob("workflow/rules/methods/*.smk")):

    include: _rules


# the rules of every declared run (after the methods declared them)
include: "workflow/rules/runs.smk"


rule all:
    input:
        lambda wc: with_report_copies(TARGETS["targets"]),
    default_target: True


# every tank, settings file and declared run checked before any job starts (common.smk)
check_inputs()


# where the run's time went, from this process's start (isaflow.timing): printed, written to
# results/timing/workflow_run.md and appended to docs/timing.md when this run made it
onsuccess:
    workflow_timing(workflow.cores)
