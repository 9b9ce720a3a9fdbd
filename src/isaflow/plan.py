"""Sweep plans of the error-against-run-time and stability study (config/study.yaml).

Every study point is one ``isaflow run`` with its own run file; :func:`plan`
lists them with their scene overrides.  Step lengths are planned as factors
of each scene's own du (the paper's rule du = w / (10 k_p)); stiffness as
factors of both force laws' r_u.  Units: cm, N, s.
"""

import math

from . import scene as scenes
from .methods.isa.settings import RULES, fire_dt_max, settings

VARIANTS = tuple(RULES)


def _num(x):
    """A number as text that YAML (1.1, as PyYAML reads overrides) parses as a float."""
    s = f"{x:.8g}"
    if "e" in s and "." not in s.split("e")[0]:
        mant, exp = s.split("e")
        s = f"{mant}.0e{exp}"
    return s


def scene_values(path, overrides=()):
    """du [cm], max_steps, k_b, k_p [N/cm], r_u of both laws [N], lattice a [cm] and w [N] of a scene."""
    sc = scenes.load(path, overrides)
    s = settings(sc)
    return dict(du=float(s["du"]), max_steps=int(s["max_steps"]), kb=sc.stiffness("wall"), kp=sc.stiffness("pair"),
                wall_r_u=sc.law("wall")[1], pair_r_u=sc.law("pair")[1], a=sc.spacing,
                w=float(sc.spec["particles"]["weight"]))


def solver_sets(variant, du, max_steps, kb, kp, dt_factor, accept):
    """Scene overrides of one study run: update rule, du [cm], step limit, every outcome
    accepted, no history (the study needs only the final state)."""
    sets = [f"solver.variant={variant}", f"solver.du={_num(du)}", f"solver.max_steps={int(max_steps)}",
            f"solver.accept=[{','.join(accept)}]", "solver.history={}"]
    if variant == "fire":
        sets.append(f"solver.dt_max={_num(fire_dt_max(kb, kp, dt_factor))}")
    return sets


def plan(study):
    """{run id: dict(group, scene, set, lattice, variant, du_factor, ...)} of every study run.

    Groups and run ids: error_runtime ``er_{lattice}_{variant}_du{f}``,
    fire_tuning ``ft_{lattice}_du{f}_dt{g}``, stability_map
    ``sm_{variant}_k{s}_du{f}``, cases ``sc_{case}_{variant}``.
    """
    out = {}
    acc = study["accept"]
    lat = study["lattices"]
    values = {name: scene_values(v["scene"]) for name, v in lat.items()}

    def add(sid, **kw):
        if sid in out:
            raise ValueError(f"study run '{sid}' is planned twice")
        out[sid] = kw

    er = study["error_runtime"]
    for block in er["blocks"]:
        for name in block["lattices"]:
            v = values[name]
            for var in block["variants"]:
                for f in block["du_factors"]:
                    steps = math.ceil(v["max_steps"] * max(1.0, 1.0 / f)) if er["scale_max_steps"] else v["max_steps"]
                    add(f"er_{name}_{var}_du{f:g}", group="error_runtime", scene=lat[name]["scene"], lattice=name,
                        variant=var, du_factor=f, paper=lat[name].get("paper"),
                        set=solver_sets(var, f * v["du"], steps, v["kb"], v["kp"], study["fire_dt_factor"], acc))
    ft = study["fire_tuning"]
    for name in ft["lattices"]:
        v = values[name]
        for f in ft["du_factors"]:
            for g in ft["dt_factors"]:
                add(f"ft_{name}_du{f:g}_dt{g:g}", group="fire_tuning", scene=lat[name]["scene"], lattice=name,
                    variant="fire", du_factor=f, dt_factor=g, paper=lat[name].get("paper"),
                    set=solver_sets("fire", f * v["du"], v["max_steps"], v["kb"], v["kp"], g, acc))
    sm = study["stability_map"]
    v = values[sm["lattice"]]
    for var in sm["variants"]:
        for s in sm["stiffness_factors"]:
            for f in sm["du_factors"]:
                stiff = [f"forces.wall.r_u={_num(s * v['wall_r_u'])}", f"forces.pair.r_u={_num(s * v['pair_r_u'])}"]
                add(f"sm_{var}_k{s:g}_du{f:g}", group="stability_map", scene=lat[sm["lattice"]]["scene"],
                    lattice=sm["lattice"], variant=var, du_factor=f, k_factor=s,
                    set=stiff + solver_sets(var, f * v["du"], sm["max_steps"], s * v["kb"], s * v["kp"],
                                            study["fire_dt_factor"], acc))
    cs = study["cases"]
    for case, c in cs["list"].items():
        extra = list(c.get("set", []))
        cv = scene_values(c["scene"], extra)  # stiffness after the case's own overrides
        base = scene_values(c["scene"])
        for var in c.get("variants", VARIANTS):
            f = cs["du_factors"].get(var, 1.0)
            sets = solver_sets(var, f * base["du"], cs["max_steps"], cv["kb"], cv["kp"], study["fire_dt_factor"], acc)
            add(f"sc_{case}_{var}", group="cases", scene=c["scene"], case=case, note=c["note"], variant=var,
                du_factor=f, set=sets + extra)
    return out


def run_files(runs, group, **match):
    """Run files results/study/runs/{id}.nc of one plan group whose entries match the given fields."""
    return [f"results/study/runs/{sid}.nc" for sid, m in runs.items()
            if m["group"] == group and all(m.get(k) == v for k, v in match.items())]


def set_args(sets):
    """``--set 'key=value' ...`` arguments of ``isaflow run`` for scene overrides, quoted for the shell."""
    return " ".join(f"--set '{s}'" for s in sets)


def cli_overrides(runs, sid):
    """The --set arguments of one planned run."""
    return set_args(runs[sid]["set"])


def meta(runs):
    """Plan entries without the scene overrides (what the tables need)."""
    return {k: {kk: vv for kk, vv in v.items() if kk != "set"} for k, v in runs.items()}
