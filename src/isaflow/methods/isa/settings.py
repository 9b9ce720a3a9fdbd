"""ISA settings: the values of config/methods/isa.yaml (:data:`VALUES`, read by isaflow.settings)
and the solver settings of a scene, the derived ones computed here, once (cm, N).

A scene's ``solver`` block gives the update rule and its numbers (every one
from the settings file); :func:`settings` derives those left null (f_ref,
dt_max, skin, the overdamped step) from the force laws.  This module imports no numerics
(the workflow reads the values while it is parsed).
"""

import math

from ...core.units import G  # cm/s^2 (a constants module: no numerics imported)
from ...settings import with_units as _in

RULE_IDS = {"paper": 0, "capped": 1, "fire": 2, "overdamped": 3, "newton_lm": 4}  # relax.PAPER, CAPPED, FIRE;
# dynamics.OVERDAMPED; newton.NEWTON (tested equal)
RULES = RULE_IDS
# the force laws' shapes R(l) = r_u (1 - l / l_u)^p (forces.law_over_d): linear is the kept reading, the other
# two are named options for the force_law_shape sweep (config/claims/papadopoulos2016.yaml), not the paper's
LAW_EXPONENT = {"linear": 1.0, "power_1.5": 1.5, "quadratic": 2.0}

_POS = {"type": "number", "exclusiveMinimum": 0}
_OPT_POS = {"type": ["number", "null"], "exclusiveMinimum": 0}
_COUNT = {"type": "integer", "minimum": 1, "maximum": 2147483647}
_LAW = {"enum": list(LAW_EXPONENT)}
_HISTORY = {"type": "object", "additionalProperties": False, "properties": {
    "every": {"type": "integer", "minimum": 1, "maximum": 10**15},
    "walls": {"type": "boolean"}, "vessels": {"type": "boolean"}}}

# {dotted key: JSON schema of the value} of config/methods/isa.yaml
VALUES = {
    "particles.weight": _in("N", _POS),  # per particle
    "particles.points": _in("cm", {"type": ["array", "null"], "minItems": 1, "items": {
        "type": "array", "items": {"type": "number"}, "minItems": 2, "maxItems": 2}}),  # null: the lattice
    "particles.lattice.a": _in("cm", _POS),  # rhomb diagonal
    "particles.lattice.rows": {"anyOf": [_COUNT, {"type": "null"}]},  # null: fill the first vessel (scene.vessel_fill)
    "particles.lattice.row_lengths": {"type": "array", "items": _COUNT, "minItems": 1, "maxItems": 2},
    "particles.lattice.center_x": _in("cm", {"type": "number"}),
    "particles.lattice.bottom_y": _in("cm", {"type": "number"}),
    "particles.lattice.kind": {"enum": ["rhombic", "square"]},
    "particles.lattice.jitter": _in("1", {"type": "number", "minimum": 0, "maximum": 0.25}),  # fraction of a
    "particles.lattice.seed": {"type": "integer", "minimum": 0, "maximum": 2**31 - 1},
    "forces.wall.law": _LAW, "forces.wall.l_u": _in("cm", _POS), "forces.wall.r_u": _in("N", _POS),
    "forces.pair.law": _LAW, "forces.pair.l_u": _in("cm", _POS), "forces.pair.r_u": _in("N", _POS),
    "solver.du": _in("cm", _POS),
    "solver.f_tol": _in("N", _POS),
    "solver.max_steps": {"type": "integer", "minimum": 1, "maximum": 10**15},
    "solver.f_ref": _in("N", _OPT_POS), "solver.dt_max": _in("s", _OPT_POS), "solver.skin": _in("cm", _OPT_POS),
    "solver.chunk": {"type": "integer", "minimum": 100, "maximum": 10**12},
    "solver.stop_on_cycle": {"type": "boolean"},
    "solver.history": _HISTORY,
    # the stored states (driver.Recording): steps between snapshots in a single vessel and in a tank of vessels
    "solver.snapshot_every_single": _COUNT, "solver.snapshot_every_flow": _COUNT,
    "solver.snapshot_megabytes": _in("1e6 byte", _POS),  # what the kept snapshots may take before they are thinned
    # the overdamped variant (dynamics.py): damping ratio zeta of the stiffest mode lambda_max, time step
    "solver.zeta": _in("1", _POS), "solver.lambda_max": _in("N cm-1", _POS), "solver.dt": _in("s", _OPT_POS),
}


def own_tank(tank, settings):
    """The overrides ('key=value') of a run on a tank no settings file was written for (isaflow compare): the
    paper's lattice rows fit the paper's 100 cm vessel only; with rows null the resolution's lattice fills the
    tank's first vessel with the tank's weight (scene.vessel_fill), in the paper's vessel the paper's lattice."""
    return ("particles.lattice.rows=null",)


# Defaults of the optional solver fields.  f_ref and dt_max depend on the
# stiffness: both come from the Gershgorin bound lambda_max <= 2 k_b + 12 k_p
# (two walls, six neighbours) of the stiffness matrix.
PAIR_NEIGHBOURS = 6
DERIVED = ("f_ref", "dt_max", "skin")  # solver.<name> computed from the force laws when the file leaves it null
# (and solver.dt, of the overdamped variant only); the run file records the value used (settings.attributes)
SKIN_FRACTION = 0.3  # neighbour-list skin as a fraction of the pair range l_pu


