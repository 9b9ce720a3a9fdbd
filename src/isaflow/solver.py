"""Drive the compiled relaxation in chunks: progress, history, outcome.

Outcomes (``Run.status``): ``converged`` (max|F| < f_tol), ``cycle`` (max|F|
repeats with a fixed period: the iteration is a limit cycle and can never
converge), ``step_limit`` (max_steps reached otherwise), ``escaped`` (a step
would carry a particle across a wall, or a particle left the walls' bounding
box), ``nonfinite`` (NaN/inf forces).
"""

import time
from dataclasses import dataclass, field

import numpy as np

from . import kernels as K

VARIANTS = {"paper": K.PAPER, "capped": K.CAPPED, "fire": K.FIRE}
VARIANT_LABELS = {
    "paper": "paper: x += du F / max|F| (section 3.3, literal)",
    "capped": "capped: x += du F / max(max|F|, f_ref) (variant, not in paper)",
    "fire": "fire: FIRE relaxation, Bitzek et al. 2006 (variant, not in paper)",
}
# capped default f_ref = du (k_b + 6 k_p): du / 2 times the Gershgorin bound
# lambda_max <= 2 k_b + 12 k_p (two walls, six neighbours) of the stiffness
# matrix, so the capped update is linearly stable; it equals w for both of the
# paper's lattices (50 N, 12.5 N).
PAIR_NEIGHBOURS = 6
# fire default dt_max = 1 / sqrt(2 k_b + 12 k_p) (unit masses): below the
# explicit-integration limit 2 / sqrt(lambda_max) for the Gershgorin bound.


@dataclass
class Run:
    """Result of one relaxation; arrays in cm and N."""

    pos0: np.ndarray  # (N, 2) initial positions, cm
    pos: np.ndarray  # (N, 2) final positions, cm
    force: np.ndarray  # (N, 2) final out-of-balance forces, N
    start_step: int  # steps already taken by the runs this one continues
    step: int  # total step count at the end (including start_step)
    status: str
    message: str
    wall_time: float  # s, solver only (excluding compilation warm-up)
    fmax: float  # final max|F|, N
    cycle_period: int = 0
    hist_step: np.ndarray = None  # (H,) step of each max|F| record
    hist_fmax: np.ndarray = None  # (H,) max|F| at that step, N
    hist_fmin_env: np.ndarray = None  # (H,) min of max|F| over the stride, N
    hist_fmax_env: np.ndarray = None  # (H,) max of max|F| over the stride, N
    chunk_step: np.ndarray = None  # (C,) steps at chunk ends
    chunk_walls: np.ndarray = None  # (C, W, 2) wall resultants on the liquid, N
    chunk_vessels: np.ndarray = None  # (C, V) particles per vessel
    snap_step: np.ndarray = None  # (S,)
    snap_pos: np.ndarray = None  # (S, N, 2), cm
    params: dict = field(default_factory=dict)


def detect_cycle(h, window=400, max_period=50, rtol=1e-6):
    """Smallest period 2 <= p <= max_period with h[k] == h[k - p] (to rtol)
    over the last ``window`` entries of the max|F| series h; 0 if none.

    Period 1 (a constant max|F|) is not a cycle of any update here: a fixed
    point has F = 0, and a constant max|F| is e.g. a free fall.
    """
    if len(h) < window + max_period:
        return 0
    tail = h[-(window + max_period):]
    scale = tail.max()
    if np.abs(tail[1:] - tail[:-1]).max() <= rtol * scale:
        return 0  # constant
    for p in range(2, max_period + 1):
        if np.abs(tail[p:] - tail[:-p]).max() <= rtol * scale:
            return p
    return 0


def wall_resultants(pos, walls, l_u, r_u):
    """(W, 2) resultant force [N] each wall exerts on the liquid."""
    part, wall, point, force = K.wall_contacts(pos, walls, l_u, r_u)
    out = np.zeros((walls.shape[0], 2))
    np.add.at(out, wall, force)
    return out


def vessel_counts(pos, vessels):
    """(V,) particles whose x lies in each vessel's [xmin, xmax) range."""
    return np.array([np.count_nonzero((pos[:, 0] >= a) & (pos[:, 0] < b)) for a, b in vessels])


def solver_params(scene):
    """Numeric solver parameters with defaults resolved (cm, N)."""
    s = scene.solver
    wl_u, wr_u = scene.law("wall")
    pl_u, pr_u = scene.law("pair")
    kb, kp = scene.stiffness("wall"), scene.stiffness("pair")
    return dict(
        variant=s["variant"],
        du=float(s["du"]),
        f_tol=float(s["f_tol"]),
        max_steps=int(s["max_steps"]),
        f_ref=float(s.get("f_ref", s["du"] * (kb + PAIR_NEIGHBOURS * kp))),
        dt_max=float(s.get("dt_max", 1.0 / np.sqrt(2 * kb + 2 * PAIR_NEIGHBOURS * kp))),
        skin=float(s.get("skin", 0.3 * pl_u)),
        chunk=int(s["chunk"]),
        wl_u=wl_u, wr_u=wr_u, pl_u=pl_u, pr_u=pr_u,
    )


def warm_up():
    """Compile (or load from numba's cache) the kernels so timings exclude it."""
    pos = np.array([[1.0, 1.0], [1.5, 1.0]])
    walls = np.array([[0.0, 2.0, 0.0, 0.0], [0.0, 0.0, 2.0, 0.0], [2.0, 0.0, 2.0, 2.0]])
    box = np.array([0.0, 0.0, 2.0, 2.0])
    for variant in VARIANTS.values():
        K.relax(pos.copy(), np.zeros_like(pos), np.ones(2), walls, box, 0.5, 1.0, 0.7, 1.0, variant,
                1e-3, 1.0, 0.1, 0.1, 2, 0.1, np.zeros_like(pos), np.zeros(2))
    K.wall_contacts(pos, walls, 0.5, 1.0)


