"""ISA's tables built from run files: the paper's Table 1 next to ours, metrics, calibration and the study.

Table 1:
Our time of a row is the sum over the runs of its chain (a flow continues
the single-vessel run, as in the paper, whose times count "from beginning of
first application"): solver time from the run files, job time (process
start, numba cache load, solver, output) from Snakemake's benchmark files.
"""

from pathlib import Path

import numpy as np
import pandas as pd

from ...report import md_table
from ...runfile import read
from . import metrics
from .plan import VARIANTS


def table1(rows, run_files, benchmark_files):
    """DataFrame: the paper's Table 1 rows with ours alongside.

    rows: config 'table1' entries; run_files / benchmark_files: paths whose
    stems are run ids (results/runs/isa/{run}.nc, results/benchmarks/runs/isa/{run}.tsv).
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
            "ours_du_mm": float(last.attrs["solver.du"]) * 10.0,
            "ours_steps": int(last["steps"]),
            "ours_status": last.attrs["status"],
            "ours_max_force_N": round(float(last["residual"]), 4),
            "ours_solver_s": round(solver_s, 3),
            "ours_job_s": round(job_s, 2),
            "speedup_solver": round(r["time_s"] / solver_s, 0),
            "speedup_job": round(r["time_s"] / job_s, 0),
        })
    return pd.DataFrame(out)


def write_table1(runs, benchmarks, outputs, rows):
    """Write Table 1 as CSV and Markdown (outputs [csv, md])."""
    out_csv, out_md = outputs
    df = table1(rows, runs, benchmarks)
    df.to_csv(out_csv, index=False)
    note = ("Paper columns from Table 1; ours: steps counted from the start of application 1 (or 2), "
            "status of the last run of the chain, solver time from the run files and job time from Snakemake "
            "benchmarks, both summed over the chain; speed-up = paper time / ours.\n")
    Path(out_md).write_text("# Table 1, regenerated\n\n" + note + "\n" + md_table(df) + "\n")
    return df


# -- study tables (results/isa/study/*.csv) --------------------------------------


def _write(df, out):
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    df.to_csv(out, index=False, float_format="%.6g")


def _stem(p):
    return Path(p).stem


def _base_row(sid, ds):
    a = ds.attrs
    return dict(run=sid, tank=a["tank"], resolution=a["resolution"], variant=a["variant"], particles=int(ds.sizes["particle"]),
                du_cm=float(a["solver.du"]), f_tol_N=float(a["solver.f_tol"]), steps=int(ds["steps"]),
                wall_time_s=float(ds["wall_time"]), status=a["status"],
                outcome_detail=outcome_detail(a["status"], a["status_message"]), residual=float(ds["residual"]))


def error_table(runs, outputs, meta, paper):
    """results/isa/study/error_vs_runtime.csv: one row per error_runtime run with its outcome,
    step count (= force evaluations), solver wall-clock time [s] and every
    metrics.hydrostatic_errors measure.  paper: config/methods/isa_workflow.yaml's 'paper' mapping."""
    rows = []
    for p in runs:
        sid = _stem(p)
        m = meta[sid]
        ds = read(p)
        ref = paper.get(m.get("paper") or "", {})
        row = _base_row(sid, ds)
        row.update(lattice=m["lattice"], a_cm=float(ds.attrs["spacing"]), du_factor=m["du_factor"],
                   paper_config=bool(ref) and m["variant"] == "paper" and m["du_factor"] == 1,
                   paper_level_cm=ref.get("level", np.nan), paper_steps=ref.get("steps", np.nan),
                   paper_time_s=ref.get("time_s", np.nan))
        row.update(metrics.hydrostatic_errors(ds, ref.get("level")))
        row["variant_label"] = ds.attrs["variant_label"]
        rows.append(row)
    df = pd.DataFrame(rows).sort_values(["lattice", "variant", "du_factor"], key=_lattice_key)
    _write(df, outputs[0])
    return df


def _lattice_key(col):
    if col.name == "lattice":
        order = {"coarse": 0, "refined": 1, "fine": 2, "finer": 3}
        return col.map(lambda x: order.get(x, 9))
    return col


