"""The one run driver (isaflow.driver): its stop decision, rest clock and progress cadence, on toy steppers."""

import dataclasses
import math

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


def test_at_rest_after_a_window_below_the_ratio_counted_from_the_runs_start():
    run = driver.drive(Toy([1.0, 1.0, 1e-4]), REST)
    # quiet from advance 3 (t = 10.75 s); the window of 1 s is full at advance 7
    assert (run.status, run.message) == ("converged", "at rest since 10.75")
    assert math.isclose(run.time_to_rest, 0.75) and run.wall_time >= 0.0
    # the driver writes what the monitor decided into the result's params, from the run's own start
    assert run.params == {"rest_energy_ratio": 1e-3, "rest_window": 1.0, "time_to_rest": run.time_to_rest,
                          "final_energy_ratio": 1e-4, "start_time": 10.0}


def test_the_steppers_outcome_comes_before_rest_and_budget():
    assert driver.drive(Toy([1e-4], fail=5, budget=5), REST).status == "escaped"  # at rest and spent too
    run = driver.drive(Toy([1.0], budget=4), REST)
    assert (run.status, run.message) == ("step_limit", "budget spent, e = 1")
    assert math.isnan(run.time_to_rest)


def test_rest_is_judged_only_for_a_method_with_rest_settings():
    run = driver.drive(Toy([0.0], budget=20), None)  # a static method: never at rest by the monitor
    assert run.status == "step_limit" and run.monitor is None and math.isnan(run.time_to_rest)
    assert run.params == {}  # nothing of rest added to a static method's result


def test_progress_lines_at_the_cadence():
    lines = []
    driver.drive(Toy([1.0], budget=3), REST, log=lines.append, every=-1.0)  # every advance
    assert lines == ["advance 1", "advance 2", "advance 3"]
    lines.clear()
    driver.drive(Toy([1.0], budget=3), REST, log=lines.append, every=3600.0)
    assert lines == []
