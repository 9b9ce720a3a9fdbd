"""Snakemake script: the paper's Table 1 next to ours -> figures/table1.{csv,md}."""
import sys

sys.stderr = open(snakemake.log[0], "w")  # noqa: F821

from isaflow import tables  # noqa: E402

tables.write_table1(snakemake.params.rows, list(snakemake.input.runs), list(snakemake.input.benchmarks),  # noqa: F821
                    snakemake.output.csv, snakemake.output.md)  # noqa: F821
