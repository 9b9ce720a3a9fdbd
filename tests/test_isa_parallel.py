"""Parallel ISA steps (issue 20): the same bits on any number of threads, the parallel neighbour
list equal to core.neighbours.cell_rows, the thread count recorded, and honest solver times
(no compilation inside them).  Units cm, N, s.

A step runs in one block per thread once every thread gets relax.PAR_MIN_PER_THREAD
particles, so the relax cases here hold more than 2 x that (the paper's lattice made wide,
benchmarks/bench_step.py's scene, perturbed so that particles cross cells, come near the
walls and the list is rebuilt several times).
"""

import json
import os
import subprocess
import sys
from pathlib import Path

import numba
import numpy as np
import pytest

from conftest import coarse_lattice, scene_of, vessel

from isaflow.core import neighbours as NB
from isaflow.methods.isa import relax as R
from isaflow.methods.isa import scene as S
from isaflow.methods.isa import solver

ROOT = Path(__file__).resolve().parents[1]
A = 10.0
L_P, R_P = float(A / np.sqrt(2.0)), float(500.0 * A / np.sqrt(2.0))  # pair law: cm, N
L_B, R_B = 5.0, 10000.0  # wall law: cm, N


def wide_vessel(n_row=240, seed=0, sigma=1.0):
    """The bench_step vessel with rows of n_row / n_row + 1 (19 rows: 19 n_row + 9 particles), perturbed."""
    width = (n_row + 1) * A
    pos = S.rhombic_lattice(A, 19, [n_row, n_row + 1], width / 2, 5.0)
    pos += np.random.default_rng(seed).normal(0.0, sigma, pos.shape)
    pos[:, 1] = np.maximum(pos[:, 1], 0.5)  # every particle above the floor
    walls = np.array([[0, 100, 0, 0], [0, 0, width, 0], [width, 0, width, 100]], float)
    return np.ascontiguousarray(pos), walls, np.array([0.0, 0.0, width, 100.0])


def run_relax(pos0, walls, box, rule, du, n_steps, threads, split=None):
    """relax_resume on a copy of pos0 (optionally split at step `split` and resumed); returns every output."""
    pos = pos0.copy()
    n = len(pos)
    vel, force, hist = np.zeros_like(pos), np.zeros_like(pos), np.zeros(n_steps)
    weight, pos_build, state = np.full(n, 50.0), np.empty_like(pos), np.zeros(4)
    args = (walls, box, L_B, R_B, L_P, R_P, rule, du, 50.0, 0.02, 1e-30)
    rets = []
    for lo, hi, resume in ((0, split or n_steps, False), (split or n_steps, n_steps, True)):
        if hi > lo:
            rets.append(R.relax_resume(pos, vel, weight, *args, hi - lo, 0.3 * L_P, force, hist[lo:], pos_build,
                                       state, resume, threads, 1.0, 1.0, R.NO_TRAIL))  # linear laws (exponents 1)
    return dict(ret=np.array(rets), pos=pos, vel=vel, force=force, hist=hist, pos_build=pos_build, state=state)


@pytest.mark.parametrize("rule,du", [(R.PAPER, 0.05), (R.CAPPED, 0.05), (R.FIRE, 0.5)])
def test_relax_gives_the_same_bits_on_one_and_several_threads(rule, du):
    pos0, walls, box = wide_vessel()
    n = len(pos0)
    assert R.blocks(n, 2) == 2 and R.blocks(n, 1) == 1 and R.blocks(R.PAR_MIN_PER_THREAD, 2) == 1
    ref = run_relax(pos0, walls, box, rule, du, 300, 1)
    assert ref["ret"][0][1] == R.RUNNING and np.abs(ref["pos"] - pos0).max() > 3 * 0.3 * L_P  # lists rebuilt
    numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
    try:
        for threads in (2, 3, 5):  # blocks beyond the machine's threads run too, with the same results
            got = run_relax(pos0, walls, box, rule, du, 300, threads)
            for k in ref:
                assert np.array_equal(ref[k], got[k]), (threads, k)
        split = run_relax(pos0, walls, box, rule, du, 300, 2, split=137)
        for k in ("pos", "vel", "force", "hist", "pos_build", "state"):
            assert np.array_equal(ref[k], split[k]), ("split", k)
    finally:
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)


