"""What makes an MPS run plausible, and what it will cost, from its settings alone (pure Python).

:func:`plausible` refuses settings no MPS run can use (isaflow.plausible):
interaction radii outside the range of the MPS literature, a Courant number
over the explicit limit, a viscous step over the diffusion limit, a liquid
with fewer than two particles across.  :func:`cost` estimates particles
(liquid + wall + dummy), steps (t / dt) and memory for isaflow.budget.
Units: cm, s, bytes; radii in spacings l0.
"""

import math

from ... import budget
from ...core.units import G
from ...plausible import extreme, finite, lattice_field, liquid_field, require, tank_field, within
from ...tank import check_points

NS_PER_PARTICLE_STEP = 2000.0  # measured 26 ms per step at about 5,000 particles (5.2 us), rounded down
BYTES_PER_PARTICLE = 2000  # state, number densities, the pressure system's vectors (order, rounded up)
BYTES_PER_PAIR = 40  # neighbour list entry + two sparse-matrix entries (value, column) per listed pair
BYTES_PER_CELL = 8  # int64 cell start of the cell list
BYTES_PER_LOAD_ENTRY = 3 * 8  # the load map (x and y rows) and the share of every panel and wall particle
RADIUS = (2.0, 4.0, "MPS interaction radii are 2.0-4.0 l0 (Koshizuka & Oka 1996: 2.1 l0 for the number density "
                    "and gradient, 4.0 l0 for the Laplacian; MPS-Basic 2.1 and 3.1 l0); below 2 l0 a lattice "
                    "particle sees only its nearest neighbours")
COURANT = (None, 0.5, "the explicit step moves a particle at the free-fall speed by courant x l0; MPS codes run "
                      "at 0.1-0.2 (Koshizuka & Oka 1996, MPS-Basic 0.2), the time-step study here up to 0.4")
DIFFUSION = (None, 0.25, "the explicit viscous step is stable for nu dt / l0^2 <= 1 / (2 d) = 0.25 in 2D")
BETA = (0.8, 0.99, "the free-surface threshold n* < beta n0: 0.97 in Koshizuka & Oka 1996 and MPS-Basic, "
                   "0.8-0.99 in the MPS literature")
RADII = ("model.re_density", "model.re_gradient", "model.re_laplacian", "model.re_surface")


def time_step(tank, l0, courant):
    """dt [s] = courant l0 / sqrt(2 g H), H = liquid top minus the lowest wall point (free-fall speed)."""
    _, floor = tank.first_vessel
    low = min(min(w["from"][1], w["to"][1]) for w in tank.spec["walls"])
    return courant * l0 / math.sqrt(2.0 * G * (floor + tank.depth - low))


def _flow(tank):
    return len(tank.spec.get("vessels", [])) > 1


def _counts(width, depth, l0):
    """(nx, ny) of a liquid block of spacing l0 (boundary.liquid_block): whole columns, the nearest whole rows;
    inf if they overflow."""
    nx, ny = width / l0, depth / l0
    return (math.floor(nx), round(ny)) if math.isfinite(nx) and math.isfinite(ny) else (nx, ny)


