"""Replay of an ISA run file step by step: what the run did in every step that its file does not hold.

The solver runs in compiled chunks and keeps only records; a claim about every step (the du rule of
section 6.1: no step changes a pair reaction by more than w/5) needs each step's state.  The replay
starts from the run's initial positions with the run's own settings (its file's attributes) and runs
the same compiled kernel (relax.relax_resume) in the run's own chunks, each from a fresh neighbour list as
the solver ran it, keeping every step's positions in the kernel's trail: the replay repeats the run bit for
bit, which :func:`pair_increments` checks on the final positions.  The measures of a chunk are one compiled
call (:func:`_measure`; 800,000 steps of the refined paper run took 199 s as a Python loop over
single compiled steps).

Units: cm, N.
"""

import numpy as np
import xarray as xr

from ...core.geometry import bounding_box
from ...core.jit import njit
from ...core.neighbours import build_pairs
from . import relax as R
from .forces import law_over_d
from .settings import LAW_EXPONENT, RULES

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
def _shifts(a, b):
    """(largest distance [cm], largest displacement component [cm]) between a particle's positions in a and in b
    (N, 2), without a temporary array (the replay asks after every step)."""
    dist, comp = 0.0, 0.0
    for i in range(a.shape[0]):
        dx, dy = a[i, 0] - b[i, 0], a[i, 1] - b[i, 1]
        dist = max(dist, np.sqrt(dx * dx + dy * dy))
        comp = max(comp, abs(dx), abs(dy))
    return dist, comp


@njit(**JIT)
def _candidates(pos, pbox, pair_l_u, reach, p, r_u, v):
    """(pi, pj, R): the candidate pairs closer than pair_l_u + reach [cm] at pos and their reactions at pos (or at
    v, (N, 2) cm, where v is not pos: the state a step started from)."""
    pi, pj, m = build_pairs(pos, pbox, pair_l_u + reach)
    out = np.empty(m)
    _reactions(v, pi[:m], pj[:m], pair_l_u, r_u, p, out)
    return pi[:m], pj[:m], out


@njit(**JIT)
def _measure(trail, n_done, step0, pbox, pair_l_u, pair_r_u, p, reach, pi, pj, v0, ref, worst, at, move):
    """Steps 1..n_done of a chunk's trail (N, 2 per step, cm): the largest change of a pair reaction [N] over a
    step and its step (from step0), the largest displacement component [cm].  The reactions are read on the
    candidate pairs (pi, pj; v0 their reactions before the chunk's first step) closer than pair_l_u + reach at
    ref, the positions of their build, rebuilt once a particle may have come within pair_l_u of one that is no
    candidate (2 x its shift since the build > reach), so every pair closer than pair_l_u before or after a step
    is a candidate and the change over the union of the two steps' pair sets is the largest change over the
    candidates.  Returns (pi, pj, v0, worst, at, move) for the next chunk (ref updated in place)."""
    v1 = np.empty(v0.shape[0])
    for k in range(1, n_done + 1):
        before, now = trail[k - 1], trail[k]
        step_shift, step_comp = _shifts(now, before)
        move = max(move, step_comp)
        if 2.0 * _shifts(now, ref)[0] > reach:  # rebuild at now, far enough to hold the pairs before the step
            pi, pj, v0 = _candidates(now, pbox, pair_l_u, reach + 2.0 * step_shift, p, pair_r_u, before)
            v1 = np.empty(v0.shape[0])
            ref[:] = now
        _reactions(now, pi, pj, pair_l_u, pair_r_u, p, v1)
        inc = 0.0
        for q in range(v0.shape[0]):
            inc = max(inc, abs(v1[q] - v0[q]))
        if inc > worst:
            worst, at = inc, step0 + k - 1
        v0, v1 = v1, v0
    return pi, pj, v0, worst, at, move


def pair_increments(ds):
    """Replay a fresh-start ISA run file (paper, capped or fire rule) and measure every step.

    Returns dict: max_pair_increment_N, the largest change of any pair reaction in one step; its step;
    max_component_move_cm, the largest displacement component of any particle in one step (from the
    positions); steps replayed; identical: the replay's final positions equal the file's bit for bit.
    The run's chunks are run as the solver ran them (relax_resume from a fresh list at each chunk's start,
    called with the solver's argument types: its one compiled specialisation), every step read off the trail.
    """
    a = ds.attrs
    if int(ds["start_step"]) != 0:
        raise ValueError("replay: only runs started from their initial lattice (start_step 0)")
    walls = ds["wall_segment"].values.astype(float)
    box = bounding_box(walls)
    pos = np.array(ds["pos0"].values, float)
    weight = np.array(ds["weight"].values, float)
    vel, force = np.zeros_like(pos), np.zeros_like(pos)
    wp, pp = LAW_EXPONENT[a["forces.wall.law"]], LAW_EXPONENT[a["forces.pair.law"]]
    l_u, r_u = float(a["forces.pair.l_u"]), float(a["forces.pair.r_u"])
    args = (float(a["forces.wall.l_u"]), float(a["forces.wall.r_u"]), l_u, r_u, int(RULES[a["variant"]]), float(a["solver.du"]),
            float(a["solver.f_ref"]), float(a["solver.dt_max"]), float(a["solver.f_tol"]))
    chunk, steps = int(a["solver.chunk"]), int(ds["steps"])
    lo, hi = pos.min(0) - 100.0, pos.max(0) + 100.0
    pbox = np.array([min(lo[0], box[0]), min(lo[1], box[1]), max(hi[0], box[2]), max(hi[1], box[3])])
    reach = 0.5 * l_u
    trail = np.empty((chunk + 1, len(pos), 2))
    pi, pj, v0 = _candidates(pos, pbox, l_u, reach, pp, r_u, pos)
    ref = pos.copy()
    worst, at, move, done = 0.0, -1, 0.0, 0
    while done < steps:
        k_max = min(chunk, steps - done)
        n_done, _, _ = R.relax_resume(pos, vel, weight, walls, box, *args, k_max, float(a["solver.skin"]), force,
                                      np.zeros(k_max), np.empty_like(pos), np.zeros(5), False, 1, wp, pp, trail)
        pi, pj, v0, worst, at, move = _measure(trail, n_done, done, pbox, l_u, r_u, pp, reach, pi, pj, v0, ref,
                                               worst, at, move)
        done += n_done
        if n_done < k_max:
            break
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


def warm_up():
    """Compile (or load from the cache) the replay's kernels with the argument types :func:`pair_increments` passes
    them, so that the ISA method's kernel generation holds them (isa.method.warm_up) and a replay job loads them
    instead of compiling them in memory (7-9 s a job)."""
    pos = np.array([[0.0, 0.0], [0.5, 0.0]])
    pbox = np.array([-1.0, -1.0, 2.0, 1.0])
    pi, pj, v0 = _candidates(pos, pbox, 1.0, 0.5, 1.0, 1.0, pos)
    _measure(np.stack([pos, pos + 0.01]), 1, 0, pbox, 1.0, 1.0, 1.0, 0.5, pi, pj, v0, pos.copy(), 0.0, -1, 0.0)