def f_ref_default(du, k_wall, k_pair):
    """capped rule's f_ref [N] = du (k_b + 6 k_p): du / 2 times the Gershgorin bound, so the
    capped update is linearly stable; it equals w for both of the paper's lattices (50 N, 12.5 N)."""
    return du * (k_wall + PAIR_NEIGHBOURS * k_pair)


def fire_dt_max(k_wall, k_pair, factor=1.0):
    """FIRE's dt_max [s] = factor / sqrt(2 k_b + 12 k_p) (unit masses): below the explicit
    integration limit 2 / sqrt(lambda_max) for factor < 2.  Written so it cannot overflow."""
    return factor / math.hypot(math.sqrt(2 * k_wall), math.sqrt(2 * PAIR_NEIGHBOURS * k_pair))


OVERDAMPED_DT_SAFETY = 0.5  # fraction of the linear stability limit the overdamped time step may take at most
OVERDAMPED_DT_RESOLUTION = 0.25  # radians of the stiffest mode per time step, times max(1, zeta)


def overdamped_dt(weight, k_wall, k_pair, zeta, lambda_max, safety=OVERDAMPED_DT_SAFETY,
                  resolution=OVERDAMPED_DT_RESOLUTION):
    """Default time step [s] of the overdamped variant (dynamics.py) for particles of weight [N].

    The update v' = (v + dt F / m) / (1 + dt c / m), x' = x + dt v' (damping implicit) follows a mode of
    frequency w = sqrt(lam / m) and damping ratio z without oscillating only while dt w is small (at z = 1 its
    discrete map has complex eigenvalues for every 0 < dt w < 4; at dt w = 0.25 they turn by 0.1 rad per step
    and shrink by 0.82, so a critically damped mode released at rest overshoots by 0.16 % of its amplitude), and for
    z >> 1 (the gradient-flow limit x' = F / c) while dt lam / c = dt w / (2 z) is small.  So dt w =
    resolution x max(1, zeta) on the stiffest mode lambda_max (dt lam / c <= 0.125), and at most safety times
    the linear stability limit dt w < 2 z + 2 sqrt(z^2 + 1) on the Gershgorin bound lam_G = 2 k_b + 12 k_p of
    any state's stiffness (c fixed by zeta on lambda_max).
    """
    m = weight / G
    lam_g = 2 * k_wall + 2 * PAIR_NEIGHBOURS * k_pair
    omega_g = math.sqrt(lam_g / m)
    z = zeta * math.sqrt(lambda_max / lam_g)
    stable = safety * (2 * z + 2 * math.sqrt(z * z + 1)) / omega_g
    return min(stable, resolution * max(1.0, zeta) / math.sqrt(lambda_max / m))


def settings(scene):
    """{name: value} of every solver setting of an ISA scene, defaults resolved.

    Keys: variant, du (cm), f_tol (N), max_steps, f_ref (N), dt_max (s),
    skin (cm), chunk, stop_on_cycle, history, snapshot_every_single / _flow (steps) and snapshot_megabytes, the force laws
    wall_l_u, wall_r_u, pair_l_u, pair_r_u (cm, N) and their exponents wall_p,
    pair_p (LAW_EXPONENT), and the overdamped variant's zeta (1), lambda_max
    (N/cm), dt (s) and damping c = 2 zeta sqrt(m lambda_max) [N s/cm] of a
    particle of the scene's weight (m = w / g).
    """
    s = scene.spec["solver"]  # every value from the settings file (VALUES); only the derived ones are computed here
    wall_l_u, wall_r_u = scene.law("wall")
    pair_l_u, pair_r_u = scene.law("pair")
    k_wall, k_pair = wall_r_u / wall_l_u, pair_r_u / pair_l_u
    du = float(s["du"])
    weight = float(scene.spec["particles"]["weight"])
    zeta, lam = float(s.get("zeta", 1.0)), float(s.get("lambda_max", 2 * k_wall + 2 * PAIR_NEIGHBOURS * k_pair))
    dt = float(s.get("dt", overdamped_dt(weight, k_wall, k_pair, zeta, lam)))
    return dict(
        variant=s["variant"], du=du, f_tol=float(s["f_tol"]), max_steps=int(s["max_steps"]),
        f_ref=float(s.get("f_ref", f_ref_default(du, k_wall, k_pair))),
        dt_max=float(s.get("dt_max", fire_dt_max(k_wall, k_pair))),
        skin=float(s.get("skin", SKIN_FRACTION * pair_l_u)), chunk=int(s["chunk"]),
        stop_on_cycle=bool(s["stop_on_cycle"]), history=dict(s["history"]),
        snapshot_every_single=int(s["snapshot_every_single"]), snapshot_every_flow=int(s["snapshot_every_flow"]),
        snapshot_megabytes=float(s["snapshot_megabytes"]),
        wall_l_u=wall_l_u, wall_r_u=wall_r_u, pair_l_u=pair_l_u, pair_r_u=pair_r_u,
        wall_p=LAW_EXPONENT[scene.spec["forces"]["wall"]["law"]], pair_p=LAW_EXPONENT[scene.spec["forces"]["pair"]["law"]],
        zeta=zeta, lambda_max=lam, dt=dt, damping=2 * zeta * math.sqrt(weight / G * lam),
    )