def fire_tables(tuning, references, outputs, meta, paper, required_ratio):
    """FIRE tuning grid and the force-evaluation ratio per lattice.

    tuning: fire_tuning run files; references: error_runtime runs of the
    same lattices (the capped and paper updates at the paper's du).
    outputs: [grid CSV, ratio CSV].  Every step evaluates the forces once, so
    steps are force evaluations.  The ratio compares the fewest FIRE steps to
    f_tol with the capped variant's steps, the paper's reported steps and the
    paper update's steps (which ends in a cycle, never at f_tol).  level_diff_cm:
    FIRE's level minus the capped equilibrium's, against the tolerance a / 4.
    """
    grid = []
    for p in tuning:
        sid = _stem(p)
        m = meta[sid]
        ds = read(p)
        row = _base_row(sid, ds)
        row.update(lattice=m["lattice"], du_factor=m["du_factor"], dt_factor=m["dt_factor"],
                   dt_max_s=float(ds.attrs["solver.dt_max"]), a_cm=float(ds.attrs["spacing"]),
                   level_cm=metrics.surface_of(ds))
        grid.append(row)
    grid = pd.DataFrame(grid).sort_values(["lattice", "du_factor", "dt_factor"], key=_lattice_key)
    refs = {}
    for p in references:
        m = meta[_stem(p)]
        ds = read(p)
        refs[m["lattice"], m["variant"]] = dict(steps=int(ds["steps"]), status=ds.attrs["status"],
                                                level=metrics.surface_of(ds))
    ratio = []
    for lattice, g in grid.groupby("lattice", sort=False):
        ok = g[g["status"] == "converged"]
        cap = refs.get((lattice, "capped"), {})
        pap = refs.get((lattice, "paper"), {})
        reported = paper.get(meta[g["run"].iloc[0]].get("paper") or "", {}).get("steps", np.nan)
        row = dict(lattice=lattice, capped_steps=cap.get("steps", np.nan), capped_status=cap.get("status", ""),
                   paper_update_steps=pap.get("steps", np.nan), paper_update_status=pap.get("status", ""),
                   paper_reported_steps=reported, fire_runs=len(g), fire_converged=len(ok))
        if len(ok):
            best = ok.loc[ok["steps"].idxmin()]
            a = float(best["a_cm"])
            row.update(fire_best_run=best["run"], fire_best_steps=int(best["steps"]), fire_best_du_cm=best["du_cm"],
                       fire_best_dt_max_s=best["dt_max_s"], fire_median_steps=float(ok["steps"].median()),
                       ratio_vs_capped=row["capped_steps"] / best["steps"],
                       ratio_vs_paper_reported=reported / best["steps"],
                       ratio_vs_paper_update=row["paper_update_steps"] / best["steps"],
                       level_diff_cm=best["level_cm"] - cap.get("level", np.nan), level_tol_cm=a / 4)
            row["meets_required_ratio"] = bool(row["ratio_vs_capped"] >= required_ratio
                                               and row["ratio_vs_paper_reported"] >= required_ratio)
        ratio.append(row)
    ratio = pd.DataFrame(ratio)
    ratio["required_ratio"] = required_ratio
    _write(grid, outputs[0])
    _write(ratio, outputs[1])
    return grid, ratio


def stability_row(sid, ds, m):
    """Outcome and its context of one stability run: k_b du / w, du / a, law usage, level."""
    a = ds.attrs
    row = _base_row(sid, ds)
    kb = a["forces.wall.r_u"] / a["forces.wall.l_u"]
    w = float(ds["weight"].values.max())
    lat_a = float(a.get("spacing", np.nan))  # absent: no lattice spacing (coincident particles)
    pos = ds["pos"].values
    finite = bool(np.isfinite(pos).all())
    row.update(variant_label=a["variant_label"], message=a["status_message"], max_steps=int(a["solver.max_steps"]), k_wall=kb,
               k_pair=a["forces.pair.r_u"] / a["forces.pair.l_u"], weight_N=w, a_cm=lat_a, k_du_over_w=kb * a["solver.du"] / w,
               du_over_a=a["solver.du"] / lat_a if np.isfinite(lat_a) else np.nan, positions_finite=finite,
               floor_cm=float(ds["wall_segment"].values[:, [1, 3]].min()),
               top_cm=float(pos[:, 1].max()) if finite else np.nan, top0_cm=float(ds["pos0"].values[:, 1].max()),
               level_cm=metrics.surface_of(ds) if finite and np.isfinite(lat_a) else np.nan)
    row.update(metrics.law_usage(ds))
    if "vessel" in ds.coords and finite:
        for name in ds["vessel"].values:
            x0, x1 = ds["vessel_x"].sel(vessel=name).values
            row[f"particles_{name}"] = int(np.count_nonzero((pos[:, 0] >= x0) & (pos[:, 0] < x1)))
    for key in ("k_factor", "du_factor", "case", "note"):
        if key in m:
            row[key] = m[key]
    return row


def map_table(runs, outputs, meta):
    """results/isa/study/stability_map.csv: outcome of every stability-map run."""
    df = pd.DataFrame([stability_row(_stem(p), read(p), meta[_stem(p)]) for p in runs])
    df = df.sort_values(["variant", "k_factor", "du_factor"])
    _write(df, outputs[0])
    return df


def cases_table(runs, outputs, meta):
    """results/isa/study/stability_cases.csv: outcome of every extreme case and variant."""
    order = {c: i for i, c in enumerate(dict.fromkeys(meta[_stem(p)]["case"] for p in runs))}
    df = pd.DataFrame([stability_row(_stem(p), read(p), meta[_stem(p)]) for p in runs])
    df["_o"] = df["case"].map(order)
    df["_v"] = df["variant"].map({v: i for i, v in enumerate(VARIANTS)})
    df = df.sort_values(["_o", "_v"]).drop(columns=["_o", "_v"])
    _write(df, outputs[0])
    return df


