"""The one run driver of every tank method: drive(stepper) -> contract.Result.

It owns the solve's wall clock (Result.wall_time: the loop only; the stepper is built, and its kernels
warmed, before), the loop, progress lines at a fixed wall-time cadence with an ETA, the rest monitor of
dynamic methods (isaflow.rest, fed by the stepper's samples), the stop decision and the outcome, the
snapshots of the run's state on its declared cadence and the at-rest and wall numbers every run file holds
(AT.AT_REST).  A method supplies a *stepper* and nothing else:

- ``advance()``: one chunk of its compiled loop (ISA, SPH) or one step (MPS); returns None, or
  (status, message) of an outcome its own code detected (escaped, nonfinite, cycle, solver_failed,
  converged by its own criterion, ...);
- ``record()``: records its diagnostics of that advance; returns (t [s], e = KE / (W h)) when it took a
  rest sample, else None (static methods: always None);
- ``spent()``: its step or time budget is used up;
- ``fraction_done()``: the fraction of that budget used, 0 to 1 (the ETA of the progress lines: the wall time so
  far times (1 - done) / done, i.e. the rate so far against t_max or the step budget);
- ``t0``: the chain's time at this run's start [s] (the origin of time_to_rest);
- ``limit_message(monitor)``: the message of 'step_limit'; and ``rest_message(monitor)``, that of 'converged'
  at rest, for a stepper driven with a rest criterion (``rest``) only;
- ``progress(monitor)``: one progress line (the driver adds the ETA);
- ``result(run)``: the contract.Result, from the final :class:`Run`;

and, for a run that keeps snapshots and gets the at-rest numbers (a :class:`Recording` passed to drive):

- ``clock()``: (t [s] on the chain's clock, NaN for a static method; step counted from the chain's start),
  cheap (the driver asks after every advance);
- ``state()``: {'pos' (N, 2) cm, and those it has of 'velocity' (N, 2) cm/s, 'pressure' (N,) N/cm^2,
  'force' (N, 2) N}: copies of the current state.

Snapshots (snap_* in the run file, contract.SHARED_HISTORY): the state at the run's start, then the state
nearest each multiple of ``Recording.every`` on this run's clock (s since t0 for a method with a clock,
steps since the run's first step for a static one), and the state at the stop; with each its time and step,
every particle's vessel (rest.vessel_of) and status (rest.STATUS, past a wall or not); positions
in double precision, velocities, pressures and forces in single (7 digits: states to look at; every measure
is computed from the double-precision state), in double only where a value exceeds single precision's range
(a run that blew up).  When the kept snapshots would take more than
``Recording.megabytes`` (at least two are kept), every other one is dropped and the interval doubles, so a
run file's snapshots stay within that size, evenly spaced (and the stop), whatever the run's length.

The driver adds to the Result's params what the rest monitor decided (rest_energy_ratio, rest_window,
final_energy_ratio, start_time: the same names and time origin for every dynamic method) and to its
measures the AT_REST numbers (isaflow.at_rest): time_to_rest, residual_speed_ratio, surface_drift, wall_loads
over the last rest window (dynamic methods), wall_crossings, and force_max / force_rms at the stop for a
static method (its state has a force and no clock).

Per advance the decision is: the stepper's outcome, else ``converged`` once the monitor is at rest,
else ``step_limit`` once the budget is spent, else go on.
"""

import collections
import math
import time
from dataclasses import dataclass

import numpy as np

from . import at_rest as AT, rest as REST

LOG_EVERY = 20.0  # s of wall time between progress lines (the project wants one at least every 30 s)
WINDOW_STATES = 20  # states kept per rest window for the surface drift (its start is found to window / 20)


@dataclass
class Run:
    """How a driven run ended: handed to the stepper's result()."""

    status: str  # one of contract.OUTCOMES
    message: str  # one line: why it stopped
    wall_time: float  # s, the loop only
    monitor: REST.Monitor | None  # the rest monitor (dynamic methods), else None
    time_to_rest: float  # s from this run's start to the start of its quiet stretch (NaN unless at rest)


