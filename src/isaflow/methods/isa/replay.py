"""Replay of an ISA run file step by step: what the run did in every step that its file does not hold.

The solver runs in compiled chunks and keeps only records; a claim about every step (the du rule of
section 6.1: no step changes a pair reaction by more than w/5) needs each step's state.  The replay
starts from the run's initial positions with the run's own settings (its file's attributes) and steps
the same compiled kernel (relax.relax_resume) one step per call, starting a fresh neighbour list where
the solver started a chunk and resuming it elsewhere: the split-anywhere guarantee of relax_resume makes
the replay repeat the run bit for bit, which :func:`pair_increments` checks on the final positions.  The
step loop and its measures are one compiled call (:func:`_replay`: 800,000 steps of the refined paper run took
199 s as a Python loop over compiled steps).

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
def _reactions(pos, pi, pj, l_u, r_u, p, out):
    """out[k]: the reaction R [N] of candidate pair (pi[k], pj[k]) if it is closer than l_u [cm] (by build_pairs'
    test, then by its distance), else 0: a pair absent from a step's set counts as R = 0."""
    l2 = l_u * l_u
    for k in range(pi.shape[0]):
        i, j = pi[k], pj[k]
        dx, dy = pos[j, 0] - pos[i, 0], pos[j, 1] - pos[i, 1]
        out[k] = 0.0
        if dx * dx + dy * dy < l2:
            d = np.sqrt((pos[i, 0] - pos[j, 0]) ** 2 + (pos[i, 1] - pos[j, 1]) ** 2)
            if d < l_u:
                out[k] = law_over_d(d, l_u, r_u, p) * d if d > 0.0 else r_u


@njit(**JIT)
def _largest_shift(a, b):
    """Largest distance [cm] between a particle's positions in a and in b (N, 2)."""
    out = 0.0
    for i in range(a.shape[0]):
        out = max(out, np.sqrt((a[i, 0] - b[i, 0]) ** 2 + (a[i, 1] - b[i, 1]) ** 2))
    return out


@njit(**JIT)
def _replay(pos, vel, weight, walls, box, pbox, wall_l_u, wall_r_u, pair_l_u, pair_r_u, rule, du, f_ref, dt_max,
            f_tol, skin, chunk, steps, wall_p, pair_p):
    """Steps ``steps`` of the run one at a time in place (relax_resume, a fresh list where the solver started a
    chunk); returns (largest change of a pair reaction [N], its step, largest displacement component [cm], steps
    done).  The pair reactions are read on candidate pairs closer than pair_l_u + the list's reach at a build,
    rebuilt once a particle may have come within pair_l_u of one that is no candidate (2 x its shift since the
    build > that reach),
    so every pair closer than pair_l_u before or after a step is a candidate and the change over the union of the
    two steps' pair sets is the largest change over the candidates."""
    force = np.zeros_like(pos)
    h = np.zeros(1)
    pos_build = pos.copy()
    state = np.zeros(5)
    reach = 0.5 * pair_l_u
    pi, pj, m = build_pairs(pos, pbox, pair_l_u + reach)
    pi, pj = pi[:m], pj[:m]
    ref = pos.copy()
    v0 = np.empty(m)
    _reactions(pos, pi, pj, pair_l_u, pair_r_u, pair_p, v0)
    v1 = np.empty(m)
    before = np.empty_like(pos)
    worst, at, move, done = 0.0, -1, 0.0, 0
    for s in range(steps):
        before[:] = pos
        n_done, status, _ = R.relax_resume(pos, vel, weight, walls, box, wall_l_u, wall_r_u, pair_l_u, pair_r_u,
                                           rule, du, f_ref, dt_max, f_tol, 1, skin, force, h, pos_build, state,
                                           s % chunk != 0, 1, wall_p, pair_p)
        if n_done != 1:
            break
        done += 1
        move = max(move, np.abs(pos - before).max())
        if 2.0 * _largest_shift(pos, ref) > reach:  # rebuild at pos, far enough to hold the pairs before the step
            pi, pj, m = build_pairs(pos, pbox, pair_l_u + reach + 2.0 * _largest_shift(pos, before))
            pi, pj = pi[:m], pj[:m]
            ref[:] = pos
            v0, v1 = np.empty(m), np.empty(m)
            _reactions(before, pi, pj, pair_l_u, pair_r_u, pair_p, v0)
        _reactions(pos, pi, pj, pair_l_u, pair_r_u, pair_p, v1)
        inc = 0.0
        for k in range(m):
            inc = max(inc, abs(v1[k] - v0[k]))
        if inc > worst:
            worst, at = inc, s
        v0, v1 = v1, v0
    return worst, at, move, done


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
    rule = RULES[a["variant"]]
    wp, pp = float(a.get("wall_p", 1.0)), float(a.get("pair_p", 1.0))
    args = (float(a["wall_l_u"]), float(a["wall_r_u"]), float(a["pair_l_u"]), float(a["pair_r_u"]), rule,
            float(a["du"]), float(a["f_ref"]), float(a["dt_max"]), float(a["f_tol"]), float(a["skin"]))
    chunk = int(a["chunk"])
    steps = int(ds["steps"])
    lo, hi = pos.min(0) - 100.0, pos.max(0) + 100.0
    pbox = np.array([min(lo[0], box[0]), min(lo[1], box[1]), max(hi[0], box[2]), max(hi[1], box[3])])
    worst, at, move, _ = _replay(pos, vel, weight, walls, box, pbox, *args, chunk, steps, wp, pp)
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
