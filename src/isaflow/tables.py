"""Table 1 of the paper, regenerated next to ours.

Our time of a row is the sum over the runs of its chain (a flow continues
the single-vessel run, as in the paper, whose times count "from beginning of
first application"): solver time from the run files, job time (process
start, numba cache load, solver, output) from Snakemake's benchmark files.
"""

from pathlib import Path

import pandas as pd

from .runfile import read


def table1(rows, run_files, benchmark_files):
    """DataFrame: the paper's Table 1 rows with ours alongside.

    rows: config 'table1' entries; run_files / benchmark_files: paths whose
    stems are run ids (results/runs/{run}.nc, results/benchmarks/run/{run}.tsv).
    """
    runs = {Path(p).stem: read(p) for p in run_files}
    bench = {Path(p).stem: float(pd.read_csv(p, sep="\t")["s"].iloc[0]) for p in benchmark_files}
    out = []
    for r in rows:
        last = runs[r["chain"][-1]]
        solver_s = sum(float(runs[c]["wall_time"]) for c in r["chain"])
        job_s = sum(bench[c] for c in r["chain"])
        out.append({
            "application": r["application"],
            "paper_particles": r["particles"],
            "paper_du_mm": r["du_mm"],
            "paper_steps": r["steps"],
            "paper_time": r["time"],
            "ours_particles": int(last.sizes["particle"]),
            "ours_du_mm": float(last.attrs["du"]) * 10.0,
            "ours_steps": int(last["steps"]),
            "ours_status": last.attrs["status"],
            "ours_residual": round(float(last["residual"]), 4),
            "ours_solver_s": round(solver_s, 3),
            "ours_job_s": round(job_s, 2),
            "speedup_solver": round(r["time_s"] / solver_s, 0),
            "speedup_job": round(r["time_s"] / job_s, 0),
        })
    return pd.DataFrame(out)


def write_table1(rows, run_files, benchmark_files, out_csv, out_md):
    """Write Table 1 as CSV and Markdown."""
    from .report import md_table

    df = table1(rows, run_files, benchmark_files)
    df.to_csv(out_csv, index=False)
    note = ("Paper columns from Table 1; ours: steps counted from the start of application 1 (or 2), "
            "status of the last run of the chain, solver time from the run files and job time from Snakemake "
            "benchmarks, both summed over the chain; speed-up = paper time / ours.\n")
    Path(out_md).write_text("# Table 1, regenerated\n\n" + note + "\n" + md_table(df) + "\n")
    return df
