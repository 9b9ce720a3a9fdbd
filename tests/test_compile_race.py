"""Many processes on one kernel cache (isaflow.core.jit): no crash, the same numbers.

From an empty cache, processes start 2.5 s apart (within the time one cold compile takes) on kernels they
share, on one and two threads; then the same processes start again from the cache they left.  Every process
must exit 0 and every run file (and the 1D errors) must be identical between the two rounds.  Numba's own
cache fails this: filled by several processes at once, an entry loads beside another process's callees and
segfaults (issue 29; the first full run from a fresh clone lost 290 of 332 ISA runs that way).  A damaged
cache is rebuilt, never loaded.

By default four processes: three ISA update rules on one generation (one fills it while the others wait,
on 1 and 2 threads) and the 1D sweep, whose generation is sealed at exit (the other path of core.jit.use).
ISAFLOW_RACE_FULL=1 runs the full form, eleven processes using every kernel overload of every method (the
five ISA update rules, two SPH and two MPS variants through ``isaflow run``, a solid case and a 1D sweep;
about 90 s of two cores): run it before any change to how kernels are compiled, cached or bound
(src/isaflow/core/jit.py, run.compile_method, a method's warm_up).

ISAFLOW_RACE_SRC: the source tree to test (default this checkout's src/), to run the same test on
another commit.
"""

import json
import os
import subprocess
import sys
import time

import numpy as np
import pytest
import xarray as xr

from conftest import ROOT

SRC = os.environ.get("ISAFLOW_RACE_SRC", str(ROOT / "src"))
SINGLE = str(ROOT / "config" / "tanks" / "single.yaml")


def _isa(variant, accept="converged,cycle,step_limit"):
    return ["run", "--method", "isa", "--tank", SINGLE, "--variant", variant, "--resolution", "coarse",
            "--accept", accept]


RUNS = {  # name: (isaflow command line or python code, numba threads)
    "isa_paper": (_isa("paper"), 1),
    "isa_capped": (_isa("capped"), 2),
    "isa_fire": (_isa("fire"), 1),
    "isa_overdamped": (_isa("overdamped") + ["--set", "solver.max_steps=2000"], 2),
    "isa_newton_lm": (_isa("newton_lm"), 1),
    "sph_wcsph": (["run", "--method", "sph", "--run", "single_wcsph_n180", "--set", "settings.t_max_single=0.05",
                   "--accept", "converged,step_limit"], 2),
    "sph_delta_wc2": (["run", "--method", "sph", "--run", "single_delta_wc2_n180", "--set",
                       "settings.t_max_single=0.05", "--accept", "converged,step_limit"], 1),
    "mps_standard": (["run", "--method", "mps", "--run", "single_standard_dx5.56", "--set", "time.single_time=0.05", "--set", "time.average_window=0.02",
                      "--accept", "converged,step_limit"], 2),
    "mps_mixed": (["run", "--method", "mps", "--run", "single_mixed_dx5.56", "--set", "time.single_time=0.05", "--set", "time.average_window=0.02",
                   "--accept", "converged,step_limit"], 1),
    "solid": ("from isaflow.methods.solid.outputs import write_run\n"
              "write_run('config/methods/solid.yaml', 'shear', 'paper', OUT)", 1),
    "sph1d": ("import numpy as np\n"
              "from isaflow.methods.sph1d import pipeline, settings, sweep\n"
              "getattr(pipeline, 'jit', None) and pipeline.jit.use('sph1d')\n"
              "s = settings.checked_values('config/methods/sph1d.yaml')\n"
              "s['n'], s['ratios'] = [32, 64], s['ratios'][::25]\n"
              "np.save(OUT + '.npy', sweep.run_sweep(s)['error'].values)\n"
              "open(OUT, 'w').write('done')", 2),
}
FULL = os.environ.get("ISAFLOW_RACE_FULL") == "1"
if not FULL:  # the default set (module docstring)
    RUNS = {k: RUNS[k] for k in ("isa_paper", "isa_capped", "isa_fire", "sph1d")}
# run-file variables that differ between identical runs (solver times)
TIMED = {"wall_time"}


def _start(name, out, env):
    cmd, threads = RUNS[name]
    env = dict(env, NUMBA_NUM_THREADS=str(threads), PYTHONPATH=SRC)
    if isinstance(cmd, list):
        argv = [sys.executable, "-m", "isaflow.cli", *cmd, "--threads", str(threads), "-o", out]
    else:
        argv = [sys.executable, "-c", f"OUT = {out!r}\n{cmd}"]
    return subprocess.Popen(argv, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)


def _round(folder, env, gap):
    """Start every run, gap s apart; {name: (exit code, output tail)}."""
    folder.mkdir()
    procs = {}
    for name in RUNS:
        procs[name] = _start(name, str(folder / f"{name}.nc"), env)
        time.sleep(gap)
    out = {}
    for name, p in procs.items():
        text, _ = p.communicate(timeout=900)
        out[name] = (p.returncode, text[-2000:])
    return out


def _numbers(path):
    """{variable: array} of a run file's numbers (solver times left out); the 1D sweep's error array."""
    if os.path.exists(f"{path}.npy"):
        return {"error": np.load(f"{path}.npy")}
    with xr.open_dataset(path) as ds:
        return {k: ds[k].values for k in ds.variables if k not in TIMED and ds[k].dtype.kind in "fiub"}


def _same(a, b):
    return a.keys() == b.keys() and all(np.array_equal(a[k], b[k], equal_nan=True) for k in a)


@pytest.fixture(scope="module")
def rounds(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("race")
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp / "cache"), OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    # the first round staggered over the time a cold compile takes, so later processes find a cache other
    # processes are filling (numba's own cache then mixes their entries); the second all at once
    first = _round(tmp / "round1", env, 2.5)
    second = _round(tmp / "round2", env, 0.3)
    return tmp, first, second, env


def test_every_process_exits_cleanly_from_an_empty_cache_and_from_the_cache_it_left(rounds):
    _, first, second, _ = rounds
    failed = {f"round {k} {n}": tail for k, r in ((1, first), (2, second)) for n, (code, tail) in r.items() if code}
    assert not failed, json.dumps(failed, indent=1)


def test_the_second_round_repeats_the_first_to_the_bit(rounds):
    tmp, first, second, _ = rounds
    differ = [n for n in RUNS if not first[n][0] and not second[n][0]
              and not _same(_numbers(tmp / "round1" / f"{n}.nc"), _numbers(tmp / "round2" / f"{n}.nc"))]
    assert not differ


def test_the_second_round_compiles_nothing(rounds):
    """Every kernel the second round uses comes from the cache the first left (a run logs a gap otherwise)."""
    _, _, second, _ = rounds
    gaps = {n: tail for n, (code, tail) in second.items() if "not in the cache" in tail or "compiling in memory" in tail}
    assert not gaps


def test_a_damaged_cache_is_rebuilt_not_loaded(rounds):
    """Every cache file overwritten with other bytes: the next run recompiles and gives the same numbers (the 1D
    sweep: the process with the shortest compile, about 8 s against the ISA kernels' 22-35 s)."""
    tmp, first, _, env = rounds
    for p in (tmp / "cache").rglob("*.nbc"):
        p.write_bytes(p.read_bytes()[::-1])
    folder = tmp / "damaged"
    folder.mkdir()
    p = _start("sph1d", str(folder / "sph1d"), env)
    text, _ = p.communicate(timeout=900)
    assert p.returncode == 0, text[-2000:]
    assert _same(_numbers(folder / "sph1d"), _numbers(tmp / "round1" / "sph1d.nc"))
