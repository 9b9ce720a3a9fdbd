"""Tables every method shares, made from run files only: the methods' comparison on the shared tanks.

Every row is metrics.comparison_row of one run file, so every method is judged by the same functions on
the same tanks; the table holds solver times (a timing file: results/, never the report's text).
"""

from pathlib import Path

import pandas as pd

from . import metrics
from .runfile import read


def compare_table(runs, outputs, compare=()):
    """outputs[0]: one metrics.comparison_row per run file, with 'compare' True for the runs of the methods'
    comparison (the paths in ``compare``; the others are single-vessel runs of the error-against-run-time
    figure)."""
    keep = {str(Path(p)) for p in compare}
    rows = []
    for p in runs:
        ds = read(p)
        rows.append({**metrics.comparison_row(ds), "compare": str(Path(p)) in keep, "file": str(p)})
    df = pd.DataFrame(rows)
    Path(outputs[0]).parent.mkdir(parents=True, exist_ok=True)
    df.to_csv(outputs[0], index=False, float_format="%.6g")
    return df
