"""The one surface and the two theories every method is judged by (isaflow.metrics, isaflow.theory)."""

import numpy as np
import pytest
import xarray as xr

from isaflow import metrics, theory
from isaflow import tank as T

from conftest import TANKS


def lattice_run(h, dx, dy, width=100.0, rhombic=False, tank="single", rho_g=None):
    """A run Dataset of particles on a lattice filling [0, width] x [0, h] exactly (layers dy apart, the first
    dy/2 above the floor; rhombic: every odd layer shifted by dx/2), with the exact hydrostatic wall loads of
    that liquid (rho_g, default the tank's) on 10 cm panels and the tank's theory attributes."""
    ys = np.arange(dy / 2, h, dy)
    pos = []
    for k, y in enumerate(ys):
        x0 = dx / 2 + (dx / 2 if rhombic and k % 2 else 0.0)
        pos += [[x, y] for x in np.arange(x0, width, dx)]
    pos = np.array(pos)
    t = T.load(TANKS / f"{tank}.yaml")
    walls = t.walls
    rho_g = t.rho_g if rho_g is None else rho_g
    weight = np.full(len(pos), rho_g * width * h / len(pos))
    cw, cp = [], []
    for w, (x0, y0, x1, y1) in enumerate(walls):
        L = np.hypot(x1 - x0, y1 - y0)
        for s in np.arange(5.0, L, 10.0):
            cw.append(w)
            cp.append([x0 + (x1 - x0) * s / L, y0 + (y1 - y0) * s / L])
    cw, cp = np.array(cw), np.array(cp)
    mag = theory.contact_theory(walls, cw, cp, rho_g, h)
    keep = mag > 0
    e = walls[cw, 2:] - walls[cw, :2]
    normal = np.column_stack([-e[:, 1], e[:, 0]]) / np.hypot(e[:, 0], e[:, 1])[:, None]  # liquid on the left
    ds = xr.Dataset({
        "pos": (("particle", "xy"), pos), "weight": (("particle",), weight), "wall_segment": (("wall", "end"), walls),
        "contact_wall": (("contact",), cw[keep]), "contact_point": (("contact", "xy"), cp[keep]),
        "contact_force": (("contact", "xy"), normal[keep] * mag[keep, None]),
        "wall_resultant": (("wall", "xy"), np.zeros((len(walls), 2))), "residual": ((), 0.0), "steps": ((), 1),
        "wall_time": ((), 0.0)}, coords={"wall": t.wall_names, "xy": ["x", "y"]})
    ds.attrs.update(spacing=dx, layer_pitch=dy, panel_length=10.0, method="test", variant="test", status="converged",
                    **t.attrs())
    return ds


@pytest.mark.parametrize("h, dx, dy, rhombic", [(72.5, 2.5, 2.5, False), (72.5, 100 / 18, 72.5 / 13, False),
                                                (75.0, 10.0, 5.0, True), (72.5, 5.0, 2.5, True)])
def test_the_surface_of_a_lattice_filling_a_depth_is_that_depth(h, dx, dy, rhombic):
    """Top particle centres sit half a layer pitch below the top of the liquid they stand for (the top layer
    reaches every strip one spacing wide: an unshifted layer)."""
    ds = lattice_run(h, dx, dy, rhombic=rhombic)
    assert metrics.surface_of(ds) == pytest.approx(h, abs=1e-9)
    assert metrics.level_of(ds) == pytest.approx(h - dy / 2, abs=1e-9)  # the paper's reading: top centres


def test_hydrostatic_loads_have_zero_error_against_both_theories():
    ds = lattice_run(72.5, 2.5, 2.5)
    for ref in ("tank", "own"):
        e = metrics.load_errors(ds, None, ref)
        assert e["side_err"] == pytest.approx(0.0, abs=1e-12) and e["floor_err"] == pytest.approx(0.0, abs=1e-12)
    # the tank's side wall: rho g h^2 / 2 = 3,262.5 N
    assert metrics.load_errors(ds, None, "tank")["theory_left"] == pytest.approx(3262.5)


def test_a_liquid_too_deep_is_wrong_against_the_tank_and_right_against_itself():
    """A method whose liquid holds the tank's 9000 N 2.5 cm deeper (rho g 1.2 instead of 1.2414 N/cm^2) loads
    the walls as its own depth says: the tank's theory shows the difference, the own-depth theory does not."""
    ds = lattice_run(75.0, 2.5, 2.5, rho_g=9000.0 / 7500.0)
    own = metrics.load_errors(ds, None, "own")
    tank = metrics.load_errors(ds, None, "tank")
    assert own["side_err"] == pytest.approx(0.0, abs=1e-12) and own["floor_err"] == pytest.approx(0.0, abs=1e-12)
    assert tank["floor_err"] == pytest.approx(0.0, abs=1e-12)  # the same weight on the floor
    assert tank["side_err"] == pytest.approx(1.2 * 75.0**2 / (9000 / 7250 * 72.5**2) - 1, rel=1e-9)  # +3.4 %


def test_the_tanks_levels_at_rest():
    assert theory.rest_levels([0.0], [100.0], 9000.0, 9000.0 / 7250) == pytest.approx(72.5)
    step = lattice_run(72.5, 2.5, 2.5, tank="flow_step50")
    same = lattice_run(72.5, 2.5, 2.5, tank="flow_samefloor")
    for ds in (step, same):
        t = T.load(TANKS / f"{ds.attrs['tank']}.yaml")
        ds["vessel_x"] = (("vessel", "bound"), np.array([v[1] for v in t.vessels]))
        ds.coords["vessel"] = [v[0] for v in t.vessels]
    # the step tank drains: the first vessel is empty (its floor), the second holds 9000 N at 36.25 cm
    assert metrics.tank_levels(step) == pytest.approx({"first": 0.0, "second": -50 + 36.25})
    # the same-floor tank: one level in both, 9000 N over 300 cm
    assert metrics.tank_levels(same) == pytest.approx({"first": 7250 / 300, "second": 7250 / 300})
