"""Snakemake script: write one report fragment via isaflow.report."""
import sys

sys.stderr = open(snakemake.log[0], "w")  # noqa: F821

from isaflow import report  # noqa: E402

inputs = {k: v for k, v in snakemake.input.items() if k != "code"}  # noqa: F821
getattr(report, snakemake.params.func)(**inputs, out=snakemake.output[0])  # noqa: F821