def plausible(tank, s, stability=False):
    """Refuse implausible settings (InputError naming the file and the setting, with the reason)."""
    path, l0 = s.path, s["resolution.spacing"]
    require(l0 is not None, path, f"resolutions.{s.resolution}", "no resolution.spacing")
    (x0, x1), _ = tank.first_vessel
    nx, ny = _counts(x1 - x0, tank.depth, l0)
    require(nx >= 2 and ny >= 2, path, lattice_field(tank, nx, ny, "resolution.spacing"),
            f"the liquid ({x1 - x0:g} cm wide, {tank.depth:g} cm deep) would be {nx:g} x {ny:g} particles of "
            f"l0 = {l0:g} cm (resolution.spacing); a liquid needs at least 2 across its width and its depth")
    finite(path, "resolution.spacing", float(nx * ny), "particle count of the liquid")
    for key in RADII:
        within(path, key, s[key], *RADIUS, stability=stability)
    within(path, "time.courant", s["time.courant"], *COURANT, stability=stability)
    within(path, "model.beta", s["model.beta"], *BETA, stability=stability)
    dt = time_step(tank, l0, s["time.courant"])
    finite(path, extreme(s, "time.courant", "resolution.spacing"), dt, "time step dt [s]")
    nu = s["model.kinematic_viscosity"]
    within(path, extreme(s, "model.kinematic_viscosity", "resolution.spacing") if nu > 0 else
           "model.kinematic_viscosity", nu * dt / l0**2, *DIFFUSION, stability=stability)
    # a stability case may set the radii apart (its point is to go outside the method's range)
    variational = s["model.gradient"].startswith("variational")
    require(stability or not variational or s["model.re_gradient"] == s["model.re_density"], path,
            "model.re_gradient", f"the variational gradient is the derivative of the number density, so its radius is "
            f"the number density's: re_gradient {s['model.re_gradient']:g} l0 against re_density "
            f"{s['model.re_density']:g} l0")
    probes = "probes.flow" if _flow(tank) else "probes.single"
    check_points(path, probes, s[probes], tank.walls_list())
    if s["start.on_wall_point"] is not None:
        check_points(path, "start.on_wall_point", [s["start.on_wall_point"]], tank.walls_list())
    t_key = "time.flow_time" if _flow(tank) else "time.single_time"
    require(s["time.average_window"] <= s[t_key], path, "time.average_window",
            f"{s['time.average_window']:g} s is longer than the run ({t_key} = {s[t_key]:g} s)")


def cost(tank, s, particles=None):
    """[budget.Cost] of a run: the liquid block (or a start file's `particles`), pressure and dummy wall
    layers, t / dt steps; memory: particles and their pairs, the cell list over the escape box, the load map
    from the wall particles to the panels (dense, panels x wall particles; both faces of a thin wall) and the
    samples."""
    l0 = s["resolution.spacing"]
    (x0, x1), _ = tank.first_vessel
    nx, ny = _counts(x1 - x0, tank.depth, l0)
    liquid = nx * ny if particles is None else particles
    wall = 2 * tank.perimeter() / l0 * (s["model.pressure_layers"] + s["model.dummy_layers"])
    n = liquid + wall
    t_key = "time.flow_time" if _flow(tank) else "time.single_time"
    dt = time_step(tank, l0, s["time.courant"])
    steps = s[t_key] / dt
    reach = max(s[k] for k in RADII) + s["model.list_skin"]
    records = s[t_key] / s["time.sample_interval"]
    box = tank.escape_box()
    grid = ((box[2] - box[0]) / (reach * l0) + 1) * ((box[3] - box[1]) / (reach * l0) + 1)
    panels = tank.panel_count(s["walls.panel_length"]) * (2 if _flow(tank) else 1)
    by_liquid = liquid_field(tank, nx, ny, "resolution.spacing") if liquid >= wall else tank_field(tank, "walls")
    wide = max(RADII, key=lambda k: s[k])
    parts = [(n * BYTES_PER_PARTICLE, by_liquid),
             (n * BYTES_PER_PAIR * math.pi * reach**2, wide if s[wide] > 2 * RADIUS[1] else by_liquid),
             (records * 400, "time.sample_interval" if s["time.sample_interval"] < dt else t_key),
             (grid * BYTES_PER_CELL, tank_field(tank, "walls")),
             (panels * wall * BYTES_PER_LOAD_ENTRY, "walls.panel_length" if panels > wall else tank_field(tank, "walls"))]
    steps_field = "time.courant" if s["time.courant"] < COURANT[1] / 50 else by_liquid if n > 1e6 else t_key
    fields = {"particles": by_liquid, "steps": steps_field, "bytes": max(parts, key=lambda p: p[0])[1]}
    return [budget.Cost(n, steps, sum(p[0] for p in parts), NS_PER_PARTICLE_STEP, fields,
                        f"t = {s[t_key]:g} s / dt = {dt:.3g} s")]
