"""Where a workflow run's time goes (isaflow.timing): a process's start is read to the clock tick, not to /proc/stat's
whole-second boot time (which charged every job up to a second it never ran)."""

import subprocess
import sys
import time

from conftest import ROOT


def test_a_process_start_is_read_to_the_clock_tick():
    before = time.time()
    out = subprocess.run([sys.executable, "-c", "import time; from isaflow import timing; "
                          "print(timing.process_start(), time.time())"], capture_output=True, text=True, check=True,
                         cwd=ROOT, env={"PYTHONPATH": str(ROOT / "src"), "PATH": "/usr/bin:/bin"})
    start, now = map(float, out.stdout.split())
    assert before - 0.02 <= start <= now  # one clock tick (10 ms) of resolution, and a little for the clocks
