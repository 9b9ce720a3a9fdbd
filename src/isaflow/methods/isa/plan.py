"""Sweep plans of ISA's calibration and its error-against-run-time and stability study.

Every planned point is one run declaration (isaflow.settings.RUN_SCHEMA: tank,
variant, resolution, overrides as {key: {value, source}}, accept) plus what
the tables need to know about it (group, lattice, du factor, ...).  Step
lengths are planned as factors of each resolution's own du (the paper's rule
du = w / (10 k_p)); stiffness as factors of both force laws' r_u.  Pure Python
(the workflow plans while it is parsed).  Units: cm, N, s.
"""

import math

from ... import settings as S
from ... import tank as T
from ...inputs import InputError, not_a_file, printable
from .settings import RULES, VALUES, fire_dt_max

VARIANTS = tuple(RULES)
SETTINGS = "config/methods/isa.yaml"


def _num(x):
    """x rounded to 8 significant digits (the precision every planned number is run at)."""
    return float(f"{x:.8g}")


def _set(key, value, why):
    return {key: {"value": value, "source": f"study plan: {why}"}}


def resolution_values(spec, resolution, overrides=()):
    """du [cm], max_steps, k_b, k_p [N/cm], r_u of both laws [N] of a resolution (after overrides)."""
    s = S.load(SETTINGS, VALUES, resolution=resolution, overrides=overrides, spec=spec)
    return dict(du=float(s["solver.du"]), max_steps=int(s["solver.max_steps"]),
                kb=s["forces.wall.r_u"] / s["forces.wall.l_u"], kp=s["forces.pair.r_u"] / s["forces.pair.l_u"],
                wall_r_u=float(s["forces.wall.r_u"]), pair_r_u=float(s["forces.pair.r_u"]),
                wall_l_u=float(s["forces.wall.l_u"]), pair_l_u=float(s["forces.pair.l_u"]))


def solver_sets(variant, du, max_steps, kb, kp, dt_factor):
    """Overrides of one study run: du [cm], step limit, no history (the study needs the final state)."""
    out = {**_set("solver.du", _num(du), "du factor x the resolution's du"),
           **_set("solver.max_steps", int(max_steps), "the study's step limit"),
           **_set("solver.history", {}, "no history (final state only)")}
    if variant == "fire":
        out.update(_set("solver.dt_max", _num(fire_dt_max(kb, kp, dt_factor)), "fire_dt_factor / sqrt(2 k_b + 12 k_p)"))
    return out


def plan(study, spec):
    """{run id: declaration + meta} of every study run; spec: the validated config/methods/isa.yaml.

    Groups and run ids: error_runtime ``er_{lattice}_{variant}_du{f}``,
    fire_tuning ``ft_{lattice}_du{f}_dt{g}``, stability_map
    ``sm_{variant}_k{s}_du{f}``, cases ``sc_{case}_{variant}``.
    """
    check_names(study, spec)
    out = {}
    acc = list(study["accept"])
    lat = study["lattices"]
    values = {name: resolution_values(spec, v["resolution"]) for name, v in lat.items()}

    own = study.get("own_jobs", {})

    def add(sid, tank, variant, resolution, sets, **meta):
        if sid in out:
            raise InputError(f"field 'study.{meta['group']}': run '{sid}' is planned twice (a value given twice, or "
                             f"two entries planning the same point)")
        out[sid] = dict(tank=tank, variant=variant, resolution=resolution, set=sets, accept=acc,
                        stability=True, meta=dict(variant=variant, **meta))
        if meta.get("lattice") not in own.get("lattices", ()) and meta.get("case") not in own.get("cases", ()):
            out[sid]["block"] = "_".join(str(x) for x in (meta["group"], meta.get("lattice")) if x)

    er = study["error_runtime"]
    for block in er["blocks"]:
        for name in block["lattices"]:
            v = values[name]
            for var in block["variants"]:
                for f in block["du_factors"]:
                    steps = math.ceil(v["max_steps"] * max(1.0, 1.0 / f)) if er["scale_max_steps"] else v["max_steps"]
                    add(f"er_{name}_{var}_du{f:g}", "single", var, lat[name]["resolution"],
                        solver_sets(var, f * v["du"], steps, v["kb"], v["kp"], study["fire_dt_factor"]),
                        group="error_runtime", lattice=name, du_factor=f, paper=lat[name].get("paper"))
    ft = study["fire_tuning"]
    for name in ft["lattices"]:
        v = values[name]
        for f in ft["du_factors"]:
            for g in ft["dt_factors"]:
                add(f"ft_{name}_du{f:g}_dt{g:g}", "single", "fire", lat[name]["resolution"],
                    solver_sets("fire", f * v["du"], v["max_steps"], v["kb"], v["kp"], g),
                    group="fire_tuning", lattice=name, du_factor=f, dt_factor=g, paper=lat[name].get("paper"))
    sm = study["stability_map"]
    v = values[sm["lattice"]]
    for var in sm["variants"]:
        for s in sm["stiffness_factors"]:
            for f in sm["du_factors"]:
                stiff = {**_set("forces.wall.r_u", _num(s * v["wall_r_u"]), "stiffness factor x r_u"),
                         **_set("forces.pair.r_u", _num(s * v["pair_r_u"]), "stiffness factor x r_u")}
                sets = solver_sets(var, f * v["du"], sm["max_steps"], s * v["kb"], s * v["kp"], study["fire_dt_factor"])
                add(f"sm_{var}_k{s:g}_du{f:g}", "single", var, lat[sm["lattice"]]["resolution"], {**stiff, **sets},
                    group="stability_map", lattice=sm["lattice"], du_factor=f, k_factor=s)
    cs = study["cases"]
    for case, c in cs["list"].items():
        extra_sets = case_sets(case, c.get("set", {}))
        cv = resolution_values(spec, c["resolution"], extra_sets)  # stiffness after the case's own overrides
        base = resolution_values(spec, c["resolution"])
        for var in c.get("variants", VARIANTS):
            f = cs["du_factors"].get(var, 1.0)
            sets = solver_sets(var, f * base["du"], cs["max_steps"], cv["kb"], cv["kp"], study["fire_dt_factor"])
            add(f"sc_{case}_{var}", c["tank"], var, c["resolution"], {**sets, **extra_sets},
                group="cases", case=case, note=c["note"], du_factor=f)
    return out


