"""What makes the solid method's settings plausible, and what its cases will cost (pure Python).

The checks of every method (isaflow.preflight.check; settings.checked_values calls it, so
every run and the workflow while it is parsed): :func:`plausible` refuses
materials no solid has, a tolerance below double-precision round-off, a Hertz
disk pressed through its plate, a vessel time step over the lattice's step
rule (eq. 26, dx / (4 c)), and a case that is no solid under load (no free
particle between its held ones, nothing holding or moving it); :func:`cost`
gives every case's particles x steps for isaflow.budget.  The solid has no
tank (tank is None).  Units: the settings file's (GPa, kg/m^3, mm, um, ns),
converted here to cm, N, s.
"""

import math

from ... import budget
from ...core.units import KG, PA
from ...plausible import extreme, finite, require

NS_PER_PARTICLE_STEP = 10.0  # a lower bound of the dynamic-relaxation step (3-D links, numba)
BYTES_PER_PARTICLE = 3000  # state, links (26 neighbours in 3-D) and their forces (order, rounded up)
UM, MM, NS = 1e-4, 0.1, 1e-9  # cm, cm, s
E_MAX_GPA = 1220.0  # diamond, the stiffest solid
RHO_RANGE = (1.0, 22600.0)  # kg/m^3: aerogels to osmium, the densest element
TOL_MIN = 1e-14  # relative residual: below it the forces are round-off of double precision


def wave_speed(mat):
    """c = sqrt(E / rho) [cm/s] of the material section."""
    return math.sqrt(mat["E_GPa"] * 1e9 * PA / (mat["rho_kg_m3"] * KG / 1e6))


BAR_LAYERS = 3  # the bar's gripped end layers and a free mid-length layer between them, where the stress is read
PLATE_ROWS = 2  # the Hertz plate's held bottom row and a free row above it
FLOOR_COLUMNS = 3  # the floor's two supported end columns and a free one between them


def plausible(tank, settings, stability=False):
    """Refuse implausible settings (settings.Settings; InputError naming the file and the setting)."""
    s, path = settings.tree(), settings.path
    mat = s["material"]
    require(mat["E_GPa"] <= E_MAX_GPA, path, "material.E_GPa",
            f"{mat['E_GPa']:g} GPa is stiffer than diamond ({E_MAX_GPA:g} GPa), the stiffest solid")
    require(RHO_RANGE[0] <= mat["rho_kg_m3"] <= RHO_RANGE[1], path, "material.rho_kg_m3",
            f"{mat['rho_kg_m3']:g} kg/m^3 is outside {RHO_RANGE[0]:g}-{RHO_RANGE[1]:g} kg/m^3 (aerogels to "
            f"osmium, the densest element)")
    finite(path, f"material.{extreme(mat, 'E_GPa', 'rho_kg_m3')}", wave_speed(mat), "wave speed sqrt(E / rho) [cm/s]")
    require(s["solver"]["tol"] >= TOL_MIN, path, "solver.tol",
            f"{s['solver']['tol']:g} is below {TOL_MIN:g}, the round-off of the forces in double precision; the "
            f"relaxation could never reach it")
    h = s["hertz"]
    thick = h["plate"][1] * h["dx_um"]
    deepest = max(h["depths_um"])
    require(deepest < thick, path, "hertz.depths_um",
            f"{deepest:g} um presses the disk through the {thick:g} um plate ({h['plate'][1]} particles of "
            f"{h['dx_um']:g} um)")
    require(deepest < h["radius_mm"] * 1000, path, "hertz.depths_um",
            f"{deepest:g} um is deeper than the disk's radius {h['radius_mm']:g} mm")
    v = s["vessel"]
    rule = v["dx_mm"] * MM / (4 * wave_speed(mat))
    require(v["dt_ns"] * NS <= rule, path, "vessel.dt_ns",
            f"{v['dt_ns']:g} ns exceeds the step rule dx / (4 c) = {rule / NS:.4g} ns (marko2017 eq. 26)")
    require(v["water_h_over_dx"] >= 1.0, path, "vessel.water_h_over_dx",
            f"{v['water_h_over_dx']:g}: below 1 the water's kernel (support 2h) sees too few neighbours "
            f"(Monaghan 1992: h ~ 1.2-1.3 dx)")
    solids(s, path)


