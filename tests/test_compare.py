"""Every method on a tank of one's own (isaflow compare, isaflow.compare): a V-shaped vessel with 45-degree walls,
written here (in no config folder), runs through every tank method, compared against the closed forms and
reported; the papers' rectangles fill exactly as before; bad input is refused with one line, nothing written.

Tolerances, from the discretisation (units cm, N):

- a wall's normal load of a lattice of layer pitch p over a liquid h deep: its wall pressure resolved to half a
  layer of head, gamma p / 2 over the wetted length L against gamma h L / 2 on average, so p / h;
- the walls' vertical load against the weight: exact statics for ISA (the walls carry the weight plus the
  particles' unbalanced forces, which its run file holds: to round-off, and each wall within the sum of their
  magnitudes); for a dynamic method at rest, the momentum the liquid can gain or lose over the load window T:
  |P| <= sqrt(2 M KE) with KE <= e W h (the rest criterion e), so at most 2 W sqrt(2 e h / g) / T;
- the free surface of SPH and MPS: half a cell of clearance at sloping walls leaves the cells' area N s^2 short of
  the liquid's A(h) (known from the initial lattice, before any step), (A - N s^2) / (2 h) of level in the V, plus
  one layer pitch (the surface is read from the top particles); ISA's lattice starts unloaded (deeper than h) and
  is compressed by its weight, so its surface lies between one pitch below h and its unloaded top.
"""

import math
import os
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest
import yaml

from isaflow import cli, compare, methods, metrics, runfile, tables, tank as T, theory
from isaflow.core.units import G

from conftest import ROOT, TANKS

W, H = 4500.0, 60.0  # N, cm: gamma = W / H^2 = 1.25 N/cm^2 in a V of 45-degree walls (area H^2)
VEE = {"name": "vee", "description": "V-shaped vessel, 45-degree walls meeting at the origin.",
       "walls": [{"name": "left", "from": [-100, 100], "to": [0, 0]}, {"name": "right", "from": [0, 0], "to": [100, 100]}],
       "liquid": {"weight": W, "depth": H}}


def write_tank(path, spec):
    path.write_text(yaml.safe_dump(spec, sort_keys=False))
    return path


def run_compare(*args):
    """isaflow compare in a child process from the project's root: (exit status, stderr)."""
    proc = subprocess.run([sys.executable, "-m", "isaflow.cli", "compare", *map(str, args)], cwd=ROOT,
                          capture_output=True, text=True, timeout=1800)
    return proc.returncode, proc.stderr