@dataclass
class Recording:
    """What the driver records of a run beside the stepper's own diagnostics (module docstring).

    every: snapshot interval on this run's clock (s of the chain's clock if timed, else steps; None: no
    snapshots but the start and the stop); megabytes: the most the kept snapshots may take (10^6 bytes, the
    run file's arrays before compression) before they are thinned; walls (W, 4) cm;
    vessels [(name, (xmin, xmax))]; box (x0, y0, x1, y1) cm, the tank's box open above its walls
    (Tank.escape_box); spacing: strip width [cm] of the free surface; timed: the cadence is in s (a
    method with a clock), else in steps."""

    every: float | None
    megabytes: float
    walls: np.ndarray
    vessels: list
    box: tuple
    spacing: float
    timed: bool = True


def eta(seconds):
    """The wall time left, as 'ETA 1 h 02 min', 'ETA 3 min 20 s' or 'ETA 45 s' ('ETA unknown' before any rate)."""
    if not math.isfinite(seconds) or seconds < 0:
        return "ETA unknown"
    s = int(round(seconds))
    if s >= 3600:
        return f"ETA {s // 3600} h {s % 3600 // 60:02d} min"
    return f"ETA {s // 60} min {s % 60:02d} s" if s >= 60 else f"ETA {s} s"


