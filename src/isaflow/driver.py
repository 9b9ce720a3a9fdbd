"""The one run driver of every tank method: drive(stepper) -> contract.Result.

It owns the solve's wall clock (Result.wall_time: the loop only; the stepper is built, and its kernels
warmed, before), the loop, progress lines at a fixed wall-time cadence, the rest monitor of dynamic
methods (isaflow.rest, fed by the stepper's samples), the stop decision and the outcome.  A method
supplies a *stepper* and nothing else:

- ``advance()``: one chunk of its compiled loop (ISA, SPH) or one step (MPS); returns None, or
  (status, message) of an outcome its own code detected (escaped, nonfinite, cycle, solver_failed,
  converged by its own criterion, ...);
- ``record()``: records its diagnostics of that advance; returns (t [s], e = KE / (W h)) when it took a
  rest sample, else None (static methods: always None);
- ``spent()``: its step or time budget is used up;
- ``t0``: the chain's time at this run's start [s] (the origin of time_to_rest);
- ``rest_message(monitor)``, ``limit_message(monitor)``: the messages of 'converged' (at rest) and
  'step_limit';
- ``progress(monitor)``: one progress line;
- ``result(run)``: the contract.Result, from the final :class:`Run`.

The driver adds to the Result's params what the rest monitor decided (rest_energy_ratio, rest_window,
time_to_rest, final_energy_ratio, start_time: the same names and time origin for every dynamic method).

Per advance the decision is: the stepper's outcome, else ``converged`` once the monitor is at rest,
else ``step_limit`` once the budget is spent, else go on.
"""

import math
import time
from dataclasses import dataclass

from . import rest as REST

LOG_EVERY = 20.0  # s of wall time between progress lines (the project wants one at least every 30 s)


@dataclass
class Run:
    """How a driven run ended: handed to the stepper's result()."""

    status: str  # one of contract.OUTCOMES
    message: str  # one line: why it stopped
    wall_time: float  # s, the loop only
    monitor: REST.Monitor | None  # the rest monitor (dynamic methods), else None
    time_to_rest: float  # s from this run's start to the start of its quiet stretch (NaN unless at rest)


def drive(stepper, rest=None, log=None, every=LOG_EVERY):
    """Advance ``stepper`` until an outcome; returns stepper.result(Run).

    rest: {'energy_ratio', 'window'} (rest.load()) for a method judged at rest by isaflow.rest, None
    for one that is not (its own criterion, if any, is an outcome of advance()); log(text): progress
    lines, at most one every ``every`` s of wall time (None: silent).
    """
    monitor = REST.Monitor(rest["energy_ratio"], rest["window"]) if rest is not None else None
    started = last_log = time.perf_counter()
    status = None
    while status is None:
        outcome = stepper.advance()
        sample = stepper.record()
        at_rest = monitor.update(*sample) if monitor is not None and sample is not None else False
        if outcome is not None:
            status, message = outcome
        elif at_rest:
            status, message = "converged", stepper.rest_message(monitor)
        elif stepper.spent():
            status, message = "step_limit", stepper.limit_message(monitor)
        now = time.perf_counter()
        if log is not None and now - last_log > every:
            log(stepper.progress(monitor))
            last_log = now
    wall_time = time.perf_counter() - started
    at = monitor.time_to_rest() - stepper.t0 if monitor is not None and status == "converged" else math.nan
    result = stepper.result(Run(status, message, wall_time, monitor, at))
    if monitor is not None:
        result.params.update(rest_energy_ratio=monitor.limit, rest_window=monitor.window, time_to_rest=at,
                             final_energy_ratio=monitor.last, start_time=float(stepper.t0))
    return result
