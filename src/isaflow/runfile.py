"""One netCDF file per run of any method: results, diagnostics and provenance (pure I/O).

:func:`to_dataset` turns a contract.Result into the same variables for every
method; :func:`write` writes it to a temporary name and renames it, so a
killed run leaves no file that looks complete.  Every variable carries
``units``.
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

from . import contract
from .methods import label

PACKAGES = ("isaflow", "numpy", "numba", "scipy", "pyamg", "xarray", "netCDF4", "pandas", "matplotlib",
            "snakemake", "pyyaml", "jsonschema")
# what can change a result: a run is "dirty" when any of these differs from the commit
RESULT_INPUTS = ("src", "config", "workflow", "Snakefile", "pyproject.toml", "benchmarks/*.py")


def _git(*args):
    try:
        return subprocess.run(["git", *args], capture_output=True, text=True, check=True, timeout=20).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None


def provenance(inputs, argv=None):
    """Global attributes: git state, input-file hashes, versions, command.

    inputs: {name: path} of the files the run reads (scene, tank, method
    settings, workflow config, start file); each gets ``<name>_file`` and
    ``<name>_sha256``.  ``git_dirty`` is computed over the sources and
    configuration that can change a result (RESULT_INPUTS), not over outputs.
    """
    commit = _git("rev-parse", "HEAD") or "unknown"
    dirty = _git("status", "--porcelain", "--untracked-files=no", "--", *RESULT_INPUTS)
    versions = []
    for p in PACKAGES:
        try:
            versions.append(f"{p}=={metadata.version(p)}")
        except metadata.PackageNotFoundError:
            pass
    out = {
        "git_commit": commit,
        "git_dirty": "unknown" if dirty is None else str(bool(dirty)).lower(),
        "package_versions": ", ".join(versions),
        "python_version": platform.python_version(),
        "machine": f"{platform.machine()} {platform.processor() or ''} {os.cpu_count()} cpus".strip(),
        "command": " ".join(argv if argv is not None else sys.argv),
    }
    for name, path in inputs.items():
        out[f"{name}_file"] = str(path) if path else "none"
        out[f"{name}_sha256"] = hashlib.sha256(Path(path).read_bytes()).hexdigest() if path else "none"
    return out


def _var(dims, data, units, long_name, **attrs):
    return xr.Variable(dims, data, {"units": units, "long_name": long_name, **attrs})


def to_dataset(result, tank, prov, started, finished, spacing, references=""):
    """xarray Dataset of a contract.Result with CF/ACDD metadata.

    tank: anything with name, walls (W, 4) cm, wall_names and spec (a
    scene.Scene or scene.Tank); spacing: initial particle spacing [cm] (the
    free-surface strip width); references: the papers the method follows.
    """
    r = result
    walls = tank.walls
    vessels = tank.spec.get("vessels", [])
    xy = ("particle", "xy")
    data = {
        "pos0": _var(xy, r.pos0, "cm", "initial particle position"),
        "pos": _var(xy, r.pos, "cm", "final particle position"),
        "weight": _var(("particle",), r.weight, "N", "particle weight m g"),
        "wall_segment": _var(("wall", "end"), walls, "cm", "wall segment x0, y0, x1, y1"),
        "wall_resultant": _var(("wall", "xy"), contract.wall_resultants(r.contact_wall, r.contact_force, len(walls)),
                               "N", "resultant force of wall on liquid (= minus load on wall)"),
        "contact_wall": _var(("contact",), np.asarray(r.contact_wall, np.int32), "1", "wall index of wall contact"),
        "contact_point": _var(("contact", "xy"), r.contact_point, "cm", "contact point (or panel centre) on the wall"),
        "contact_force": _var(("contact", "xy"), r.contact_force, "N", "force of the wall on the liquid at the contact"),
        "steps": _var((), np.int64(r.steps), "1", "total algorithm steps since the start of the chain"),
        "start_step": _var((), np.int64(r.start_step), "1", "steps taken before this run (continued runs)"),
        "wall_time": _var((), r.wall_time, "s", "solver wall-clock time of this run"),
        "force_evals": _var((), np.int64(r.force_evals), "1", "force (or pressure-solve) evaluations of this run"),
        "residual": _var((), r.residual, r.residual_units, f"final {r.residual_name}"),
        "converged": _var((), np.int8(r.status == "converged"), "1", "1 if the stop criterion was met"),
    }
    if np.isfinite(r.sim_time):
        data["sim_time"] = _var((), r.sim_time, "s", "physical time simulated")
    for name, (dims, arr, units, long_name) in {**r.fields, **r.history}.items():
        data[name] = _var(dims, arr, units, long_name)
    coords = {"xy": ["x", "y"], "wall": tank.wall_names, "end": ["x0", "y0", "x1", "y1"]}
    if vessels:
        coords["vessel"] = [v["name"] for v in vessels]
        data["vessel_x"] = _var(("vessel", "bound"), np.array([v["x"] for v in vessels], float), "cm",
                                "vessel x range [xmin, xmax)")
    ds = xr.Dataset(data, coords=coords)
    ds.attrs = {
        "Conventions": "CF-1.10, ACDD-1.3",
        "title": f"isaflow run: {tank.name} ({r.method}, {r.variant})",
        "summary": tank.spec.get("description", "").strip(),
        "references": references or "Papadopoulos, Koutitas & Lazaridis (2016), Open J. Civil Eng. 6, 397-409, "
                                    "doi:10.4236/ojce.2016.63034",
        "source": f"isaflow method '{r.method}'",
        "creator_name": "isaflow replication workflow",
        "date_created": finished,
        "time_coverage_start": started,
        "time_coverage_end": finished,
        "history": f"{finished}: {prov['command']}",
        "units_system": "length cm, force N, time s, mass N s2 cm-1",
        "scene": tank.name,
        "method": r.method,
        "variant": r.variant,
        "variant_label": label(r.method, r.variant),
        "status": r.status,
        "status_message": r.message,
        "residual_name": r.residual_name,
        "spacing": float(spacing),
        **r.params,
        **prov,
    }
    return ds


def now():
    """Current UTC time, ISO 8601 to the second."""
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
