"""ParaView output of a run file: ``isaflow export RUN.nc --vtk DIR`` (VTK XML files, units cm, N, s).

Into DIR it writes, for the run ``<run>`` (its run id):

- ``<run>_<k>.vtu``, one per stored state k (the run's snapshots, snap_*; a run without snapshots: its
  initial and final state): the particles as an unstructured grid of vertices at z = 0 with the point
  arrays ``id`` (the particle's index in the run file), ``weight`` [N], ``velocity`` [cm/s] and
  ``pressure`` [N/cm^2] or ``force`` [N] (those the run stores), ``vessel`` (index of the vessel whose x
  range holds it, -1 none) and ``status`` (at_rest.STATUS: 0 in the tank, 1 past a wall), and the field
  ``TimeValue`` (its time, below);
- ``<run>_walls.vtp``: the walls as poly lines, one line per wall panel (core.panels, the run's panel
  length), with the cell arrays ``wall`` (its index), ``force`` [N] (of the liquid on the panel at the
  stop: minus the run's contacts summed over it), ``load`` [N] and ``load_per_length`` [N/cm] of it, and
  ``wall_load_mean`` / ``wall_load_std`` [N] of its wall over the last rest window; its field data holds
  every at-rest and wall number of the run (at_rest.AT_REST, one array per number: per wall, per vessel, or
  one value);
- ``<run>.pvd``: the collection ParaView opens: every state's .vtu at its time (simulated s, or the step
  for a method without a clock, ISA) as part 0, the walls as part 1 at every time.

Writer: pyevtk (PyPI ``pyevtk``), not meshio.  pyevtk writes all three kinds of file this needs through
its own API: unstructured grids and poly data (``vtk.VtkFile`` with ``VtkUnstructuredGrid`` /
``VtkPolyData``: vertices, lines, point, cell and field data) and the ``.pvd`` collection
(``vtk.VtkGroup``), as binary appended arrays any VTK reader takes; it depends on numpy alone and is
maintained (1.7.0, 2026).  Its one-call ``hl`` functions are not used: they put field data inside the
piece, where VTK's readers do not look for it, and pyevtk writes no tuple count for field data (added here
through its XmlWriter, _field_header).  meshio 5.3.5
writes the .vtu but no poly data and no .pvd collection (its time series are XDMF), so the walls and the
collection would have been written by hand.

Everything is written into a temporary folder inside DIR and moved into DIR at the end, so an export that
fails leaves no partial set.  Bad input (a file that is no run file, a run file of no method, a directory
that cannot be written) raises ExportError: one line naming the file and the field.
"""

import os
import shutil
from pathlib import Path

import numpy as np

from . import at_rest, methods, metrics, runfile
from .core.panels import bin_to_panels, wall_panels
from .inputs import InputError
from .tank import Tank


class ExportError(InputError):
    """Input an export refuses (one line naming the file and the field)."""


def _tank(ds):
    """The isaflow.tank.Tank of a run file's walls and vessels (its vessels and box)."""
    walls = [{"name": str(n), "from": [float(w[0]), float(w[1])], "to": [float(w[2]), float(w[3])]}
             for n, w in zip(ds["wall"].values, ds["wall_segment"].values)]
    spec = {"name": str(ds.attrs.get("tank", "tank")), "walls": walls}
    if "vessel_x" in ds:
        spec["vessels"] = [{"name": str(n), "x": [float(a), float(b)]}
                           for n, (a, b) in zip(ds["vessel"].values, ds["vessel_x"].values)]
    return Tank("<run file>", spec, "")


def states(ds):
    """The stored states of a run file: [(time, {point array: values})], time in s of the chain's clock, or
    the step for a run without a clock; every state's arrays as the .vtu holds them (module docstring)."""
    n = ds.sizes["particle"]
    common = {"id": np.arange(n, dtype=np.int64), "weight": ds["weight"].values.astype(float)}
    if "snap_pos" in ds:
        times = ds["snap_time"].values if "snap_time" in ds else ds["snap_step"].values
        out = []
        for k, t in enumerate(times):
            arrays = {"pos": ds["snap_pos"].values[k], **common}
            for key in ("velocity", "pressure", "force"):
                if f"snap_{key}" in ds:
                    arrays[key] = ds[f"snap_{key}"].values[k]
            arrays["vessel"] = ds["snap_vessel"].values[k].astype(np.int8)
            arrays["status"] = ds["snap_status"].values[k].astype(np.int8)
            out.append((float(t), arrays))
        return out
    tank = _tank(ds)
    clocked = "sim_time" in ds
    t0 = float(ds.attrs.get("start_time", 0.0)) if clocked else float(ds["start_step"])
    t1 = float(ds["sim_time"]) if clocked else float(ds["steps"])
    out = []
    for t, pos, final in ((t0, ds["pos0"].values, False), (t1, ds["pos"].values, True)):
        arrays = {"pos": pos, **common}
        for key in ("velocity", "pressure", "force"):
            if final and key in ds and ds[key].dims[:1] == ("particle",):
                arrays[key] = ds[key].values
        arrays["vessel"] = at_rest.vessel_of(pos, tank.vessels)
        arrays["status"] = at_rest.outside_tank(pos, tank.walls, tank.escape_box()).astype(np.int8)
        out.append((t, arrays))
    return out


