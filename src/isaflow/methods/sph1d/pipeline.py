"""Workflow entry points of the 1D study: one call per Snakemake rule through workflow/scripts/call.py
(``func(**inputs, outputs=[...])``; stderr is the rule's log)."""

import logging
import sys
from pathlib import Path

import pandas as pd
import xarray as xr

from isaflow import runfile
from isaflow.methods import registry

from . import figures, report, settings, sweep

log = logging.getLogger("isaflow.methods.sph1d")


def _logging():
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("%(asctime)s %(message)s"))
    log.addHandler(handler)
    log.setLevel(logging.INFO)
    return handler


def run_sweep(settings_path, outputs):
    """Solve the sweep; outputs: the netCDF (with provenance), the case table and the summary table."""
    sweep_nc, cases_csv, summary_csv = outputs
    handler = _logging()
    try:
        s = settings.load(settings_path)
        started = runfile.now()
        ds = sweep.run_sweep(s)
        ds.attrs.update(started=started, finished=runfile.now(),
                        **runfile.provenance({"method_settings": settings_path}))
        runfile.write(ds, sweep_nc)
        cases = sweep.classify(ds, s)
        cases.to_csv(cases_csv, index=False, float_format="%.6g")
        sweep.summarise(cases).to_csv(summary_csv, index=False, float_format="%.6g")
        log.info("sph1d: %d cases solved in %.1f s", cases.shape[0], ds.attrs["solve_seconds"])
    finally:
        log.removeHandler(handler)


def _labels():
    m = registry()["sph1d"]
    return {v.name: (v.label, v.colour) for v in m.variants.values()}


FIGURES = ("error_vs_n", "maps", "variants")


def make_figures(settings_path, sweep_nc, cases_csv, outputs):
    """outputs: [png, pdf] of each of FIGURES, in that order."""
    out = {name: outputs[2 * k:2 * k + 2] for k, name in enumerate(FIGURES)}
    handler = _logging()
    try:
        s = settings.load(settings_path)
        default = list(s["variants"])[0]
        figures.error_vs_n(sweep_nc, cases_csv, default, out["error_vs_n"])
        figures.maps(sweep_nc, cases_csv, default, s["classify"]["ill_conditioned"], out["maps"])
        labels = {v: lc for v, lc in _labels().items() if v in s["variants"]}
        figures.variants(cases_csv, labels, out["variants"])
        log.info("sph1d figures written")
    finally:
        log.removeHandler(handler)


def make_report(settings_path, sweep_nc, cases_csv, summary_csv, outputs, figure_files=()):
    """outputs: the claims CSV, the report fragment and the timing fragment, from the tables (figure_files:
    inputs for ordering only)."""
    claims_csv, fragment_md, timing_md = outputs
    handler = _logging()
    try:
        s = settings.load(settings_path)
        cases, summary = pd.read_csv(cases_csv), pd.read_csv(summary_csv)
        variants = list(s["variants"])
        evidence = ["figures/sph1d_maps.png (top, one-neighbour band)", "figures/sph1d_error_vs_n.png, "
                    "figures/sph1d_maps.png", "figures/sph1d_maps.png (x marks), figures/sph1d_error_vs_n.png",
                    "figures/sph1d_maps.png, figures/sph1d_variants.png"]
        claims = report.claims_table(cases, variants, s["classify"]["small_error"], evidence)
        Path(claims_csv).parent.mkdir(parents=True, exist_ok=True)
        claims.to_csv(claims_csv, index=False)
        with xr.open_dataset(sweep_nc) as ds:
            nmax, secs = int(ds.n[-1]), float(ds.attrs["solve_seconds"])
        labels = {v: lab for v, (lab, _) in _labels().items()}
        text = report.fragment(cases, summary, claims, variants, labels, nmax)
        for path, content in ((fragment_md, text), (timing_md, report.timing(cases, nmax, secs))):
            Path(path).parent.mkdir(parents=True, exist_ok=True)
            Path(path).write_text(content)
        log.info("sph1d claims: %s", ", ".join(claims.verdict))
    finally:
        log.removeHandler(handler)
