"""One netCDF file per run of any method: results, diagnostics and provenance (pure I/O).

:func:`to_dataset` turns a contract.Result into the same variables for every
method; :func:`write` writes it to a temporary name (.NAME.partial-PID,
marked incomplete until written) and renames it over a regular file only, so
a killed run leaves no file that :func:`read` accepts; :func:`check_output`
refuses unusable output paths before any work.  Every variable carries
``units``.
"""

import datetime as dt
import glob
import hashlib
import os
import platform
import stat
import subprocess
import sys
import time
from importlib import metadata
from pathlib import Path

import numpy as np
import xarray as xr

from . import contract
from .methods import label

PACKAGES = ("isaflow", "numpy", "numba", "scipy", "pyamg", "xarray", "netCDF4", "pandas", "matplotlib",
            "snakemake", "pyyaml", "jsonschema")
# what can change a result: a run is "dirty" when any of these differs from the commit
RESULT_INPUTS = ("src", "config", "workflow", "Snakefile", "pyproject.toml", "requirements", "benchmarks/*.py")
# the pinned environment (requirements/compile.sh); its hash is recorded with every run
LOCK_FILE = Path(__file__).resolve().parents[2] / "requirements" / "lock-py311.txt"


def _git(*args):
    try:
        return subprocess.run(["git", *args], capture_output=True, text=True, check=True, timeout=20).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None


def provenance(inputs, argv=None):
    """Global attributes: git state, input-file hashes, versions, command.

    inputs: {name: path} of the files the run reads (scene, tank, method
    settings, workflow config, start file); each gets ``<name>_file`` and
    ``<name>_sha256``; so does the lock file of the pinned environment (``lock``).  ``git_dirty`` is computed over the sources and
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
    if LOCK_FILE.is_file():  # named relative to the project, so two clones record the same attribute
        out["lock_file"] = str(LOCK_FILE.relative_to(LOCK_FILE.parents[1]))
        out["lock_sha256"] = sha256(LOCK_FILE)
    for name, path in inputs.items():
        out[f"{name}_file"] = str(path) if path else "none"
        out[f"{name}_sha256"] = sha256(path) if path else "none"
    return out


def _var(dims, data, units, long_name, **attrs):
    return xr.Variable(dims, data, {"units": units, "long_name": long_name, **attrs})


def contract_variables(r):
    """The variables every run file holds of a contract.Result r, as two {name: xarray.Variable} in file order:
    the particles' (pos0, pos (N, 2) cm, weight (N,) N) and the wall contacts' (contact_wall, contact_point cm,
    contact_force N) with the run's counts, time and residual."""
    xy = ("particle", "xy")
    particles = {
        "pos0": _var(xy, r.pos0, "cm", "initial particle position"),
        "pos": _var(xy, r.pos, "cm", "final particle position"),
        "weight": _var(("particle",), r.weight, "N", "particle weight m g"),
    }
    rest = {
        "contact_wall": _var(("contact",), np.asarray(r.contact_wall, np.int32), "1", "wall index of wall contact"),
        "contact_point": _var(("contact", "xy"), r.contact_point, "cm", "contact point (or panel centre) on the wall"),
        "contact_force": _var(("contact", "xy"), r.contact_force, "N", "force of the wall on the liquid at the contact"),
        "steps": _var((), np.int64(r.steps), "1", "total algorithm steps since the start of the chain"),
        "start_step": _var((), np.int64(r.start_step), "1", "steps taken before this run (continued runs)"),
        "wall_time": _var((), r.wall_time, "s", "solver wall-clock time of this run"),
        "force_evals": _var((), np.int64(r.force_evals), "1", "force (or pressure-solve) evaluations of this run"),
        "residual": _var((), r.residual, r.residual_units, f"final {r.residual_name}"),
    }
    return particles, rest


