"""Snakemake script: one study table, figure or report fragment.

params.func names a function 'module.function' of the isaflow package (e.g.
'study.error_table', 'figures.study.stability_map_figure'); it gets the named
inputs (except 'code') as keyword arguments, the outputs and params.kw.
"""
import importlib
import sys

sys.stderr = open(snakemake.log[0], "w")  # noqa: F821

mod, name = snakemake.params.func.rsplit(".", 1)  # noqa: F821
func = getattr(importlib.import_module(f"isaflow.{mod}"), name)
inputs = {k: (v if isinstance(v, str) else list(v)) for k, v in snakemake.input.items() if k != "code"}  # noqa: F821
func(**inputs, outputs=list(snakemake.output), **dict(snakemake.params.get("kw", {}) or {}))  # noqa: F821