def test_a_wall_crossing_is_found_at_the_same_particle_by_every_block_split():
    # a huge du carries the lowest rows through the floor: the step is refused, and the
    # refusing particle (the lowest caller number) is the same for 1 and 4 blocks
    pos0, walls, box = wide_vessel(seed=3)
    ref = run_relax(pos0, walls, box, R.PAPER, 30.0, 5, 1)
    got = run_relax(pos0, walls, box, R.PAPER, 30.0, 5, 4)
    assert ref["ret"][0][1] == R.CROSSED
    for k in ref:
        assert np.array_equal(ref[k], got[k]), k


def test_a_crossing_near_the_walls_is_found_in_parallel_blocks_as_in_one():
    """Two heavy particles 0.02 cm above the floor step through it (du = 0.05 cm, within the
    near-wall reach, so only the near-wall rows are tested, in parallel blocks once there are
    2 x PAR_MIN_PER_THREAD of them): the lower caller number and the floor are reported, and the
    step is not taken, on 1 and 2 blocks alike."""
    pos0, walls, box = wide_vessel(n_row=4400, seed=4, sigma=0.2)
    heavy = [len(pos0) - 100, 7]  # the later-numbered one comes first in cell order
    pos0[heavy] = [[box[2] - 30.0, 0.02], [30.0, 0.02]]
    n = len(pos0)
    outs = []
    for threads in (1, 2):
        pos, force, hist = pos0.copy(), np.zeros_like(pos0), np.zeros(3)
        weight = np.full(n, 50.0)
        weight[heavy] = 1e7
        ret = R.relax(pos, np.zeros_like(pos), weight, walls, box, L_B, R_B, L_P, R_P, R.PAPER, 0.05, 50.0, 0.1,
                      1e-30, 3, 0.3 * L_P, force, hist, threads)
        outs.append((tuple(ret), pos, force, hist))
    near = R._near_walls(pos0, walls, L_B + 0.3 * L_P)[0]
    assert R.blocks(len(near), 2) == 2
    assert outs[0][0] == (0, R.CROSSED, 7 * len(walls) + 1)  # particle 7, floor
    for a, b in zip(outs[0], outs[1]):
        assert np.array_equal(np.asarray(a), np.asarray(b))
    assert np.array_equal(outs[0][1], pos0)


@pytest.mark.parametrize("seed", [0, 1])
@pytest.mark.parametrize("nb", [2, 3, 7])
def test_parallel_neighbour_list_equals_cell_rows(seed, nb):
    rng = np.random.default_rng(seed)
    n = 3000
    pos = rng.uniform(0, 100, (n, 2))
    pos[:200] = rng.normal(50, 2, (200, 2))  # a dense cluster: long rows
    pos[200:210] = [[-3.0, 50.0]] * 10  # outside the box (clamped into the edge cells), coincident
    box = np.array([0.0, 0.0, 100.0, 100.0])
    rc = 6.0
    ref = [np.empty(n, np.int32), np.empty(1, np.int32), np.empty(n + 1, np.int32)]
    nbr_ref, cs_ref = NB.cell_rows(pos, box, rc, ref[0], ref[1], ref[2], np.empty(16, np.int32))
    for hint in (8.0, 0.1):  # 0.1: the blocks' scratch overflows and the serial search takes over
        order, row_start = np.empty(n, np.int32), np.empty(n + 1, np.int32)
        nbr, cs = NB.cell_rows_par(pos, box, rc, order, np.empty(1, np.int32), row_start, np.empty(16, np.int32), nb,
                                   hint)
        m = row_start[n]
        assert m == ref[2][n] > 10 * n
        assert np.array_equal(order, ref[0]) and np.array_equal(row_start, ref[2]) and np.array_equal(cs, cs_ref)
        assert np.array_equal(nbr[:m], nbr_ref[:m])


def test_near_wall_list_holds_exactly_the_particles_within_reach():
    """The near-wall rows (with the bounding-box shortcut) against plain point-segment distances."""
    pos, walls, box = wide_vessel(n_row=60, seed=2, sigma=3.0)
    reach = L_B + 2.0
    part, wall = R._near_walls(pos, walls, reach)
    want = []
    for i, p in enumerate(pos):
        for w, (x0, y0, x1, y1) in enumerate(walls):
            e = np.array([x1 - x0, y1 - y0])
            t = np.clip((p - [x0, y0]) @ e / (e @ e), 0, 1)
            if np.sum((p - [x0, y0] - t * e) ** 2) < reach * reach:
                want.append((i, w))
    assert set(wall) == {0, 1, 2} and list(zip(part, wall)) == want


