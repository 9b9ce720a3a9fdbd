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
from ...plausible import finite, require, within

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


def sound_speed(s):
    """c0 [cm/s] = sound_speed_factor sqrt(2 g max_drop)."""
    return s["settings.sound_speed_factor"] * math.sqrt(2 * G * s["settings.max_drop"])


def _first_vessel(tank):
    x0, x1 = tank.vessels[0][1]
    return x1 - x0


def lattice(tank, s):
    """(nx, ny, dx, dy) [cm] of the liquid lattice a resolution asks for (particles.lattice_shape, in Python)."""
    width, depth = _first_vessel(tank), tank.depth
    n, spacing = s["resolution.particles"], s["resolution.spacing"]
    if spacing is None:
        spacing = math.sqrt(width * depth / n) if n else float("nan")
    if not (math.isfinite(spacing) and spacing > 0):
        return 0, 0, float("nan"), float("nan")
    nx, ny = max(1, round(width / spacing)), max(1, round(depth / spacing))
    return nx, ny, width / nx, depth / ny


def time_step(s, h, c0):
    """dt [s] = min(cfl h / c0, 0.25 sqrt(h / g)) (solver.setup)."""
    return min(s["settings.cfl"] * h / c0, 0.25 * math.sqrt(h / G))


def plausible(tank, s, stability=False):
    """Refuse implausible settings (InputError naming the file and the setting, with the reason)."""
    path, field = s.path, _resolution_field(s)
    nx, ny, dx, dy = lattice(tank, s)
    require(nx >= 2 and ny >= 2, path, field,
            f"the liquid ({_first_vessel(tank):g} cm wide, {tank.depth:g} cm deep) would be {nx} x {ny} particles; "
            f"a liquid needs at least 2 across its width and its depth")
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
    finite(path, "settings.cfl", time_step(s, h, c0), "time step dt [s]")


def _resolution_field(s):
    return "resolution.spacing" if s["resolution.spacing"] is not None else "resolution.particles"


def _steps_field(s, n, t_key):
    """The setting a too long run is blamed on: a tiny CFL number, a huge sound speed, a fine resolution
    (dt follows h), else the time limit."""
    if s["settings.cfl"] < CFL_MAX[1] / 10:
        return "settings.cfl"
    if s["settings.sound_speed_factor"] > 10 * MACH[0]:
        return "settings.sound_speed_factor"
    if n > 1e6:
        return _resolution_field(s)
    return t_key


def cost(tank, s, particles=None):
    """budget.Cost of a run: the liquid lattice (or a start file's `particles`), wall particles 2h deep,
    t_max / dt steps."""
    nx, ny, dx, dy = lattice(tank, s)
    h = s["settings.h_factor"] * math.sqrt(dx * dy)
    liquid = nx * ny if particles is None else particles
    perimeter = sum(math.hypot(w["to"][0] - w["from"][0], w["to"][1] - w["from"][1]) for w in tank.spec["walls"])
    wall = 2 * perimeter / dx * max(1.0, 2 * h / dy)  # both faces of a thin wall, 2h deep
    n = liquid + wall
    flow = len(tank.spec.get("vessels", [])) > 1
    t_key = "settings.t_max_flow" if flow else "settings.t_max_single"
    dt = time_step(s, h, sound_speed(s))
    steps = s[t_key] / dt
    neighbours = math.pi * (2 * s["settings.h_factor"] * (1 + s["settings.skin"])) ** 2
    chunks = s[t_key] / s["settings.chunk_time"]
    nbytes = n * (BYTES_PER_PARTICLE + BYTES_PER_PAIR * neighbours) + chunks * 200
    fields = {"particles": _resolution_field(s), "steps": _steps_field(s, n, t_key),
              "bytes": _resolution_field(s) if chunks * 200 <= nbytes / 2 else
              "settings.chunk_time" if s["settings.chunk_time"] < dt else t_key}
    return [budget.Cost(n, steps, nbytes, NS_PER_PARTICLE_STEP, fields,
                        f"t = {s[t_key]:g} s / dt = {dt:.3g} s")]
