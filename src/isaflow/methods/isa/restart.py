"""Continuing a run from its run file (a start file: ``--start``, a declaration's ``start``; the scene's
``particles.from_run``): checks and the solver's restart state.

A start file is refused (one line: ``--start: '<file>' ...``, or ``<file>: field '<variable>'`` for a
variable of it that is wrong, or the settings field it conflicts with) unless it is a complete ISA run
file whose particles fit this scene; its solver state (solver.STATE_VARS) is restored when it was made
under the same dynamics, so the continued run repeats the uninterrupted one bit for bit.
"""

import numpy as np

from ... import runfile
from ...inputs import InputError as SceneError
from ...tank import check_positions
from . import budget, solver
from .settings import settings


def start_file(scene):
    """The state a ``from_run`` scene continues, checked before any work.

    Returns {pos, weight, steps, spacing, path, sha256, state, restart}:
    state is the solver's restart state (solver.STATE_VARS) when the run file
    was made under the same dynamics (walls, force laws, update rule and its
    numbers, chunk), so the continued run repeats the uninterrupted one bit
    for bit; otherwise, and for the newton_lm variant, None (positions only: a new problem started from a
    previous state, e.g. application 3 from application 1), and restart
    says why.  Refused (SceneError naming the start file and its variable, or the conflicting settings
    field): missing, a directory or other non-regular file, not netCDF, an incomplete write, not an ISA
    run, missing or malformed variables, non-finite or escaped states, particles outside this scene's
    walls, another particle weight, or a step at or past solver.max_steps.
    """

    src = scene.spec["particles"]["from_run"]
    where = "--start"  # the file as a whole; a variable of it is named as (file, variable)
    try:
        ds = runfile.open_run(src)
    except runfile.RunFileError as err:
        raise SceneError(f"{where}: {err}") from None
    try:
        with ds:
            pos, weight, steps, spacing, state = _read_start(scene, ds, src, where)
            chain = _chain(ds, spacing, weight)
    except SceneError:
        raise
    except (OSError, RuntimeError, ValueError, TypeError, KeyError, IndexError) as err:
        raise SceneError(f"{where}: '{src}' cannot be read as a run file ({type(err).__name__})") from None
    if not np.issubdtype(steps.dtype, np.integer) or not 0 <= int(steps) < 2**62:
        raise SceneError(f"{src}: field 'steps': the start file has no valid step count")
    steps = int(steps)
    check_positions(src, "pos", pos, scene.walls)  # the start file's own positions
    if not (np.isfinite(weight).all() and (weight > 0).all()):
        raise SceneError(f"{src}: field 'weight': the start file has non-finite or non-positive particle weights")
    w = float(scene.spec["particles"]["weight"])
    if not np.all(weight == w):
        raise SceneError(f"{scene.path}: field 'particles.weight': {w:g} N, but the particles of '{src}' weigh "
                         f"{weight.min():g}-{weight.max():g} N (a run of another scene)")
    max_steps = scene.spec["solver"]["max_steps"]
    if steps >= max_steps:
        raise SceneError(f"{scene.path}: field 'solver.max_steps': {max_steps} steps, but '{src}' is already at "
                         f"step {steps} (counted from the chain's start): nothing to do")
    budget.check_memory(scene, pos, (src, "pos"))
    state, restart = state
    return dict(pos=pos, weight=weight, steps=steps, spacing=spacing, path=src, sha256=runfile.sha256(src),
                state=state, restart=restart, chain=chain)


def _chain(ds, spacing, weight):
    """(layer_pitch cm, held_weight N, initial_depth cm, tank_difference) of the chain a start file belongs to."""
    a = ds.attrs
    try:
        return (float(a.get("layer_pitch", spacing / 2)), float(a.get("held_weight", float(np.sum(weight)))),
                float(a.get("initial_depth", np.nan)), str(a.get("tank_difference", "continued run")))
    except (TypeError, ValueError):
        return spacing / 2, float(np.sum(weight)), float("nan"), "continued run"