@pytest.fixture(scope="module")
def vee_run(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("vee")
    tank = write_tank(tmp / "vee.yaml", VEE)
    out = tmp / "out"
    code, err = run_compare(tank, "-o", out)
    assert code == 0, err[-3000:]
    return out, pd.read_csv(out / "compare.csv"), err


def rows(out, df):
    """The table's rows at full precision: the functions compare.csv is made of (tables.tank_table), on the run
    files; compare.csv holds them to its 6 digits."""
    full = []
    for _, r in df.iterrows():
        ds = runfile.read(out / "runs" / f"{r['method']}.nc")
        row = {**metrics.comparison_row(ds), **tables.wall_columns(ds), **metrics.weight_on_walls(ds)}
        for k, v in row.items():
            if isinstance(v, float) and np.isfinite(v):
                assert r[k] == pytest.approx(v, rel=1e-5, abs=1e-9), k
        full.append((row, ds))
    return full


def test_every_method_runs_the_v_tank_compared_and_reported(vee_run):
    out, df, err = vee_run
    names = list(methods.tank_methods())
    assert list(df["method"]) == names and df["compare"].all()
    for m in names:
        assert (out / "runs" / f"{m}.nc").is_file()
    assert (out / "methods.png").stat().st_size > 0 and (out / "methods.pdf").stat().st_size > 0
    page = (out / "report.md").read_text()
    assert "# Every method on tank `vee`" in page and "![every method on this tank](methods.png)" in page
    for m in names:
        assert f"**{m}**" in page and f"isaflow run --method {m} " in page
    # one vessel: no flow or second-vessel columns
    assert not [c for c in df.columns if c.startswith(("vessel_", "left_fraction", "particles_"))]
    assert set(df["status"]) <= set(compare.ACCEPT)
    assert f"methods ran on tank 'vee'" in err


def test_the_v_theory_is_the_closed_form(vee_run):
    """Each 45-degree wall wetted to h carries gamma h^2 / (2 sin 45) = W / sqrt 2 normal to it, pushed out and
    down by gamma h^2 / 2 each; the tank's level at rest is h, rho g = W / h^2."""
    out, df, _ = vee_run
    closed = 1.25 * H**2 / (2 * math.sin(math.radians(45.0)))
    for r, _ in rows(out, df):
        assert r["tank_surface_cm"] == pytest.approx(H, rel=1e-12)
        for wall, sx in (("left", -1), ("right", 1)):
            assert r[f"theory_{wall}_N"] == pytest.approx(closed, rel=1e-12)
            assert r[f"theory_fx_{wall}_N"] == pytest.approx(sx * 1.25 * H**2 / 2, rel=1e-12)
            assert r[f"theory_fy_{wall}_N"] == pytest.approx(-1.25 * H**2 / 2, rel=1e-12)


@pytest.mark.parametrize("method", methods.tank_methods())
def test_every_method_holds_the_weight_and_loads_the_walls_as_the_theory(vee_run, method):
    out, df, _ = vee_run
    closed = W / math.sqrt(2.0)
    assert method in set(df["method"])
    for r, ds in rows(out, df[df["method"] == method]):
        pitch, spacing = float(r["layer_pitch_cm"]), float(r["spacing_cm"])
        assert r["held_weight_N"] == pytest.approx(W, rel=1e-9) and r["weight_N"] == pytest.approx(W, rel=1e-9)
        walls = ds["contact_force"].values.sum(0)
        if r["method"] == "isa":
            force = ds["force"].values  # each particle's unbalanced force: the walls carry the weight plus their sum
            R = force.sum(0)
            assert walls == pytest.approx(R + [0.0, W], abs=1e-9 * W)
            assert r["normal_left_N"] == pytest.approx((W + R[1] + R[0]) / math.sqrt(2), rel=1e-9)
            assert r["normal_right_N"] == pytest.approx((W + R[1] - R[0]) / math.sqrt(2), rel=1e-9)
            bound = float(np.hypot(*force.T).sum())
            for wall in ("left", "right"):
                assert abs(r[f"normal_{wall}_N"] - closed) <= bound
            surface = (-pitch, float(r["initial_depth_cm"]) - H)
        else:
            assert r["status"] == "converged"  # at rest: the momentum bound holds over the load window
            window = float(ds.attrs.get("load_window", ds.attrs.get("time.average_window", np.nan)))
            depth = max(H, float(r["initial_depth_cm"]))
            bound = 2 * math.sqrt(2 * float(ds.attrs["rest_energy_ratio"]) * depth / G) / window
            assert abs(walls[1] / W - 1) <= bound and abs(walls[0]) <= bound * W
            fill = (H**2 - r["particles"] * spacing**2) / (2 * H)  # the initial lattice's area short of A(h)
            surface = (-pitch - abs(fill), pitch + abs(fill))
        for wall in ("left", "right"):
            assert abs(r[f"normal_{wall}_N"] / closed - 1) <= pitch / H, (r["method"], wall)
        assert surface[0] <= r["surface_err_tank_cm"] <= surface[1], (r["method"], r["surface_err_tank_cm"], surface)
        if r["method"] != "isa":
            assert 0.0 <= r["time_to_rest_s"] <= r["sim_time_s"]
        assert r["wall_time_s"] > 0


def test_the_papers_rectangles_fill_as_before_and_the_v_inside_its_walls():
    """The shared polygon test keeps every cell of a rectangular vessel (SPH, MPS) and ISA's vessel fill is the
    paper's coarse lattice in the paper's vessel; in the V every method's particles lie inside its walls at their
    clearance."""
    from isaflow import settings as S
    from isaflow.core.geometry import point_segment_distance
    from isaflow.methods.isa import scene
    from isaflow.methods.isa.settings import VALUES
    from isaflow.methods.mps import boundary
    from isaflow.methods.sph import particles as P

    for name in ("single", "flow_step50", "flow_samefloor"):
        t = T.load(TANKS / f"{name}.yaml")
        (x0, x1), floor = t.first_vessel
        for n in (180, 684):
            nx, ny = P.lattice_shape(x1 - x0, t.depth, n)
            assert (nx, ny) == P.lattice_shape(x1 - x0, t.depth, n, area=t.liquid_area)
            plain = P.liquid_lattice(x0, floor, x1 - x0, t.depth, nx, ny)[0]
            assert np.array_equal(P.liquid_lattice(x0, floor, x1 - x0, t.depth, nx, ny, t.vessel_polygon(0), t.walls)[0],
                                  plain)
        for l0 in (100 / 18, 100 / 29, 1.25):
            assert np.array_equal(boundary.liquid_block((x0, x1), floor, t.depth, l0, t.vessel_polygon(0), t.walls),
                                  boundary.liquid_block((x0, x1), floor, t.depth, l0))
    single = T.load(TANKS / "single.yaml")
    rows = S.load(ROOT / "config/methods/isa.yaml", VALUES, "paper", "coarse")
    fill = S.load(ROOT / "config/methods/isa.yaml", VALUES, "paper", "coarse", ["particles.lattice.rows=null"])
    assert np.array_equal(scene.initial_positions(scene.build(single, fill, "paper")),
                          scene.initial_positions(scene.build(single, rows, "paper")))
    vee = T.Tank("vee", VEE, "")
    poly = vee.vessel_polygon(0)
    sc = scene.build(vee, fill, "paper")
    pos = scene.initial_positions(sc)
    assert len(pos) == round(W / 50.0) and sc.spec["particles"]["weight"] * len(pos) == pytest.approx(W)
    assert point_segment_distance(pos, vee.walls).min() >= 5.0 - 1e-9  # l_bu from both walls
    nx, ny = P.lattice_shape(200.0, H, 180, area=vee.liquid_area)
    sph, (dx, dy) = P.liquid_lattice(-100.0, 0.0, 200.0, H, nx, ny, poly, vee.walls)
    mps = boundary.liquid_block((-100.0, 100.0), 0.0, H, 100 / 18, poly, vee.walls)
    for pts, c in ((sph, min(dx, dy) / 2), (mps, 50 / 18)):
        assert len(pts) and (np.abs(pts[:, 0]) < pts[:, 1]).all()  # inside the V
        assert point_segment_distance(pts, vee.walls).min() >= c * (1 - 1e-9)
        assert pts[:, 1].max() < H


def test_the_example_tanks_load_and_their_theory_follows_their_walls():
    """config/tanks/examples: the V (its level at rest is its depth) and the sloping vessel draining through an
    opening into a lower one (the level at rest over both polygons: the first vessel empties into the second)."""
    vee = T.load(ROOT / "config/tanks/examples/vee.yaml")
    assert vee.liquid_area == pytest.approx(H**2) and vee.rho_g == pytest.approx(1.25)
    ramp = T.load(ROOT / "config/tanks/examples/ramp_opening.yaml")
    assert ramp.liquid_area == pytest.approx(100 * 60 + 0.4 * 60**2 / 2) and ramp.rho_g == pytest.approx(1.25)
    polys = [ramp.vessel_polygon(k) for k in range(2)]
    level = theory.rest_level(polys, [ramp.floor_y(0), ramp.floor_y(1)], ramp.weight, ramp.rho_g)
    t = (-900 + math.sqrt(900**2 + 4 * 6 * ramp.weight / ramp.rho_g)) / 2  # 150 t + t^2 / 6 = A above y = -50
    assert level == pytest.approx(t - 50.0, rel=1e-12) and level < ramp.floor_y(0)


def _refused(tmp_path, capsys, args, out, field):
    code = cli.main(["compare", *map(str, args)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and err[0].startswith("error: ") and field in err[0], err
    assert not os.path.lexists(out) or out.is_file()
    return err[0]


@pytest.mark.parametrize("case", ["walls_cross", "liquid_outside_every_vessel", "depth_over_the_walls",
                                  "output_under_a_file", "output_is_a_file", "resolution_unknown",
                                  "method_resolution_unknown"])
def test_bad_input_is_refused_with_one_line_and_nothing_written(tmp_path, capsys, monkeypatch, case):
    monkeypatch.chdir(ROOT)
    spec = dict(VEE)
    args, field = [], "field"
    if case == "walls_cross":
        spec["walls"] = VEE["walls"] + [{"name": "bar", "from": [-80, 30], "to": [80, 30]}]
        field = "field 'walls': walls 'left' and 'bar' cross"
    elif case == "liquid_outside_every_vessel":  # the liquid starts in the first vessel: here outside the walls
        spec["vessels"] = [{"name": "far", "x": [200, 300]}]
        field = "field 'vessels' (far)"
    elif case == "depth_over_the_walls":
        spec["liquid"] = {"weight": W, "depth": 150.0}
        field = "field 'liquid.depth'"
    tank = write_tank(tmp_path / "tank.yaml", spec)
    out = tmp_path / "out"
    if case == "output_under_a_file":
        (tmp_path / "file").write_text("x")
        out, field = tmp_path / "file" / "out", "is not a directory"
    elif case == "output_is_a_file":
        out = tmp_path / "file"
        out.write_text("x")
        field = "field '-o': the output path exists and is not a directory"
    elif case == "resolution_unknown":
        args, field = ["--resolution", "medium"], "argument --resolution 'medium'"
    elif case == "method_resolution_unknown":
        m = next(iter(methods.tank_methods()))
        args, field = ["--resolution", f"{m}=nowhere"], f"{methods.get(m).settings}: field 'resolutions'"
    line = _refused(tmp_path, capsys, [tank, "-o", out, *args], out, field)
    if case.startswith(("walls", "liquid", "depth")):
        assert str(tank) in line
    if case.startswith("output"):
        assert str(out) in line


def test_a_method_that_cannot_run_says_why_and_the_others_run(tmp_path):
    """A 40 cm box holding 2000 N: ISA's 50 N particles need 40 sites of its coarse lattice 5 cm inside the walls,
    24 fit; ISA says so in one line, every other method runs and is compared."""
    box = {"name": "box", "walls": [{"name": "left", "from": [0, 40], "to": [0, 0]},
                                    {"name": "floor", "from": [0, 0], "to": [40, 0]},
                                    {"name": "right", "from": [40, 0], "to": [40, 40]}],
           "liquid": {"weight": 2000.0, "depth": 20.0}}
    out = tmp_path / "out"
    code, err = run_compare(write_tank(tmp_path / "box.yaml", box), "-o", out)
    assert code == 0, err[-3000:]
    df = pd.read_csv(out / "compare.csv")
    first = next(iter(methods.tank_methods()))
    lines = [s for s in err.splitlines() if s.startswith(f"{first}: cannot run tank 'box': ")]
    assert len(lines) == 1 and "field 'particles.lattice.rows'" in lines[0] and "only 24 sites" in lines[0]
    row = df[df["method"] == first].iloc[0]
    assert not row["compare"] and "only 24 sites" in row["message"]
    ran = df[df["compare"].astype(bool)]
    assert set(ran["method"]) == set(methods.tank_methods()) - {first}
    assert np.allclose(ran["held_weight_N"], 2000.0, rtol=1e-9)
    assert f"**{first}**: did not run" in (out / "report.md").read_text()


def test_the_workflow_target_compare_plans_the_tank_into_a_folder_of_its_name(tmp_path):
    tank = write_tank(tmp_path / "vee.yaml", VEE)
    proc = subprocess.run([sys.executable, "-m", "snakemake", "-n", "-c2", "--forceall", "--workflow-profile", "none",
                           "compare", "--config", f"tank={tank}"], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert "results/compare/vee" in proc.stdout and "compare_tank" in proc.stdout
    proc = subprocess.run([sys.executable, "-m", "snakemake", "-n", "-c1", "--workflow-profile", "none", "compare"],
                          cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert proc.returncode != 0 and "needs a tank file" in proc.stdout + proc.stderr
