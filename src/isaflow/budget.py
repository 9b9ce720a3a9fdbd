"""What a run will cost, checked before anything large is allocated: one place for every method.

Each method estimates a run from its settings alone (:class:`Cost`: particles,
steps, memory, and the setting each number comes from); :func:`check` refuses
a run whose memory exceeds what the machine has (:func:`memory_limit`) or
whose time, particles x steps x the method's measured cost per particle-step,
exceeds the CPU-hour budget of ``config/limits.yaml`` (or the run's own
``max_hours``).  The message names the file and the setting and gives the
numbers.  Pure Python: the workflow checks every declared run while it is
parsed.  Units: bytes, s, hours.
"""

import math
import os
from dataclasses import dataclass, field
from pathlib import Path

from . import inputs
from .inputs import InputError
from .plausible import where

LIMITS = Path("config") / "limits.yaml"
LIMIT_VALUES = {"cpu_hours": {"type": "number", "exclusiveMinimum": 0}}
DEFAULT_MEMORY = 8.0 * 2**30  # bytes, when neither the environment nor /proc/meminfo says

# What the scheduler is asked for per run job (job_resources), from the estimate and measured peaks: the
# Snakemake benchmarks of 204 run jobs (isa, mps, sph) on the shared 2-core test machine peaked at
# 195-379 MB resident (the interpreter with numpy, xarray, netCDF4 and the compiled kernels; a run's own
# arrays are a few MB) and took at most 60 s + 3 x the estimate's time in wall-clock time at load 2-4;
# with the machine running a full workflow besides (load 6-7 on 2 cores) a two-thread SPH run with an
# estimate of 63 s took 207-557 s locally and 391-628 s as a SLURM job (up to 10 x).
JOB_BASE_MB = 400  # resident size of a run job before its own arrays (measured peak 379 MB, rounded up)
JOB_MEMORY_FACTOR = 2  # safety factor on (JOB_BASE_MB + the estimate's bytes)
JOB_START_S = 120  # imports, numba cache load or compile (15 s cold), reading and writing files
JOB_TIME_FACTOR = 15  # the estimate uses the fastest measured step cost; worst measured 10 x the estimate
JOB_MIN_RUNTIME = 5  # min


@dataclass
class Cost:
    """A run's estimate.  particles: the most held at once; steps: the steps (or solves) it may take;
    bytes: its peak memory; ns_per_particle_step: the method's measured step cost [ns];
    fields: {'particles' | 'steps' | 'bytes': the setting the number comes from, a dotted key of the settings
    file or (file, field) of another (the tank)}; detail: how the steps follow from the settings, e.g.
    't = 5 s / dt = 3.1e-4 s'."""

    particles: float
    steps: float
    bytes: float
    ns_per_particle_step: float
    fields: dict = field(default_factory=dict)
    detail: str = ""

    @property
    def hours(self):
        return self.particles * self.steps * self.ns_per_particle_step * 1e-9 / 3600.0


def memory_limit():
    """Bytes a run may use: ISAFLOW_MEMORY_LIMIT_MB if set, else MemAvailable, else 8 GB."""
    env = os.environ.get("ISAFLOW_MEMORY_LIMIT_MB")
    if env:
        try:
            value = float(env) * 2**20
        except ValueError:
            value = float("nan")
        if not (math.isfinite(value) and value > 0):
            raise InputError(f"environment variable ISAFLOW_MEMORY_LIMIT_MB: '{env[:40]}' is not a positive number")
        return value
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024
    except OSError:
        pass
    return DEFAULT_MEMORY


def machine_cores():
    """Cores this process may run on (its CPU affinity, as numba counts them)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


def check_threads(where, value, most=None):
    """Refuse a thread or core count that is not a whole number from 1 to ``most`` (default: the machine's
    cores); where: what the user wrote, e.g. 'argument --threads'."""
    cores = machine_cores()
    most = cores if most is None else most
    if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= most:
        raise InputError(f"{where}: {inputs.printable(str(value))} is not a whole number from 1 to {most} (this "
                         f"machine gives the process {cores} cores)")
    return value


def check_environment():
    """Refuse a NUMBA_NUM_THREADS in the environment that numba cannot use or this machine cannot give."""
    env = os.environ.get("NUMBA_NUM_THREADS")
    if env is not None:
        check_threads("environment variable NUMBA_NUM_THREADS", int(env) if env.strip().isdigit() else env)


def cpu_hours(path=LIMITS):
    """The CPU-hour budget of a run (config/limits.yaml, read by the one settings loader)."""
    from . import settings

    return float(settings.load(path, LIMIT_VALUES, what="resource limits")["cpu_hours"])


def job_resources(cost):
    """{'mem_mb', 'runtime' (minutes)} to request for a run job from its estimate (constants above):
    mem_mb = JOB_MEMORY_FACTOR x (JOB_BASE_MB + estimated MB), rounded up to 100 MB;
    runtime = (JOB_START_S + JOB_TIME_FACTOR x estimated s) in minutes, rounded up, at least JOB_MIN_RUNTIME."""
    mem_mb = math.ceil(JOB_MEMORY_FACTOR * (JOB_BASE_MB + cost.bytes / 2**20) / 100) * 100
    runtime = max(JOB_MIN_RUNTIME, math.ceil((JOB_START_S + JOB_TIME_FACTOR * cost.hours * 3600) / 60))
    return {"mem_mb": int(mem_mb), "runtime": int(runtime)}


def gb(b):
    return f"{b / 2**30:.3g} GB"


def check(path, cost, max_hours=None):
    """Refuse (InputError naming path and the setting) a run whose memory or time exceeds the limits;
    returns the cost.

    max_hours: the run's own CPU-hour limit (a deliberate long run), else config/limits.yaml's."""

    def blame(kind):
        return where(path, cost.fields.get(kind, "resolution"))

    numbers = {"particles": cost.particles, "steps": cost.steps, "bytes": cost.bytes}
    bad = [kind for kind, x in numbers.items() if not (math.isfinite(x) and x >= 0)]
    if bad:
        raise InputError(f"{blame(bad[0])}: the run's size is not a finite number ({cost.particles:.3g} particles, "
                         f"{cost.steps:.3g} steps, {cost.bytes:.3g} bytes); choose less extreme values")
    limit = memory_limit()
    if cost.bytes > limit:
        raise InputError(f"{blame('bytes')}: the run needs about {gb(cost.bytes)} of memory ({cost.particles:.3g} "
                         f"particles, {cost.steps:.3g} steps, {cost.detail}); {gb(limit)} available")
    budget = cpu_hours() if max_hours is None else float(max_hours)
    if cost.hours > budget:
        raise InputError(f"{blame('steps')}: the run needs about {cost.particles * cost.steps:.3g} particle-steps "
                         f"({cost.particles:.3g} particles x {cost.steps:.3g} steps, {cost.detail}), about {cost.hours:.3g} CPU-hours at "
                         f"{cost.ns_per_particle_step:g} ns per particle-step; the budget is {budget:g} h "
                         f"(config/limits.yaml cpu_hours, or the run's max_hours for a deliberate long run)")
    return cost
