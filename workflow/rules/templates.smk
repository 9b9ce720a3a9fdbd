# The template of every rule that calls one isaflow function through scripts/call.py (params.func, params.kw):
# its start line (JOB), resources (SMALL), conda environment and script.  A rule is
#     use rule call as <name> with:
# giving what differs: input, output, params, log, and message or resources where not JOB or SMALL (a directive
# given there replaces the template's).  Included after common.smk (JOB, SMALL), before every rules file.
# A rule made by `use rule` resolves a relative script: or conda: path against its own file (rules/ or
# rules/methods/), so the template names them from the workflow's directory.  Its output matches no file (a
# wildcard matching nothing) and, having a wildcard, it cannot be a target: it never becomes a job.  A rule made
# from it that names no log of its own is refused while the workflow is parsed (the template's log has that
# wildcard, its output does not).


rule call:
    output:
        "results/.template/{_template,(?!)}",
    message:
        JOB
    resources:
        **SMALL,
    log:
        "logs/.template/{_template}.log",
    conda:
        os.path.join(workflow.basedir, "workflow", "envs", "isaflow.yaml")
    script:
        os.path.join(workflow.basedir, "workflow", "scripts", "call.py")
