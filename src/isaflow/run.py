"""Run one method on one tank and write its run file: the one path every tank run takes.

:func:`prepare` does every check that can refuse a run before any work (tank,
settings of the variant and resolution, overrides, start file, output path,
the method's own plausibility and budget checks); :func:`run` then warms the
method's compiled code, solves, and writes the run file atomically with its
provenance (runfile).  Exit codes (also those of ``isaflow run``): 0 written;
1 the run ended in an outcome the run does not accept (nothing written);
2 bad input (one line naming the file and the field; nothing written); 3 the
output could not be written after the solve.
"""

import os
import sys
import threading
import time
from dataclasses import dataclass
from pathlib import Path

from . import budget, methods, preflight, runfile, settings, tank as tanks
from .inputs import InputError, printable

HEARTBEAT = 25.0  # s: without any line for this long (compiling, a method's own pace), a 'running' line


@dataclass
class Prepared:
    """Everything a checked run needs: method entry module, tank, resolved settings."""

    method: str
    entry: object
    tank: tanks.Tank
    settings: settings.Settings
    variant: str
    resolution: str
    start: str | None
    out: str
    accept: tuple
    threads: int | None
    run_id: str
    label: str = ""
    stability: bool = False


def _same_file(a, b):
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def _start_particles(start):
    with runfile.open_run(start) as ds:
        return int(ds["pos"].shape[0]) if "pos" in ds.variables else None


def tank_method(method):
    """The registry's Method of a method that runs on tanks, or InputError naming --method."""
    try:
        m = methods.get(method)
    except KeyError as err:
        raise InputError(f"--method: {err.args[0]}") from None
    if not m.tank:
        raise InputError(f"--method: method '{method}' does not run on tanks (choose from "
                         f"{', '.join(methods.tank_methods())})")
    return m


def prepare(method, tank, variant, resolution, out, settings_path=None, overrides=(), start=None,
            accept=("converged",), threads=None, run_id=None, label="", stability=False, max_hours=None):
    """Check a run before any work; returns Prepared or raises InputError / runfile.RunFileError.

    tank: path of a tank file; overrides: 'key=value' strings or {key: {value, source}};
    start: path of the run file of the same method to continue, or None; stability: a declared
    stability case (literature ranges not enforced, unstable outcomes may be accepted); max_hours: this
    run's own CPU-hour budget (config/limits.yaml's otherwise).
    """
    m = tank_method(method)
    if threads is not None:
        budget.check_threads("argument --threads", threads,
                             min(budget.machine_cores(), settings.RUN_SCHEMA["properties"]["threads"]["maximum"]))
    if variant not in m.variants:
        raise InputError(f"--variant: method '{method}' has no variant '{printable(str(variant))}' "
                         f"(choose from {', '.join(m.variants)})")
    t = tanks.load(tank)
    path = settings_path or m.settings
    s = settings.load(path, m.values_schema(), variant, resolution, overrides, what=f"{method} settings")
    if start is not None:
        try:
            runfile.open_run(start).close()
        except runfile.RunFileError as err:
            raise InputError(f"--start: {err}") from None
    runfile.check_output(out)
    for what, src in {"the tank": tank, "the settings": path, "the start file": start}.items():
        if src and _same_file(src, out):
            raise runfile.RunFileError(f"{out}: the output would overwrite {what} ('{src}'); choose another path")
    preflight.check(method, t, s, accept, stability, max_hours,
                    _start_particles(start) if start is not None else None)
    entry = m.entry_module()
    entry.check(t, s, start)
    return Prepared(method, entry, t, s, variant, resolution, start, str(out), tuple(accept), threads,
                    run_id or Path(out).stem, label, stability)


class _Heartbeat:
    """Every line of a run goes through log(); a daemon thread adds '<run id>: running, N s, <phase>' whenever
    no line came for HEARTBEAT s, so a job's log never stays silent for 30 s: compiled code is warming up, or a
    method prints at its own pace (numba kernels release the GIL, so the thread runs while they do)."""

    def __init__(self, run_id, log):
        self.run_id, self._log = run_id, log
        self.phase = "starting"
        self.t0 = self.last = time.perf_counter()
        self._stop = threading.Event()
        self._lock = threading.Lock()
        self._thread = threading.Thread(target=self._beat, name=f"heartbeat {run_id}", daemon=True)

    def log(self, msg):
        with self._lock:
            self.last = time.perf_counter()
            self._log(msg)

    def _beat(self):
        while not self._stop.wait(1.0):
            if time.perf_counter() - self.last >= HEARTBEAT:
                self.log(f"{self.run_id}: running, {time.perf_counter() - self.t0:.0f} s, {self.phase}")

    def __enter__(self):
        self._thread.start()
        return self

    def __exit__(self, *exc):
        self._stop.set()
        self._thread.join()


