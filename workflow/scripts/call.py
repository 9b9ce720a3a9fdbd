"""Snakemake script: call one isaflow function; the one calling convention of every script rule.

params.func names 'module.function' under isaflow (e.g. 'methods.isa.tables.error_table',
'figures.methods.tanks_figure').  It is called as func(**named inputs except 'code' and 'compiled',
outputs=[output files], **params.kw); single-file inputs are passed as a path, others as a list.
params.kernels, if given, names the kernel generation (isaflow.core.jit.use) of its kernels, whose
compile stamp is the input 'compiled', or a list: that generation, then others it reads too (jit.read_also).  A function that
runs solvers returns the list of their contract.Results (their solver time counts as the job's solve phase in
docs/timing.md).  stderr goes to the rule's log.  BLAS and OpenMP run on the
rule's threads.  An input error (isaflow.inputs.InputError, or a
file that is no run file) ends the job with one line in the log and exit status 2, no traceback.
"""
import importlib
import os
import sys
import time

# the project's source of this checkout (src/ next to workflow/), ahead of any installed copy: the rules run
# the checked-out code without an (editable) install tied to one checkout
sys.path.insert(0, os.path.realpath(os.path.join(os.path.dirname(__file__), "..", "..", "src")))
from isaflow import timing  # noqa: E402  (imports nothing numerical: threads are set before numpy loads)

_script_start = timing.job_start(snakemake)  # noqa: F821
# the command run files record: the rule and function, not Snakemake's temporary copy of this script
sys.argv = ["snakemake", f"rule {snakemake.rule}:", f"isaflow.{snakemake.params.func}", "->", *snakemake.output]  # noqa: F821

if snakemake.params.get("kernels"):  # noqa: F821  the kernel generation (isaflow.core.jit) its calls use
    from isaflow.core import jit  # noqa: E402

    _kernels = snakemake.params.kernels  # noqa: F821  one generation, or [its own, others it reads too]
    _kernels = [_kernels] if isinstance(_kernels, str) else list(_kernels)
    jit.use(_kernels[0])
    jit.read_also(*_kernels[1:])
from isaflow.inputs import InputError  # noqa: E402
from isaflow.runfile import RunFileError  # noqa: E402

mod, name = snakemake.params.func.rsplit(".", 1)  # noqa: F821
func = getattr(importlib.import_module(f"isaflow.{mod}"), name)
_imported = time.time()
inputs = {k: (v if isinstance(v, str) else list(v)) for k, v in snakemake.input.items() if k not in ("code", "compiled")}  # noqa: F821
try:
    _out = func(**inputs, outputs=list(snakemake.output), **dict(snakemake.params.get("kw", {}) or {}))  # noqa: F821
except (InputError, RunFileError) as err:
    print(f"error: {err}", file=sys.stderr)
    sys.exit(2)
print(f"{snakemake.params.func}: wrote {', '.join(snakemake.output)}", file=sys.stderr)  # noqa: F821
# a function that runs solvers returns their contract.Results: their solver time is the job's solve phase
_runs = [r for r in (_out if isinstance(_out, list) else []) if hasattr(r, "wall_time")]
timing.record(snakemake.rule, snakemake.output[0], _script_start, _imported, sum(r.wall_time for r in _runs),  # noqa: F821
              len(_runs))
