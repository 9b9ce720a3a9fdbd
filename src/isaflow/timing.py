"""Where a workflow run's time goes: each job records its phases, the end of the run adds them up.

Every job script (workflow/scripts/run.py, call.py, compile.py) appends one JSON line to
``logs/timing/jobs.jsonl`` (:func:`record`): its process start (the kernel's clock, so the
interpreter and Snakemake's script preamble count), when the script got to its first line, when its
imports were done, its end, the solver time of its runs, and numba's compile and cache-load times
(isaflow.core.jit.counters).  At the end of a run (the Snakefile's ``onsuccess``) :func:`summary`
splits the run's wall time W on C cores into

- solve: the solvers' own clocks (compilation excluded),
- compile: numba compiling (cold cache, or kernels missing from it),
- start-up: process start to the end of the imports, plus loading kernels from the cache,
- other work: everything else jobs do (reading inputs, writing files, figures, tables, claims),
- scheduling: the core-seconds no job used, C W minus the jobs' total (Snakemake planning and
  polling, and cores idle while waiting for dependencies),

so that solve + compile + start-up + other work + scheduling = C W.  Units: s.
"""

import json
import os
import sys
import time
from pathlib import Path

JOBS = Path("logs") / "timing" / "jobs.jsonl"
_JOB = {"threads": 1}  # the cores this job holds (job_start)
PHASES = ("solve", "compile", "start-up", "other work", "scheduling")


def job_start(job):
    """Start of every job script (job: Snakemake's ``snakemake`` object), before numpy loads: BLAS, OpenMP and
    numba run on the rule's threads (a threaded OpenBLAS sums in an order that varies from run to run, and two
    runs of the same commit must give byte-identical physics outputs), stderr goes to the rule's log.
    Returns the epoch time the script started (for :func:`record`)."""
    started = time.time()
    _JOB["threads"] = int(job.threads)
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
        os.environ[var] = str(job.threads)
    sys.stderr = open(job.log[0], "w", buffering=1)
    return started


def process_start():
    """Epoch time [s] this process started (Linux: its start in clock ticks since boot, /proc/self/stat, on the boot
    time read to the nanosecond from CLOCK_BOOTTIME, not /proc/stat's btime, which is truncated to whole seconds and
    charged every job up to a second it never ran; the current time elsewhere)."""
    try:
        ticks = int(Path("/proc/self/stat").read_text().rsplit(")", 1)[1].split()[19])
        boot = time.time() - time.clock_gettime(time.CLOCK_BOOTTIME)
        return boot + ticks / os.sysconf("SC_CLK_TCK")
    except (OSError, ValueError, IndexError, AttributeError):
        return time.time()


def record(rule, job, script_start, imported, solve_s=0.0, runs=0, path=JOBS):
    """Append this job's line to path (one write, atomic on a local disk); times are epoch seconds."""
    jit = sys.modules.get("isaflow.core.jit")  # read only if this job loaded kernels at all
    c = jit.counters() if jit else {"compile_s": 0.0, "load_s": 0.0, "compiled": 0, "gaps": []}
    line = {"rule": rule, "job": job, "process_start": process_start(), "script_start": script_start,
            "imported": imported, "end": time.time(), "solve_s": solve_s, "runs": runs,
            "compile_s": c["compile_s"], "load_s": c["load_s"], "compiled": c["compiled"], "gaps": len(c["gaps"]),
            "threads": _JOB["threads"]}
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "a") as f:
        f.write(json.dumps(line) + "\n")


def read(since, path=JOBS):
    """The job lines of jobs that started at or after epoch time ``since``."""
    if not Path(path).exists():
        return []
    out = []
    for text in Path(path).read_text().splitlines():
        try:
            rec = json.loads(text)
        except ValueError:
            continue
        if rec.get("process_start", 0) >= since - 1.0:
            out.append(rec)
    return out


def summary(jobs, start, end, cores):
    """{phase: core-seconds} of a run from start to end [epoch s] on ``cores`` cores (module docstring), and
    'wall', 'jobs', 'runs', 'gaps'."""
    out = dict.fromkeys(PHASES, 0.0)
    busy = 0.0
    for j in jobs:  # a job holds its threads' cores from start to end
        n = j.get("threads", 1)
        total = max(0.0, j["end"] - j["process_start"])
        startup = max(0.0, j["imported"] - j["process_start"]) + j["load_s"]
        solve, comp = j["solve_s"], j["compile_s"]
        out["solve"] += n * solve
        out["compile"] += n * comp
        out["start-up"] += n * startup
        out["other work"] += n * max(0.0, total - solve - comp - startup)
        busy += n * total
    out["scheduling"] = max(0.0, cores * (end - start) - busy)
    out.update(wall=end - start, jobs=len(jobs), runs=sum(j["runs"] for j in jobs),
               gaps=sum(j["gaps"] for j in jobs), cores=cores)
    return out


def markdown(s, title="This workflow run"):
    """The summary as a short markdown section."""
    total = s["cores"] * s["wall"] or 1.0
    m, sec = divmod(s["wall"], 60)
    lines = [f"## {title}", "",
             f"Wall time {int(m)} min {sec:.0f} s on {s['cores']} cores ({s['jobs']} jobs, {s['runs']} runs; "
             f"{s['gaps']} kernel signatures compiled outside the cache).", "",
             "| phase | core-seconds | share |", "|---|---|---|"]
    lines += [f"| {p} | {s[p]:.0f} | {100 * s[p] / total:.0f} % |" for p in PHASES]
    overhead = s["compile"] + s["start-up"] + s["scheduling"]
    lines += ["", f"Start-up, compile and scheduling together: {100 * overhead / total:.0f} % of the run's "
                  f"core-seconds.", ""]
    return "\n".join(lines)
