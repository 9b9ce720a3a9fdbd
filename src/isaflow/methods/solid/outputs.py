"""Run files of the solid cases (netCDF, units on every variable, provenance, atomic write).

The variables every run file holds are isaflow.runfile.contract_variables'; the rest is built here, not by
isaflow.runfile.to_dataset, because that one needs a tank and the solid cases have none (no walls, no
liquid); provenance and the atomic write are runfile's.
"""

import logging
import sys
import time

import numpy as np
import xarray as xr

from isaflow import runfile
from isaflow.core import jit
from isaflow.methods import label

from . import cases, settings, solve, water


def to_dataset(r, config_path, started, finished):
    """xarray Dataset of a solid contract.Result (runfile.contract_variables, and the case's own)."""

    def var(dims, data, units, long_name):
        return xr.Variable(dims, np.asarray(data), {"units": units, "long_name": long_name})

    particles, rest = runfile.contract_variables(r)
    data = {**particles, **rest, "sim_time": var((), r.sim_time, "s", "physical time simulated")}
    data["weight"].attrs["long_name"] += " (dim 2: per cm thickness)"
    if not np.isfinite(r.residual):  # a fixed-length run (the vessel with water) has no stop test
        data["residual"].attrs["missing"] = "not applicable: the run has no stop test"
    for name, (dims, arr, units, long_name) in {**r.fields, **r.history}.items():
        data[name] = var(dims, arr, units, long_name)
    ds = xr.Dataset(data, coords={"xy": ["x", "y"], "stress_component": ["xx", "yy", "zz", "yx", "zy", "zx"],
                                  "axis": ["i", "j", "k"]})
    ds.attrs = {
        "title": f"isaflow solid run: {r.params['case']} ({r.variant})",
        "references": "Marko (2017), A Discrete Approach to Meshless Lagrangian Solid Modeling, Computation 5, 33",
        "units_system": "length cm, force N, time s, mass N s2 cm-1",
        "method": r.method, "variant": r.variant, "variant_label": label(r.method, r.variant),
        "status": r.status, "status_message": r.message, "residual_name": r.residual_name,
        "time_coverage_start": started, "time_coverage_end": finished,
        "Conventions": "CF-1.10, ACDD-1.3", "creator_name": "isaflow replication workflow", "date_created": finished,
        **runfile.provenance({"settings": config_path, **({"loads": r.params["load_source"]}
                                                          if "load_source" in r.params else {})}),
        **{k: (v if isinstance(v, (int, float, str)) else str(v)) for k, v in r.params.items()},
    }
    return ds


def run_case(cfg, outputs, case, variant, loads=None):
    """Workflow entry point (stderr is the rule's log): write_run to outputs[0]; loads: the rigid-floor
    run file of an elastic-floor case."""
    logging.basicConfig(stream=sys.stderr, level=logging.INFO, format="%(asctime)s %(message)s")
    return write_run(cfg, case, variant, outputs[0], loads=loads)


def run_cases(cfg, outputs, cases, loads=None, kernels=None):
    """Workflow entry point of a block of cases in one process: write_run of each [case, variant] in cases to
    the output at the same place; loads: the rigid-floor run file of each (elastic-floor cases), or None;
    kernels: an input that only orders the job (its file is not read).  Returns the contract.Result of each."""
    logging.basicConfig(stream=sys.stderr, level=logging.INFO, format="%(asctime)s %(message)s")
    return [write_run(cfg, case, variant, out, loads=loads[k] if loads else None)
            for k, ((case, variant), out) in enumerate(zip(cases, outputs))]


def write_run(config_path, case, variant, out, loads=None):
    """Run one case/variant from the settings file and write its run file to out."""
    jit.use("solid")  # this process's kernels: the solid's cache generation (core.jit)
    log = logging.getLogger("isaflow.solid")
    cfg = settings.checked_values(config_path)
    solve.warmup()
    water.warmup()
    started, t0 = runfile.now(), time.perf_counter()
    r = cases.run_case(cfg, case, variant, loads=loads)
    log.info("%s %s: %s (%s), %d steps, %.2f s", case, variant, r.status, r.message, r.steps, time.perf_counter() - t0)
    runfile.write(to_dataset(r, config_path, started, runfile.now()), out)
    return r
