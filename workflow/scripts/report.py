"""Snakemake script: write one report fragment via isaflow.report."""
import sys

sys.stderr = open(snakemake.log[0], "w")  # noqa: F821

from isaflow import report  # noqa: E402

getattr(report, snakemake.params.func)(**dict(snakemake.input), out=snakemake.output[0])  # noqa: F821