class _Snapshots:
    """The snapshots of one run on its cadence (module docstring), and the particles ever past a wall."""

    def __init__(self, rec, clock0):
        self.rec, self.every = rec, rec.every
        self.timed = rec.timed  # the cadence is in s since t0, else in steps
        self.clocked = math.isfinite(clock0[0])  # the method has a clock: snap_time is written
        self.origin = clock0[0] if self.timed else clock0[1]
        self.taken = []  # (grid index, clock, state, past a wall)
        self.limit = None  # snapshots that fit Recording.megabytes (set by the first one)
        self.next, self.last = 1, 0.0  # next grid index due; this run's clock at the last check
        self.past = None  # (N,) bool: found past a wall in some snapshot or at the stop

    def _elapsed(self, clock):
        return clock[0] - self.origin if self.timed else float(clock[1] - self.origin)

    def take(self, stepper, clock, index):
        """Keep the current state as snapshot ``index`` of the grid; returns it (double precision)."""
        raw = stepper.state()
        state = {k: np.array(v, float) for k, v in raw.items()}  # single precision is chosen in history()
        out = AT.outside_tank(state["pos"], self.rec.walls, self.rec.box)
        if self.limit is None:  # the bytes of one snapshot as written: positions in double, the other arrays
            # in single precision, the vessel and status (one byte each)
            size = state["pos"].nbytes + sum(4 * a.size for k, a in state.items() if k != "pos") + 2 * len(state["pos"])
            self.limit = max(2, int(self.rec.megabytes * 1e6 // size))
        self.past = out if self.past is None else self.past | out
        self.taken.append((index, clock, state, out))
        return raw

    def check(self, stepper):
        """Take a snapshot when one is due after an advance (the state nearest the due time: within half the
        advance's length of it), thinning the kept ones when they exceed the limit."""
        clock = stepper.clock()
        now = self._elapsed(clock)
        half = 0.5 * (now - self.last)
        self.last = now
        if self.every is None or now < self.next * self.every - half:
            return
        self.take(stepper, clock, self.next)
        self.next = int(math.floor((now + half) / self.every)) + 1
        while len(self.taken) > self.limit:
            self.taken = [(i // 2, *rest) for i, *rest in self.taken if i % 2 == 0]
            self.every *= 2
            self.next = max(self.taken[-1][0] + 1, int(math.floor((now + half) / self.every)) + 1)

    def final(self, stepper):
        """The state at the stop (a snapshot unless the last one already is it); returns it."""
        clock = stepper.clock()
        if self.taken and self.taken[-1][1] == clock:
            return stepper.state()
        return self.take(stepper, clock, -1)

    def history(self):
        """{snap_* name: (dims, array, units, long_name[, attrs])} of the kept snapshots."""
        from .contract import SHARED_HISTORY

        clocks = [c for _, c, _, _ in self.taken]
        states = [s for _, _, s, _ in self.taken]
        arrays = {"snap_step": np.array([c[1] for c in clocks], np.int64),
                  "snap_pos": np.array([s["pos"] for s in states], float),
                  "snap_vessel": np.array([AT.vessel_of(s["pos"], self.rec.vessels) for s in states], np.int8),
                  "snap_status": np.array([o for _, _, _, o in self.taken], np.int8)}
        if self.clocked:
            arrays["snap_time"] = np.array([c[0] for c in clocks], float)
        for key in ("velocity", "pressure", "force"):
            if key in states[0]:
                arrays[f"snap_{key}"] = _single([s[key] for s in states])
        what = {"snap_time": "chain time of the snapshot", "snap_step": "step of the snapshot (from the chain's start)",
                "snap_pos": "particle positions at the snapshot", "snap_velocity": "particle velocities at the snapshot",
                "snap_pressure": "particle pressures at the snapshot",
                "snap_force": "out-of-balance force on each particle at the snapshot",
                "snap_vessel": "index of the vessel whose x range holds the particle (-1: none)",
                "snap_status": "0: in the tank, 1: past a wall (rest.STATUS)"}
        unit = "s" if self.timed else "steps"
        thinned = f"thinned from every {self.rec.every:g} {unit}, " if self.every != self.rec.every else ""
        cadence = (f"the start, every {self.every:g} {unit} of this run ({thinned}at most {self.limit} kept: "
                   f"{self.rec.megabytes:g} MB) and the stop" if self.every is not None else "the start and the stop")
        missing = {"missing": "not known at that state (a static method's force before its first evaluation, or a run "
                              "that became non-finite)"}
        return {k: (SHARED_HISTORY[k][0], a, SHARED_HISTORY[k][1], what[k],
                    {"cadence": cadence, **(missing if a.dtype.kind == "f" and np.isnan(a).any() else {})})
                for k, a in arrays.items()}


def _single(states):
    """The snapshots' arrays of one field in single precision (7 digits: states to look at), or in double where
    a value lies beyond single precision's range (a run blowing up: its escape is then written as it was, not as
    inf); a non-finite value becomes NaN, which the variable's attrs['missing'] explains."""
    a = np.array(states, float)
    finite = np.isfinite(a)
    a[~finite] = np.nan
    big = np.abs(a[finite]).max(initial=0.0) > np.finfo(np.float32).max
    return a if big else a.astype(np.float32)


class _Window:
    """States over the last rest window (at most WINDOW_STATES + 1 of them), for the surface's drift over it."""

    def __init__(self, window):
        self.window = window
        self.states = collections.deque()

    def add(self, t, stepper):
        if self.states and t < self.states[-1][0] + self.window / WINDOW_STATES:
            return
        self.states.append((t, stepper.state()["pos"]))
        while len(self.states) > 1 and self.states[1][0] <= t - self.window + 1e-12:
            self.states.popleft()

    def start(self):
        """The kept state at (or just before) the start of the last window, None if none."""
        return self.states[0][1] if self.states else None


def _rest_measures(monitor, samples, at):
    """time_to_rest and residual_speed_ratio (AT.AT_REST) of a run judged at rest -> {name: variable}."""
    m = AT.measure
    times, ratios = zip(*samples) if samples else ((), ())
    ratio = AT.residual_speed_ratio(times, ratios, monitor.window)
    return {"time_to_rest": m("time_to_rest", at, None if math.isfinite(at) else "not at rest when the run stopped"),
            "residual_speed_ratio": m("residual_speed_ratio", ratio, None if math.isfinite(ratio) else "no rest sample")}


def _measures(result, rec, snaps, monitor, window_start, final):
    """The AT_REST numbers of a recorded run beyond _rest_measures' (isaflow.rest) -> {name: run-file variable}."""
    m = AT.measure
    out = {"wall_crossings": m("wall_crossings", int(np.count_nonzero(snaps.past)))}
    if "force" in final:  # a static method: its out-of-balance force at the stop
        fmax, frms = AT.force_stats(final["force"])
        out.update(force_max=m("force_max", fmax), force_rms=m("force_rms", frms))
    if monitor is None:
        return out
    if window_start is not None:
        drift = (AT.surface_levels(final["pos"], rec.spacing, rec.vessels)
                 - AT.surface_levels(window_start, rec.spacing, rec.vessels))
        out["surface_drift"] = m("surface_drift", drift, "a vessel without liquid at the window's start or at the stop"
                                 if not np.isfinite(drift).all() else None)
    h = result.history
    if "sample_time" in h and "sample_wall_resultant" in h:
        mean, std = AT.wall_load_stats(h["sample_time"][1], h["sample_wall_resultant"][1], monitor.window)
        missing = None if np.isfinite(mean).all() else "no wall-load sample"
        out.update(wall_load_mean=m("wall_load_mean", mean, missing), wall_load_std=m("wall_load_std", std, missing))
    return out


def rest_params(limit, window, last, t0):
    """The rest attributes of a run judged at rest (its Result.params): the criterion's e limit and window [s], the
    last e and the chain's time at the run's start [s]; one set of names for the driver's monitor and for a method
    whose rest test is compiled into its own loop (ISA's overdamped variant)."""
    return dict(rest_energy_ratio=float(limit), rest_window=float(window), final_energy_ratio=float(last),
                start_time=float(t0))


def drive(stepper, rest=None, log=None, every=LOG_EVERY, recording=None):
    """Advance ``stepper`` until an outcome; returns stepper.result(Run).

    rest: {'energy_ratio', 'window'} (rest.load()) for a method judged at rest by isaflow.rest, None
    for one that is not (its own criterion, if any, is an outcome of advance()); log(text): progress
    lines with an ETA, at most one every ``every`` s of wall time (None: silent); recording: a
    :class:`Recording` for a run that keeps snapshots and gets the AT_REST numbers (None: neither).
    """
    monitor = REST.Monitor(rest["energy_ratio"], rest["window"]) if rest is not None else None
    snaps = _Snapshots(recording, stepper.clock()) if recording is not None else None
    window = _Window(monitor.window) if snaps is not None and monitor is not None else None
    samples = []  # (t, e) of every rest sample
    started = last_log = time.perf_counter()
    if snaps is not None:
        snaps.take(stepper, stepper.clock(), 0)  # the run's start (outside the timed loop's work)
        started = last_log = time.perf_counter()
    status = None
    while status is None:
        outcome = stepper.advance()
        sample = stepper.record()
        at_rest = monitor.update(*sample) if monitor is not None and sample is not None else False
        if sample is not None and monitor is not None:
            samples.append(sample)
            if window is not None:
                window.add(sample[0], stepper)
        if outcome is not None:
            status, message = outcome
        elif at_rest:
            status, message = "converged", stepper.rest_message(monitor)
        elif stepper.spent():
            status, message = "step_limit", stepper.limit_message(monitor)
        if snaps is not None and status is None:
            snaps.check(stepper)
        now = time.perf_counter()
        if log is not None and now - last_log > every:
            done = stepper.fraction_done()
            log(f"{stepper.progress(monitor)}; {eta((now - started) * (1 - done) / done if done > 0 else math.nan)}")
            last_log = now
    wall_time = time.perf_counter() - started
    at = monitor.time_to_rest() - stepper.t0 if monitor is not None and status == "converged" else math.nan
    final = snaps.final(stepper) if snaps is not None else None
    result = stepper.result(Run(status, message, wall_time, monitor, at))
    if monitor is not None:
        result.params.update(rest_params(monitor.limit, monitor.window, monitor.last, stepper.t0))
        result.measures.update(_rest_measures(monitor, samples, at))
    if snaps is not None:
        result.history.update(snaps.history())
        result.measures.update(_measures(result, recording, snaps, monitor,
                                         window.start() if window is not None else None, final))
    return result