TINY = {
    "name": "wide", "walls": vessel(2410, 100), "particles": coarse_lattice(19, [240, 241], 1205.0),
    "forces": {"wall": {"law": "linear", "l_u": L_B, "r_u": R_B}, "pair": {"law": "linear", "l_u": L_P, "r_u": R_P}},
    "solver": {"variant": "paper", "du": 0.01, "f_tol": 0.1, "max_steps": 1500, "chunk": 1000,
               "accept": ["step_limit"], "history": {"every": 7}},
}
SETTINGS = str(ROOT / "config" / "methods" / "isa.yaml")


@pytest.mark.parametrize("variant", ["paper", "fire"])
def test_solve_records_its_threads_and_gives_the_same_run_on_one_and_two(variant):
    sc = scene_of({**TINY, "solver": {**TINY["solver"], "variant": variant,
                                         **({"du": 0.1} if variant == "fire" else {})}})
    pos0, weight, _, _ = S.initial_state(sc)
    one = solver.solve(sc, pos0, weight, threads=1)
    two = solver.solve(sc, pos0, weight, threads=min(2, numba.config.NUMBA_NUM_THREADS))
    assert one.params["threads"] == 1 and two.params["threads"] == min(2, numba.config.NUMBA_NUM_THREADS)
    assert one.steps == two.steps == 1500 and one.force_evals == two.force_evals
    for a, b in ((one.pos, two.pos), (one.fields["force"][1], two.fields["force"][1])):
        assert np.array_equal(a, b)
    for k, v in one.history.items():  # the first snapshot's force is not evaluated yet in either (NaN)
        assert np.array_equal(v[1], two.history[k][1], equal_nan=v[1].dtype.kind == "f"), k
    assert numba.get_num_threads() == numba.config.NUMBA_NUM_THREADS  # restored after the solve


@pytest.mark.parametrize("bad", [0, -1, 10**6, 1.5, "2", True])
def test_a_thread_count_outside_the_machine_is_refused(bad):
    with pytest.raises(ValueError, match="threads"):
        solver.thread_count(bad)


COLD_PROBE = """
import json, sys, time
from numba.core import event
from isaflow import driver
from isaflow.methods.isa import scene as S
from isaflow.methods.isa import solver
compiles = []  # perf_counter at the start of every compile (numba's own events)

class Listener(event.Listener):
    def on_start(self, ev):
        compiles.append(time.perf_counter())

    def on_end(self, ev):
        pass

event.register("numba:compile", Listener())
loops, drive = [], driver.drive

def timed_drive(*args, **kw):  # the driver's timed loop lies inside this call
    start = time.perf_counter()
    result = drive(*args, **kw)
    loops.append((start, time.perf_counter()))
    return result

driver.drive = timed_drive
out = {}
for variant in ("capped", "newton_lm"):
    sc = S.of_run("single", "refined", variant, (), sys.argv[1])
    pos0, weight, _, _ = S.initial_state(sc)
    r = solver.solve(sc, pos0, weight, threads=1)
    a, b = loops[-1]
    out[variant] = dict(status=r.status, before=sum(c < a for c in compiles), inside=sum(a <= c <= b for c in compiles))
print(json.dumps(out))
"""


def test_solver_times_exclude_compilation():
    """In a fresh process with an empty numba cache (every kernel compiled in it), no kernel compiles while the
    run driver's timed loop runs (Result.wall_time): the stepper is built and its kernels warmed before.  Read
    off numba's compile events, not off timings."""
    import tempfile

    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "NUMBA_CACHE_DIR": cache, "PYTHONPATH": str(ROOT / "src")}
        out = subprocess.run([sys.executable, "-c", COLD_PROBE, SETTINGS], env=env, cwd=ROOT, capture_output=True,
                             text=True, check=True)
    cold = json.loads(out.stdout.strip().splitlines()[-1])
    assert cold["capped"]["before"] > 0  # the cache was empty: the process compiled, and the events were seen
    for variant in ("capped", "newton_lm"):
        assert cold[variant]["status"] == "converged"
        assert cold[variant]["inside"] == 0, (variant, cold[variant])
