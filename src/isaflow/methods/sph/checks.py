"""What makes an SPH run plausible, and what it will cost, from its settings alone (pure Python).

:func:`plausible` refuses settings no WCSPH run can use (isaflow.plausible):
a smoothing length too short for the kernel to see neighbours, a time step
over the acoustic CFL limit, a sound speed too low for weak compressibility,
viscosity, Tait exponent and density diffusion outside their literature
ranges, a liquid with fewer than two particles across.  :func:`cost`
estimates particles (liquid + wall), steps (t_max / dt) and memory for
isaflow.budget.  Units: cm, s, bytes.
"""

import math

from ... import budget
from ...core.units import G
from ...plausible import extreme, finite, lattice_field, liquid_field, require, tank_field, within
from ...tank import bounds

NS_PER_PARTICLE_STEP = 70.0  # fastest measured, 2 threads at 2e4-5e4 particles (benchmarks/); 1 thread 127-130
BYTES_PER_PARTICLE = 900  # state, accelerations, wall contacts, neighbour-list bookkeeping (order, rounded up)
BYTES_PER_PAIR = 24  # pair indices and the kernel values and gradients of each listed pair
H_RANGE = (1.0, None, "h / dx below 1 leaves the cubic spline about 12 neighbours inside 2h, too few for its "
                      "sums (Monaghan 1992: h ~ 1.2-1.3 dx)")
CFL_MAX = (None, 0.4, "the acoustic CFL condition dt = cfl h / c0: WCSPH codes run at cfl 0.1-0.4 (Monaghan 1992: "
                      "0.25-0.3; DualSPHysics 0.2)")
MACH = (10.0, None, "weak compressibility needs c0 >= 10 x the largest velocity sqrt(2 g max_drop), Mach <= 0.1, "
                    "density variations <= 1 % (Monaghan 1994)")
GAMMA = (1.0, 7.15, "Tait exponents of liquids lie between 1 (isothermal) and 7.15 (water, Cole 1948); "
                    "Monaghan 1994 uses 7")
ALPHA = (0.0, 1.0, "Monaghan's artificial viscosity: 0.01-0.1 for free-surface flows, up to 1 for shocks "
                   "(Monaghan 1992)")
DELTA = (0.0, 1.0, "delta-SPH density diffusion: 0.1 (Molteni & Colagrossi 2009); above 1 it dominates the "
                   "continuity equation")
FRACTION = (0.0, 1.0, "a fraction of the cell spacing or of h")


BLOCK_CELLS = 3  # cells of 2h across a periodic block (sph.block: the minimum image)
BYTES_PER_CELL = 8  # int64 cell start of a cell list
BYTES_PER_PANEL = 16  # a panel's force (x, y) in the rest window's records (bounded here by one per chunk)
BYTES_PER_SNAPSHOT_PARTICLE = 30  # a liquid particle in a snapshot (driver.drive): position, velocity, pressure, vessel, status


def sound_speed(s):
    """c0 [cm/s] = sound_speed_factor sqrt(2 g max_drop)."""
    return s["settings.sound_speed_factor"] * math.sqrt(2 * G * s["settings.max_drop"])


def _first_vessel(tank):
    x0, x1 = tank.vessels[0][1]
    return x1 - x0


def lattice(tank, s):
    """(nx, ny, dx, dy) [cm] of the liquid lattice a resolution asks for (particles.lattice_shape, in Python);
    counts that overflow are inf, a spacing that is not finite and positive gives 0 x 0 and NaN."""
    width, depth = _first_vessel(tank), tank.depth
    n, spacing = s["resolution.particles"], s["resolution.spacing"]
    if spacing is None:
        area = tank.liquid_area or width * depth  # a liquid too thin for its polygon's area: the rectangle's
        spacing = math.sqrt(area / n) if n else float("nan")
    if not (math.isfinite(spacing) and spacing > 0):
        return 0, 0, float("nan"), float("nan")
    nx, ny = width / spacing, depth / spacing
    if not (math.isfinite(nx) and math.isfinite(ny)):
        return nx, ny, float("nan"), float("nan")
    nx, ny = max(1, round(nx)), max(1, round(ny))
    return nx, ny, width / nx, depth / ny


def time_step(s, h, c0):
    """dt [s] = min(cfl h / c0, 0.25 sqrt(h / g)) (solver.setup)."""
    return min(s["settings.cfl"] * h / c0, 0.25 * math.sqrt(h / G))