def recommend(table, targets):
    """Which configuration to pick for each error target |measure| <= value.

    table: error_table DataFrame; targets: {measure: [values]}.  Only runs that
    reached their own stopping criterion (status converged) count.  The final
    state depends on the relaxation path, so the converged runs of one lattice
    and update rule spread over du; a (lattice, variant) family is *robust* for
    a target when all its converged runs meet it.  Returns one row per target:
    converged run of a robust family with the least work (particle-steps;
    ``run``, 'none' if no family is robust) with that family's worst error
    (``family_worst``), and the cheapest converged run meeting the target at
    all (``by_chance``: another du of the same family may miss it).  Ranked by
    force evaluations, not wall-clock time, so the choice is deterministic.
    """
    ok = table[table["status"] == "converged"].copy()
    ok["work"] = ok["steps"] * ok["particles"]  # particle-steps: the cost of a relaxation, machine-independent
    rows = []
    for measure, values in targets.items():
        worst = ok.groupby(["lattice", "variant"])[measure].apply(lambda s: s.abs().max())
        for t in values:
            fams = worst[worst <= t].index
            robust = ok[[(la, va) in fams for la, va in zip(ok["lattice"], ok["variant"])]]
            anyhit = ok[ok[measure].abs() <= t]
            row = dict(measure=measure, target=t,
                       robust_families=", ".join(f"{la}/{va}" for la, va in fams) or "none")
            if len(robust):
                b = robust.loc[robust["work"].idxmin()]
                row.update(run=b["run"], lattice=b["lattice"], variant=b["variant"], du_mm=10 * b["du_cm"],
                           error=b[measure], family_worst=worst[b["lattice"], b["variant"]],
                           particle_steps=int(b["steps"]) * int(b["particles"]), steps=int(b["steps"]))
            else:
                row.update(run="none", lattice="", variant="", du_mm=np.nan, error=np.nan,
                           family_worst=worst.min() if len(worst) else np.nan, particle_steps=np.nan, steps=np.nan)
            row["by_chance"] = anyhit.loc[anyhit["work"].idxmin(), "run"] if len(anyhit) else "none"
            rows.append(row)
    return pd.DataFrame(rows)


def resolution_table(table, measures=("level_err_paper_cm", "level_err_hydro_cm", "side_err", "contact_rms")):
    """Per lattice: the capped equilibrium at the paper's du (the reference path), the
    range of each measure over all converged runs (the path spread) and run times."""
    ok = table[table["status"] == "converged"]
    rows = []
    for lat, g in ok.groupby("lattice", sort=False):
        ref = g[(g["variant"] == "capped") & (g["du_factor"] == 1)]
        row = dict(lattice=lat, a_cm=g["a_cm"].iloc[0], particles=int(g["particles"].iloc[0]), converged_runs=len(g))
        for m in measures:
            row[f"{m} capped"] = ref[m].iloc[0] if len(ref) else np.nan
            row[f"{m} range"] = f"{g[m].min():.3g} .. {g[m].max():.3g}" if g[m].notna().any() else ""
        row["capped_steps"] = int(ref["steps"].iloc[0]) if len(ref) else np.nan
        row["fewest_steps"] = int(g["steps"].min())
        rows.append(row)
    return pd.DataFrame(rows)


def outcome_detail(status, message):
    """Finer class of an outcome from the solver's message (escaped: which check caught it)."""
    if status == "escaped":
        return "crossed a wall (step refused)" if "would cross wall" in message else "left the walls' bounding box"
    if status == "cycle":
        return "limit cycle"
    return status.replace("_", " ")


def metrics_table(runs, outputs):
    """results/metrics.csv: one metrics.run_row per run file; 'run' is the file stem."""
    rows = []
    for p in runs:
        ds = read(p)
        rows.append({"run": _stem(p), **metrics.run_row(ds), "variant_label": ds.attrs["variant_label"]})
    df = pd.DataFrame(rows)
    _write(df, outputs[0])
    return df


def calibration_table(runs, outputs):
    """results/calibration.csv: calibration runs cal_{run}_kb{k}_r{ratio}.nc: run, k_b [N/cm],
    k_p / k_b, level [cm] (the one surface, metrics.surface_of), level_top [cm] (the top particle centres, the
    reading the adopted k_p was calibrated on), outcome."""
    rows = []
    for p in runs:
        ds = read(p)
        kb = ds.attrs["forces.wall.r_u"] / ds.attrs["forces.wall.l_u"]
        kp = ds.attrs["forces.pair.r_u"] / ds.attrs["forces.pair.l_u"]
        e = metrics.load_errors(ds, None, "own")
        rows.append(dict(run=Path(p).stem.removeprefix("cal_").rsplit("_kb", 1)[0], resolution=ds.attrs["resolution"],
                         variant=ds.attrs["variant"], k_wall=kb, ratio=round(kp / kb, 6),
                         spacing=float(ds.attrs["spacing"]), level=e["level"], level_top=metrics.level_of(ds),
                         level_max=e["level_max"], level_implied=e["level_implied"],
                         status=ds.attrs["status"], steps=int(ds["steps"]), residual=float(ds["residual"])))
    df = pd.DataFrame(rows).sort_values(["run", "k_wall", "ratio"])
    _write(df, outputs[0])
    return df
