"""Killed runs (issue 9, item 3): SIGKILL, SIGTERM or SIGINT during the write of the run file leave no
file that opens as a run file, and a later run cleans up.

Deterministic, not timing-dependent: the test hook ISAFLOW_TEST_PAUSE_WRITE=<s> (runfile.PAUSE_HOOK)
makes the writer print one line and pause after the data are in the temporary file and before it is
marked complete and renamed; the test sends the signal once it has read that line.  Every wait has a
timeout, so a hang fails the test instead of stalling CI.
"""

import os
import queue
import signal
import subprocess
import sys
import threading

import pytest
from conftest import ROOT, TINY, write_spec

from isaflow import runfile

TIMEOUT = 120  # s for any one wait (numba loads its cache in a few seconds)


def command(tmp_path, out):
    """The command line of TINY's run (its tank and settings files live in tmp_path/inputs)."""
    inputs = tmp_path / "inputs"
    inputs.mkdir(exist_ok=True)
    tank, settings = write_spec(inputs, TINY)
    return [sys.executable, "-m", "isaflow.cli", "run", "--method", "isa", "--tank", str(tank), "--settings",
            str(settings), "--variant", "capped", "--resolution", "r", "-o", str(out)]


def start_run(tmp_path, out, pause="60"):
    env = {**os.environ, runfile.PAUSE_HOOK: pause}
    # SIGINT at its default disposition in the child: a shell's background job (e.g. CI started with '&')
    # inherits it ignored, and Python then installs no KeyboardInterrupt handler
    proc = subprocess.Popen(command(tmp_path, out), stderr=subprocess.PIPE, text=True, cwd=ROOT, env=env,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    lines = queue.Queue()
    threading.Thread(target=lambda: [lines.put(x) for x in proc.stderr], daemon=True).start()
    while True:
        try:
            line = lines.get(timeout=TIMEOUT)
        except queue.Empty:
            proc.kill()
            pytest.fail("the writer never reached the test hook")
        if line.startswith("isaflow test hook: pausing"):
            return proc, lines


def leftovers(directory):
    return sorted(p.name for p in directory.iterdir() if p.name != "inputs")


def assert_nothing_opens_as_a_run_file(directory):
    for p in directory.iterdir():
        if p.name != "inputs":
            with pytest.raises(runfile.RunFileError):
                runfile.read(p)


@pytest.mark.parametrize("sig, code", [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_sigterm_and_sigint_during_the_write_remove_the_temporary_file(tmp_path, sig, code):
    out = tmp_path / "run.nc"
    proc, lines = start_run(tmp_path, out)
    assert len(leftovers(tmp_path)) == 1  # the temporary file exists while the writer pauses
    proc.send_signal(sig)
    assert proc.wait(timeout=TIMEOUT) == code
    err = "".join(iter_queue(lines))
    assert "Traceback" not in err and "no output written" in err
    assert leftovers(tmp_path) == []


def iter_queue(q):
    while not q.empty():
        yield q.get()


def test_sigkill_during_the_write_leaves_nothing_that_reads_as_a_run_file(tmp_path):
    out = tmp_path / "run.nc"
    proc, _ = start_run(tmp_path, out)
    proc.kill()
    assert proc.wait(timeout=TIMEOUT) == -signal.SIGKILL
    left = leftovers(tmp_path)
    assert not out.exists() and len(left) == 1 and runfile.PARTIAL in left[0] and not left[0].endswith(".nc")
    assert_nothing_opens_as_a_run_file(tmp_path)
    # the next run of the same output removes the dead writer's temporary file
    proc = subprocess.run(command(tmp_path, out), capture_output=True, text=True, cwd=ROOT, timeout=TIMEOUT)
    assert proc.returncode == 0, proc.stderr
    assert leftovers(tmp_path) == ["run.nc"]
    assert runfile.read(out).attrs["isaflow_complete"] == "yes"
