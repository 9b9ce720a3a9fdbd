"""The one run driver (isaflow.driver): its stop decision, rest clock, progress cadence and ETA, snapshots on their
cadence and the at-rest numbers, on toy steppers."""

import dataclasses
import math

import numpy as np

from isaflow import driver

REST = {"energy_ratio": 1e-3, "window": 1.0}


class Toy:
    """A stepper of ``dt`` s per advance: energy ratios ``e`` (one per advance, the last repeated), an outcome
    of its own at advance ``fail`` (1-based), a budget of ``budget`` advances."""

    def __init__(self, e, dt=0.25, t0=10.0, fail=None, budget=100):
        self.e, self.dt, self.t0, self.fail, self.budget = e, dt, t0, fail, budget
        self.k = 0

    def advance(self):
        self.k += 1
        return ("escaped", f"left at advance {self.k}") if self.k == self.fail else None

    def record(self):
        return self.t0 + self.k * self.dt, self.e[min(self.k, len(self.e)) - 1]

    def spent(self):
        return self.k >= self.budget

    def fraction_done(self):
        return self.k / self.budget

    def rest_message(self, monitor):
        return f"at rest since {monitor.time_to_rest():g}"

    def limit_message(self, monitor):
        return f"budget spent, e = {monitor.last:g}" if monitor is not None else "budget spent"

    def progress(self, monitor):
        return f"advance {self.k}"

    def result(self, run):
        return ToyResult(**dataclasses.asdict(run) | {"monitor": run.monitor})


@dataclasses.dataclass
class ToyResult(driver.Run):
    """The Run a toy stepper hands back, with the params a contract.Result carries."""

    params: dict = dataclasses.field(default_factory=dict)
    measures: dict = dataclasses.field(default_factory=dict)
    history: dict = dataclasses.field(default_factory=dict)


def test_at_rest_after_a_window_below_the_ratio_counted_from_the_runs_start():
    run = driver.drive(Toy([1.0, 1.0, 1e-4]), REST)
    # quiet from advance 3 (t = 10.75 s); the window of 1 s is full at advance 7
    assert (run.status, run.message) == ("converged", "at rest since 10.75")
    assert math.isclose(run.time_to_rest, 0.75) and run.wall_time >= 0.0
    # the driver writes what the monitor decided into the result's params, from the run's own start, and the time
    # to rest and the residual speed (sqrt(2 e) over the last window) as variables with units
    assert run.params == {"rest_energy_ratio": 1e-3, "rest_window": 1.0, "final_energy_ratio": 1e-4, "start_time": 10.0}
    assert run.measures["time_to_rest"][1:3] == (0.75, "s")
    assert math.isclose(float(run.measures["residual_speed_ratio"][1]), math.sqrt(2e-4))
    assert run.measures["residual_speed_ratio"][2] == "1"


def test_the_steppers_outcome_comes_before_rest_and_budget():
    assert driver.drive(Toy([1e-4], fail=5, budget=5), REST).status == "escaped"  # at rest and spent too
    run = driver.drive(Toy([1.0], budget=4), REST)
    assert (run.status, run.message) == ("step_limit", "budget spent, e = 1")
    assert math.isnan(run.time_to_rest)
    # not at rest: the variable says why it holds no number (a run file holds no NaN without a reason)
    assert math.isnan(run.measures["time_to_rest"][1]) and "not at rest" in run.measures["time_to_rest"][4]["missing"]


def test_rest_is_judged_only_for_a_method_with_rest_settings():
    run = driver.drive(Toy([0.0], budget=20), None)  # a static method: never at rest by the monitor
    assert run.status == "step_limit" and run.monitor is None and math.isnan(run.time_to_rest)
    assert run.params == {} and run.measures == {}  # nothing of rest added to a static method's result


def test_progress_lines_at_the_cadence():
    lines = []
    driver.drive(Toy([1.0], budget=3), REST, log=lines.append, every=-1.0)  # every advance
    assert [line.split(";")[0] for line in lines] == ["advance 1", "advance 2", "advance 3"]
    # the ETA: the wall time so far against the budget left (a third, then none)
    assert all(line.split("; ")[1].startswith("ETA ") for line in lines) and lines[-1].endswith("ETA 0 s")
    lines.clear()
    driver.drive(Toy([1.0], budget=3), REST, log=lines.append, every=3600.0)
    assert lines == []


def test_eta_reads_as_hours_minutes_seconds():
    assert [driver.eta(t) for t in (0.4, 59.6, 200.0, 3725.0, math.nan, -1.0)] == [
        "ETA 0 s", "ETA 1 min 00 s", "ETA 3 min 20 s", "ETA 1 h 02 min", "ETA unknown", "ETA unknown"]


