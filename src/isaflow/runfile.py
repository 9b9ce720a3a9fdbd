"""One netCDF file per run: results, diagnostics and provenance.

Written to a temporary name and renamed, so a killed run leaves no file that
looks complete.  Every variable carries ``units``.
"""

import datetime as dt
import hashlib
import os
import platform
import subprocess
import sys
from importlib import metadata
from pathlib import Path

import numpy as np
import xarray as xr

from . import kernels as K
from .solver import VARIANT_LABELS, wall_resultants

PACKAGES = ("isaflow", "numpy", "numba", "xarray", "netCDF4", "pandas", "matplotlib", "snakemake", "pyyaml", "jsonschema")


def _git(*args):
    try:
        return subprocess.run(["git", *args], capture_output=True, text=True, check=True, timeout=20).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None


def provenance(scene, config_path=None, argv=None):
    """Global attributes: git state, scene/config hashes, versions, command."""
    commit = _git("rev-parse", "HEAD") or "unknown"
    dirty = _git("status", "--porcelain", "--untracked-files=no")
    versions = []
    for p in PACKAGES:
        try:
            versions.append(f"{p}=={metadata.version(p)}")
        except metadata.PackageNotFoundError:
            pass
    cfg_hash = hashlib.sha256(Path(config_path).read_bytes()).hexdigest() if config_path else "none"
    return {
        "git_commit": commit,
        "git_dirty": "unknown" if dirty is None else str(bool(dirty)).lower(),
        "scene_file": scene.path,
        "scene_yaml": scene.text,
        "scene_overrides": "; ".join(scene.overrides) or "none",
        "scene_sha256": scene.digest,
        "config_file": str(config_path or "none"),
        "config_sha256": cfg_hash,
        "package_versions": ", ".join(versions),
        "python_version": platform.python_version(),
        "machine": f"{platform.machine()} {platform.processor() or ''} {os.cpu_count()} cpus".strip(),
        "command": " ".join(argv if argv is not None else sys.argv),
    }


def _var(dims, data, units, long_name, **attrs):
    return xr.Variable(dims, data, {"units": units, "long_name": long_name, **attrs})