def to_dataset(result, tank, prov, started, finished, spacing=None, references=""):
    """xarray Dataset of a contract.Result with CF/ACDD metadata.

    tank: anything with name, walls (W, 4) cm, wall_names and spec (an
    isaflow.tank.Tank; its liquid's theory attributes are recorded when it has
    them); spacing: initial particle spacing [cm] (the free-surface strip
    width), default result.spacing; references: the papers the method follows.
    """
    r = result
    bad = contract.history_problems(r.history)
    if bad:
        raise ValueError(f"{r.method} run history breaks the naming rule (isaflow.contract): {'; '.join(bad)}")
    spacing = r.spacing if spacing is None else spacing
    walls = tank.walls
    vessels = tank.spec.get("vessels", [])
    particles, rest = contract_variables(r)
    data = {
        **particles,
        "wall_segment": _var(("wall", "end"), walls, "cm", "wall segment x0, y0, x1, y1"),
        "wall_resultant": _var(("wall", "xy"), contract.wall_resultants(r.contact_wall, r.contact_force, len(walls)),
                               "N", "resultant force of wall on liquid (= minus load on wall)"),
        **rest,
        "converged": _var((), np.int8(r.status == "converged"), "1", "1 if the stop criterion was met"),
    }
    if np.isfinite(r.sim_time):
        data["sim_time"] = _var((), r.sim_time, "s", "physical time simulated")
    for name, (dims, arr, units, long_name, *extra) in {**r.fields, **r.history, **r.measures}.items():
        data[name] = _var(dims, arr, units, long_name, **(extra[0] if extra else {}))
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
        **(tank.attrs() if hasattr(tank, "attrs") else {}),
        **r.params,
        **prov,
    }
    return ds


def now():
    """Current UTC time, ISO 8601 to the second."""
    return dt.datetime.now(dt.UTC).isoformat(timespec="seconds")


class RunFileError(ValueError):
    """A path that cannot be read as, or written to as, a run file (the message says why)."""


PARTIAL = ".partial-"  # temporary names: .NAME.partial-PID (never *.nc; read() refuses them)
PAUSE_HOOK = "ISAFLOW_TEST_PAUSE_WRITE"  # test hook: seconds to pause mid-write (after the data, before the rename)