class Moving(Toy):
    """A toy with a state: N particles in a 10 cm box (walls left, floor, right), falling 1 cm per advance from
    y = 5 cm for ``fall`` advances (then still); particle ``leak`` is put below the floor at advance ``leak_at``."""

    WALLS = np.array([[0.0, 10.0, 0.0, 0.0], [0.0, 0.0, 10.0, 0.0], [10.0, 0.0, 10.0, 10.0]])

    def __init__(self, e, n=4, fall=3, leak=None, leak_at=1, **kw):
        super().__init__(e, **kw)
        self.pos = np.column_stack([np.linspace(1.0, 9.0, n), np.full(n, 5.0)])
        self.fall, self.leak, self.leak_at = fall, leak, leak_at

    def advance(self):
        out = super().advance()
        if self.k <= self.fall:
            self.pos[:, 1] -= 1.0
        if self.leak is not None and self.k == self.leak_at:
            self.pos[self.leak, 1] = -1.0
        return out

    def clock(self):
        return self.t0 + self.k * self.dt, 100 + self.k

    def state(self):
        return {"pos": self.pos.copy(), "velocity": np.ones_like(self.pos), "pressure": np.arange(len(self.pos), 0.0, -1)}

    def result(self, run):
        r = super().result(run)
        r.history["sample_time"] = ((), np.array([self.t0 + self.dt * k for k in range(1, self.k + 1)]), "s", "")
        loads = np.array([[[3.0, 4.0]] * 3 if k % 2 else [[0.0, 2.0]] * 3 for k in range(1, self.k + 1)])
        r.history["sample_wall_resultant"] = ((), loads, "N", "")
        return r


def recording(every, megabytes=1.0):
    return driver.Recording(every, megabytes, Moving.WALLS, [("box", (0.0, 10.0))], (0.0, 0.0, 10.0, 20.0), 2.0)


def test_snapshots_on_their_cadence_with_the_start_and_the_stop():
    run = driver.drive(Moving([1.0], budget=9), REST, recording=recording(0.5))
    h = run.history
    # every 0.5 s of this run's clock (advances of 0.25 s), the start at t0 = 10 s and the stop at 12.25 s
    assert list(h["snap_time"][1]) == [10.0, 10.5, 11.0, 11.5, 12.0, 12.25]
    assert list(h["snap_step"][1]) == [100, 102, 104, 106, 108, 109]
    assert h["snap_pos"][1].shape == (6, 4, 2) and h["snap_pos"][2] == "cm" and h["snap_time"][0] == ("snapshot",)
    assert list(h["snap_pos"][1][:, 0, 1]) == [5.0, 3.0, 2.0, 2.0, 2.0, 2.0]
    assert h["snap_velocity"][1].dtype == np.float32 and h["snap_pressure"][2] == "N cm-2"
    assert (h["snap_vessel"][1] == 0).all() and (h["snap_status"][1] == 0).all()


def test_snapshots_are_thinned_to_their_size_evenly():
    # a snapshot of 4 particles: 64 + 32 + 16 + 8 bytes = 120; 600 bytes hold 5
    run = driver.drive(Moving([1.0], budget=40), REST, recording=recording(0.25, 600e-6))
    t = run.history["snap_time"][1] - 10.0
    assert len(t) <= 6 and list(t[:-1]) == [0.0, 2.0, 4.0, 6.0, 8.0][: len(t) - 1] and t[-1] == 10.0
    assert "every 2 s" in run.history["snap_time"][4]["cadence"]


def test_at_rest_numbers_of_a_run():
    run = driver.drive(Moving([1.0, 1e-4], budget=40, fall=1, leak=2), REST, recording=recording(1.0))
    m = run.measures
    assert run.status == "converged"
    assert m["wall_crossings"][1:3] == (1, "1")  # the particle below the floor, counted once over its states
    assert (run.history["snap_status"][1][:, 2] == 1).sum() >= 1
    # the last 1 s of samples alternate 5 N and 2 N on every wall: mean and standard deviation over the window
    assert np.allclose(m["wall_load_mean"][1], 3.5) and np.allclose(m["wall_load_std"][1], 1.5)
    assert m["wall_load_mean"][0] == ("wall",) and m["wall_load_std"][2] == "N"
    # still over the window: no drift of the surface; sqrt(2 e) with e = 1e-4 over the window
    assert m["surface_drift"][1].shape == (1,) and m["surface_drift"][1][0] == 0.0 and m["surface_drift"][2] == "cm"
    # the surface moves over the window: its drift is the change of the top centres
    moved = driver.drive(Moving([1.0, 1e-4], budget=40, fall=5), REST, recording=recording(1.0))
    assert moved.status == "converged" and moved.measures["surface_drift"][1][0] == -3.0
    assert math.isclose(float(m["residual_speed_ratio"][1]), math.sqrt(2e-4))


def test_snapshot_field_beyond_single_precision_is_written_in_double():
    """A run that blows up (SPH's stab_on_wall: a velocity of 7.5e49 cm/s at its escape) keeps its snapshot
    values as they were, in double precision, instead of inf (a run file never holds inf); ordinary values stay
    single, and a non-finite one becomes NaN (explained by the variable's attrs['missing'])."""
    from isaflow.driver import _single

    big = _single([[[7.5e49, 1.0]]])
    assert big.dtype == np.float64 and big[0, 0, 0] == 7.5e49
    small = _single([[[1.5, np.inf]]])
    assert small.dtype == np.float32 and small[0, 0, 0] == np.float32(1.5) and np.isnan(small[0, 0, 1])
