"""Snakemake script: free-surface level of every calibration run -> CSV."""
import sys

sys.stderr = open(snakemake.log[0], "w")  # noqa: F821

from isaflow import metrics  # noqa: E402

metrics.calibration_table(list(snakemake.input.runs)).to_csv(snakemake.output[0], index=False, float_format="%.6g")  # noqa: F821
