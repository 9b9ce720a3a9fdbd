"""Snakemake script: one metrics row per run file -> results/metrics.csv."""
import sys

sys.stderr = open(snakemake.log[0], "w")  # noqa: F821

from isaflow import metrics  # noqa: E402

metrics.table(list(snakemake.input.runs)).to_csv(snakemake.output[0], index=False, float_format="%.6g")  # noqa: F821
