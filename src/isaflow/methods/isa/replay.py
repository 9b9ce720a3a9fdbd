"""Replay of an ISA run file step by step: what the run did in every step that its file does not hold.

The solver runs in compiled chunks and keeps only records; a claim about every step (the du rule of
section 6.1: no step changes a pair reaction by more than w/5) needs each step's state.  The replay
starts from the run's initial positions with the run's own settings (its file's attributes) and steps
the same compiled kernel (relax.relax_resume) one step per call, starting a fresh neighbour list where
the solver started a chunk and resuming it elsewhere: the split-anywhere guarantee of relax_resume makes
the replay repeat the run bit for bit, which :func:`pair_increments` checks on the final positions.

Units: cm, N.
"""

import numpy as np
import xarray as xr

from ...core.geometry import bounding_box
from ...core.jit import njit
from ...core.neighbours import build_pairs
from . import relax as R
from .forces import law_over_d
from .settings import RULES

JIT = dict(cache=True, nogil=True)


@njit(**JIT)
def _pair_reactions(pos, l_u, r_u, p, box):
    """(keys, R): the pairs i < j closer than l_u [cm] as sorted keys i * N + j and their reactions R [N]."""
    n = pos.shape[0]
    pi, pj, m = build_pairs(pos, box, l_u)
    keys = np.empty(m, np.int64)
    vals = np.empty(m)
    c = 0
    for k in range(m):
        i, j = pi[k], pj[k]
        d = np.sqrt((pos[i, 0] - pos[j, 0]) ** 2 + (pos[i, 1] - pos[j, 1]) ** 2)
        if d >= l_u:
            continue
        a, b = (i, j) if i < j else (j, i)
        keys[c] = a * n + b
        vals[c] = law_over_d(d, l_u, r_u, p) * d if d > 0.0 else r_u
        c += 1
    order = np.argsort(keys[:c])
    return keys[:c][order], vals[:c][order]


@njit(**JIT)
def _largest_change(k0, v0, k1, v1):
    """Largest |R_1 - R_0| [N] over the union of two sorted pair sets (a pair absent from one has R = 0)."""
    a = 0
    b = 0
    out = 0.0
    while a < k0.shape[0] or b < k1.shape[0]:
        if b >= k1.shape[0] or (a < k0.shape[0] and k0[a] < k1[b]):
            out = max(out, abs(v0[a]))
            a += 1
        elif a >= k0.shape[0] or k1[b] < k0[a]:
            out = max(out, abs(v1[b]))
            b += 1
        else:
            out = max(out, abs(v1[b] - v0[a]))
            a += 1
            b += 1
    return out


def pair_increments(ds):
    """Replay a fresh-start ISA run file (paper, capped or fire rule) and measure every step.

    Returns dict: max_pair_increment_N, the largest change of any pair reaction in one step; its step;
    max_component_move_cm, the largest displacement component of any particle in one step (from the
    positions); steps replayed; identical: the replay's final positions equal the file's bit for bit.
    """
    a = ds.attrs
    if int(ds["start_step"]) != 0:
        raise ValueError("replay: only runs started from their initial lattice (start_step 0)")
    walls = ds["wall_segment"].values.astype(float)
    box = bounding_box(walls)
    pos = np.array(ds["pos0"].values, float)
    weight = np.array(ds["weight"].values, float)
    vel = np.zeros_like(pos)
    force = np.zeros_like(pos)
    pos_build = pos.copy()
    state = np.zeros(5)
    h = np.zeros(1)
    rule = RULES[a["variant"]]
    wp, pp = float(a.get("wall_p", 1.0)), float(a.get("pair_p", 1.0))
    args = (float(a["wall_l_u"]), float(a["wall_r_u"]), float(a["pair_l_u"]), float(a["pair_r_u"]), rule,
            float(a["du"]), float(a["f_ref"]), float(a["dt_max"]), float(a["f_tol"]), 1, float(a["skin"]))
    chunk = int(a["chunk"])
    steps = int(ds["steps"])
    lo, hi = pos.min(0) - 100.0, pos.max(0) + 100.0
    pbox = np.array([min(lo[0], box[0]), min(lo[1], box[1]), max(hi[0], box[2]), max(hi[1], box[3])])
    k0, v0 = _pair_reactions(pos, args[2], args[3], pp, pbox)
    worst, at, move = 0.0, -1, 0.0
    for s in range(steps):
        before = pos.copy()
        done, status, _ = R.relax_resume(pos, vel, weight, walls, box, *args, force, h, pos_build, state,
                                         s % chunk != 0, 1, wp, pp)
        if done != 1:
            break
        move = max(move, float(np.abs(pos - before).max()))
        k1, v1 = _pair_reactions(pos, args[2], args[3], pp, pbox)
        inc = _largest_change(k0, v0, k1, v1)
        if inc > worst:
            worst, at = inc, s
        k0, v0 = k1, v1
    return dict(max_pair_increment_N=worst, at_step=at, max_component_move_cm=move, steps=steps,
                identical=bool(np.array_equal(pos, ds["pos"].values)))


def increments(ds):
    """:func:`pair_increments` of run file ds as a Dataset (the registry's derived 'isa:replay_<run>'); a replay
    that does not end where the run ended is refused (RuntimeError), so no file holds a replay of another run."""
    r = pair_increments(ds)
    if not r["identical"]:
        raise RuntimeError(f"replay of {ds.attrs.get('run_id', 'the run')} did not repeat the run")
    values = (("max_pair_increment", np.float64(r["max_pair_increment_N"]), "N",
               "largest change of any pair reaction in one step"),
              ("at_step", np.int64(r["at_step"]), "1", "the step of that change"),
              ("max_component_move", np.float64(r["max_component_move_cm"]), "cm",
               "largest displacement component of any particle in one step"),
              ("steps", np.int64(r["steps"]), "1", "steps replayed"))
    return xr.Dataset({k: ((), v, {"units": u, "long_name": n}) for k, v, u, n in values})
