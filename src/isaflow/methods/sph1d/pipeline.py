"""Workflow entry points of the 1D study: one call per Snakemake rule through workflow/scripts/call.py
(``func(**inputs, outputs=[...])``; stderr is the rule's log)."""

import logging
import sys
from pathlib import Path

import pandas as pd
import xarray as xr

from isaflow import claims_registry, runfile
from isaflow.core import jit
from isaflow.inputs import InputError, load as load_yaml
from isaflow.methods import registry

from . import figures, report, settings, sweep

log = logging.getLogger("isaflow.methods.sph1d")


def _logging():
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("%(asctime)s %(message)s"))
    log.addHandler(handler)
    log.setLevel(logging.INFO)
    return handler


def rule_of_file(path):
    """(settle_band, round_off) of the classification rule of a claims registry file (config/claims/
    merino_alonso2020.yaml: its rows' tolerance.parameters), the same in every row that states it (InputError naming
    the file otherwise): the method's tables and figures classify with it, so they agree with the claims."""
    _, spec = load_yaml(path, claims_registry.SCHEMA, "claims registry file")
    found = {(float(p["settle_band"]), float(p["round_off"])) for c in spec["claims"]
             for p in [c.get("tolerance", {}).get("parameters", {})] if "settle_band" in p}
    if len(found) != 1:
        raise InputError(f"{path}: the rows state {len(found)} different classification rules "
                         "(tolerance.parameters settle_band, round_off); exactly one is needed")
    return found.pop()


def run_sweep(settings_path, outputs, resolution=None):
    """Solve the sweep (the settings file's ``resolutions`` entry ``resolution`` applied if given); outputs:
    [the netCDF (with provenance)]."""
    (sweep_nc,) = outputs
    jit.use("sph1d")  # this process's kernels: the 1D method's cache generation (core.jit)
    handler = _logging()
    try:
        s = settings.checked_values(settings_path, resolution)
        started = runfile.now()
        ds = sweep.run_sweep(s)
        ds.attrs.update(started=started, finished=runfile.now(),
                        **runfile.provenance({"method_settings": settings_path}))
        runfile.write(ds, sweep_nc)
        log.info("sph1d: %d cases solved in %.1f s", ds.error.size // ds.sizes["n"], ds.attrs["solve_seconds"])
    finally:
        log.removeHandler(handler)


def make_cases(sweep_nc, registry, outputs):
    """outputs: the case table and the summary table, classified by the rule of the claims registry file
    ``registry`` (rule_of_file), over the sweep's window."""
    cases_csv, summary_csv = outputs
    band, round_off = rule_of_file(registry)
    with xr.open_dataset(sweep_nc) as ds:
        cases = sweep.classify(ds.load(), int(ds.attrs["classify_window"]), band, round_off)
    cases.to_csv(cases_csv, index=False, float_format="%.6g")
    sweep.summarise(cases).to_csv(summary_csv, index=False, float_format="%.6g")


def _labels():
    m = registry()["sph1d"]
    return {v.name: (v.label, v.colour) for v in m.variants.values()}


FIGURES = ("error_vs_n", "maps", "variants")


def make_figures(settings_path, sweep_nc, cases_csv, outputs, surface_nc=None, registry=None):
    """outputs: [png, pdf] of each of FIGURES, in that order; surface_nc: the sweep with the top particle on the
    surface (registry input surface_placement), classified by the rule of the claims registry file ``registry``
    and drawn beside the variants."""
    out = {name: outputs[2 * k:2 * k + 2] for k, name in enumerate(FIGURES)}
    handler = _logging()
    try:
        s = settings.checked_values(settings_path)
        default = list(s["variants"])[0]
        figures.error_vs_n(sweep_nc, cases_csv, default, out["error_vs_n"])
        figures.maps(sweep_nc, cases_csv, default, out["maps"])
        labels = {v: lc for v, lc in _labels().items() if v in s["variants"]}
        surface = None
        if surface_nc:
            band, round_off = rule_of_file(registry)
            with xr.open_dataset(surface_nc) as ds:
                surface = sweep.classify(ds.load(), int(ds.attrs["classify_window"]), band, round_off)
            surface = surface[surface.variant == default]
        figures.variants(cases_csv, labels, out["variants"], surface)
        log.info("sph1d figures written")
    finally:
        log.removeHandler(handler)


def make_report(settings_path, sweep_nc, cases_csv, summary_csv, registry, outputs, figure_files=()):
    """outputs: the report fragment and the timing fragment, from the tables (figure_files: inputs for ordering
    only).  The claims are judged by isaflow.claims from the registry (config/claims/merino_alonso2020.yaml)."""
    fragment_md, timing_md = outputs
    handler = _logging()
    try:
        s = settings.checked_values(settings_path)
        cases, summary = pd.read_csv(cases_csv), pd.read_csv(summary_csv)
        variants = list(s["variants"])
        band, round_off = rule_of_file(registry)
        with xr.open_dataset(sweep_nc) as ds:
            nmax, secs = int(ds.n[-1]), float(ds.attrs["solve_seconds"])
            ns = [int(n) for n in ds.n.values[-int(ds.attrs["classify_window"]):]]
        labels = {v: lab for v, (lab, _) in _labels().items()}
        text = report.fragment(cases, summary, variants, labels, nmax, ns, band, round_off)
        for path, content in ((fragment_md, text), (timing_md, report.timing(cases, nmax, secs))):
            Path(path).parent.mkdir(parents=True, exist_ok=True)
            Path(path).write_text(content)
        log.info("sph1d report fragment written")
    finally:
        log.removeHandler(handler)