def solve(scene, pos0, weight, start_step=0, progress=None):
    """Relax ``pos0`` (N, 2) cm with per-particle ``weight`` (N,) N under ``scene``.

    start_step: steps already taken (a continued run counts from there up to
    solver.max_steps).  progress(step, fmax) is called after each chunk.
    """
    p = solver_params(scene)
    s = scene.solver
    hist = s["history"]
    walls = scene.walls
    lo, hi = walls.reshape(-1, 2).min(0), walls.reshape(-1, 2).max(0)
    box = np.array([lo[0], lo[1], hi[0], hi[1]])
    vessels = [v["x"] for v in scene.spec.get("vessels", [])]
    pos = np.array(pos0, float, copy=True)
    weight = np.asarray(weight, float)
    vel = np.zeros_like(pos)
    force = np.zeros_like(pos)
    chunk = p["chunk"]
    buf = np.zeros(chunk)
    every = hist.get("every", 0)
    h_step, h_last, h_lo, h_hi = [], [], [], []
    c_step, c_walls, c_vessels, snaps, snap_steps = [], [], [], [], []
    n_snap = hist.get("snapshots", 0)
    snap_every = max(1, round((p["max_steps"] - start_step) / max(n_snap, 1) / chunk))
    recent = np.zeros(0)
    warm_up()
    step = start_step
    status, message, period, info = "step_limit", "", 0, -1
    t0 = time.perf_counter()
    n_chunk = 0
    while step < p["max_steps"]:
        # chunks end on multiples of `chunk` counted from the chain's start, so
        # a run continued from a state file repeats an uninterrupted run exactly
        n = min(chunk - step % chunk, p["max_steps"] - step)
        chunk_start = pos.copy()
        done, code, info = K.relax(
            pos, vel, weight, walls, box, p["wl_u"], p["wr_u"], p["pl_u"], p["pr_u"],
            VARIANTS[p["variant"]], p["du"], p["f_ref"], p["dt_max"], p["f_tol"], n, p["skin"], force, buf,
        )
        h = buf[:done]
        if every:
            for k0 in range(0, done, every):
                seg = h[k0:k0 + every]
                h_step.append(step + k0)
                h_last.append(seg[0])
                h_lo.append(seg.min())
                h_hi.append(seg.max())
        step += done
        n_chunk += 1
        recent = np.concatenate([recent, h])[-2000:]
        if hist.get("walls"):
            c_walls.append(wall_resultants(pos, walls, p["wl_u"], p["wr_u"]))
        if hist.get("vessels"):
            c_vessels.append(vessel_counts(pos, vessels))
        if hist.get("walls") or hist.get("vessels"):
            c_step.append(step)
        if n_snap and (n_chunk % snap_every == 0):
            snaps.append(pos.copy())
            snap_steps.append(step)
        if progress:
            progress(step, float(h[-1]) if done else np.nan)
        if code == K.CONVERGED:
            status = "converged"
            break
        if code == K.NONFINITE:
            status, message = "nonfinite", f"non-finite forces at step {step}"
            break
        if code == K.CROSSED:
            i, w = divmod(info, walls.shape[0])
            status = "escaped"
            message = (f"particle {i} at ({pos[i, 0]:.4g}, {pos[i, 1]:.4g}) cm would cross wall "
                       f"'{scene.wall_names[w]}' at step {step}; step refused, run stopped")
            break
        out = ((pos < lo - 1e-9) | (pos > hi + 1e-9)).any(1)
        if out.any():
            status = "escaped"
            message = f"{out.sum()} particle(s) left the walls' bounding box by step {step}"
            break
        if s["stop_on_cycle"]:
            period = detect_cycle(recent)
            # a cycle returns to its states: the net move over the chunk stays
            # within a few du, unlike a slow drift with a periodic max|F|
            if period and np.abs(pos - chunk_start).max() > 2 * period * p["du"]:
                period = 0
            if period:
                tail = recent[-400:]
                status = "cycle"
                message = (f"max|F| repeats with period {period} steps between {tail.min():.4g} and "
                           f"{tail.max():.4g} N (f_tol {p['f_tol']:g} N) by step {step}")
                break
    wall_time = time.perf_counter() - t0
    fmax = float(np.abs(force).max()) if len(force) else 0.0
    if status == "step_limit":
        message = f"max|F| = {fmax:.4g} N >= f_tol = {p['f_tol']:g} N after {step} steps"
    elif status == "converged":
        message = f"max|F| = {fmax:.4g} N < f_tol = {p['f_tol']:g} N after {step} steps"
    arr = lambda x, dt=float: np.array(x, dt)  # noqa: E731
    return Run(
        pos0=np.array(pos0, float), pos=pos, force=force, start_step=start_step, step=step,
        status=status, message=message, wall_time=wall_time, fmax=fmax, cycle_period=period,
        hist_step=arr(h_step, np.int64), hist_fmax=arr(h_last), hist_fmin_env=arr(h_lo), hist_fmax_env=arr(h_hi),
        chunk_step=arr(c_step, np.int64), chunk_walls=arr(c_walls).reshape(len(c_walls), walls.shape[0], 2),
        chunk_vessels=arr(c_vessels, np.int64).reshape(len(c_vessels), len(vessels)),
        snap_step=arr(snap_steps, np.int64), snap_pos=arr(snaps).reshape(len(snaps), len(pos), 2), params=p,
    )
