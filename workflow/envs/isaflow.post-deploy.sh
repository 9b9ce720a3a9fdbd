#!/usr/bin/env bash
# Snakemake runs this once inside a new isaflow environment (after the lock's
# packages are installed), from the workflow's working directory: the project
# itself, editable so the rules run the checked-out code, and no dependencies
# so nothing but the lock's pins is installed.
set -euo pipefail
python -m pip install --no-deps -e .
