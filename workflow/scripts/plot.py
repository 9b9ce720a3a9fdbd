"""Snakemake script: draw one figure from run files via isaflow.figures."""
import sys

sys.stderr = open(snakemake.log[0], "w")  # noqa: F821

from isaflow import figures  # noqa: E402

func = getattr(figures, snakemake.params.func)  # noqa: F821
func(list(snakemake.input.runs), list(snakemake.output), **dict(snakemake.params.get("kw", {}) or {}))  # noqa: F821
