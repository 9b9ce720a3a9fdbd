"""Numbers the claims read that no solver writes, each computed by its own workflow job from one run file.

A claims registry file's ``derived`` entries (config/claims/<paper>.yaml) declare them: ``id``
('<method>:<name>', the key a row's ``runs`` names), ``from`` (the run key it is computed from), ``compute``
(an isaflow function ``module.function`` taking that run's Dataset and returning an xarray Dataset, every
variable with ``units``) and ``what``.  Rule ``derived`` (workflow/rules/claims.smk) writes each to
:func:`path` with provenance; the claims read it as they read any run file, so a measure computes from run
files and nothing else (paper arithmetic on printed numbers aside).  Units: those of each variable.
"""

import importlib


def path(key):
    """results/derived/<method>/<name>.nc of key '<method>:<name>'."""
    method, name = key.split(":", 1)
    return f"results/derived/{method}/{name}.nc"


def function(compute):
    """The function an entry's ``compute`` names ('module.function' under isaflow)."""
    module, name = compute.rsplit(".", 1)
    return getattr(importlib.import_module(f"isaflow.{module}"), name)


def write(run, outputs, key, compute):
    """Rule derived: ``compute`` on run file ``run`` written to outputs[0], with provenance (the run file's
    name and hash) and the derived key."""
    from . import runfile  # numerical libraries: not needed to name the files while the workflow is parsed

    started = runfile.now()
    ds = runfile.read(run)
    out = function(compute)(ds)
    out.attrs.update(derived=key, compute=f"isaflow.{compute}", started=started, finished=runfile.now(),
                     **runfile.provenance({"run": run}))
    runfile.write(out, outputs[0])