def panel_loads(ds):
    """(wall (P,), ends (P, 2, 2) cm, force (P, 2) N) of every wall panel of a run file: the force of the liquid
    on the panel at the stop, minus the run's contacts (the wall on the liquid) summed over it (core.panels, the
    run's panel length: metrics.panel_length)."""
    walls = ds["wall_segment"].values
    length = metrics.panel_length(ds)
    pw, _, f = bin_to_panels(walls, length, ds["contact_wall"].values, ds["contact_point"].values,
                             ds["contact_force"].values)
    _, _, s0, s1 = wall_panels(walls, length)
    w = walls[pw]
    L = np.hypot(w[:, 2] - w[:, 0], w[:, 3] - w[:, 1])
    e = (w[:, 2:] - w[:, :2]) / L[:, None]
    ends = np.stack([w[:, :2] + s0[:, None] * e, w[:, :2] + s1[:, None] * e], axis=1)
    return pw, ends, -f


def _field_data(ds):
    """The at-rest and wall numbers of a run file (at_rest.AT_REST) as VTK field data: one array each."""
    return {name: np.atleast_1d(ds[name].values).astype(float) for name in at_rest.AT_REST if name in ds}


def _vector(a):
    """pyevtk's vector of an (n, 2) array: (x, y, z) contiguous, z = 0."""
    a = np.asarray(a)
    return np.ascontiguousarray(a[:, 0]), np.ascontiguousarray(a[:, 1]), np.zeros(len(a), a.dtype)


def _field_header(w, name, a):
    """A field-data array's header: pyevtk's VtkFile.addHeader with NumberOfTuples, which VTK's readers need
    for field data (with no points or cells to count, an array without it reads as empty) and pyevtk leaves out;
    through pyevtk's XmlWriter, its offset kept as addHeader keeps it (8 bytes of size before each array)."""
    from pyevtk.vtk import np_to_vtk

    dtype = np_to_vtk[a.dtype.name]
    w.xml.openElement("DataArray")
    w.xml.addAttributes(Name=name, NumberOfTuples=a.size, NumberOfComponents=1, type=dtype.name, format="appended",
                        offset=w.offset)
    w.xml.closeElement()
    w.offset += a.size * dtype.size + 8


def _write(path, kind, xy, topology, point_data=None, cell_data=None, field_data=None):
    """One VTK XML file through pyevtk's VtkFile: kind VtkUnstructuredGrid (vertices: topology 'vertices') or
    VtkPolyData (lines: topology (connectivity, offsets) of its 'lines'); points xy (n, 2) cm at z = 0; point,
    cell and field data {name: array, or (x, y, z) for a vector}.  The field data goes before the piece, where
    VTK's readers look for it (pyevtk's hl functions put it inside the piece, where they do not), with its
    tuple count (_field_header).  Returns the file's name."""
    from pyevtk.vtk import VtkFile, VtkUnstructuredGrid, VtkVertex

    n = len(xy)
    points = _vector(np.asarray(xy, float))
    w = VtkFile(str(path), kind)
    w.openGrid()
    appended = []

    def add(name, a):
        w.addData(name, a)
        appended.append(a)

    if field_data:
        w.openData("Field")
        for name, a in field_data.items():
            _field_header(w, name, a)
            appended.append(a)
        w.closeData("Field")
    if kind is VtkUnstructuredGrid:
        w.openPiece(ncells=n, npoints=n)
    else:
        w.openPiece(npoints=n, nlines=len(topology[1]))
    w.openElement("Points")
    add("points", points)
    w.closeElement("Points")
    if kind is VtkUnstructuredGrid:
        w.openElement("Cells")
        add("connectivity", np.arange(n, dtype=np.int32))
        add("offsets", np.arange(1, n + 1, dtype=np.int32))
        add("types", np.full(n, VtkVertex.tid, np.uint8))
        w.closeElement("Cells")
    else:
        w.openElement("Lines")
        add("connectivity", topology[0])
        add("offsets", topology[1])
        w.closeElement("Lines")
    for where, data in (("Point", point_data), ("Cell", cell_data)):
        if data:
            w.openData(where)
            for name, a in data.items():
                add(name, a)
            w.closeData(where)
    w.closePiece()
    w.closeGrid()
    for a in appended:
        w.appendData(a)
    w.save()
    return Path(w.getFileName()).name