def check_names(study, spec):
    """Refuse a study whose names point at nothing, naming the study file's field (the workflow puts the file's
    name before it): a lattice no ``lattices`` entry defines, a resolution config/methods/isa.yaml (spec) has not, a
    case without a tank file, an ``own_jobs`` name of nothing.  A name the plan did not find was a KeyError, or a
    refusal naming config/methods/isa.yaml's field or a generated run's."""
    lat, cases = study["lattices"], study["cases"]["list"]
    resolutions = spec.get("resolutions", {})

    def need(ok, field, what, choices):
        if not ok:
            raise InputError(f"field '{field}': {what} (choose from {', '.join(choices)})")

    for name, v in lat.items():
        need(v["resolution"] in resolutions, f"study.lattices.value.{name}.resolution",
             f"config/methods/isa.yaml has no resolution '{v['resolution']}'", resolutions)
    uses = [(f"study.error_runtime.value.blocks.{k}.lattices", b["lattices"])
            for k, b in enumerate(study["error_runtime"]["blocks"])]
    uses += [("study.fire_tuning.value.lattices", study["fire_tuning"]["lattices"]),
             ("study.stability_map.value.lattice", [study["stability_map"]["lattice"]]),
             ("study.own_jobs.value.lattices", study.get("own_jobs", {}).get("lattices", []))]
    for field, names in uses:
        for name in names:
            need(name in lat, field, f"no lattice '{name}' in study.lattices", lat)
    for name in study.get("own_jobs", {}).get("cases", []):
        need(name in cases, "study.own_jobs.value.cases", f"no case '{name}' in study.cases", cases)
    for case, c in cases.items():
        need(c["resolution"] in resolutions, f"study.cases.value.list.{case}.resolution",
             f"config/methods/isa.yaml has no resolution '{c['resolution']}'", resolutions)
        kind = not_a_file(T.path_of(c["tank"]))
        if kind:
            raise InputError(f"field 'study.cases.value.list.{case}.tank': no tank '{c['tank']}' "
                             f"({T.path_of(c['tank'])}: {kind})")


def case_sets(case, sets):
    """{key: {value, source}} of a study case's ``set`` mapping, each checked against the ISA values; an error names
    the study file's field (``field 'study.cases.value.list.<case>.set.<key>'``; the workflow puts the file's name
    before it)."""
    for key, leaf in sets.items():
        where = f"field 'study.cases.value.list.{case}.set.{printable(key)}'"
        if not (isinstance(leaf, dict) and set(leaf) == {"value", "source"}):
            raise InputError(f"{where}: an override is a {{value, source}} mapping (the source says why)")
        S.apply(S.Settings({}, {}, where, {}), {key: leaf}, VALUES, where)
    return dict(sets)


def calibration(cal, runs, spec):
    """{run id: declaration + meta} of the free-surface calibration: for each listed run (its
    resolution), k_b = kb and k_p = ratio kb with the laws' ranges kept, the capped update."""
    out = {}
    for run in cal["runs"]:
        decl = runs[run]
        v = resolution_values(spec, decl["resolution"])
        for kb in cal["wall_stiffness"]:
            for ratio in cal["stiffness_ratio"]:
                sets = {**_set("forces.wall.r_u", kb * v["wall_l_u"], "calibration k_b x l_bu"),
                        **_set("forces.pair.r_u", kb * ratio * v["pair_l_u"], "calibration k_p x l_pu"),
                        **_set("solver.max_steps", int(cal["max_steps"]), "calibration step limit"),
                        **_set("solver.history", {}, "no history")}
                out[f"cal_{run}_kb{kb:g}_r{ratio:g}"] = dict(
                    tank=decl["tank"], variant=cal["variant"], resolution=decl["resolution"], set=sets,
                    accept=["converged", "cycle", "step_limit"], block=f"calibration_{run}",
                    meta=dict(group="calibration", run=run, k_wall=kb, ratio=ratio, variant=cal["variant"]))
    return out


def run_files(runs, group, **match):
    """Run files results/runs/isa/{id}.nc of one plan group whose meta match the given fields."""
    return [f"results/runs/isa/{sid}.nc" for sid, m in runs.items()
            if m["meta"]["group"] == group and all(m["meta"].get(k) == v for k, v in match.items())]


def meta(runs):
    """{run id: meta} of a plan (what the tables need)."""
    return {k: dict(v["meta"]) for k, v in runs.items()}
