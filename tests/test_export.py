"""ParaView output (isaflow.export, `isaflow export RUN.nc --vtk DIR`) read back by the real VTK library, the flow's
animation (figures.animation), and, opt-in, the flows rendered by ParaView itself.

A run file with snapshots is made here by the one run driver (driver.drive) from a small stepper whose liquid
flows from a first vessel into a second, written by runfile like every run; the VTK files are read back with
vtkXMLUnstructuredGridReader / vtkXMLPolyDataReader (ParaView's vtkPVDReader is not in the vtk wheel: the .pvd
is parsed here) and every count, array and time must equal the run file's.
"""

import math
import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from isaflow import at_rest, driver, export, metrics, runfile
from isaflow.contract import Result
from isaflow.tank import Tank

from conftest import ROOT

vtk = pytest.importorskip("vtk", reason="the vtk wheel (test extra: pip install -r requirements/lock-py311.txt)")
from vtk.util.numpy_support import vtk_to_numpy  # noqa: E402

TANK = Tank("<test>", {"name": "two_boxes", "walls": [
    {"name": "left", "from": [0, 40], "to": [0, 0]}, {"name": "floor1", "from": [0, 0], "to": [20, 0]},
    {"name": "step", "from": [20, 0], "to": [20, -20]}, {"name": "floor2", "from": [20, -20], "to": [60, -20]},
    {"name": "right", "from": [60, -20], "to": [60, 40]}],
    "vessels": [{"name": "first", "x": [0, 20]}, {"name": "second", "x": [20, 60]}],
    "liquid": {"weight": 120.0, "depth": 10.0}}, "")
N = 12
REST = {"energy_ratio": 1e-3, "window": 0.5}


