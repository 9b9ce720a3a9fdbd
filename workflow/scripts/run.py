"""Snakemake script of the rules `run` (one tank run) and `block_*` (a block of short runs in one process):
each run through isaflow.run, its declaration passed as data (never through a shell line), in the order
given (a run continuing another of the block comes after it).  stderr (progress, outcomes, input errors as
one line) goes to the rule's log.  Exit status: 0 if every run was written, else the largest of
isaflow.run's codes (1 outcome not accepted, 2 bad input, 3 the file could not be written); every run of a
block is tried.  The job's timing goes to logs/timing/jobs.jsonl (isaflow.timing)."""
import os
import sys
import time

# the project's source of this checkout (src/ next to workflow/), ahead of any installed copy: the rules run
# the checked-out code without an (editable) install tied to one checkout
sys.path.insert(0, os.path.realpath(os.path.join(os.path.dirname(__file__), "..", "..", "src")))
from isaflow import timing  # noqa: E402  (imports nothing numerical: threads are set before numpy loads)

_script_start = timing.job_start(snakemake)  # noqa: F821
from isaflow import run  # noqa: E402

_imported = time.time()
codes, solve_s = [], 0.0
for (method, run_id, decl), out in zip(snakemake.params.runs, snakemake.output):  # noqa: F821
    command = ["snakemake", f"rule {snakemake.rule}: {method}/{run_id}", "->", out]  # noqa: F821
    code, result = run.run_with_result(
        method, decl["tank_file"], decl["variant"], decl["resolution"], out, settings_path=decl["settings_file"],
        overrides=decl.get("set", {}), start=decl.get("start_file"), accept=decl.get("accept", ["converged"]),
        threads=snakemake.threads, run_id=run_id, command=command, label=decl.get("label", ""),  # noqa: F821
        stability=decl.get("stability", False), max_hours=decl.get("max_hours"))
    codes.append(code)
    solve_s += result.wall_time if result is not None else 0.0
timing.record(snakemake.rule, snakemake.output[0], _script_start, _imported, solve_s, len(codes))  # noqa: F821
sys.exit(max(codes))
