"""ISA solver settings with every default resolved here, once (cm, N).

A scene's ``solver`` block gives the update rule and its numbers; anything it
leaves out is filled in by :func:`settings`.
"""

import math

from . import relax as R
from .newton import NEWTON

# update rules: relax.relax_resume's rule codes, and the equilibrium solver (newton.newton_resume)
RULES = {"paper": R.PAPER, "capped": R.CAPPED, "fire": R.FIRE, "newton_lm": NEWTON}
# Defaults of the optional solver fields.  f_ref and dt_max depend on the
# stiffness: both come from the Gershgorin bound lambda_max <= 2 k_b + 12 k_p
# (two walls, six neighbours) of the stiffness matrix.
PAIR_NEIGHBOURS = 6
DEFAULTS = {"chunk": 1000, "stop_on_cycle": True, "accept": ["converged"], "history": {}}
SKIN_FRACTION = 0.3  # neighbour-list skin as a fraction of the pair range l_pu


def f_ref_default(du, k_wall, k_pair):
    """capped rule's f_ref [N] = du (k_b + 6 k_p): du / 2 times the Gershgorin bound, so the
    capped update is linearly stable; it equals w for both of the paper's lattices (50 N, 12.5 N)."""
    return du * (k_wall + PAIR_NEIGHBOURS * k_pair)


def fire_dt_max(k_wall, k_pair, factor=1.0):
    """FIRE's dt_max [s] = factor / sqrt(2 k_b + 12 k_p) (unit masses): below the explicit
    integration limit 2 / sqrt(lambda_max) for factor < 2.  Written so it cannot overflow."""
    return factor / math.hypot(math.sqrt(2 * k_wall), math.sqrt(2 * PAIR_NEIGHBOURS * k_pair))


def settings(scene):
    """{name: value} of every solver setting of an ISA scene, defaults resolved.

    Keys: variant, du (cm), f_tol (N), max_steps, f_ref (N), dt_max (s),
    skin (cm), chunk, stop_on_cycle, accept, history, and the force laws
    wall_l_u, wall_r_u, pair_l_u, pair_r_u (cm, N).
    """
    s = {**DEFAULTS, **scene.spec["solver"]}
    wall_l_u, wall_r_u = scene.law("wall")
    pair_l_u, pair_r_u = scene.law("pair")
    k_wall, k_pair = wall_r_u / wall_l_u, pair_r_u / pair_l_u
    du = float(s["du"])
    return dict(
        variant=s["variant"], du=du, f_tol=float(s["f_tol"]), max_steps=int(s["max_steps"]),
        f_ref=float(s.get("f_ref", f_ref_default(du, k_wall, k_pair))),
        dt_max=float(s.get("dt_max", fire_dt_max(k_wall, k_pair))),
        skin=float(s.get("skin", SKIN_FRACTION * pair_l_u)), chunk=int(s["chunk"]),
        stop_on_cycle=bool(s["stop_on_cycle"]), accept=list(s["accept"]), history=dict(s["history"]),
        wall_l_u=wall_l_u, wall_r_u=wall_r_u, pair_l_u=pair_l_u, pair_r_u=pair_r_u,
    )