class Flow:
    """A stepper for driver.drive: 12 particles that move from the first vessel over the step into the second,
    0.1 s per advance from t0 = 2 s, still after advance 20 (quiet from 4.1 s, at rest 0.5 s later); one of them
    ends below the second floor (past a wall).  Wall loads: the weight on the floor under each particle."""

    t0 = 2.0

    def __init__(self):
        self.k = 0
        self.start = np.column_stack([np.linspace(2.0, 18.0, N), np.tile([2.0, 6.0], N // 2)])
        self.end = np.column_stack([np.linspace(24.0, 56.0, N), np.tile([-18.0, -14.0], N // 2)])
        self.end[3] = [40.0, -25.0]  # past the second floor
        self.pos = self.start.copy()
        self.vel = np.zeros_like(self.pos)
        self.rec = {"t": [], "wall": []}

    def advance(self):
        self.k += 1
        f = min(self.k / 20.0, 1.0)  # across at its height over the first 10 advances, then down
        new = np.column_stack([self.start[:, 0] + min(2 * f, 1.0) * (self.end[:, 0] - self.start[:, 0]),
                               self.start[:, 1] + max(2 * f - 1, 0.0) * (self.end[:, 1] - self.start[:, 1])])
        self.vel, self.pos = (new - self.pos) / 0.1, new
        return None

    def _walls(self):
        out = np.zeros((5, 2))
        np.add.at(out[:, 1], np.where(self.pos[:, 0] < 20, 1, 3), 10.0)
        return out

    def record(self):
        t = self.t0 + 0.1 * self.k
        self.rec["t"].append(t)
        self.rec["wall"].append(self._walls())
        return t, 1.0 if self.k <= 20 else 1e-4

    def spent(self):
        return self.k >= 60

    def fraction_done(self):
        return self.k / 60

    def clock(self):
        return self.t0 + 0.1 * self.k, 1000 + self.k

    def state(self):
        return {"pos": self.pos.copy(), "velocity": self.vel.copy(), "pressure": np.linspace(0.1, 1.2, N) * self.k}

    def rest_message(self, monitor):
        return "at rest"

    def limit_message(self, monitor):
        return "time limit"

    def progress(self, monitor):
        return f"advance {self.k}"

    def result(self, run):
        floor = np.where(self.pos[:, 0] < 20, 1, 3)
        return Result(
            method="sph", variant="wcsph", pos0=self.start, pos=self.pos.copy(), weight=np.full(N, 10.0),
            contact_wall=floor, contact_point=np.column_stack([self.pos[:, 0], np.where(floor == 1, 0.0, -20.0)]),
            contact_force=np.column_stack([np.zeros(N), np.full(N, 10.0)]), status=run.status, message=run.message,
            steps=1000 + self.k, start_step=1000, wall_time=run.wall_time, force_evals=self.k, residual=0.0,
            residual_name="rms speed", residual_units="cm s-1", sim_time=self.t0 + 0.1 * self.k, spacing=4.0,
            history={"sample_time": (("sample",), np.array(self.rec["t"]), "s", "time of sample"),
                     "sample_wall_resultant": (("sample", "wall", "xy"), np.array(self.rec["wall"]), "N",
                                               "force of each wall on the liquid")},
            fields={"velocity": (("particle", "xy"), self.vel.copy(), "cm s-1", "velocity")},
            params={"layer_pitch": 4.0, "panel_length": 10.0})


@pytest.fixture(scope="module")
def flow_run(tmp_path_factory):
    """The toy flow driven by driver.drive (snapshots every 0.3 s) and written as a run file."""
    stepper = Flow()
    rec = driver.Recording(0.3, 8.0, TANK.walls, TANK.vessels, TANK.escape_box(), 4.0)
    res = driver.drive(stepper, REST, recording=rec)
    path = tmp_path_factory.mktemp("run") / "toy_flow.nc"
    prov = {"command": "test", "run_id": "toy_flow"}
    runfile.write(runfile.to_dataset(res, TANK, prov, runfile.now(), runfile.now()), path)
    return path


def _read(reader, path):
    r = reader()
    r.SetFileName(str(path))
    r.Update()
    return r.GetOutput()


def _arrays(data):
    return {data.GetArrayName(i): vtk_to_numpy(data.GetArray(i)) for i in range(data.GetNumberOfArrays())}


def _pvd(path):
    """[(time, part, file)] of a .pvd collection."""
    return [(float(d.get("timestep")), d.get("part"), d.get("file")) for d in ET.parse(path).getroot().iter("DataSet")]


def test_the_run_file_holds_snapshots_and_the_at_rest_numbers(flow_run):
    ds = runfile.read(flow_run)
    assert ds.attrs["status"] == "converged"
    # the start, every 0.3 s of the run's clock (0.1 s advances), and the stop at rest
    assert np.allclose(ds["snap_time"].values, [2.0, 2.3, 2.6, 2.9, 3.2, 3.5, 3.8, 4.1, 4.4, 4.6])
    for name in ("snap_pos", "snap_velocity", "snap_pressure", "snap_vessel", "snap_status", "snap_step", "snap_time"):
        assert ds[name].dims[0] == "snapshot" and "units" in ds[name].attrs, name
    assert list(ds["snap_vessel"].values[0]) == [0] * N and list(ds["snap_vessel"].values[-1]) == [1] * N
    assert ds["snap_status"].values[-1, 3] == 1 and ds["snap_status"].values[-1].sum() == 1
    assert int(ds["wall_crossings"]) == 1 and ds["wall_crossings"].attrs["units"] == "1"
    assert float(ds["time_to_rest"]) == pytest.approx(2.1) and ds["time_to_rest"].attrs["units"] == "s"
    assert float(ds["residual_speed_ratio"]) == pytest.approx(math.sqrt(2e-4))
    # every wall's load over the last rest window: the liquid's whole weight on the second floor, steady
    assert ds["wall_load_mean"].values == pytest.approx([0, 0, 0, 120.0, 0]) and not ds["wall_load_std"].values.any()
    assert ds["surface_drift"].dims == ("vessel",) and ds["surface_drift"].attrs["units"] == "cm"
    assert np.isnan(ds["surface_drift"].values[0]) and ds["surface_drift"].values[1] == 0.0  # a dry first vessel
    assert "without liquid" in ds["surface_drift"].attrs["missing"]
    # the comparison table's columns (metrics.comparison_row), units in the names
    row = metrics.comparison_row(ds)
    assert row["time_to_rest_s"] == pytest.approx(2.1) and row["wall_crossings"] == 1
    assert row["floor2_wall_load_mean_N"] == pytest.approx(120.0) and row["second_surface_drift_cm"] == 0.0


def test_vtk_reads_back_every_state_the_walls_and_the_times(flow_run, tmp_path):
    out = tmp_path / "vtk"
    proc = subprocess.run([sys.executable, "-m", "isaflow.cli", "export", str(flow_run), "--vtk", str(out)],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    ds = runfile.read(flow_run)
    entries = _pvd(out / "toy_flow.pvd")
    parts = [e for e in entries if e[1] == "0"]
    assert [t for t, _, _ in parts] == list(ds["snap_time"].values)  # the simulated times, exactly
    assert {f for _, p, f in entries if p == "1"} == {"toy_flow_walls.vtp"}
    assert len(list(out.glob("*.vtu"))) == ds.sizes["snapshot"]
    for k, (t, _, name) in enumerate(parts):
        grid = _read(vtk.vtkXMLUnstructuredGridReader, out / name)
        assert grid.GetNumberOfPoints() == N and grid.GetNumberOfCells() == N
        pts = vtk_to_numpy(grid.GetPoints().GetData())
        assert np.array_equal(pts[:, :2], ds["snap_pos"].values[k]) and not pts[:, 2].any()
        a = _arrays(grid.GetPointData())
        assert set(a) == {"id", "weight", "velocity", "pressure", "vessel", "status"}
        assert np.array_equal(a["id"], np.arange(N)) and np.array_equal(a["weight"], ds["weight"].values)
        assert np.array_equal(a["velocity"][:, :2], ds["snap_velocity"].values[k]) and not a["velocity"][:, 2].any()
        assert np.array_equal(a["pressure"], ds["snap_pressure"].values[k])
        assert np.array_equal(a["vessel"], ds["snap_vessel"].values[k])
        assert np.array_equal(a["status"], ds["snap_status"].values[k])
        assert vtk_to_numpy(grid.GetFieldData().GetArray("TimeValue"))[0] == t
    walls = _read(vtk.vtkXMLPolyDataReader, out / "toy_flow_walls.vtp")
    cells = _arrays(walls.GetCellData())
    # one line per 10 cm panel; the liquid's force on each wall: minus the run's wall resultants
    assert walls.GetNumberOfLines() == len(cells["wall"]) == 4 + 2 + 2 + 4 + 6
    for w in range(5):
        on = cells["wall"] == w
        assert np.allclose(cells["force"][on, :2].sum(0), -ds["wall_resultant"].values[w], atol=1e-12)
    assert np.allclose(cells["load"], np.hypot(cells["force"][:, 0], cells["force"][:, 1]))
    assert np.allclose(cells["wall_load_mean"], ds["wall_load_mean"].values[cells["wall"]])
    fields = _arrays(walls.GetFieldData())
    for name in at_rest.AT_REST:
        if name in ds:
            assert np.array_equal(fields[name], np.atleast_1d(ds[name].values).astype(float), equal_nan=True), name
    assert set(fields) == {n for n in at_rest.AT_REST if n in ds}


def test_an_export_is_the_same_bytes_twice(flow_run, tmp_path):
    a, b = export.export_vtk(flow_run, tmp_path / "a"), export.export_vtk(flow_run, tmp_path / "b")
    files = sorted(p.name for p in a.parent.iterdir())
    assert files == sorted(p.name for p in b.parent.iterdir())
    assert all((a.parent / f).read_bytes() == (b.parent / f).read_bytes() for f in files)


def test_a_run_without_snapshots_exports_its_initial_and_final_state(flow_run, tmp_path):
    ds = runfile.read(flow_run)
    bare = ds.drop_vars([v for v in ds.variables if v.startswith("snap_")])
    bare.to_netcdf(tmp_path / "bare.nc")
    pvd = export.export_vtk(tmp_path / "bare.nc", tmp_path / "vtk")
    parts = [e for e in _pvd(pvd) if e[1] == "0"]
    assert [t for t, _, _ in parts] == [2.0, float(ds["sim_time"])]
    last = _arrays(_read(vtk.vtkXMLUnstructuredGridReader, pvd.parent / parts[-1][2]).GetPointData())
    assert np.array_equal(last["velocity"][:, :2], ds["velocity"].values) and last["status"].sum() == 1


@pytest.mark.parametrize("case", ["no_run_file", "no_method", "dir_is_a_file", "dir_below_a_file"])
def test_bad_input_gets_one_line_and_exit_2_and_nothing_written(flow_run, tmp_path, case):
    run, out = str(flow_run), tmp_path / "vtk"
    if case == "no_run_file":
        run = str(tmp_path / "text.nc")
        (tmp_path / "text.nc").write_text("not netCDF")
    elif case == "no_method":
        ds = runfile.read(flow_run)
        ds.attrs["method"] = "nomethod"
        ds.to_netcdf(tmp_path / "other.nc")
        run = str(tmp_path / "other.nc")
    elif case == "dir_is_a_file":
        out.write_text("")
    else:
        (tmp_path / "file").write_text("")
        out = tmp_path / "file" / "vtk"
    before = sorted(p.name for p in tmp_path.rglob("*"))
    proc = subprocess.run([sys.executable, "-m", "isaflow.cli", "export", run, "--vtk", str(out)],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1, proc.stderr
    want = {"no_run_file": ("text.nc", "not a netCDF file"), "no_method": ("other.nc", "attribute 'method'"),
            "dir_is_a_file": ("--vtk", "not a directory"), "dir_below_a_file": ("--vtk", "not a directory")}[case]
    assert all(w in proc.stderr for w in want), proc.stderr
    assert sorted(p.name for p in tmp_path.rglob("*")) == before


def test_the_flow_animation_has_a_frame_per_state(flow_run, tmp_path):
    from PIL import Image

    from isaflow.figures import animation

    n = animation.flow_animation([str(flow_run)], [str(tmp_path / "flow.gif")])
    with Image.open(tmp_path / "flow.gif") as im:
        assert im.n_frames == n == runfile.read(flow_run).sizes["snapshot"]
    assert animation.frame_sheet(tmp_path / "flow.gif", tmp_path / "sheet.png") == n


# --- the real thing: ParaView's own reader and renderer, opt-in -------------------------------------------------

PVBATCH = shutil.which("pvbatch")
# each method's flow and the fractions of its stored states pictured: the start, two moments of the drain, the stop
FLOWS = {"isa": ("flow_incomplete", (0, 0.2, 0.5, 1)), "sph": ("flow_wcsph_dx2.5", (0, 0.03, 0.08, 1)),
         "mps": ("flow_standard_dx3.45", (0, 0.1, 0.25, 1))}


@pytest.mark.skipif(os.environ.get("ISAFLOW_PARAVIEW") != "1",
                    reason="ParaView rendering is opt-in: ISAFLOW_PARAVIEW=1 (Debian: apt-get install -y paraview xvfb; "
                           "renders the workflow's flow runs results/runs/<method>/<run>.nc, one per method)")
@pytest.mark.parametrize("method", sorted(FLOWS))
def test_paraview_renders_each_methods_flow(method, tmp_path):
    run = ROOT / "results" / "runs" / method / f"{FLOWS[method][0]}.nc"
    if PVBATCH is None or shutil.which("xvfb-run") is None:
        pytest.skip("pvbatch or xvfb-run not found (apt-get install -y paraview xvfb)")
    if not run.exists():
        pytest.skip(f"{run} not made (snakemake -c2 {run.relative_to(ROOT)})")
    pvd = export.export_vtk(run, tmp_path / "vtk")
    for _ in range(3):  # xvfb-run -a may hand out a display another X server holds ("bad X server connection")
        proc = subprocess.run(["xvfb-run", "-a", "-s", "-screen 0 1400x900x24", PVBATCH,
                               str(ROOT / "tests" / "paraview" / "render.py"), str(pvd), str(tmp_path / method),
                               *map(str, FLOWS[method][1])],
                              capture_output=True, text=True, timeout=600)
        if "bad X server connection" not in proc.stdout + proc.stderr:
            break
    print(proc.stdout)  # one line per picture: time, particles, the colour array's range (pytest -rP)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    ds = runfile.read(run)
    lines = [ln for ln in proc.stdout.splitlines() if " particles " in ln]
    assert len(lines) == 4 and all(f" particles {ds.sizes['particle']} " in ln for ln in lines)
    for k in range(4):
        png = tmp_path / f"{method}_{k}.png"
        assert png.stat().st_size > 10_000  # a picture, not a blank frame
