#!/usr/bin/env bash
# Regenerate the lock file and the conda environment from pyproject.toml.
#   bash requirements/compile.sh            (needs uv: pip install uv)
# The lock pins every package for CPython 3.11 on x86_64 Linux (this project's
# machines and the usual cluster node); pyproject.toml keeps the ranges.
set -euo pipefail
cd "$(dirname "$0")/.."
uv pip compile pyproject.toml requirements/extras.in --extra test \
    --python-version 3.11 --python-platform x86_64-unknown-linux-gnu \
    --quiet -o requirements/lock-py311.txt
python3 requirements/conda_env.py requirements/lock-py311.txt workflow/envs/isaflow.yaml