def _read_start(scene, ds, src, where):
    """(pos, weight, steps, spacing, (state, why)) of an open start file, shapes checked before loading."""
    problem = runfile.start_problem(ds, src, "isa", unusable=())  # the method first, the outcome after the shapes
    if problem:
        raise SceneError(f"{where}: {problem}")
    shapes = {"pos": ("particle", "xy"), "weight": ("particle",), "steps": ()}
    for name, dims in shapes.items():
        if name not in ds.variables or ds[name].dims != dims:
            raise SceneError(f"{where}: '{src}' has no variable '{name}' with dimensions {dims}")
    n = ds.sizes["particle"]
    if ds.sizes["xy"] != 2 or n == 0:
        raise SceneError(f"{where}: '{src}' holds no particles in 2D")
    budget.check_count(scene, n, (src, "pos"))
    problem = runfile.start_problem(ds, src, "isa")
    if problem:
        raise SceneError(f"{where}: {problem}")
    pos = np.asarray(ds["pos"].values, float)
    weight = np.asarray(ds["weight"].values, float)
    steps = ds["steps"].values
    try:
        spacing = float(ds.attrs.get("spacing", np.nan))
    except (TypeError, ValueError):
        spacing = np.nan
    return pos, weight, steps, spacing, _restart_state(scene, ds, n, src)


# {run-file attribute (the setting's dotted key): name in settings(scene)} of the values a continuation must share
DYNAMICS = {**{f"solver.{k}": k for k in ("du", "f_tol", "f_ref", "dt_max", "skin", "chunk", "stop_on_cycle")},
            **{f"forces.{w}.{k}": f"{w}_{k}" for w in ("wall", "pair") for k in ("l_u", "r_u")}}
OVERDAMPED_DYNAMICS = {f"solver.{k}": k for k in ("zeta", "lambda_max", "dt")}
LAWS = ("forces.wall.law", "forces.pair.law")


def _restart_state(scene, ds, n, src):
    """(state or None, why) of an open run file: its solver state if its dynamics equal this scene's."""
    s = settings(scene)
    differ = ["variant"] if ds.attrs.get("variant") != s["variant"] else []
    keys = {**DYNAMICS, **(OVERDAMPED_DYNAMICS if s["variant"] == "overdamped" else {})}
    for attr, name in keys.items():
        try:
            if float(ds.attrs[attr]) != float(s[name]):
                differ.append(attr)
        except (KeyError, TypeError, ValueError):
            differ.append(attr)
    differ += [k for k in LAWS if ds.attrs.get(k) != scene.spec["forces"][k.split(".")[1]]["law"]]
    if "wall_segment" not in ds or ds["wall_segment"].shape != scene.walls.shape or \
            not np.array_equal(ds["wall_segment"].values, scene.walls):
        differ.append("walls")
    if differ:
        return None, f"positions only (the run differs from this scene in {', '.join(differ)})"
    if s["variant"] == "newton_lm":
        return None, "positions only (the newton_lm variant keeps no state between runs: its damping starts afresh)"
    present = [k for k in solver.STATE_VARS if k in ds.variables]
    if not present:
        return None, "positions only (the run file holds no solver state)"
    state = {}
    for name, (dims, _, _) in solver.STATE_VARS.items():
        ok = name in ds.variables and ds[name].dims == dims
        ok = ok and (dims[:1] != ("particle",) or ds[name].shape == (n, 2))
        ok = ok and (dims != ("cycle_window",) or ds[name].size <= 10**6)
        v = np.asarray(ds[name].values, float) if ok else None
        if not ok or not np.isfinite(v).all():
            raise SceneError(f"{src}: field '{name}': the start file's solver state is missing, malformed or not "
                             f"finite")
        state[name] = v
    return state, "solver state restored (bit-identical continuation)"