def sha256(path):
    """sha256 hex digest of a file, read in blocks."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _partial_name(path, pid):
    return path.with_name(f".{path.name}{PARTIAL}{pid}")


def check_output(path):
    """Refuse, before any work, an output path the final rename could not or must not use.

    Refused: an existing directory, device, FIFO, socket or symbolic link (the
    rename would replace it: only a regular file is ever replaced), a parent
    that is a file, a directory where a file cannot be created (probed by
    creating and removing this run's temporary file).  Missing parent
    directories are created.  Raises RunFileError.
    """
    path = Path(path)
    if not path.name or path.name in (".", ".."):
        raise RunFileError(f"{path}: output path names no file")
    if os.path.lexists(path):
        st = os.lstat(path)
        if not stat.S_ISREG(st.st_mode):
            kind = ("a directory" if stat.S_ISDIR(st.st_mode) else "a symbolic link" if stat.S_ISLNK(st.st_mode)
                    else "a device, FIFO or socket")
            raise RunFileError(f"{path}: output path is {kind}, not a regular file; refusing to replace it")
    parent = path.parent
    for anc in (parent, *parent.parents):
        if os.path.lexists(anc):
            if not anc.is_dir():
                raise RunFileError(f"{path}: cannot create the output: '{anc}' is not a directory")
            break
    try:
        parent.mkdir(parents=True, exist_ok=True)
        probe = _partial_name(path, os.getpid())
        fd = os.open(probe, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
        os.close(fd)
        os.unlink(probe)
    except OSError as err:
        raise RunFileError(f"{path}: cannot write the output: {err.strerror or err}") from None


def _remove_stale(path):
    """Remove temporary files of earlier writers of path whose process is gone."""
    for tmp in path.parent.glob(f".{glob.escape(path.name)}{PARTIAL}*"):
        pid = tmp.name.rsplit(PARTIAL, 1)[1]
        alive = pid.isdigit() and pid != str(os.getpid())
        if alive:
            try:
                os.kill(int(pid), 0)
            except ProcessLookupError:
                alive = False
            except OSError:
                pass
        if not alive:
            try:
                tmp.unlink()
            except OSError:
                pass


FILL = 9.969209968386869e36  # netCDF's default fill value of doubles: CF marks missing values with it


def finite(ds, path):
    """ds ready to write without NaN or infinity: a variable whose values may be missing says why in its
    'missing' attribute and is written with a _FillValue (CF; read back as NaN); any other non-finite value
    is refused (RunFileError), except in a run whose status is 'nonfinite' (its values are missing because
    the run blew up: marked so); non-finite global attributes (not applicable, e.g. the time to rest of a run
    that never came to rest) are left out."""
    ds = ds.copy()
    ds.attrs = {k: v for k, v in ds.attrs.items()
                if not (isinstance(v, (float, np.floating)) and not np.isfinite(v))}
    for name, var in ds.variables.items():
        if var.dtype.kind != "f":
            continue
        bad = ~np.isfinite(var.values)
        if bad.any() and "missing" not in var.attrs and ds.attrs.get("status") == "nonfinite":
            var.attrs["missing"] = "non-finite when the run stopped (status nonfinite)"
        if bad.any() and "missing" not in var.attrs:
            raise RunFileError(f"{path}: variable '{name}' holds {int(bad.sum())} non-finite value(s); a run file never "
                               f"holds NaN (a variable whose values may be missing says why in attrs['missing'])")
        var.encoding["_FillValue"] = FILL if bad.any() else None
    return ds


def write(ds, path):
    """Write ds to path: a temporary file .NAME.partial-PID marked incomplete, marked
    complete once written, then renamed over path (which must be a regular
    file or absent).  A killed writer leaves at most a temporary file that
    read() refuses and a later write() removes; SIGTERM/SIGINT (as
    SystemExit/KeyboardInterrupt, see cli) remove it on the way out."""
    path = Path(path)
    check_output(path)
    _remove_stale(path)
    tmp = _partial_name(path, os.getpid())
    ds = finite(ds, path)
    for var in ds.variables.values():  # the snapshots are most of a run file: compressed (lossless, deterministic)
        if var.dims[:1] == ("snapshot",):
            var.encoding.update(zlib=True, complevel=4, shuffle=True)
    ds.attrs["isaflow_complete"] = "no"
    try:
        ds.to_netcdf(tmp, engine="netcdf4")
        pause = os.environ.get(PAUSE_HOOK)
        if pause:
            print(f"isaflow test hook: pausing {pause} s while writing {tmp}", file=sys.stderr, flush=True)
            time.sleep(float(pause))
        import netCDF4

        with netCDF4.Dataset(tmp, "a") as nc:
            nc.setncattr("isaflow_complete", "yes")
        if os.path.lexists(path) and not stat.S_ISREG(os.lstat(path).st_mode):
            raise RunFileError(f"{path}: output path became a non-regular file; refusing to replace it")
        os.replace(tmp, path)
    finally:
        if os.path.lexists(tmp):
            tmp.unlink()


UNUSABLE = ("escaped", "nonfinite", "solver_failed")  # outcomes whose final state no run may continue


def start_problem(ds, path, method, needs=(), unusable=UNUSABLE):
    """Why the open run file ds (at path) cannot start a run of ``method``, in one line, or None: a run of another
    method, a variable or attribute of needs missing, or an outcome of unusable (every method's start check;
    unusable=() leaves the outcome to a later call)."""
    if ds.attrs.get("method") != method:
        return f"'{path}' is a run of method '{ds.attrs.get('method')}', not an {method.upper()} run"
    missing = [n for n in needs if n not in ds.variables and n not in ds.attrs]
    if missing:
        return f"'{path}' holds no {method.upper()} state ({', '.join(missing)} missing)"
    if ds.attrs.get("status") in unusable:
        return f"'{path}' holds no valid state (status {ds.attrs['status']})"
    return None


def open_run(path):
    """Open a run file lazily (caller closes); RunFileError if it is not a complete netCDF run file."""
    p = Path(path)
    if PARTIAL in p.name:
        raise RunFileError(f"'{path}' is the temporary file of an unfinished write, not a run file")
    try:
        if not p.is_file():
            kind = "a directory" if p.is_dir() else "not a regular file" if p.exists() else "no such file"
            raise RunFileError(f"'{path}': {kind}")
        with open(p, "rb") as f:
            magic = f.read(8)
    except OSError as err:
        raise RunFileError(f"'{path}': cannot read: {err.strerror or err}") from None
    if not (magic.startswith(b"CDF") or magic.startswith(b"\x89HDF")):
        raise RunFileError(f"'{path}' is not a netCDF file")
    try:
        ds = xr.open_dataset(p, engine="netcdf4")
    except Exception as err:  # netCDF4/HDF5 raise assorted errors for corrupt files
        raise RunFileError(f"'{path}' cannot be opened as netCDF ({type(err).__name__})") from None
    if ds.attrs.get("isaflow_complete", "yes") != "yes":
        ds.close()
        raise RunFileError(f"'{path}' is an incomplete write (killed before it finished)")
    return ds


def read(path):
    """Open a complete run file fully into memory (the file is closed on return); RunFileError otherwise."""
    with open_run(path) as ds:
        return ds.load()