def to_dataset(scene, run, weight, started, finished, prov):
    """xarray Dataset of a Run (see solver.Run) with CF/ACDD metadata."""
    p = run.params
    walls = scene.walls
    part, wall, point, cforce = K.wall_contacts(run.pos, walls, p["wl_u"], p["wr_u"])
    vessels = scene.spec.get("vessels", [])
    xy = ("particle", "xy")
    data = {
        "pos0": _var(xy, run.pos0, "cm", "initial particle position"),
        "pos": _var(xy, run.pos, "cm", "final particle position"),
        "force": _var(xy, run.force, "N", "final out-of-balance force on particle"),
        "weight": _var(("particle",), weight, "N", "particle weight"),
        "wall_segment": _var(("wall", "end"), walls, "cm", "wall segment x0, y0, x1, y1"),
        "wall_resultant": _var(("wall", "xy"), wall_resultants(run.pos, walls, p["wl_u"], p["wr_u"]), "N",
                               "resultant force of wall on liquid (= minus load on wall)"),
        "contact_particle": _var(("contact",), part.astype(np.int32), "1", "particle index of wall contact"),
        "contact_wall": _var(("contact",), wall.astype(np.int32), "1", "wall index of wall contact"),
        "contact_point": _var(("contact", "xy"), point, "cm", "closest point of the wall to the particle"),
        "contact_force": _var(("contact", "xy"), cforce, "N", "repulsive reaction R_b of the wall on the particle"),
        "steps": _var((), np.int64(run.step), "1", "total algorithm steps since the start of the chain"),
        "start_step": _var((), np.int64(run.start_step), "1", "steps taken before this run (continued runs)"),
        "wall_time": _var((), run.wall_time, "s", "solver wall-clock time of this run"),
        "max_force": _var((), run.fmax, "N", "final max over particles of max(|Fx|, |Fy|)"),
        "converged": _var((), np.int8(run.status == "converged"), "1", "1 if max|F| < f_tol"),
    }
    if len(run.hist_step):
        data.update(
            hist_step=_var(("record",), run.hist_step, "1", "algorithm step of max|F| record"),
            hist_fmax=_var(("record",), run.hist_fmax, "N", "max|F| at hist_step"),
            hist_fmax_lo=_var(("record",), run.hist_fmin_env, "N", "smallest max|F| over the record stride"),
            hist_fmax_hi=_var(("record",), run.hist_fmax_env, "N", "largest max|F| over the record stride"),
        )
    if len(run.chunk_step):
        data["sample_step"] = _var(("sample",), run.chunk_step, "1", "algorithm step of diagnostic sample")
    if len(run.chunk_walls):
        data["hist_wall_resultant"] = _var(("sample", "wall", "xy"), run.chunk_walls, "N",
                                           "resultant force of wall on liquid over the run")
        data["hist_sum_fx"] = _var(("sample",), run.chunk_walls[:, :, 0].sum(1), "N",
                                   "horizontal resultant of all wall reactions (0 in equilibrium)")
    if len(run.chunk_vessels) and vessels:
        data["hist_vessel_count"] = _var(("sample", "vessel"), run.chunk_vessels, "1", "particles per vessel")
    if len(run.snap_step):
        data["snap_step"] = _var(("snapshot",), run.snap_step, "1", "algorithm step of snapshot")
        data["snap_pos"] = _var(("snapshot", "particle", "xy"), run.snap_pos, "cm", "particle positions at snapshot")
    coords = {"xy": ["x", "y"], "wall": scene.wall_names, "end": ["x0", "y0", "x1", "y1"]}
    if vessels:
        coords["vessel"] = [v["name"] for v in vessels]
        data["vessel_x"] = _var(("vessel", "bound"), np.array([v["x"] for v in vessels], float), "cm",
                                "vessel x range [xmin, xmax)")
    ds = xr.Dataset(data, coords=coords)
    lat = scene.spec["particles"].get("lattice", {})
    ds.attrs = {
        "Conventions": "CF-1.10, ACDD-1.3",
        "title": f"isaflow run: {scene.name}",
        "summary": scene.spec.get("description", "").strip(),
        "references": "Papadopoulos, Koutitas & Lazaridis (2016), Open J. Civil Eng. 6, 397-409, "
                      "doi:10.4236/ojce.2016.63034",
        "source": "isaflow incremental static analysis of point particles",
        "creator_name": "isaflow replication workflow",
        "date_created": finished,
        "time_coverage_start": started,
        "time_coverage_end": finished,
        "history": f"{finished}: {prov['command']}",
        "units_system": "length cm, force N, stiffness N/cm, time s",
        "scene": scene.name,
        "variant": p["variant"],
        "variant_label": VARIANT_LABELS[p["variant"]],
        "status": run.status,
        "status_message": run.message,
        "cycle_period": int(run.cycle_period),
        "du": p["du"], "f_tol": p["f_tol"], "max_steps": p["max_steps"], "f_ref": p["f_ref"],
        "dt_max": p["dt_max"], "skin": p["skin"],
        "wall_l_u": p["wl_u"], "wall_r_u": p["wr_u"], "pair_l_u": p["pl_u"], "pair_r_u": p["pr_u"],
        "lattice_a": float(lat.get("a", scene.spacing or np.nan)),
        **prov,
    }
    return ds


def now():
    return dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds")


def write(ds, path):
    """Write ds to path via a temporary file and an atomic rename."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp{os.getpid()}")
    try:
        ds.to_netcdf(tmp, engine="netcdf4")
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def read(path):
    """Open a run file fully into memory (the file is closed on return)."""
    with xr.open_dataset(path, engine="netcdf4") as ds:
        return ds.load()