def write_state(path, t, arrays):
    """The particles .vtu of one state (module docstring) at path (without extension); returns its file name."""
    from pyevtk.vtk import VtkUnstructuredGrid

    data = {k: (_vector(a) if np.ndim(a) == 2 else np.ascontiguousarray(a)) for k, a in arrays.items() if k != "pos"}
    return _write(path, VtkUnstructuredGrid, arrays["pos"], "vertices", point_data=data,
                  field_data={"TimeValue": np.array([float(t)])})


def write_walls(ds, path):
    """The walls .vtp of a run file (module docstring) at path (without extension); returns its file name."""
    from pyevtk.vtk import VtkPolyData

    pw, ends, force = panel_loads(ds)
    p = len(pw)
    length = np.hypot(*(ends[:, 1] - ends[:, 0]).T)
    load = np.hypot(force[:, 0], force[:, 1])
    cells = {"wall": pw.astype(np.int32), "force": _vector(force), "load": load, "load_per_length": load / length}
    for name in ("wall_load_mean", "wall_load_std"):
        if name in ds:
            cells[name] = np.ascontiguousarray(ds[name].values.astype(float)[pw])
    lines = (np.arange(2 * p, dtype=np.int32), np.arange(2, 2 * p + 1, 2, dtype=np.int32))
    return _write(path, VtkPolyData, ends.reshape(-1, 2), lines, cell_data=cells, field_data=_field_data(ds))


def check_dir(out, name):
    """Refuse, before any work, an output directory that cannot be written (ExportError naming --vtk): the checks
    and write probe of a run file's output (runfile.check_output) on the collection DIR/<name>.pvd; creates DIR."""
    try:
        runfile.check_output(Path(out) / f"{name}.pvd")
    except runfile.RunFileError as err:
        raise ExportError(f"--vtk: {err}") from None


def open_run(path):
    """The run file at path, fully read (ExportError if it is no run file or a run of no method)."""
    try:
        ds = runfile.read(path)
    except runfile.RunFileError as err:
        raise ExportError(f"{err}") from None
    method = ds.attrs.get("method")
    if method not in methods.registry():
        raise ExportError(f"'{path}': attribute 'method': '{method}' is no method of the registry "
                          f"(choose from {', '.join(methods.registry())}): not a run file of this project")
    missing = [v for v in ("pos", "pos0", "weight", "wall_segment", "contact_wall") if v not in ds]
    if missing:
        raise ExportError(f"'{path}': variable '{missing[0]}': missing, so this is no run file of a tank method")
    return ds


def export_vtk(run, out, name=None):
    """Write the VTK files of a run file into the directory out (module docstring); returns the .pvd's path.
    name: the files' stem (default the run's run id, else the file's stem)."""
    from pyevtk.vtk import VtkGroup

    ds = open_run(run)
    name = name or str(ds.attrs.get("run_id") or Path(run).stem)
    check_dir(out, name)
    out = Path(out)
    tmp = out / f".{name}.export-{os.getpid()}"
    if tmp.exists():
        shutil.rmtree(tmp)
    tmp.mkdir()
    try:
        group = VtkGroup(str(tmp / name))
        walls = write_walls(ds, tmp / f"{name}_walls")
        for k, (t, arrays) in enumerate(states(ds)):
            piece = write_state(tmp / f"{name}_{k:04d}", t, arrays)
            group.addFile(str(tmp / piece), sim_time=t, part="0", name="particles")
            group.addFile(str(tmp / walls), sim_time=t, part="1", name="walls")
        group.save()
        for f in sorted(tmp.iterdir()):
            os.replace(f, out / f.name)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return out / f"{name}.pvd"


def export_runs(runs, outputs):
    """Workflow rule: export each run file of ``runs`` (a path or a list) into the folder of the matching .pvd of
    ``outputs``, the files named after the .pvd."""
    for run, pvd in zip([runs] if isinstance(runs, str) else runs, outputs):
        export_vtk(run, Path(pvd).parent, Path(pvd).stem)
