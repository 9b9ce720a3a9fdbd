"""The kernel cache's rules (isaflow.core.jit) on a two-kernel module, one process per step: one process
fills a generation and seals it, later processes only read it; a damaged or foreign generation is rebuilt;
a process that finds another filling the same generation waits for it (runs) or compiles in memory."""

import json
import os
import subprocess
import sys
import textwrap
import time

import pytest

from conftest import ROOT

KERNELS = textwrap.dedent('''
    from isaflow.core.jit import njit

    @njit(cache=True)
    def inner(x):
        return 2.0 * x

    @njit(cache=True)
    def outer(a):
        s = 0.0
        for v in a:
            s += inner(v)
        return s
''')

SCRIPT = textwrap.dedent('''
    import json, sys, time
    import numpy as np
    from isaflow.core import jit
    import tiny
    sleep = float(sys.argv[2])
    mode = jit.use(sys.argv[1], fill=(lambda: (tiny.outer(np.ones(3)), time.sleep(sleep))) if sleep >= 0 else None)
    value = tiny.outer(np.arange(4.0))
    print(json.dumps(dict(jit.counters(), mode=mode, value=value)))
''')


@pytest.fixture()
def env(tmp_path):
    (tmp_path / "tiny.py").write_text(KERNELS)
    return dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"),
                PYTHONPATH=os.pathsep.join([str(tmp_path), str(ROOT / "src")]))


def start(env, generation="tiny", sleep=0.0):
    return subprocess.Popen([sys.executable, "-c", SCRIPT, generation, str(sleep)], env=env, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)


def result(p):
    out, err = p.communicate(timeout=300)
    assert p.returncode == 0, err
    return json.loads(out.splitlines()[-1]), err


def test_one_process_fills_and_seals_then_others_only_read(env, tmp_path):
    first, _ = result(start(env))
    assert first["mode"] == "read" and first["compiled"] >= 2 and first["value"] == 12.0  # filled, then sealed
    assert (tmp_path / "cache" / "tiny" / "MANIFEST.json").exists()
    second, _ = result(start(env))
    assert second["mode"] == "read" and second["compiled"] == 0 and second["loaded"] >= 1 and second["value"] == 12.0


def test_a_damaged_generation_is_rebuilt_not_loaded(env, tmp_path):
    result(start(env))
    for p in (tmp_path / "cache" / "tiny").rglob("*.nbc"):
        p.write_bytes(p.read_bytes()[::-1])
    again, _ = result(start(env))
    assert again["compiled"] >= 2 and again["value"] == 12.0
    third, _ = result(start(env))
    assert third["compiled"] == 0 and third["value"] == 12.0


def test_a_generation_from_another_machine_is_rebuilt(env, tmp_path):
    result(start(env))
    manifest = tmp_path / "cache" / "tiny" / "MANIFEST.json"
    m = json.loads(manifest.read_text())
    m["machine"]["cpu"] = "another-cpu"
    manifest.write_text(json.dumps(m))
    again, _ = result(start(env))
    assert again["compiled"] >= 2 and again["value"] == 12.0


def test_a_run_waits_for_the_process_filling_its_generation(env):
    writer = start(env, sleep=3.0)  # fills, then holds the generation 3 s before sealing it
    time.sleep(1.5)
    reader = start(env)
    w, _ = result(writer)
    r, _ = result(reader)
    assert w["compiled"] >= 2 and r["compiled"] == 0 and r["mode"] == "read" and r["value"] == 12.0


def test_a_process_without_a_fill_compiles_in_memory_while_another_writes(env):
    writer = start(env, generation="default", sleep=-1)  # a writer without fill: seals at exit
    other = start(env, generation="default", sleep=-1)
    a, _ = result(writer)
    b, _ = result(other)
    assert {a["mode"], b["mode"]} <= {"write", "private", "read"} and a["value"] == b["value"] == 12.0
    # the two may also both have met the other's lock and compiled in memory (they start at the same instant):
    # then the next process writes and seals, and the one after it only reads
    third, _ = result(start(env, generation="default", sleep=-1))
    if "write" not in (a["mode"], b["mode"]):
        assert third["mode"] == "write"
        third, _ = result(start(env, generation="default", sleep=-1))
    assert third["mode"] == "read" and third["compiled"] == 0


def test_a_process_without_a_fill_never_waits_for_a_long_lived_writer(env):
    """A writer without fill (a test session, a script) seals only at its exit: a workflow job that meets it
    compiles in memory at once instead of waiting for that exit (CI hung 400 s on this)."""
    holder = subprocess.Popen([sys.executable, "-c", "import time, numpy as np; from isaflow.core import jit; "
                               "import tiny; jit.use('default'); tiny.outer(np.ones(2)); print('ready', flush=True); "
                               "time.sleep(60)"], env=env, text=True, stdout=subprocess.PIPE)
    try:
        assert holder.stdout.readline().strip() == "ready"
        other, err = result(start(env, generation="default", sleep=-1))
        assert other["mode"] == "private" and other["value"] == 12.0 and "being written" in err
    finally:
        holder.kill()
        holder.wait()


READER = textwrap.dedent('''
    import json, sys
    import numpy as np
    from isaflow.core import jit
    import tiny
    jit.use(sys.argv[1])
    read = jit.read_also(*sys.argv[2:], package="{}")
    value = tiny.outer(np.arange(4.0))
    print(json.dumps(dict(jit.counters(), read=read, value=value)))
''')


def test_a_process_reads_another_methods_sealed_generation_and_writes_nothing_there(env, tmp_path):
    """The claims job's case: bound to one generation, it loads another method's kernels from that method's
    sealed generation (read_also) instead of compiling them, and saves nothing into either."""
    filled, _ = result(start(env, "tiny"))
    assert filled["mode"] == "read" and filled["compiled"] > 0
    sealed = (tmp_path / "cache" / "tiny" / "MANIFEST.json").read_text()

    def reader(*also):
        p = subprocess.run([sys.executable, "-c", READER, "claims", *also], env=env, text=True, capture_output=True,
                           timeout=300)
        assert p.returncode == 0, p.stderr
        return json.loads(p.stdout.splitlines()[-1])

    both = reader("tiny")
    assert both["read"] == ["tiny"] and both["compiled"] == 0 and both["loaded"] >= 1 and both["value"] == 12.0
    assert (tmp_path / "cache" / "tiny" / "MANIFEST.json").read_text() == sealed
    assert not (tmp_path / "cache" / "claims" / "tiny").exists()
    alone = reader()  # without it the same kernels compile (in its own generation)
    assert alone["read"] == [] and alone["compiled"] > 0
    missing = reader("nowhere")  # a generation that does not exist is skipped
    assert missing["read"] == []


def test_a_writer_without_a_fill_that_compiled_nothing_leaves_its_generation_unsealed(env, tmp_path):
    """A test session that ran no kernel sealed an empty generation at exit, so every later session compiled
    all its kernels in memory; now the next process finds it unsealed, fills it and seals it."""
    empty = subprocess.run([sys.executable, "-c", "from isaflow.core import jit; print(jit.use('default'))"],
                           env=env, text=True, capture_output=True, check=True)
    assert empty.stdout.strip() == "write" and not (tmp_path / "cache" / "default" / "MANIFEST.json").exists()
    first, _ = result(start(env, generation="default", sleep=-1))
    assert first["mode"] == "write" and first["compiled"] >= 2
    second, _ = result(start(env, generation="default", sleep=-1))
    assert second["mode"] == "read" and second["compiled"] == 0 and second["value"] == 12.0
