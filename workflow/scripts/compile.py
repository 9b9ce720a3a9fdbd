"""Snakemake script of the rule `compile`: fill one method's kernel cache in this one process (isaflow.core.jit:
a generation is written by one process, then sealed) with every kernel signature its runs use (the method's
warm-up), or find it sealed already.  The output lists what was compiled; the job's timing goes to
logs/timing/jobs.jsonl (isaflow.timing)."""
import os
import sys
import time

# the project's source of this checkout (src/ next to workflow/), ahead of any installed copy: the rules run
# the checked-out code without an (editable) install tied to one checkout
sys.path.insert(0, os.path.realpath(os.path.join(os.path.dirname(__file__), "..", "..", "src")))
from isaflow import timing  # noqa: E402  (imports nothing numerical: threads are set before numpy loads)

_script_start = timing.job_start(snakemake)  # noqa: F821
from isaflow import run  # noqa: E402
from isaflow.core import jit  # noqa: E402

_imported = time.time()
run.compile_method(snakemake.wildcards.method, snakemake.threads)  # noqa: F821
c = jit.counters()
text = (f"method {snakemake.wildcards.method}: cache generation {c['generation']} ({c['mode']}), "  # noqa: F821
        f"{c['compiled']} kernels compiled in {c['compile_s']:.1f} s, {c['loaded']} loaded in {c['load_s']:.2f} s\n")
with open(snakemake.output[0], "w") as f:  # noqa: F821
    f.write(text)
print(text, file=sys.stderr, end="")
timing.record(snakemake.rule, snakemake.output[0], _script_start, _imported)  # noqa: F821