def compile_method(method, threads=None, entry=None):
    """Bind this process to method's kernel generation (core.jit.use), compiling and sealing it first if no
    process has, then load (or compile) every kernel its runs time: the warm-up excluded from solver times.
    entry: the method's entry module (default the registry's)."""
    from .core import jit

    entry = entry or methods.get(method).entry_module()
    jit.use(method, fill=lambda: entry.warm_up(threads))
    entry.warm_up(threads)


def solve(p, log=None):
    """(Result, started, finished) of a prepared run; compiled code is warmed first (not timed).  A line at
    least every HEARTBEAT s while it works (_Heartbeat)."""
    log = log or (lambda msg: print(msg, file=sys.stderr, flush=True))
    with _Heartbeat(p.run_id, log) as beat:
        beat.phase = "warming up compiled code"
        compile_method(p.method, p.threads, p.entry)
        beat.phase = "solving"
        started = runfile.now()
        result = p.entry.solve(p.tank, p.settings, p.variant, p.resolution, p.start,
                               log=lambda text: beat.log(f"{p.run_id}: {text}"), threads=p.threads)
    return result, started, runfile.now()


def write(p, result, started, finished, command=None):
    """Write the run file of a solved run (raises OSError / RunFileError)."""
    files = {"tank": p.tank.path, "settings": p.settings.path, "start": p.start}
    prov = runfile.provenance(files, command)
    prov.update(run_id=p.run_id, run_label=p.label or "none", resolution=p.resolution,
                stability_case=int(p.stability),
                threads=result.params.get("threads", p.threads or 0))
    prov.update(settings.attributes(p.settings, {k: v for k, v in result.params.items() if k in p.settings}))
    ds = runfile.to_dataset(result, p.tank, prov, started, finished, references=p.entry.REFERENCES)
    runfile.write(ds, p.out)


def run(method, tank, variant, resolution, out, settings_path=None, overrides=(), start=None,
        accept=("converged",), threads=None, run_id=None, log=None, command=None, label="", stability=False,
        max_hours=None):
    """Check, solve and write one run; returns the exit code (module docstring); errors as one line on stderr."""
    return run_with_result(method, tank, variant, resolution, out, settings_path, overrides, start, accept, threads,
                           run_id, log, command, label, stability, max_hours)[0]


def run_with_result(method, tank, variant, resolution, out, settings_path=None, overrides=(), start=None,
                    accept=("converged",), threads=None, run_id=None, log=None, command=None, label="",
                    stability=False, max_hours=None):
    """run(), returning (exit code, the solve's Result or None if refused before solving)."""
    log = log or (lambda msg: print(msg, file=sys.stderr, flush=True))
    try:
        p = prepare(method, tank, variant, resolution, out, settings_path, overrides, start, accept, threads, run_id,
                    label, stability, max_hours)
    except (InputError, runfile.RunFileError) as err:
        log(f"error: {err}")
        return 2, None
    except OSError as err:
        log(f"error: {getattr(err, 'filename', None) or tank}: {err.strerror or err}")
        return 2, None
    result, started, finished = solve(p, log)
    log(f"{p.run_id}: finished: {result.status}: {result.message} ({result.wall_time:.3f} s solver, "
        f"{result.params.get('threads', p.threads or 1)} thread(s))")
    if result.status not in p.accept:
        log(f"error: {p.run_id}: outcome '{result.status}' is not accepted ({', '.join(p.accept)}); no output written")
        return 1, result
    try:
        write(p, result, started, finished, command)
        log(f"{p.run_id}: wrote {out}")
    except (OSError, runfile.RunFileError) as err:
        log(f"error: {out}: the run finished but its file could not be written: "
            f"{getattr(err, 'strerror', None) or err}")
        return 3, result
    return 0, result
