"""Snakemake script of the rule `run`: one tank run of any method through isaflow.run, its declaration
passed as data (never through a shell line).  stderr (progress, the outcome, input errors as one line)
goes to the rule's log; the exit status is isaflow.run's (0 written, 1 outcome not accepted, 2 bad input,
3 the file could not be written)."""
import os
import sys

# BLAS/OpenMP/numba threads = the rule's threads, set before numpy loads (byte-identical outputs)
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ[_var] = str(snakemake.threads)  # noqa: F821

sys.stderr = open(snakemake.log[0], "w", buffering=1)  # noqa: F821
# the project's source of this checkout (src/ next to workflow/), ahead of any installed copy: the rules run
# the checked-out code without an (editable) install tied to one checkout
sys.path.insert(0, os.path.realpath(os.path.join(os.path.dirname(__file__), "..", "..", "src")))

from isaflow import run  # noqa: E402

decl = snakemake.params.decl  # noqa: F821
wc = snakemake.wildcards  # noqa: F821
command = ["snakemake", f"rule run: {wc.method}/{wc.run}", "->", snakemake.output[0]]  # noqa: F821
code = run.run(wc.method, snakemake.input.tank, decl["variant"], decl["resolution"], snakemake.output[0],  # noqa: F821
               settings_path=snakemake.input.settings, overrides=decl.get("set", {}),  # noqa: F821
               start=snakemake.input.get("start"), accept=decl.get("accept", ["converged"]),  # noqa: F821
               threads=snakemake.threads, run_id=wc.run, command=command, label=decl.get("label", ""),  # noqa: F821
               stability=decl.get("stability", False), max_hours=decl.get("max_hours"))
sys.exit(code)
