"""Compare the outputs of two runs of the workflow (a local run and a SLURM run).

    python tests/cluster/compare_outputs.py LOCAL_CLONE SLURM_CLONE [STAMP]

Walks results/, figures/ and docs/ of LOCAL_CLONE (files newer than STAMP
only, i.e. what the run wrote; results/benchmarks/ is timing, skipped; the timing
fragments, docs/timing.md and the error-against-run-time figures are listed, not
compared) and requires the same file in SLURM_CLONE with equal content:
run files (.nc) variable by variable, bit for bit, except wall-clock timings,
the creation-time attributes and the hashes of input run files (which hold
their own timings; those files are compared themselves); PNG by pixels; CSV
and Markdown tables cell by cell except measured times (columns or rows that
TIMING matches: solver/job seconds, speed-ups); everything else byte for byte.
Prints one line per file; exit status 1 if any differs or is missing.
"""

import csv
import re
import sys
from pathlib import Path

import numpy as np

SKIP_DIRS = ("results/benchmarks",)
# outputs that are measured times as a whole (timing fragments, the report of them, run time on an axis)
TIMING_FILES = re.compile(r"^(results/timing/|docs/timing\.md$|figures/(methods_)?error_vs_runtime\.(png|pdf)$)")
TIME_ATTR = re.compile(r"^time_\w+_s$|wall_time|_seconds$")  # timers of a run (MPS: time_predict_s, ...)
TIME_ATTRS = {"date_created", "time_coverage_start", "time_coverage_end", "history", "started", "finished"}
TIMING = re.compile(r"wall_time|_s$|speedup|per_step|per_particle_step|computing time|\(s\)", re.IGNORECASE)


def is_timing(var):
    return "wall_time" in var.name or "wall-clock" in var.attrs.get("long_name", "")


def netcdf_difference(a, b):
    """'' if the two run files hold the same results, else what differs."""
    import xarray as xr

    with xr.open_dataset(a) as da, xr.open_dataset(b) as db:
        names_a = {n for n in da.variables if not is_timing(da[n])}
        names_b = {n for n in db.variables if not is_timing(db[n])}
        if names_a != names_b:
            return f"variables differ: {sorted(names_a ^ names_b)}"
        for n in sorted(names_a):
            if not np.array_equal(da[n].values, db[n].values, equal_nan=da[n].dtype.kind == "f"):
                return f"variable {n} differs"
        run_file_hashes = {k.removesuffix("_file") + "_sha256" for k, v in da.attrs.items()
                           if k.endswith("_file") and str(v).endswith(".nc")}
        attrs = [k for k in set(da.attrs) | set(db.attrs) if k not in TIME_ATTRS | run_file_hashes
                 and not TIME_ATTR.search(k) and str(da.attrs.get(k)) != str(db.attrs.get(k))]
        return f"attributes differ: {sorted(attrs)}" if attrs else ""


def png_difference(a, b):
    from matplotlib.image import imread

    pa, pb = imread(a), imread(b)
    return "" if pa.shape == pb.shape and np.array_equal(pa, pb) else "pixels differ"


def csv_without_timing(path):
    rows = list(csv.reader(path.open()))
    keep = [i for i, name in enumerate(rows[0]) if not TIMING.search(name.strip())] if rows else []
    return [[row[i] for i in keep if i < len(row)] for row in rows]


def markdown_without_timing(path):
    """Lines of a Markdown file; table rows as lists of cells without timing columns or rows."""
    out, header = [], None
    for line in path.read_text().splitlines():
        if not line.startswith("|"):
            out.append(line)
            header = None
            continue
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if header is None:
            header = cells
            out.append([c for c in cells if not TIMING.search(c)])
        elif not TIMING.search(cells[0]):
            out.append([c for c, h in zip(cells, header) if not TIMING.search(h)])
    return out


def difference(a, b):
    if not b.exists():
        return "missing"
    if a.read_bytes() == b.read_bytes():
        return ""
    if a.suffix == ".nc":
        return netcdf_difference(a, b)
    if a.suffix == ".png":
        return png_difference(a, b)
    if a.suffix == ".csv":
        return "" if csv_without_timing(a) == csv_without_timing(b) else "cells differ (not timing)"
    if a.suffix == ".md":
        return "" if markdown_without_timing(a) == markdown_without_timing(b) else "text differs (not timing)"
    return "bytes differ"


def outputs(root, since=0.0):
    for top in ("results", "figures", "docs"):
        for path in sorted((root / top).rglob("*")):
            rel = path.relative_to(root).as_posix()
            if (path.is_file() and path.stat().st_mtime > since and not rel.startswith(SKIP_DIRS)
                    and not path.name.startswith(".")):
                yield rel


def main(local, slurm, stamp=None):
    local, slurm = Path(local), Path(slurm)
    bad = 0
    files = list(outputs(local, Path(stamp).stat().st_mtime if stamp else 0.0))
    for rel in files:
        if TIMING_FILES.match(rel):
            print(f"timing  {rel}")
            continue
        why = difference(local / rel, slurm / rel)
        bad += bool(why)
        print(f"{'DIFFERS' if why else 'equal  '} {rel}{': ' + why if why else ''}")
    timing = sum(bool(TIMING_FILES.match(rel)) for rel in files)
    print(f"{len(files) - timing - bad} of {len(files) - timing} outputs equal ({timing} timing outputs not compared)")
    return 1 if bad or not files else 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:]))
