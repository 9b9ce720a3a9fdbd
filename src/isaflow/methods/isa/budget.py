"""What an ISA run will need, checked before anything large is allocated (cm, N, bytes).

:func:`check_settings` refuses settings whose derived numbers (stiffness,
f_ref, dt_max, skin) are not finite and positive; :func:`check_count` and
:func:`check_memory` estimate the run's memory (particles, neighbour pairs,
cell grid, history records, snapshots, chunk buffer) and refuse, with the
estimate, a run that cannot fit the memory available.  The limit is the
machine's (isaflow.budget.memory_limit).
"""

import math

import numpy as np

from ...budget import gb as _gb
from ...budget import memory_limit
from ...inputs import InputError
from ...plausible import extreme, where
from .checks import BYTES_PER_PARTICLE, BYTES_PER_RECORD, BYTES_PER_SNAPSHOT_PARTICLE, check_grid, particle_count, particles_field  # noqa: F401
from .settings import settings

BYTES_PER_PAIR = 12  # int32 neighbour entry with its doubling growth


def check_settings(scene):
    """Refuse derived solver numbers that are not finite and positive, naming the input each follows: the
    stiffness r_u / l_u its farther-from-1 factor, f_ref, dt_max and the skin their own field if set, else what
    their defaults follow (du, the stiffness, the pair range), the overdamped step its own field or the weight."""
    s = settings(scene)
    given = scene.spec["solver"]
    v = {f"forces.{side}.{k}": scene.spec["forces"][side][k] for side in ("wall", "pair") for k in ("l_u", "r_u")}
    laws = list(v)
    v.update({"solver.du": s["du"], "particles.weight": scene.spec["particles"]["weight"], "solver.zeta": s["zeta"]})
    checks = [(extreme(v, "forces.wall.r_u", "forces.wall.l_u"), s["wall_r_u"] / s["wall_l_u"]),
              (extreme(v, "forces.pair.r_u", "forces.pair.l_u"), s["pair_r_u"] / s["pair_l_u"]),
              ("solver.f_ref" if "f_ref" in given else extreme(v, "solver.du", *laws), s["f_ref"]),
              ("solver.dt_max" if "dt_max" in given else extreme(v, *laws), s["dt_max"]),
              ("solver.skin" if "skin" in given else "forces.pair.l_u", s["skin"])]
    if s["variant"] == "overdamped":
        checks.append(("solver.dt" if "dt" in given else extreme(v, "particles.weight", "solver.zeta", *laws),
                       s["dt"]))
    for field, value in checks:
        if not (math.isfinite(value) and value > 0):
            raise InputError(f"{scene.path}: field '{field}': the derived value {value!r} is not a finite positive "
                             f"number (over- or underflow); choose less extreme numbers")
    return s


def _refuse(scene, field, need, limit, what):
    """field: a settings key, or (file, field) of another file (a start file's variable)."""
    raise InputError(f"{where(scene.path, field)}: the run needs about {_gb(need)} of memory ({what}); "
                     f"{_gb(limit)} available")


def _fixed_bytes(scene, n):
    """(bytes, field, what) of the history records, snapshots and chunk buffer of a run of n particles."""
    s = settings(scene)
    hist = s["history"]
    steps = s["max_steps"]
    chunks = steps // s["chunk"] + 2
    records = steps // hist["every"] + chunks if hist.get("every") else 0
    snaps = s["snapshot_megabytes"] * 1e6 + 3 * n * BYTES_PER_SNAPSHOT_PARTICLE
    samples = chunks * (len(scene.walls) * 48 + len(scene.spec.get("vessels", [])) * 24 + 64) \
        if hist.get("walls") or hist.get("vessels") else 0
    parts = [(records * BYTES_PER_RECORD, "solver.history.every", f"{records:.3g} max|F| records"),
             (snaps, "solver.snapshot_megabytes", f"{snaps / 1e6:.3g} MB of snapshots of {n} particles"),
             (samples, "solver.chunk", f"{chunks:.3g} chunk-end samples"),
             (s["chunk"] * 8, "solver.chunk", f"a chunk buffer of {s['chunk']:.3g} steps")]
    return parts


def check_count(scene, n, field):
    """Refuse a particle count (before the particles exist) whose run cannot fit in memory; field: where the count
    comes from (a settings key, or (start file, 'pos'))."""
    limit = memory_limit()
    parts = [(n * BYTES_PER_PARTICLE, field, f"{n:.3g} particles")] + _fixed_bytes(scene, n)
    need = sum(p[0] for p in parts)
    if need > limit:
        big = max(parts)
        _refuse(scene, big[1], need, limit, big[2])


def pair_bound(pos, box, rc):
    """Upper bound on the neighbour pairs within rc: all pairs in the same or adjacent cells of the rc grid."""
    ncx = max(1, int((box[2] - box[0]) / rc))
    ncy = max(1, int((box[3] - box[1]) / rc))
    cx = np.clip(((pos[:, 0] - box[0]) / ((box[2] - box[0]) / ncx)).astype(np.int64), 0, ncx - 1)
    cy = np.clip(((pos[:, 1] - box[1]) / ((box[3] - box[1]) / ncy)).astype(np.int64), 0, ncy - 1)
    keys, counts = np.unique(cy * ncx + cx, return_counts=True)
    counts = counts.astype(float)
    total = float((counts * (counts - 1) / 2).sum())
    kx, ky = keys % ncx, keys // ncx
    for ox, oy in ((1, 0), (-1, 1), (0, 1), (1, 1)):
        nx, ny = kx + ox, ky + oy
        ok = (nx >= 0) & (nx < ncx) & (ny < ncy)
        nb = ny * ncx + nx
        j = np.clip(np.searchsorted(keys, nb), 0, len(keys) - 1)
        hit = ok & (keys[j] == nb)
        total += float((counts * np.where(hit, counts[j], 0.0)).sum())
    return total


def check_memory(scene, pos, field=None):
    """Refuse a run whose particles, pairs, grid and records cannot fit in memory (pos (N, 2) cm); field: where the
    particles come from (default the settings' particles.points or particles.lattice; (file, 'pos') of a start
    file)."""
    s = settings(scene)
    walls = scene.walls
    lo, hi = walls.reshape(-1, 2).min(0), walls.reshape(-1, 2).max(0)
    rc = s["pair_l_u"] + s["skin"]
    cells = check_grid(scene.path, walls.tolist(), rc, "walls")  # the scene's walls: its settings file's copy
    n = len(pos)
    pairs = pair_bound(pos, np.array([lo[0], lo[1], hi[0], hi[1]]), rc)
    field = field or particles_field(scene.spec["particles"])
    parts = [(n * BYTES_PER_PARTICLE, field, f"{n} particles"),
             (pairs * BYTES_PER_PAIR, field, f"up to {pairs:.3g} neighbour pairs"),
             (cells * 4, "forces.pair.l_u", f"{cells:.3g} grid cells")] + _fixed_bytes(scene, n)
    need = sum(p[0] for p in parts)
    limit = memory_limit()
    if need > limit:
        big = max(parts)
        _refuse(scene, big[1], need, limit, big[2])
    return need