def plausible(tank, s, stability=False):
    """Refuse implausible settings (InputError naming the file and the setting, with the reason)."""
    path, field = s.path, _resolution_field(s)
    nx, ny, dx, dy = lattice(tank, s)
    require(nx >= 2 and ny >= 2, path, lattice_field(tank, nx, ny, field),
            f"the liquid ({_first_vessel(tank):g} cm wide, {tank.depth:g} cm deep) would be {nx} x {ny} particles "
            f"({field} = {s[field]:g}); a liquid needs at least 2 across its width and its depth")
    finite(path, field, float(nx * ny), "particle count of the liquid")
    within(path, "settings.h_factor", s["settings.h_factor"], *H_RANGE, stability=stability)
    within(path, "settings.cfl", s["settings.cfl"], *CFL_MAX, stability=stability)
    within(path, "settings.sound_speed_factor", s["settings.sound_speed_factor"], *MACH, stability=stability)
    if s["settings.eos"] == "tait":
        within(path, "settings.gamma", s["settings.gamma"], *GAMMA, stability=stability)
    within(path, "settings.alpha", s["settings.alpha"], *ALPHA, stability=stability)
    within(path, "settings.delta", s["settings.delta"], *DELTA, stability=stability)
    for key in ("settings.repulsion_radius", "settings.skin"):
        within(path, key, s[key], *FRACTION, stability=stability)
    top = tank.escape_box()[3] - tank.escape_box()[1]
    require(s["settings.max_drop"] <= top, path, "settings.max_drop",
            f"{s['settings.max_drop']:g} cm is a longer fall than the tank allows ({top:g} cm from its floor to the "
            f"top of its escape box); max_drop sets the sound speed")
    c0 = sound_speed(s)
    finite(path, "settings.sound_speed_factor", c0, "sound speed c0 [cm/s]")
    h = s["settings.h_factor"] * math.sqrt(dx * dy)
    finite(path, extreme(s, "settings.cfl", "settings.h_factor"), time_step(s, h, c0), "time step dt [s]")
    if s["settings.domain"] == "periodic_block":
        block(tank, s, nx, ny, dx, dy, h)


def block(tank, s, nx, ny, dx, dy, h):
    """Refuse a periodic block (sph.block) it cannot run: a density or diffusion it does not implement, a box of
    fewer than BLOCK_CELLS x BLOCK_CELLS cells of 2h (its minimum image needs them)."""
    path = s.path
    require(s["settings.density"] == "continuity", path, "settings.density",
            f"a periodic block (settings.domain) implements the continuity density only, not '{s['settings.density']}'")
    require(s["settings.delta"] == 0, path, "settings.delta",
            f"a periodic block (settings.domain) implements no density diffusion, not delta = {s['settings.delta']:g}")
    cells = min(nx * dx, ny * dy) * (1 + s["settings.stretch"]) / (2 * h)
    require(cells >= BLOCK_CELLS, path, _resolution_field(s) if min(nx, ny) < 2 * BLOCK_CELLS else "settings.h_factor",
            f"the periodic block holds {cells:.3g} cells of 2h = {2 * h:.4g} cm across ({nx} x {ny} particles); "
            f"its minimum image needs {BLOCK_CELLS}")


def _resolution_field(s):
    return "resolution.spacing" if s["resolution.spacing"] is not None else "resolution.particles"


def _steps_field(s, n, particles):
    """The setting a too long run is blamed on: a tiny CFL number, a huge sound speed, a fine resolution
    (dt follows h; particles: what the particle count follows), else the time limit."""
    if s["settings.cfl"] < CFL_MAX[1] / 10:
        return "settings.cfl"
    if s["settings.sound_speed_factor"] > 10 * MACH[0]:
        return "settings.sound_speed_factor"
    if n > 1e6:
        return particles
    return _t_key(s, None)


def _t_key(s, tank):
    if s["settings.domain"] == "periodic_block":
        return "settings.t_max_block"
    flow = tank is not None and len(tank.spec.get("vessels", [])) > 1
    return "settings.t_max_flow" if flow else "settings.t_max_single"


def cost(tank, s, particles=None):
    """[budget.Cost] of a run: the liquid lattice (or a start file's `particles`), wall particles 2h deep,
    t_max / dt steps; memory: particles and pairs, the finest cell list (the wall particles' de-duplication
    grid, half a spacing over the walls' bounding box), the panels' rest-window records and the snapshots."""
    nx, ny, dx, dy = lattice(tank, s)
    h = s["settings.h_factor"] * math.sqrt(dx * dy)
    liquid = nx * ny if particles is None else particles
    wall = 2 * tank.perimeter() / dx * max(1.0, 2 * h / dy)  # both faces of a thin wall, 2h deep
    n = liquid + wall
    t_key = _t_key(s, tank)
    dt = time_step(s, h, sound_speed(s))
    steps = s[t_key] / dt
    neighbours = math.pi * (2 * s["settings.h_factor"] * (1 + s["settings.skin"])) ** 2
    chunks = s[t_key] / s["settings.chunk_time"]
    box = bounds(tank.walls_list())
    cell = 0.5 * min(dx, dy)
    grid = ((box[2] - box[0]) / cell + 1) * ((box[3] - box[1]) / cell + 1)
    panels = tank.panel_count(s["settings.panel_length"])
    by_liquid = liquid_field(tank, nx, ny, _resolution_field(s)) if liquid >= wall else tank_field(tank, "walls")
    by_chunks = "settings.chunk_time" if s["settings.chunk_time"] < dt else t_key
    parts = [(n * (BYTES_PER_PARTICLE + BYTES_PER_PAIR * neighbours), by_liquid), (chunks * 200, by_chunks),
             (grid * BYTES_PER_CELL, tank_field(tank, "walls")),
             (panels * BYTES_PER_PANEL * (chunks + 4), "settings.panel_length" if panels > chunks else by_chunks),
             (s["settings.snapshot_megabytes"] * 1e6 + 3 * liquid * BYTES_PER_SNAPSHOT_PARTICLE,
              "settings.snapshot_megabytes")]
    fields = {"particles": by_liquid, "steps": _steps_field(s, n, by_liquid), "bytes": max(parts, key=lambda p: p[0])[1]}
    return [budget.Cost(n, steps, sum(p[0] for p in parts), NS_PER_PARTICLE_STEP, fields,
                        f"t = {s[t_key]:g} s / dt = {dt:.3g} s")]