def solids(s, path):
    """Refuse a case that is no solid under load: its held particles leave none free, or nothing holds it."""
    layers = s["bar"]["particles"][1]
    require(layers >= BAR_LAYERS, path, "bar.particles",
            f"{layers} layer(s) along y: the bar's end layers are gripped and its stress is read at mid-length, so "
            f"it needs at least {BAR_LAYERS} (a free layer between the grips)")
    require(s["shear"]["grip_layers"] >= 1, path, "shear.grip_layers",
            "0: no layer holds the block or moves it, so it carries no load")
    rows = s["hertz"]["plate"][1]
    require(rows >= PLATE_ROWS, path, "hertz.plate",
            f"{rows} row(s): the plate's bottom row is held, so it needs at least {PLATE_ROWS} (a free row under the "
            f"disk)")
    f = s["floor"]
    ratio = f["span_cm"] / f["dx_cm"]
    columns = round(ratio) + 1 if math.isfinite(ratio) else ratio
    require(columns >= FLOOR_COLUMNS, path, "floor.dx_cm",
            f"{f['dx_cm']:g} cm over the {f['span_cm']:g} cm span gives {columns:g} column(s); the two end columns are "
            f"supported, so the plate needs at least {FLOOR_COLUMNS} (a free one between the supports)")


def _steps(*terms):
    """(total steps, the field of the largest term) of (steps, field) terms: a case's steps are refused under the
    setting that gives most of them."""
    return sum(n for n, _ in terms), max(terms, key=lambda t: t[0])[1]


def cost(tank, settings, particles=None):
    """[budget.Cost] of every case of the settings (settings.Settings): each steps figure names the setting it
    mostly comes from (a case run with the 'hooke' variant's solver.max_steps and the 'paper' variant's
    solver.max_steps_mechanism is two costs)."""
    s = settings.tree()
    steps_hooke, steps_paper = s["solver"]["max_steps"], s["solver"]["max_steps_mechanism"]
    b, sh, h, v, f = s["bar"], s["shear"], s["hertz"], s["vessel"], s["floor"]
    n_bar = math.prod(b["particles"])
    n_shear = sh["particles"][0] * (sh["particles"][1] + 2 * sh["grip_layers"]) * sh["particles"][2]
    n_hertz = h["plate"][0] * h["plate"][1]
    n_vessel = math.pi * ((v["water_radius_particles"] + v["ring_particles"] + 1) ** 2)
    n_floor = (f["span_cm"] / f["dx_cm"] + 1) * f["layers"]
    history = v["history_us"] * 1e-6 / (v["dt_ns"] * NS)
    # the pressure-load history steps whole records of record_every steps (vessel.history: ceil(history / every) x
    # every), so a record longer than the history is a longer run, named after record_every
    every = v["record_every"]
    recorded = math.ceil(history / every) * every if math.isfinite(history) else history
    history = (recorded, "vessel.record_every" if recorded > 2 * history else "vessel.history_us")

    def case(n, steps, field_n, detail):
        steps, field_steps = steps if isinstance(steps, tuple) else (steps, None)
        return budget.Cost(n, steps, n * BYTES_PER_PARTICLE, NS_PER_PARTICLE_STEP,
                           {"particles": field_n, "steps": field_steps, "bytes": field_n}, detail)

    dt_checks = (len(h["paper_dt_ns"]) * h["dt_check_steps"], "hertz.dt_check_steps")
    out = []
    for steps, key, variant in ((steps_hooke, "solver.max_steps", "hooke"),
                                (steps_paper, "solver.max_steps_mechanism", "paper")):
        out += [
            case(n_bar, _steps((2 * steps, key)), "bar.particles", f"{variant}: two loads x {key.split('.')[1]}"),
            case(n_shear, _steps((steps, key)), "shear.particles", f"{variant}: {key.split('.')[1]}"),
            case(n_hertz, _steps((len(h["depths_um"]) * steps, key), dt_checks), "hertz.plate",
                 f"{variant}: depths x {key.split('.')[1]} + the paper's dt checks"),
        ]
    return out + [
        case(n_vessel, _steps((steps_hooke, "solver.max_steps"), history, (v["steps"], "vessel.steps")),
             "vessel.water_radius_particles",
             f"settling + history {v['history_us']:g} us / dt {v['dt_ns']:g} ns + the paper's {v['steps']} steps"),
        case(n_bar, _steps((s["bar_long"]["steps"], "bar_long.steps")), "bar.particles", "one sustained-tension run"),
        case(n_floor, _steps((f["max_steps"], "floor.max_steps")), "floor.dx_cm", "max_steps"),
    ]
